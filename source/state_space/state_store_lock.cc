// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The writer's lock (StoreLock): one process at a time appends to a store.
// Apart from the HDF5 code because it is about processes, not the file's
// format: a kernel lock on a file beside the store, shared within a
// process, and the holder named to a process that is refused.

#include <palpate/state_space/state_store_impl.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>

namespace palpate
{
  using internal::acquire_lock;
  using internal::check_store_file;
  using internal::store_error;


  // Why a lock file of our own, with flock: HDF5 1.10 locks the file it
  // opens, but a SWMR writer drops that lock as soon as it has marked the
  // superblock "open for writing"; a second writer then finds the mark and
  // is refused. The mark is also what a killed writer leaves, and it cannot
  // tell a live writer from a dead one: cleared by a writer that cannot
  // know (open() clears it only holding this lock), two writers would
  // interleave their rows. A kernel lock can tell them apart: flock belongs
  // to the open file and goes with the process, however it ends. The lock
  // is on `STORE.lock`, not on the store: the store does not exist before
  // its first state, is created under another name and renamed (and once
  // more when the first state fixes the record sizes), and HDF5 takes and
  // drops flocks of its own on it, which would release ours (flock is per
  // open file, and a process may have the store open twice). fcntl locks
  // would not survive that either: they go when the process closes any
  // descriptor of the file.

  StoreLock::Held::~Held()
  {
    // Removed while still locked, so that nobody takes a lock on a file
    // about to vanish unseen (acquire_lock() checks that the file it locked is
    // still the one at the path). A process forked from the holder shares
    // its lock but leaves the file alone.
    if (pid == getpid())
      unlink(lock_file.c_str());
    if (fd >= 0)
      close(fd);
  }



  namespace
  {
    std::mutex &
    lock_registry_mutex()
    {
      static std::mutex m;
      return m;
    }

    /** The locks this process holds, by lock file: a second StateStore or
     * StoreLock of the same store shares the lock instead of failing on
     * it (flock would refuse a second descriptor of the same process). */
    std::map<std::string, std::weak_ptr<StoreLock::Held>> &
    lock_registry()
    {
      static std::map<std::string, std::weak_ptr<StoreLock::Held>> r;
      return r;
    }

    /** This process's command line, for the lock file. */
    std::string
    command_line()
    {
      std::ifstream in("/proc/self/cmdline", std::ios::binary);
      std::string   c((std::istreambuf_iterator<char>(in)),
                    std::istreambuf_iterator<char>());
      while (!c.empty() && c.back() == '\0')
        c.pop_back();
      std::replace(c.begin(), c.end(), '\0', ' ');
      std::replace(c.begin(), c.end(), '\n', ' ');
      if (c.size() > 300)
        c = c.substr(0, 300) + "...";
      return c.empty() ? "(unknown)" : c;
    }

    std::string
    utc_now()
    {
      const std::time_t t = std::time(nullptr);
      std::tm           tm{};
      gmtime_r(&t, &tm);
      char s[32];
      std::strftime(s, sizeof(s), "%Y-%m-%d %H:%M:%S UTC", &tm);
      return s;
    }

    /** The value of "KEY value" in the text of a lock file, or "". */
    std::string
    lock_entry(const std::string &text, const std::string &key)
    {
      std::istringstream in(text);
      std::string        line;
      while (std::getline(in, line))
        if (line.compare(0, key.size() + 1, key + " ") == 0)
          return line.substr(key.size() + 1);
      return "";
    }



    // acquire_lock(), a step: the path the lock is taken for, the same for
    // every name of the store, and the refusal of a store with hard links.
    std::filesystem::path
    lock_target(const std::string &store)
    {
      // One lock per store file, whatever name it is given: the lock file
      // sits beside the file symbolic links lead to.
      std::error_code       error;
      std::filesystem::path where = std::filesystem::absolute(store, error);
      if (error)
        where = store;
      const auto canonical = std::filesystem::weakly_canonical(where, error);
      if (!error)
        where = canonical;
      // Symbolic links lead to one lock; hard links do not (each name has
      // its own lock file), so two writers through two names would append
      // to the same rows. A store with more than one name is refused.
      if (struct stat st; stat(where.c_str(), &st) == 0 &&
                          S_ISREG(st.st_mode) && st.st_nlink > 1)
        store_error(store,
                    "the store has " + std::to_string(st.st_nlink) +
                      " names (hard links to one file): the lock that keeps "
                      "a second writer out is taken by name, so two "
                      "processes could write it through two names at once",
                    "keep one name: remove the other links (find them with "
                    "'find / -samefile " +
                      where.string() +
                      "'), or copy the store to a file of its own.");
      return where;
    }



