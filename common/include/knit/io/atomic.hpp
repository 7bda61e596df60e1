// Atomic outputs (design/style.md: "outputs are written atomically").
//
// A reader (or a crash) never sees a half-written result: files are written to a temporary
// next to the target and renamed over it on commit(); output directories are built as
// DIR.partial-<pid> and swapped in on commit(). Without commit() (an exception unwound the
// writer), the target is left exactly as it was.
//
//   knit::io::AtomicFile out("result.h5");
//   { auto f = knit::io::H5File::create(out.temp_path()); ...; f.close(); }
//   out.commit();
//
//   knit::io::AtomicFile csv("curve.csv");
//   csv.stream() << "a,b\n1,2\n";
//   csv.commit();
//
//   knit::io::AtomicDirectory dir("out/rod_case");
//   write things into dir.path() / "...";   // = out/rod_case.partial-<pid>
//   dir.commit();                           // out/rod_case now holds exactly the new files
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <string_view>

#include "knit/io/output_target.hpp"

namespace knit::io {

/// One output file written to "<dir>/.<name>.tmp-<pid>-<n>" and renamed over the target on
/// commit(). Not copyable; movable. The constructor removes stale temporaries of the same
/// target left by killed processes (regular files of that name whose pid is dead and whose
/// content is empty or HDF5: a user's file of that name is not ours to delete).
class AtomicFile {
 public:
  /// The target's directory must exist (throws std::runtime_error otherwise).
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(AtomicFile&& o) noexcept;
  AtomicFile& operator=(AtomicFile&&) = delete;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  /// Removes the temporary file unless committed.
  ~AtomicFile();

  const std::filesystem::path& target() const { return target_; }
  /// Where to write (e.g. with a library that opens files by name, like HDF5).
  const std::filesystem::path& temp_path() const { return temp_; }
  /// A binary output stream on temp_path(), opened on first use.
  std::ofstream& stream();
  /// Closes the stream (if used), fsyncs the temporary, renames it onto the target and
  /// fsyncs the directory. Throws std::runtime_error naming the target on any failure (the
  /// temporary is then removed by the destructor).
  void commit();
  bool committed() const { return committed_; }

