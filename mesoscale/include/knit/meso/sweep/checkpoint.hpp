// Checkpoints of a sweep (issue #7, "resumable"): every finished job is persisted atomically as
// one small file DB.h5.parts/job_NNNNN.txt (serialize() of job.hpp: hex floats, bit-exact), next
// to a manifest that holds the fingerprint of the job definition. A sweep killed at any moment
// leaves only complete job files (temporary file + rename), so `--resume` recomputes nothing
// that finished and loses nothing. Every job file ends with a digest line (64-bit FNV-1a of the
// record text above it); on --resume a record whose digest does not match (edited by hand,
// damaged on disk) or that does not parse is refused with knit::InputError naming the file and
// the record (exit 2): delete that file to recompute the case, or use --force. Before the
// digest, a "sweep <fingerprint>" line ties the record to its sweep (session 36). The database
// itself is assembled from the job files and written atomically at the end; the parts directory is
// then removed.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "knit/meso/sweep/job.hpp"

namespace knit::meso::sweep {

class CheckpointStore {
 public:
  /// DB.h5 -> DB.h5.parts
  static std::filesystem::path parts_dir(const std::filesystem::path& database);

  /// Opens the parts directory of `database` for the given job definition.
  ///  resume = false: the directory must not exist (throws knit::InputError telling to use
  ///                  --resume or --force), unless force = true (then it is discarded);
  ///  resume = true:  an existing directory must carry the same fingerprint (InputError
  ///                  otherwise); a missing one starts fresh.
  /// A directory of ours without a finished case's record (a run stopped while it wrote its
  /// first manifest) is discarded either way: nothing in it can be continued or lost.
  CheckpointStore(const std::filesystem::path& database, const std::string& job_definition,
                  int job_count, bool resume, bool force);

  const std::filesystem::path& dir() const { return dir_; }
  /// The builds ("knit-meso VERSION (git REV)") whose cases the checkpoints hold, oldest
  /// first, as the manifest's "builds" lists them (session 45): this build alone for new
  /// checkpoints; resumed ones add this build when it stores its first case (store()).
  const std::vector<std::string>& builds() const { return builds_; }
  /// This build as the manifest names it.
  static std::string this_build();
  /// Finished results found on opening, validated against the jobs: a record with a missing
  /// or wrong digest, or one that does not parse, throws knit::InputError (file + record);
  /// a valid record of another job definition, or one sealed for another sweep (its sweep
  /// line names another fingerprint: a job file copied from other checkpoints), is ignored
  /// and recomputed.
  std::map<int, JobResult> load_finished(const std::vector<Job>& jobs) const;
  /// Persists one result atomically (and, the first time, this build in the manifest's list).
  void store(const JobResult& r);
  /// Removes the directory (after the database is in place).
  void remove() const;
  /// Marks the checkpoints as those of a sweep whose database is in place (the file
  /// "database_written"), before remove(): a stop in between leaves checkpoints that the next
  /// sweep without --resume discards instead of refusing them as an unfinished sweep's
  /// (session 38's red team); --resume still takes them. Not for --keep-parts (kept on
  /// purpose: a later sweep without --resume refuses them as before).
  void mark_written() const;

 private:
  std::filesystem::path dir_;
  std::string fingerprint_;  ///< of the job definition; every record carries it
  std::vector<std::string> builds_;
  bool resumed_ = false;   ///< opened with --resume on existing checkpoints
  bool keep_dir_ = false;  ///< the directory existed empty: not ours to remove (remove())
};

/// `text` cut to at most `max_bytes` bytes with "..." at the end, never inside a UTF-8
/// sequence (the checkpoints' messages: a manifest's values and build names).
std::string shortened(std::string text, std::size_t max_bytes);

}  // namespace knit::meso::sweep
