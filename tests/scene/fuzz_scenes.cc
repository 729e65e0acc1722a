// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Fuzzing the scene reader: 10,000 mutations (seeded, so the counts below
// are the same on every run) of the shipped scenes: bytes flipped, ranges
// deleted, lines duplicated, swapped, dropped or taken from another scene,
// keywords and nasty values (nan, 1e308, 1e-320, huge integers, 10,000
// characters, lists of the wrong length) put in. Every mutant must either
// be read or give an InputError: any other exception, a crash, or a read
// slower than 2 s of CPU time fails the test.
//
// The mutants that are read are then set up as palpate does (mesh, node
// selection), and those on a small mesh are solved to the active node's
// prescribed displacement (or 5 mm down): a solve that reports convergence
// must give a finite force. "exit 0 with a non-finite force" would show
// here.

#include <palpate/hyperelastic/state_solver.h>
#include <palpate/mesh/mesh.h>
#include <palpate/mesh/node_selection.h>

#include <cmath>
#include <filesystem>
#include <mutex>
#include <random>
#include <thread>

#include "../tests.h"

#include "../fuzz.h"

namespace
{
  const std::vector<std::string> tokens = {"subsection ",
                                           "end",
                                           "set ",
                                           " = ",
                                           "=",
                                           "#",
                                           "\\",
                                           "\n",
                                           "\t",
                                           "\r",
                                           ",",
                                           " ",
                                           "subsection Mesh\n",
                                           "end\n",
                                           "set Source = file\n",
                                           "include x.prm\n",
                                           "\xff\xfe",
                                           "\xc3\xa9",
                                           "subsection Material model\n"};

  const std::vector<std::string> values = {"",
                                           "0",
                                           "-1",
                                           "1e308",
                                           "-1e308",
                                           "1e-320",
                                           "nan",
                                           "inf",
                                           "1e9",
                                           "2147483648",
                                           "-2147483649",
                                           "0x1p3",
                                           "1,2",
                                           "1, 2, 3, 4",
                                           "0, 0, 0",
                                           "1e6, 1e6, 1e6",
                                           "a",
                                           "true",
                                           "St.Venant-Kirchhoff",
                                           "Mooney-Rivlin",
                                           "0.5",
                                           "0.4999999",
                                           "1e-12",
                                           "3",
                                           "1000",
                                           std::string(10000, '7')};

  /** Uniform in [0, n) from our own generator (the same on every
   * platform, unlike std::uniform_int_distribution). */
  std::size_t
  pick(std::mt19937 &rng, const std::size_t n)
  {
    return n == 0 ? 0 : rng() % n;
  }

  std::vector<std::string>
  lines_of(const std::string &s)
  {
    std::vector<std::string> lines;
    std::size_t              start = 0;
    while (start < s.size())
      {
        const auto end  = s.find('\n', start);
        const auto stop = end == std::string::npos ? s.size() : end + 1;
        lines.push_back(s.substr(start, stop - start));
        start = stop;
      }
    return lines;
  }

  std::string
  joined(const std::vector<std::string> &lines)
  {
    std::string s;
    for (const auto &l : lines)
      s += l;
    return s;
  }