 private:
  std::filesystem::path target_, temp_;
  std::ofstream stream_;
  bool committed_ = false;
  int live_slot_ = -1;  ///< the temporary's slot for unlink_live_temporaries(); -1: none
};

/// Unlinks the temporaries of this process's AtomicFiles that are not committed (async-signal-
/// safe: ::unlink over a fixed table; at most 16 at once are tracked, the rest are left for the
/// next run's clean-up). For a handler that ends the program on a signal (knit::cli's): an
/// interrupted database write left its half-written ".DB.h5.tmp-<pid>-<n>" beside the target
/// until the next run into it (session 43's red team).
void unlink_live_temporaries() noexcept;

/// A scratch file of this process, created exclusively (mkstemps) from a name pattern ending in
/// "XXXXXX" + `suffix` in `dir`, and removed by the destructor and by unlink_live_temporaries()
/// on a signal (session 54's red team: a `knit-meso fit` interrupted during its in-place
/// pre-check left its empty "knit-meso-fit-check-XXXXXX.h5" in TMPDIR for good). The file may be
/// replaced by rename (a database written over it) and is still removed: the name is tracked,
/// not the inode. valid() is false when it could not be created (no slot is then held).
/// Signals are blocked in the calling thread while the file is created and registered, and
/// while it is removed; a signal handled by another thread in that instant, or more than the 16
/// live temporaries unlink_live_temporaries() tracks, leaves it to the owner's removal only.
class ScratchFile {
 public:
  ScratchFile(const std::filesystem::path& dir, std::string_view stem, std::string_view suffix);
  ~ScratchFile();
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  bool valid() const { return !path_.empty(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int live_slot_ = -1;
};

/// Writes `content` to `target` atomically.
void write_file_atomically(const std::filesystem::path& target, std::string_view content);

/// The message of an error that abandoned an output directory of this process (an
/// AtomicDirectory, removed by then with its "DIR.partial-<pid>"), said of DIR: "DIR: outputs not
/// written (the earlier outputs are left as they were | nothing was written): REASON", files of
/// the partial directory named relative to DIR in REASON (a full file system said only
/// "DIR.partial-123/vtk/step_0005.vtu: write failed (disk full?)", naming a directory that no
/// longer exists). Any other message is returned unchanged. The programs' error printer
/// (knit::cli::run_main) passes every failure through it.
std::string explain_unwritten_outputs(const std::string& message);

/// An output directory built as "<DIR>.partial-<pid>" and put in place on commit(). An existing
/// DIR stays untouched until the new one is complete. Only a directory knitscale wrote (it holds
/// the marker file kOutputMarker, written into every output directory) or an empty one is ever
/// replaced: a non-empty directory without the marker is refused (check_output_target) and
/// never deleted. The output is locked (OutputLock on DIR.lock) from construction to
/// destruction, so two runs never write the same DIR at once.
class AtomicDirectory {
 public:
  /// What happens to the partial directory when the object dies without commit().
  enum class OnAbandon {
    Remove,  ///< delete it (default)
    Keep     ///< keep it for inspection, with a file INCOMPLETE inside saying so
  };
  /// Checks the target (check_output_target, InputError naming `option`), creates the parents
  /// of DIR, takes the lock (InputError naming the holder's pid while another process holds
  /// it), removes the stale "DIR.partial-<pid>" and "DIR.old-<pid>" directories of dead
  /// processes (only those holding the marker), then creates the partial directory with the
  /// marker in it. `input`: the input file the output is made from, for the marker's provenance
  /// (empty for a command without one).
  explicit AtomicDirectory(std::filesystem::path target, OnAbandon on_abandon = OnAbandon::Remove,
                           std::string_view option = "output directory", std::string input = {});
  AtomicDirectory(AtomicDirectory&& o) noexcept;
  AtomicDirectory& operator=(AtomicDirectory&&) = delete;
  AtomicDirectory(const AtomicDirectory&) = delete;
  AtomicDirectory& operator=(const AtomicDirectory&) = delete;
  ~AtomicDirectory();

  const std::filesystem::path& target() const { return target_; }
  /// The directory to write into until commit() (after commit(): the target).
  const std::filesystem::path& path() const { return committed_ ? target_ : partial_; }
  std::filesystem::path operator/(const std::filesystem::path& name) const { return path() / name; }
  /// fsyncs the files, then replaces DIR by the partial directory: atomically where the file
  /// system supports renameat2(RENAME_EXCHANGE), otherwise by two renames (DIR is moved
  /// aside to DIR.old-<pid> first, then removed). Throws std::runtime_error on failure, and
  /// when DIR became a non-empty directory without the marker meanwhile (it is left alone).
  void commit();
  bool committed() const { return committed_; }
  /// At commit, the earlier output this one replaces is moved to DIR`suffix` (e.g.
  /// "DIR.last-completed", DIR without a trailing '/') instead of being removed (session 46: a
  /// stopped rerun replaced a completed earlier output). An output kept there before for this
  /// DIR (its marker's "for:" names DIR) is replaced; anything else there is left alone and the
  /// output goes to DIR`suffix`-<pid>. replaced_kept_in(): where it went after commit() (empty
  /// when nothing was replaced, or when it could not be moved and was removed as before).
  void keep_replaced_as(std::string suffix) { keep_suffix_ = std::move(suffix); }
  const std::filesystem::path& replaced_kept_in() const { return replaced_kept_in_; }
  /// Whether this output's command ended with its work done, recorded in the marker at commit
  /// ("completed: yes" / "no"; not called: no line). A stopped output (false) that replaces a
  /// completed one of the same DIR (its marker says "completed: yes") keeps that one as
  /// "DIR.last-completed" (keep_replaced_as) unless another suffix was set: a failed rerun of
  /// knit-macro design or knit-meso path or rod does not cost a completed output written since
  /// session 49 (its red team; an older output has no such line: a command may judge it from
  /// its files, judge_earlier_by_files; knit-macro run judges from summary.txt since session 46
  /// and does not call this).
  void set_completed(bool completed) { completed_flag_ = completed ? 1 : 0; }
  /// The output in DIR when this one was started was a completed one (its marker said so, or,
  /// where it does not say, the command's judge_earlier_by_files).
  bool earlier_completed() const { return earlier_completed_; }
  /// An earlier output whose marker does not say whether it completed (no "completed:" line:
  /// written before session 49) is judged by the command from its files:
  /// completed_by_files(DIR) (knit-meso path reads its path.csv, rod its CSV's comment,
  /// knit-macro design its summary.txt). A marker's "completed: no" is not overridden, and
  /// without a marker there is nothing to judge (session 51's review: the rule was written out
  /// by each of the three callers, and overrode "completed: no").
  void judge_earlier_by_files(
      const std::function<bool(const std::filesystem::path&)>& completed_by_files) {
    if (earlier_marked_ && !earlier_recorded_) earlier_completed_ = completed_by_files(target_);
  }

 private:
  /// Removes the replaced output `old` (now beside the target), or keeps it (keep_replaced_as).
  void dispose_replaced(const std::filesystem::path& old);

  std::filesystem::path target_;
  OutputLock lock_;  ///< held from construction to destruction (after the checks)
  std::filesystem::path partial_;
  std::string keep_suffix_;
  std::filesystem::path replaced_kept_in_;
  int completed_flag_ = -1;  ///< set_completed: 1 yes, 0 no, -1 not said
  bool earlier_completed_ = false;
  bool earlier_marked_ = false;    ///< DIR held an output with a marker when this one started
  bool earlier_recorded_ = false;  ///< ... whose marker had a "completed:" line
  OnAbandon on_abandon_;
  bool committed_ = false;
  bool active_ = true;
};

/// What a command that wrote nothing says of its output `path`: " is left as it was" when a
/// file is there, " was not created" when none is (session 41: "left as it was" of an -o file
/// that never existed). One wording for knit-meso fit, synth and sweep.
const char* unwritten_output_state(const std::filesystem::path& path);

}  // namespace knit::io
