// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The table `palpate study` writes: its name checked before anything runs
// (a name that says no file, a directory that is not there, a file of the
// user's or a device under it or under its plot's name is refused with
// what to give instead), and the rows written after every knob setting.

#include <palpate/app/study_impl.h>
#include <palpate/base/exceptions.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace palpate
{
  namespace internal
  {
    namespace
    {
      /** The first line of the study's CSV: a file that has another is not
       * overwritten. */
      const std::string csv_header =
        "material,knob,value,interpolation,probe,h_mm,samples,covered,"
        "err_mean_N,err_p95_N,err_max_N,err_mean_pct,err_p95_pct,"
        "err_max_pct,shape_err_mm,state_ms,states,failures,states_per_cm,"
        "region_states,precompute_s,memory_MiB,speed_mm_s,recommended";

      /** The refusal of --csv @p csv_file: an InputError with the problem
       * and its fix. */
      auto
      refusal(const std::string &csv_file)
      {
        return [&csv_file](const std::string &problem, const std::string &fix) {
          throw InputError(
            "command line", 0, "--csv " + csv_file, problem, fix);
        };
      }
    } // namespace



    void
    Study::check_csv_file()
    {
      result.csv_file = options.csv_file;
      if (options.csv_given || !result.csv_file.empty())
        {
          check_csv_name();
          check_csv_directory();
          check_csv_target();
        }
      if (result.csv_file.empty())
        {
          std::filesystem::create_directories(p0.output.directory);
          result.csv_file =
            (std::filesystem::path(p0.output.directory) /
             ("study-" + std::filesystem::path(scene.file()).stem().string() +
              ".csv"))
              .string();
        }
    }

    void
    Study::check_csv_name()
    {
      namespace fs      = std::filesystem;
      const auto refuse = refusal(result.csv_file);
      // Names that do not say a file are refused with what to give:
      // otherwise an empty one would silently take the default name,
      // "-" would make a file of that name rather than mean standard
      // output, and "x.csv/" would be blamed as a missing directory.
      if (result.csv_file.empty())
        refuse("the file name is empty",
               "name the table, e.g. --csv study.csv, or leave --csv "
               "out to write it to Output / Directory.");
      // A name like an option or of blanks only is a slip, not a file
      // to make in the working directory.
      if (result.csv_file.front() == '-' && result.csv_file != "-")
        refuse("the name begins with '-', like an option",
               "name the table, e.g. --csv study.csv (a file whose "
               "name begins with '-': --csv ./" +
                 result.csv_file + ").");
      if (result.csv_file.find_first_not_of(" \t") == std::string::npos)
        refuse("the file name is blank",
               "name the table, e.g. --csv study.csv.");
      if (result.csv_file == "-")
        refuse("the study cannot write its table to standard output: "
               "the Pareto plot reads it back from a file",
               "name a file, e.g. --csv study.csv.");
      if (result.csv_file.back() == '/')
        refuse("the name ends in '/', so it names a directory, not "
               "a file",
               "give the CSV file's name, e.g. --csv " +
                 (fs::path(result.csv_file) / "study.csv").string() + ".");
      // A link to nowhere: the table would be made wherever it
      // points, or fail after the whole study.
      if (const std::string link = dangling_link(result.csv_file);
          !link.empty())
        refuse(link,
               "name another file, or remove the link (rm '" + result.csv_file +
                 "') first.");
      // The plot is written beside the CSV, its name ending in .png.
      if (fs::path(result.csv_file).extension() == ".png")
        refuse("the Pareto plot is written beside the table under the "
               "table's name ending in .png: it would overwrite the "
               "table",
               "name the CSV with .csv, e.g. --csv study.csv.");
    }

    void
    Study::check_csv_directory()
    {
      namespace fs      = std::filesystem;
      const auto refuse = refusal(result.csv_file);
      // Its directory, now, not after the first knob.
      const auto parent = fs::path(result.csv_file).parent_path();
      if (!parent.empty())
        {
          std::error_code error;
          const auto      status = fs::status(parent, error);
          if (const std::string link = dangling_link(parent.string());
              !link.empty())
            refuse("its directory " + link,
                   "make the link's target, or name a file in a "
                   "directory that exists.");
          if (status.type() == fs::file_type::not_found)
            refuse("its directory '" + parent.string() + "' does not exist",
                   "make it (mkdir -p '" + parent.string() +
                     "') or name a file in one that exists.");
          if (error)
            refuse("the file system refuses its directory '" +
                     parent.string().substr(0, 300) + "' (" + error.message() +
                     ")",
                   "check the links on the way (a loop of symbolic "
                   "links?), the path's length and the permissions, "
                   "or name another file.");
          if (!fs::is_directory(status))
            refuse("'" + parent.string() + "' is not a directory",
                   "name a file in a directory, e.g. --csv "
                   "study.csv.");
        }
    }

    void
    Study::check_csv_target()
    {
      const auto refuse = refusal(result.csv_file);
      // Said before anything runs, not at the first knob's end.
      std::error_code                    error;
      const std::filesystem::file_status status =
        std::filesystem::status(result.csv_file, error);
      if (error && status.type() != std::filesystem::file_type::not_found)
        throw InputError("command line",
                         0,
                         "--csv " + result.csv_file,
                         "the file system refuses the path (" +
                           error.message() + ")",
                         "check the links on the way (a loop of "
                         "symbolic links?) and the permissions, or "
                         "name another file.");
      // A device or a pipe (/dev/zero, a FIFO) is no table: the
      // Pareto plot would read it without end.
      if (std::filesystem::exists(status) &&
          !std::filesystem::is_directory(status) &&
          !std::filesystem::is_regular_file(status))
        throw InputError("command line",
                         0,
                         "--csv " + result.csv_file,
                         "'" + result.csv_file +
                           "' is a device, a pipe or a socket, not a "
                           "file: the study writes its table there "
                           "and the Pareto plot reads it back",
                         "name a regular file, e.g. --csv study.csv.");
      // Nor is a PNG beside it that this plot did not draw (its
      // Software text chunk says "palpate study").
      // A link to nowhere there would be followed: the plot made
      // its target.
      if (const std::string link =
            dangling_link(std::filesystem::path(result.csv_file)
                            .replace_extension(".png")
                            .string());
          options.plot && !link.empty())
        refuse("the Pareto plot would be written beside it, but " + link,
               "name the CSV so that its .png is free, e.g. --csv "
               "study.csv, or remove that link first.");
      if (std::filesystem::path png =
            std::filesystem::path(result.csv_file).replace_extension(".png");
          options.plot && std::filesystem::exists(png, error))
        {
          std::ifstream in(png, std::ios::binary);
          std::string   head(65536, '\0');
          in.read(head.data(), head.size());
          head.resize(in.gcount());
          if (head.find("palpate study") == std::string::npos)
            refuse("the Pareto plot would be written to '" + png.string() +
                     "', which exists and is not a plot of a study",
                   "name the CSV so that its .png is free, e.g. --csv "
                   "study.csv, or remove that file first.");
        }
      // A file of the user's (the scene, its mesh) is not a table
      // to overwrite: only one a study wrote is.
      if (std::filesystem::is_regular_file(status))
        {
          // Its first bytes only (a large file without a newline
          // was read whole); printable, to quote them.
          std::ifstream in(result.csv_file, std::ios::binary);
          std::string   head(4096, '\0');
          in.read(head.data(), head.size());
          head.resize(in.gcount());
          if (!head.empty() && head.rfind(csv_header, 0) != 0)
            {
              std::string begins = head.substr(0, 40);
              for (char &ch : begins)
                if (!std::isprint(static_cast<unsigned char>(ch)))
                  ch = ' ';
              refuse("'" + result.csv_file +
                       "' exists and is not a study's table (it "
                       "begins '" +
                       begins + "'): the study would overwrite it",
                     "name a new file, e.g. --csv study.csv, or remove "
                     "this one first if it is no longer needed.");
            }
        }
      if (std::filesystem::is_directory(status))
        throw InputError(
          "command line",
          0,
          "--csv " + result.csv_file,
          "'" + result.csv_file + "' is a directory, not a file",
          "give the CSV file's name, e.g. --csv " +
            (std::filesystem::path(result.csv_file) / "study.csv").string() +
            ".");
    }

    void
    Study::write_csv() const
    {
      std::ofstream csv(result.csv_file);
      csv << csv_header << "\n";
      for (unsigned int r = 0; r < result.rows.size(); ++r)
        {
          const auto &row = result.rows[r];
          csv << result.material << "," << row.knob << ",\"" << row.value
              << "\"," << row.interpolation << "," << row.probe << ","
              << row.h_mm << "," << row.samples << "," << row.covered << ","
              << row.err_mean_N << "," << row.err_p95_N << "," << row.err_max_N
              << "," << row.err_mean_pct << "," << row.err_p95_pct << ","
              << row.err_max_pct << "," << row.shape_err_mm << ","
              << row.state_ms << "," << row.states << "," << row.failures << ","
              << row.states_per_cm << "," << row.region_states << ","
              << row.precompute_s << "," << row.memory_MiB << ","
              << row.speed_mm_s << ","
              << (int(r) == result.recommended ? "yes" : "no") << "\n";
        }
      csv.close();
      if (!csv)
        throw OutputError("the study's CSV '" + result.csv_file +
                          "' could not be written (" + std::strerror(errno) +
                          ")");
    }
  } // namespace internal
} // namespace palpate
