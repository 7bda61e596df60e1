// One job of the sweep = one load case (paper eq. 7) on the unit cell of one loop length, run
// step by step (Sect. 3.1.1: 20 steps), with the retry policy of issue #7: a case that does not
// converge is rerun with more, smaller steps; if it still fails, its result keeps the status of
// every step (database: 0 = converged, 1 = did not converge, 2 = not reached) and is reported.
//
// Jobs are deterministic and independent, so the order in which threads or MPI ranks run them
// does not change the database.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "knit/material/database.hpp"
#include "knit/meso/sweep/input.hpp"

namespace knit::meso::sweep {

/// Per-step status values stored in the database's raw/path_NN/status.
inline constexpr int kStepConverged = 0;
inline constexpr int kStepFailed = 1;      ///< the step was attempted and did not converge
inline constexpr int kStepNotReached = 2;  ///< an earlier step failed

struct Job {
  int index = 0;  ///< position in the work list (= loop * paths + path)
  int loop = 0;   ///< index into SweepInput::loop_lengths
  int path = 0;   ///< index into SweepInput::paths
  double loop_length = 0.0;
  material::LoadPath load_path;
};

/// The work list: loop lengths outer, paths inner.
std::vector<Job> make_jobs(const SweepInput& in);

/// What a runner returns for one load path run with `load_path.steps` steps: one row per step
/// in `raw` (unreached steps: zeros and kStepNotReached), the cell dimensions, a message.
struct PathOutcome {
  material::RawPath raw;
  material::CellParameters cell;
  /// Residual stress (S11, S22, S12) of the equilibrated cell at F* = I (MPa): the initial
  /// penetrations push the yarns apart (design/notes.md); zero for the synthetic runner.
  Eigen::Vector3d residual = Eigen::Vector3d::Zero();
  std::string message;
  int iterations = 0;  ///< Newton iterations (information)
};

/// Runs one load path on the cell of `loop_length` (steps = load_path.steps). Must be
/// deterministic and thread-safe (called concurrently for different jobs).
using PathRunner =
    std::function<PathOutcome(double loop_length, const material::LoadPath& load_path)>;

enum class JobStatus {
  kConverged = 0,  ///< every step converged
  kPartial = 1,    ///< some steps converged, then the path failed even with the retries
  kFailed = 2,     ///< not even the first step converged
  kError = 3       ///< the runner threw (message says what)
};
std::string to_string(JobStatus s);

struct JobResult {
  int index = 0;
  JobStatus status = JobStatus::kFailed;
  material::RawPath raw;  ///< at the requested steps (subsampled from the refined run)
  material::CellParameters cell;
  Eigen::Vector3d residual = Eigen::Vector3d::Zero();  ///< see PathOutcome
  int attempts = 0;                                    ///< runs made (1 = no retry)
  int step_factor = 1;                                 ///< refinement of the run that was kept
  double seconds = 0;                                  ///< wall time of all attempts
  std::string message;
  int converged_steps() const;
};

/// Runs the job with the retry policy. Never throws: runner exceptions become kError.
JobResult run_job(const Job& job, const RetryPolicy& retry, const PathRunner& runner);

/// Exact, text serialization of a result (checkpoints and MPI messages): doubles as hex floats,
/// so a round trip gives bit-identical numbers.
std::string serialize(const JobResult& r);
/// Parses serialize()'s output; throws std::runtime_error on anything malformed.
JobResult deserialize(const std::string& text);
/// True if r was computed for this job (index, path kind, target, axis, H, set, steps).
bool matches(const JobResult& r, const Job& job);

}  // namespace knit::meso::sweep
