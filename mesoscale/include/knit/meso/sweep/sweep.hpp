// The mesoscale database sweep (issue #7; paper Sect. 2.1.2 and 3.1.1): loop lengths x load
// cases x steps on the unit cell, then the response-surface fit (eq. 17), written as the
// material database (knit/material/database.hpp).
//
//   run()      = load the checkpoints (resume) -> run the pending jobs on a thread pool (and MPI
//                ranks) -> persist each result as it finishes -> assemble -> fit -> write
//                atomically -> remove the checkpoints.
// A case that does not converge (after the retries of job.hpp) stays in the database with the
// status of every step and of the case (/sweep/report), is left out of the fit, and is listed
// at the end; SweepReport::ok() is then false (exit code 1).
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "knit/material/database.hpp"
#include "knit/meso/fit/energy_fit.hpp"
#include "knit/meso/fit/response_fit.hpp"
#include "knit/meso/sweep/input.hpp"
#include "knit/meso/sweep/job.hpp"
#include "knit/meso/sweep/mpi.hpp"

namespace knit::meso::sweep {

struct SweepOptions {
  std::filesystem::path output = "database.h5";
  bool resume = false;           ///< continue from DB.h5.parts
  bool force = false;            ///< discard existing checkpoints
  bool keep_parts = false;       ///< keep DB.h5.parts after writing the database
  int threads = 0;               ///< workers per rank; 0 = all cores (divided among local ranks)
  std::FILE* progress = stderr;  ///< progress bar / lines (nullptr: silent)
  int tty = -1;                  ///< -1 detect, 0 plain lines, 1 bar
  std::FILE* log = stdout;       ///< summary, time per case (nullptr: silent)
  /// Called once the database is in place, before the checkpoints are removed (the command
  /// changes what an interrupt from then on says: the database is complete).
  /// Its argument: the file written (the output, or DB.failed.h5 beside it for a failing
  /// sweep: SweepReport::written).
  std::function<void(const std::filesystem::path&)> on_written;
};

struct SweepReport {
  std::vector<JobResult> results;  ///< every job, in job order (rank 0 only)
  int computed = 0;  ///< jobs run in this session (rank 0: by all ranks; others: by this rank)
  int resumed = 0;   ///< jobs taken from the checkpoints
  std::vector<fit::FitSummary> fits;  ///< one per loop length (empty if no fit)
  /// The energy-based law's fit (absent without a fit or with "energy_fit": false).
  std::optional<fit::EnergyFitSummary> energy_fit;
  double seconds_cases = 0, seconds_fit = 0, seconds_total = 0;
  int threads = 1, ranks = 1;
  /// The builds whose cases the database holds (CheckpointStore::builds(): more than this one
  /// after a resume by another build); /sweep/report/case_builds (rank 0 only).
  std::vector<std::string> case_builds;
  bool wrote_database = false;  ///< false on ranks other than 0
  /// Where rank 0 wrote the database: the output, or, for a sweep that fails (ok() false)
  /// while a database is at the output, beside it as failed_database_path(output) (session
  /// 38's red team: a failed sweep replaced a working database with one knit-macro cannot use).
  std::filesystem::path written;
  /// Why rank 0 did not write the database (empty: it did, or another rank): a sweep in which
  /// no case converged a single step stores nothing, and the output is left as it was.
  std::string not_written;
  /// Cases that fail the sweep: a paper path that did not converge to its end, or a runner
  /// error on any path. Coverage and held-out paths may stop early where the cell jams or
  /// buckles (issue 11): they are kept with their step status, counted by stopped_cases().
  int failed_cases() const;
  int stopped_cases() const;
  bool fits_ok() const;
  bool ok() const { return failed_cases() == 0 && fits_ok() && not_written.empty(); }
};

/// "DB.failed.h5" for "DB.h5" (the extension kept, ".failed" before it; "DB.failed" without
/// one): where a failing sweep writes its database when one is at the output already. The
/// n-th name (n >= 2), "DB.failed-n.h5", is taken when the ones before it are locked by
/// another process (a `knit-meso fit DB.failed.h5` running) or are not a database.
std::filesystem::path failed_database_path(const std::filesystem::path& output, int n = 1);

/// How many names failed_database_path offers a failing sweep (n = 1 .. this).
inline constexpr int kFailedDatabaseNames = 10;

/// True if this result makes the sweep fail (see SweepReport::failed_cases).
bool fails_sweep(const JobResult& r);

/// Runs the sweep; rank 0 writes the database. `mpi` may be nullptr (serial). Throws
/// knit::InputError before running any case if the fit cannot succeed with the input's paths
/// and fit options (fit::check_feasible), or if a checkpoint fails its digest on resume.
SweepReport run_sweep(const SweepInput& in, const SweepOptions& opt, const PathRunner& runner,
                      const MpiSession* mpi = nullptr);

/// The database of the finished jobs (raw data of every case, failed ones included; cell
/// parameters; yarn; the input), not fitted yet.
material::Database assemble_database(const SweepInput& in, const std::vector<JobResult>& results);

/// Fits every loop length from its usable cases (paper-set paths with at least one converged
/// step; the fitter skips non-converged steps; coverage and held-out paths never enter the
/// eq. 17 fit); stores the surfaces in db. Fits run in parallel.
std::vector<fit::FitSummary> fit_sweep_database(material::Database& db,
                                                const fit::FitOptions& options, int threads);

/// Writes db atomically to `output`, with the per-case report (/sweep/report: status,
/// attempts, step factor, converged steps, seconds, messages, residual stresses) -- via a
/// temporary file next to `output`, fsynced and renamed onto it when complete.
void write_sweep_database(const std::filesystem::path& output, const material::Database& db,
                          const SweepInput& in, const std::vector<JobResult>& results,
                          const SweepReport& report);

/// The default cap of knit-meso sweep --max-output-size, as knit-meso path's and rod's and
/// knit-macro run's: 2 GB.
inline constexpr std::uint64_t kDefaultMaxOutputBytes = 2'000'000'000;

/// The estimated size of what the sweep writes: the database and its checkpoints (both on
/// disk before the checkpoints are removed, and kept together with --keep-parts), from the
/// cases x steps of the input (measured on the synthetic runner: 116 bytes per step in the
/// database and 285 in a checkpoint, about 17 kB per case; rounded up, with 340 bytes per
/// checkpoint step for the cell runner's longer numbers and 128 kB per database).
std::uint64_t estimate_output_bytes(const SweepInput& in);

/// Refuses, before any case runs, a sweep whose estimated output exceeds max_bytes (0: no
/// cap): knit::InputError at the input field whose paths make most of it ("/load_paths/
/// holdout", "/load_paths/coverage", "/steps", ...), naming the loop lengths and the option.
void check_output_size(const SweepInput& in, std::uint64_t max_bytes);

/// The synthetic runner (knit-meso synth's law on the sweep's paths): deterministic, instant.
/// Test hooks (environment): KNIT_SWEEP_TEST_DELAY_MS sleeps per case; KNIT_SWEEP_TEST_COUNT_FILE
/// gets one line appended per case computed.
PathRunner synthetic_runner();
/// The same for a sweep input, whose loop lengths it checks first: an InputError at
/// /loop_lengths/k where the stand-in's stress would exceed what a database holds.
PathRunner synthetic_runner(const SweepInput& in);

/// The unit-cell runner (knit/meso/homog), configured by the input's "cell" object.
/// Throws knit::InputError for cell parameters the cell rejects.
PathRunner cell_runner(const SweepInput& in);

/// The runner selected by the input.
PathRunner make_runner(const SweepInput& in);

}  // namespace knit::meso::sweep