  std::string
  mutate(std::string                     s,
         const std::vector<std::string> &seeds,
         std::mt19937                   &rng)
  {
    const unsigned int n = 1 + pick(rng, 3);
    for (unsigned int m = 0; m < n; ++m)
      {
        auto lines = lines_of(s);
        switch (pick(rng, 9))
          {
            case 0: // flip a byte
              if (!s.empty())
                s[pick(rng, s.size())] = static_cast<char>(pick(rng, 256));
              break;
            case 1: // delete a range
              if (!s.empty())
                s.erase(pick(rng, s.size()), 1 + pick(rng, 20));
              break;
            case 2: // insert a token
              s.insert(pick(rng, s.size() + 1),
                       tokens[pick(rng, tokens.size())]);
              break;
            case 3: // duplicate a line
              if (!lines.empty())
                {
                  const auto l = pick(rng, lines.size());
                  lines.insert(lines.begin() + pick(rng, lines.size() + 1),
                               lines[l]);
                  s = joined(lines);
                }
              break;
            case 4: // drop a line
              if (!lines.empty())
                {
                  lines.erase(lines.begin() + pick(rng, lines.size()));
                  s = joined(lines);
                }
              break;
            case 5: // swap two lines
              if (lines.size() > 1)
                {
                  std::swap(lines[pick(rng, lines.size())],
                            lines[pick(rng, lines.size())]);
                  s = joined(lines);
                }
              break;
            case 6: // a nasty value for an entry
              {
                std::vector<std::size_t> sets;
                for (std::size_t l = 0; l < lines.size(); ++l)
                  if (lines[l].find('=') != std::string::npos)
                    sets.push_back(l);
                if (!sets.empty())
                  {
                    std::string &line = lines[sets[pick(rng, sets.size())]];
                    line = line.substr(0, line.find('=') + 1) + " " +
                           values[pick(rng, values.size())] + "\n";
                    s = joined(lines);
                  }
                break;
              }
            case 7: // truncate
              s.resize(pick(rng, s.size() + 1));
              break;
            default: // a line of another scene
              {
                const auto other = lines_of(seeds[pick(rng, seeds.size())]);
                if (!other.empty())
                  {
                    lines.insert(lines.begin() + pick(rng, lines.size() + 1),
                                 other[pick(rng, other.size())]);
                    s = joined(lines);
                  }
              }
          }
      }
    return s;
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  std::vector<std::string> names, seeds;
  for (const auto &e :
       std::filesystem::directory_iterator(palpate_source_dir + "/parameters"))
    if (e.path().extension() == ".prm")
      names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  // The scenes name their meshes relative to parameters/ (../meshes/);
  // the mutants are written here, where a link 'organs' points to the
  // project's meshes/. The seeds then have the same bytes wherever the
  // project is checked out, and so have the mutants. (Not 'meshes': that
  // is where a surface scene keeps the volume meshes it makes.)
  std::filesystem::remove("organs");
  std::filesystem::create_directory_symlink(palpate_meshes_dir, "organs");
  const std::string relative = "../meshes/";
  for (const auto &n : names)
    {
      std::string text = read_file(palpate_source_dir + "/parameters/" + n);
      for (auto at = text.find(relative); at != std::string::npos;
           at      = text.find(relative))
        text.replace(at, relative.size(), "organs/");
      seeds.push_back(text);
    }
  // The mutants, generated first: the same on every run.
  const unsigned int       mutants = 10000;
  std::mt19937             rng(20261123);
  std::vector<std::string> texts(mutants);
  std::vector<std::size_t> origin(mutants);
  for (unsigned int i = 0; i < mutants; ++i)
    {
      origin[i] = pick(rng, seeds.size());
      texts[i]  = mutate(seeds[origin[i]], seeds, rng);
    }

  // Two threads read them (each mutant's outcome does not depend on the
  // order). Every 8th mutant read is also set up, and every 160th one
  // on a small mesh solved.
  struct Counts
  {
    unsigned int read = 0, rejected = 0, other = 0, slow = 0, set_up = 0,
                 set_up_rejected = 0, solved = 0, converged = 0, non_finite = 0;
  };
  std::mutex log_mutex;
  const auto check = [&](const unsigned int thread, Counts &c) {
    const std::string file = "mutant-" + std::to_string(thread) + ".prm";
    for (unsigned int i = thread; i < mutants; i += 2)
      {
        write_file(file, texts[i]);
        const fuzz::CpuTimer timer;
        try
          {
            const palpate::Scene scene = palpate::Scene::read(file);
            ++c.read;
            if (i % 8 == 0)
              try
                {
                  const palpate::Mesh mesh = palpate::Mesh::create(scene);
                  const palpate::NodeSelection nodes =
                    palpate::NodeSelection::create(scene, mesh);
                  ++c.set_up;
                  if (i % 160 == 0 && mesh.n_vertices() <= 600)
                    {
                      ++c.solved;
                      palpate::StateSolver solver(mesh,
                                                  nodes,
                                                  scene.parameters);
                      auto target = scene.parameters.boundary_conditions
                                      .active_node.prescribed_displacement;
                      if (palpate::Utilities::norm(target) == 0)
                        target = {{0, 0, -0.005}};
                      const palpate::State s =
                        solver.solve(solver.rest_state(), target);
                      c.converged += s.converged;
                      if (s.converged && !(all_finite(s.force)))
                        {
                          ++c.non_finite;
                          std::lock_guard<std::mutex> lock(log_mutex);
                          deallog << "mutant " << i << ": converged with "
                                  << "force ("
                                  << palpate::Utilities::to_string(s.force, 3)
                                  << ")" << std::endl;
                        }
                    }
                }
              catch (const palpate::InputError &)
                {
                  ++c.set_up_rejected;
                }
              catch (const palpate::NotAvailableError &)
                {
                  ++c.set_up_rejected;
                }
          }
        catch (const palpate::InputError &e)
          {
            ++c.rejected;
            // Every message names the file.
            if (std::string(e.what()).find(file) == std::string::npos)
              {
                std::lock_guard<std::mutex> lock(log_mutex);
                deallog << "mutant " << i
                        << ": message without the file name: " << e.what()
                        << std::endl;
              }
          }
        catch (const std::exception &e)
          {
            if (++c.other <= 3)
              {
                std::lock_guard<std::mutex> lock(log_mutex);
                deallog << "mutant " << i << " of " << names[origin[i]]
                        << ": NOT an input error: " << e.what() << std::endl;
              }
          }
        if (const double took = timer.seconds(); took > 2)
          {
            ++c.slow;
            // Which one, to look at (printed only when this fails).
            std::lock_guard<std::mutex> lock(log_mutex);
            deallog << "mutant " << i << " of " << names[origin[i]] << " took "
                    << took << " s (CPU)" << std::endl;
          }
      }
    std::filesystem::remove(file);
  };
  Counts      counts[2];
  std::thread second(check, 1, std::ref(counts[1]));
  check(0, counts[0]);
  second.join();
  const auto sum = [&](unsigned int Counts::*field) {
    return counts[0].*field + counts[1].*field;
  };
  const unsigned int read     = sum(&Counts::read),
                     rejected = sum(&Counts::rejected),
                     other = sum(&Counts::other), slow = sum(&Counts::slow),
                     set_up          = sum(&Counts::set_up),
                     set_up_rejected = sum(&Counts::set_up_rejected),
                     solved          = sum(&Counts::solved),
                     converged       = sum(&Counts::converged),
                     non_finite      = sum(&Counts::non_finite);

  deallog << mutants << " mutants of " << seeds.size()
          << " shipped scenes: " << read << " read, " << rejected
          << " input errors, " << other << " other exceptions (must be 0)"
          << std::endl;
  deallog << "set up: " << set_up
          << ", input errors in the set-up: " << set_up_rejected << std::endl;
  deallog << "solved: " << solved << ", converged: " << converged
          << ", converged with a non-finite force: " << non_finite
          << " (must be 0)" << std::endl;
  deallog << "reads or set-ups slower than 2 s: " << slow << " (must be 0)"
          << std::endl;
}