    // acquire_lock(), a step: the lock file opened (made if needed), or the
    // store refused with what keeps palpate from making it.
    int
    open_lock_file(const std::string &store, const std::string &lock_file)
    {
      const int fd =
        open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
      if (fd < 0)
        {
          const int         e = errno;
          const std::string dir =
            std::filesystem::path(lock_file).parent_path().string();
          if (e == EACCES || e == EPERM || e == EROFS)
            store_error(store,
                        "palpate cannot make the lock file '" + lock_file +
                          "' beside the store (" + std::strerror(e) +
                          "): a writer takes it so that no other "
                          "process writes the store at the same time",
                        "make the directory '" + dir +
                          "' writable for this user, or name a store in "
                          "a directory you can write (State space / "
                          "Store).");
          store_error(store,
                      "palpate cannot make the lock file '" + lock_file +
                        "' beside the store: " + std::strerror(e),
                      "name a store in a directory that exists and "
                      "that you can write (State space / Store).");
        }
      return fd;
    }



    // acquire_lock(), a step: the refusal when the lock file @p fd cannot be
    // locked (errno @p e): its holder named, or the file system blamed.
    [[noreturn]] void
    refuse_lock(const std::string &store,
                const std::string &lock_file,
                const int          fd,
                const int          e)
    {
      if (e != EWOULDBLOCK)
        {
          close(fd);
          store_error(store,
                      "the file system does not lock the file '" + lock_file +
                        "' (" + std::strerror(e) +
                        "), and without a lock two processes could "
                        "write the store at once",
                      "name a store on a local file system (State "
                      "space / Store).");
        }
      // Somebody holds it: say who, from what it wrote there.
      std::string text(4096, '\0');
      const auto  n = pread(fd, text.data(), text.size(), 0);
      close(fd);
      text.resize(n > 0 ? n : 0);
      const std::string pid     = lock_entry(text, "pid");
      const std::string command = lock_entry(text, "command");
      const std::string since   = lock_entry(text, "since");
      const std::string who =
        pid.empty() ?
          "another process (its lock file '" + lock_file +
            "' does not say which yet)" :
          "process " + pid +
            (command.empty() ? std::string() : " ('" + command + "')") +
            (since.empty() ? std::string() : ", since " + since) +
            ", by its lock file '" + lock_file + "'";
      store_error(store,
                  "another process is writing this store: " + who +
                    ". Two writers would append to the same rows and damage "
                    "each other's records, so this one does not start",
                  "wait until it ends, or stop it" +
                    (pid.empty() ? std::string() : " (kill " + pid + ")") +
                    ": palpate stops cleanly and keeps every state it "
                    "stored; or give this run a store of its own (State "
                    "space / Store = another file).");
    }



    // acquire_lock(), a step: the holder's pid, command and start written
    // into the locked file @p fd, for a process that is refused.
    void
    write_holder(const int fd, const std::filesystem::path &where)
    {
      // Ours. Say who we are, for a process that is refused (it is
      // only information: the lock is the flock, not the text).
      const std::string text = "pid " + std::to_string(getpid()) +
                               "\ncommand " + command_line() + "\nstore " +
                               where.string() + "\nsince " + utc_now() + "\n";
      if (ftruncate(fd, 0) == 0)
        {
          const auto written = pwrite(fd, text.data(), text.size(), 0);
          (void)written;
        }
    }
  } // namespace



  namespace internal
  {
    std::shared_ptr<StoreLock::Held>
    acquire_lock(const std::string &store)
    {
      const std::filesystem::path where     = lock_target(store);
      const std::string           lock_file = where.string() + ".lock";

      std::lock_guard<std::mutex> registry_lock(lock_registry_mutex());
      auto                       &entry = lock_registry()[lock_file];
      if (auto held = entry.lock(); held && held->pid == getpid())
        return held;

      // A few rounds: the holder may remove its lock file just as we lock
      // it (see ~Held); then the file at the path is a new one.
      for (unsigned int round = 0; round < 20; ++round)
        {
          const int fd = open_lock_file(store, lock_file);
          if (flock(fd, LOCK_EX | LOCK_NB) != 0)
            refuse_lock(store, lock_file, fd, errno);
          struct stat locked, at_path;
          if (fstat(fd, &locked) != 0 ||
              stat(lock_file.c_str(), &at_path) != 0 ||
              locked.st_ino != at_path.st_ino ||
              locked.st_dev != at_path.st_dev)
            {
              close(fd);
              continue;
            }
          write_holder(fd, where);
          auto held       = std::make_shared<StoreLock::Held>();
          held->store     = store;
          held->lock_file = lock_file;
          held->fd        = fd;
          held->pid       = getpid();
          entry           = held;
          return held;
        }
      store_error(store,
                  "palpate could not take the lock file '" + lock_file +
                    "': it was removed and made again 20 times while "
                    "locking it",
                  "check what else makes and removes files there, then run "
                  "again.");
    }
  } // namespace internal



  StoreLock::StoreLock(const std::string &store)
  {
    // What is wrong with the store itself is said before any lock: a
    // directory, no permission, not a store.
    check_store_file(store, true);
    held = acquire_lock(store);
  }



  StoreLock::~StoreLock() = default;



  const std::string &
  StoreLock::lock_file() const
  {
    return held->lock_file;
  }



  std::string
  StoreLock::failure() const
  {
    std::lock_guard<std::mutex> lock(held->mutex);
    return held->failure;
  }
} // namespace palpate
