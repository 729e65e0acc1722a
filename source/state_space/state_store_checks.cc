// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// What a file is before HDF5 sees it: a name that fits, a path where a
// store can be made, a regular file this process may open as HDF5 will,
// an HDF5 file. Apart from the HDF5 code so that every refusal here says
// what is wrong (a directory, no permission, a text file) and a file that
// is fine but not writable never reaches HDF5, which would call it damaged.

#include <palpate/base/exceptions.h>
#include <palpate/state_space/state_store_impl.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <filesystem>

namespace palpate
{
  namespace internal
  {
    [[noreturn]] void
    store_error(const std::string &store,
                const std::string &problem,
                const std::string &fix)
    {
      throw InputError(store, 0, "State space / Store", problem, fix);
    }
  } // namespace internal



  using internal::store_error;

  namespace
  {
    /** "mode -r--r--r--, owner uid 0" of @p st. */
    std::string
    describe_mode(const struct stat &st)
    {
      std::string m = "-rwxrwxrwx";
      for (unsigned int i = 0; i < 9; ++i)
        if ((st.st_mode & (0400 >> i)) == 0)
          m[1 + i] = '-';
      return "mode " + m + ", owner uid " + std::to_string(st.st_uid) +
             ", this process uid " + std::to_string(geteuid());
    }

    /**
     * Refuse, for @p writing, a file name too long for the files a writer
     * makes beside the store.
     */
    void
    check_name_length(const std::string           &file,
                      const std::filesystem::path &path,
                      const bool                   writing)
    {
      // A writer makes STORE.lock and STORE.creating beside it: their
      // names, 9 characters longer, must fit the file system's limit too
      // (NAME_MAX, 255 on Linux), or the failure looks like a full disk.
      if (const std::size_t n = path.filename().string().size();
          writing && n + std::strlen(".creating") > NAME_MAX)
        {
          // The limit is in bytes; a character outside ASCII takes 2-4 of
          // them in UTF-8, so a name's characters are said too when they
          // differ.
          const std::string name       = path.filename().string();
          std::size_t       characters = 0;
          for (const char c : name)
            characters += (static_cast<unsigned char>(c) & 0xc0) != 0x80;
          store_error(
            file,
            "its file name has " + std::to_string(n) + " bytes" +
              (characters != n ?
                 " (" + std::to_string(characters) +
                   " characters: one outside ASCII takes 2-4 bytes in "
                   "UTF-8)" :
                 std::string()) +
              "; palpate makes NAME.creating and NAME.lock beside it, and "
              "a file name may have at most " +
              std::to_string(NAME_MAX) + " bytes",
            "use a name of at most " +
              std::to_string(NAME_MAX - std::strlen(".creating")) +
              " bytes (as many ASCII characters), e.g. 'liver.h5'.");
        }
    }

    /**
     * A store that does not exist yet: a reader has nothing to read; a
     * writer needs a directory it can make files in.
     */
    void
    check_store_can_be_made(const std::string           &file,
                            const std::filesystem::path &path,
                            const bool                   writing)
    {
      namespace fs = std::filesystem;
      if (!writing)
        store_error(file,
                    "there is no store at this path",
                    "name an existing store, or make one with palpate "
                    "precompute SCENE.prm.");
      // A link to nowhere: the store, made under a temporary name and
      // renamed, would replace the link, and its target would never be made.
      if (const std::string link = dangling_link(path.string()); !link.empty())
        store_error(file,
                    link,
                    "name the store by the link's target instead (in a "
                    "directory that exists), or remove the link (rm '" +
                      path.string() + "') to make the store here.");
      std::error_code error;
      const fs::path  dir =
        path.has_parent_path() ? path.parent_path() : fs::path(".");
      if (const std::string link = dangling_link(dir.string()); !link.empty())
        store_error(file,
                    "its directory " + link,
                    "make the link's target, or name a store in a "
                    "directory that exists.");
      const fs::file_status d = fs::status(dir, error);
      if (d.type() == fs::file_type::not_found)
        store_error(file,
                    "its directory '" + dir.string() +
                      "' does not exist, so the store cannot be made",
                    "make the directory (mkdir -p '" + dir.string() +
                      "') or name a store in one that exists.");
      if (d.type() != fs::file_type::directory)
        store_error(file,
                    "'" + dir.string() + "' is not a directory",
                    "name a store file in a directory, e.g. "
                    "'liver.h5'.");
      if (access(dir.c_str(), W_OK | X_OK) != 0)
        {
          const int e = errno;
          store_error(file,
                      e == EROFS ?
                        "its directory '" + dir.string() +
                          "' is on a read-only file system, so the "
                          "store cannot be made" :
                        "permission denied: palpate cannot make files "
                        "in its directory '" +
                          dir.string() + "' (" + std::strerror(e) + ")",
                      "name a store in a directory this user can "
                      "write, or make this one writable.");
        }
    }

