// Output targets: what every command checks and holds before it writes (docs/io.md, "Output
// targets"). Used by AtomicDirectory (atomic.hpp) and by the commands that write one file.
//
//   knit::io::check_output_target(out, knit::io::OutputKind::kDirectory, "--output");  // at once
//   knit::io::AtomicDirectory dir(out);  // locks OUT.lock, cleans stale OUT.partial-<pid>
//
//   knit::io::check_output_target(db, knit::io::OutputKind::kFile, "--output");
//   knit::io::OutputLock lock(db);       // db.h5.lock while the sweep runs
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace knit::io {

/// The file in every output directory knitscale writes ("knitscale output" and the provenance
/// of the run that wrote it). A non-empty directory without it is never replaced or deleted.
inline constexpr const char* kOutputMarker = ".knitscale-output";

/// True if `dir` is a directory holding the marker file.
bool is_knitscale_output(const std::filesystem::path& dir);

/// Who writes this process's output directories, as its markers say: "knit-macro run",
/// "knit-meso cell", ... (knit::cli::run_main sets it from the program and the subcommand).
/// Empty (the default: a library caller, a test) writes markers that name no owner.
void set_output_owner(std::string owner);
const std::string& output_owner();

/// The owner `dir`'s marker names: the first line "knitscale output: OWNER" gives OWNER, a
/// plain "knitscale output" (markers before session 26, library callers) gives "", any other
/// first line gives that line; nothing without a marker.
std::optional<std::string> output_marker_owner(const std::filesystem::path& dir);

/// True if this process may replace the directory `dir`: it holds the marker, and the marker
/// names no owner or this process's (output_owner()). Session 26: `knit-macro run -o out`
/// replaced the reproduction pipeline's whole output directory -- its database, figures and
/// report -- because any marker was taken for the program's own.
bool is_own_output(const std::filesystem::path& dir);

/// The marker's further lines (session 29), below the owner and the provenance:
///   "for: NAME"            the name of the output the directory was written for (at creation)
///   "input: PATH"          the input file's absolute path (at creation, when there is one;
///                          since session 47, for check_default_output_input)
///   "file: REL/PATH"       one per file and directory the run wrote (at commit: the manifest)
///   "replaced by pid N"    the output is being moved aside by process N (DIR.old-<N>)
/// A rerun replaced its output directory as a whole and deleted the files a user had put in
/// it; and the clean-up after killed runs deleted any marked "DIR.partial-<N>" or "DIR.old-<N>"
/// of a dead N -- a user's copy "cp -a out out.old-2024" or an output asked for by that name.
struct OutputMarker {
  std::string for_name;            ///< empty when the marker has no "for:" line
  bool has_manifest = false;       ///< any "file:" line (a committed output of session >= 29)
  std::vector<std::string> files;  ///< the manifest, relative paths with '/'
  long replaced_by_pid = -1;       ///< -1 without that line
  /// The "pid <pid>" line: the process that built the directory as DIR.partial-<pid> (-1
  /// without it; markers before session 38).
  long writer_pid = -1;
  /// The provenance's "input" (the input file as the run was given it; empty without one, or
  /// when the provenance line is not JSON).
  std::string input;
  /// The "input: PATH" line (since session 47): the input file's absolute path; empty without.
  std::string input_absolute;
  /// A "completed: yes" line (since session 49): the command that wrote it ended with its work
  /// done (AtomicDirectory::set_completed); false with "completed: no" or without the line.
  bool completed = false;
  /// The marker has a "completed:" line, yes or no (an output written before session 49, or by
  /// knit-macro run, has none); false when it has both (contradictory: it says nothing).
  bool completed_recorded = false;
};
/// The marker of `dir`, read; nothing without a marker.
std::optional<OutputMarker> read_output_marker(const std::filesystem::path& dir);

/// Entries inside the output directory `dir` that the run which wrote it did not write (not in
/// its marker's manifest), relative to dir, at most `max` of them; empty for a directory whose
/// marker has no manifest (written before session 29: nothing to tell them by).
std::vector<std::string> foreign_entries(const std::filesystem::path& dir, std::size_t max = 5);

enum class OutputKind { kDirectory, kFile };

/// For an output directory named by default after its input file (no --output given): refuses
/// (knit::InputError(target, "output directory", why)) a `target` that holds the output of
/// another input file: by the marker's "input:" line (absolute) when it has one; for older
/// markers by the provenance "input" resolved from the current directory, and then only when
/// both name existing files that are not the same file (a relative input typed in another
/// directory resolves elsewhere: session 47's review found a rerun of the same case refused).
/// Session 47's walkthrough: two designs' case.json files, each mapped with `knit-macro knitmap
/// DIR/case.json`, went to one ./case_knitmap, the second replacing the first with exit 0. Nothing
/// to refuse without a marker or an input in it.
void check_default_output_input(const std::filesystem::path& target, const std::string& input);

/// Refuses, before any work, an output target the run could not (or must not) write. Throws
/// knit::InputError(target, option, why) ("out: --output: is a regular file ...") for
///  * an empty name, ".", "..", "/" or any path ending in "." or "..";
///  * a symbolic link (dangling or not: the rename would replace the link, not its target);
///  * kDirectory: an existing non-directory; the current directory or one of its ancestors; a
///    non-empty directory that is not a knitscale output (no marker file), or the output of
///    another program (is_own_output), or an output holding entries its run did not write
///    (foreign_entries: a user's notes in a run's directory);
///  * kFile (an HDF5 file: the database outputs): a name ending in "/"; an existing directory
///    (or other non-regular file); an existing non-empty file that is not HDF5 (not ours to
///    replace); with `hdf5_format` given, an existing HDF5 file whose root attribute "format" is
///    not `hdf5_format` (session 21: somebody else's HDF5 file was taken for an earlier database
///    and replaced);
///  * a target whose nearest existing ancestor is not a writable directory (missing parents
///    are created by the writer, so "a/b/out" needs "a" — or the first existing one — writable).
void check_output_target(const std::filesystem::path& target, OutputKind kind,
                         std::string_view option = "--output", std::string_view hdf5_format = {});

/// An exclusive lock on an output, held for the lifetime of the object: flock(2) on
/// "<target>.lock" beside the target, which holds "knitscale lock pid <pid>". Another process
/// (or another OutputLock in this process) asking for the same target is refused with a
/// knit::InputError naming the holder's pid. A lock file left by a killed process is not held
/// (the kernel drops flock locks with the process) and is taken over. The file is removed when
/// the lock is released. A knitscale lock file is tagged and locked under a private name
/// ("<target>.lock.new-XXXXXX") and then linked into place, so it is never seen untagged; a
/// "<target>.lock" that is not a knitscale lock file, an empty one included, is never touched.
/// Missing parent directories of the target are created (as the writer would), and removed again
/// on release (or when the lock cannot be taken) if they are still empty.
class OutputLock {
 public:
  explicit OutputLock(std::filesystem::path target);
  OutputLock(OutputLock&& o) noexcept;
  OutputLock& operator=(OutputLock&&) = delete;
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  ~OutputLock();

  /// "<target>.lock" (a trailing '/' of the target is ignored).
  static std::filesystem::path lock_path(const std::filesystem::path& target);
  const std::filesystem::path& path() const { return file_; }

 private:
  void take(const std::string& out);

  std::filesystem::path file_;
  int fd_ = -1;
  /// The parent directories the lock created (deepest first): removed on release if empty.
  std::vector<std::filesystem::path> new_dirs_;
};

/// Estimated output size in bytes as "1.2 GB" / "350 MB" / "12 kB" (decimal units).
std::string format_bytes(std::uint64_t bytes);

/// Parses a size given on the command line: a number with an optional unit k, M, G, T (decimal,
/// an optional trailing "B"): "500M", "2G", "1.5GB", "100000". Throws knit::InputError(option)
/// for anything else.
std::uint64_t parse_size(std::string_view text, std::string_view option);

}  // namespace knit::io
