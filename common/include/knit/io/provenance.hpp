// Provenance of an output (design/style.md habit 10): every output file says which program,
// version and git revision made it, when, where, from which command line and input.
//
//   auto prov = knit::io::Provenance::current("cases/rod.json");
//   knit::io::write_provenance(h5file, prov);            // attributes on the root group
//   csv.add_comment("provenance: " + prov.to_json_string());
#pragma once

#include <string>

namespace knit::io {

class H5Group;

struct Provenance {
  std::string program = "knitscale";  ///< "knitscale" (the executable is in command_line)
  std::string version;                ///< knit::project_version()
  std::string git_revision;           ///< knit::git_revision()
  std::string date_utc;               ///< ISO-8601, e.g. "2026-11-22T00:13:11Z"
  std::string host;                   ///< gethostname()
  std::string command_line;           ///< /proc/self/cmdline, arguments joined by spaces
  std::string input;                  ///< input file path as given ("" if none)

  /// Fills everything from the running process; `input` as given.
  static Provenance current(const std::string& input = "");
  /// One-line JSON object with the keys program, version, git_revision, date_utc, host,
  /// command_line, input.
  std::string to_json_string() const;
};

/// Current UTC time as ISO-8601 "YYYY-MM-DDThh:mm:ssZ".
std::string utc_now_iso8601();
/// The command line of this process (arguments containing spaces are single-quoted).
std::string process_command_line();

/// Writes the fields as string attributes "knit_program", "knit_version", "git_revision",
/// "date_utc", "host", "command_line", "input" on the object at obj_path of `g` ("." = g
/// itself, e.g. the file root).
void write_provenance(H5Group& g, const Provenance& p, const std::string& obj_path = ".");
/// Reads what write_provenance wrote (missing attributes stay empty).
Provenance read_provenance(const H5Group& g, const std::string& obj_path = ".");

}  // namespace knit::io