    /** Refuse a directory, a device, a pipe or a socket as a store. */
    void
    check_regular_file(const std::string                 &file,
                       const std::filesystem::path       &path,
                       const std::filesystem::file_status status)
    {
      namespace fs = std::filesystem;
      if (status.type() == fs::file_type::directory)
        store_error(file,
                    "this is a directory, not a store file",
                    "name a file, e.g. '" +
                      (path / "liver.h5").lexically_normal().string() +
                      "' (palpate makes it).");
      if (status.type() != fs::file_type::regular)
        {
          const auto  t    = status.type();
          const char *kind = t == fs::file_type::character ?
                               "character device" :
                             t == fs::file_type::block  ? "block device" :
                             t == fs::file_type::fifo   ? "FIFO (named pipe)" :
                             t == fs::file_type::socket ? "socket" :
                                                          "special file";
          store_error(file,
                      std::string("this is a ") + kind +
                        ", not a regular file; a store is a file that "
                        "palpate reads and appends to",
                      "name a store file, e.g. 'liver.h5' (palpate makes "
                      "it if it does not exist).");
        }
    }

    /**
     * Open @p file as HDF5 will (read and write if @p writing); say why
     * this process cannot, without calling the store damaged.
     */
    int
    open_as_hdf5_will(const std::string &file, const bool writing)
    {
      // Permissions as this process has them: open it as HDF5 will.
      const int fd =
        open(file.c_str(), (writing ? O_RDWR : O_RDONLY) | O_CLOEXEC);
      if (fd >= 0)
        return fd;
      const int   e = errno;
      struct stat st
      {};
      stat(file.c_str(), &st);
      const bool readable = access(file.c_str(), R_OK) == 0;
      if (e == EROFS)
        store_error(file,
                    "the store is on a read-only file system, and "
                    "palpate appends to it the states it computes",
                    "copy it to a writable place and name the copy in "
                    "State space / Store (its states are loaded from "
                    "there), or mount the file system writable.");
      if (e == EACCES || e == EPERM)
        store_error(
          file,
          std::string("permission denied: palpate can ") +
            (writing && readable ? "read this store but not write it" :
                                   "not read this store") +
            " (" + describe_mode(st) + "). The store itself is not damaged",
          (st.st_uid == geteuid() ?
             "give yourself permission: chmod u+" +
               std::string(writing ? "rw" : "r") + " '" + file + "'" :
             "ask its owner (uid " + std::to_string(st.st_uid) + ") for " +
               (writing ? "read and write" : "read") +
               " permission, or run as that user") +
            "; to use its states without appending, copy it to a file "
            "you can write and name the copy in State space / Store. "
            "Do not delete it: its states are fine.");
      store_error(file,
                  std::string("palpate cannot open it: ") + std::strerror(e),
                  "check the file and its permissions.");
    }

    /**
     * Refuse an empty file and one that is not HDF5 (named as text when it
     * is); closes @p fd.
     */
    void
    check_hdf5_signature(const std::string &file, const int fd)
    {
      // An HDF5 file begins with its signature, at byte 0 or after a user
      // block of 512, 1024, 2048, ... bytes.
      struct stat st
      {};
      fstat(fd, &st);
      static const char signature[8] = {
        '\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
      bool        hdf5 = false;
      std::string head(64, '\0');
      const auto  n = pread(fd, head.data(), head.size(), 0);
      head.resize(n > 0 ? n : 0);
      for (off_t at = 0; !hdf5 && at + 8 <= st.st_size;
           at       = at == 0 ? 512 : 2 * at)
        {
                char bytes[8];
                hdf5 = pread(fd, bytes, 8, at) == 8 &&
                       std::memcmp(bytes, signature, 8) == 0;
        }
      close(fd);
      if (st.st_size == 0)
        store_error(file,
                    "the file is empty, so it is not a state store (palpate "
                    "never leaves an empty one: it makes a store under a "
                    "temporary name and renames it when it is complete)",
                    "name another store file, or remove this empty one: "
                    "palpate then makes the store.");
      if (!hdf5)
        {
          const bool text =
            std::all_of(head.begin(), head.end(), [](const char c) {
              return c == '\n' || c == '\t' || c == '\r' ||
                     (static_cast<unsigned char>(c) >= 32 &&
                      static_cast<unsigned char>(c) < 127);
            });
          std::string first = head.substr(0, head.find('\n'));
          if (first.size() > 40)
            first = first.substr(0, 40) + "...";
          store_error(file,
                      "this is not an HDF5 file, so not a state store: " +
                        (text ? "it is text, beginning '" + first + "'" :
                                std::string("it does not begin with HDF5's "
                                            "signature")),
                      "State space / Store names the HDF5 file palpate "
                      "keeps the states in (e.g. 'liver.h5'; made if it "
                      "does not exist); this file is something else: name "
                      "another one.");
        }
    }
  } // namespace



  namespace internal
  {
    bool
    check_store_file(const std::string &file, const bool writing)
    {
      namespace fs = std::filesystem;
      std::error_code error;
      const fs::path  path(file);
      check_name_length(file, path, writing);
      const fs::file_status status = fs::status(path, error);
      if (status.type() == fs::file_type::none ||
          (error && status.type() != fs::file_type::not_found))
        store_error(file,
                    "the file system refuses this path: " + error.message(),
                    "name a store file in a directory you can write, e.g. "
                    "'liver.h5'.");
      if (status.type() == fs::file_type::not_found)
        {
          check_store_can_be_made(file, path, writing);
          return false;
        }
      check_regular_file(file, path, status);
      check_hdf5_signature(file, open_as_hdf5_will(file, writing));
      return true;
    }
  } // namespace internal
} // namespace palpate
