// The sweep input (issue #7; paper Sect. 2.1.2 and 3.1.1): which loop lengths, which load paths
// (eq. 7) with how many steps, how the unit cell is set up, how non-converged cases are retried
// and how the response surfaces are fitted (eq. 17). Schema: schemas/sweep.schema.json;
// the default sweep is cases/sweep/default.json (5 loop lengths x 13 paths x 20 steps).
//
//   auto in = knit::meso::sweep::load_sweep_input("cases/sweep/default.json");
//
// Bad input throws knit::InputError(file, json_pointer, message) (exit code 2).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "knit/material/load_paths.hpp"
#include "knit/meso/fit/energy_fit.hpp"
#include "knit/meso/fit/response_fit.hpp"

namespace knit::meso::sweep {

enum class RunnerKind {
  kCell,      ///< the periodic unit cell (knit/meso/homog)
  kSynthetic  ///< the synthetic law of `knit-meso synth` (tests/demos of the orchestration)
};

/// The most cell solves one attempt of a path may take (steps x substeps x step_factor^a):
/// at about 30 ms a solve (the default sweep on this project's machine) about 1.7 hours.
/// A sweep input whose last retry would take more is refused when it is read.
inline constexpr long long kMaxCellSolvesPerAttempt = 200'000;

/// Retry policy for a load case that does not converge: rerun with step_factor^a times more
/// steps (a = 1..max_retries); the recorded steps (every step_factor^a-th) are unchanged,
/// because F* is linear in the step fraction along every path.
struct RetryPolicy {
  int max_retries = 2;
  int step_factor = 2;
  /// Retries of coverage and held-out paths (issue 11): many of them end where the cell jams
  /// or buckles, where smaller steps do not help, and each retry reruns the whole path.
  int max_retries_extra = 0;
  int retries_for(const material::LoadPath& p) const {
    return p.set == "paper" ? max_retries : max_retries_extra;
  }
  /// Cell solves per recorded step on the first attempt, per path set (sweep input
  /// "substeps", session 18; retries multiply it by step_factor). With friction the cell is
  /// path-dependent, and a large step can land on another equilibrium branch than the
  /// quasi-static path: in the default sweep two held-out paths' stresses change by up to
  /// 21.8 % of the range with 4 times the steps (docs/law-experiments.md). 1: every solve recorded.
  int substeps_paper = 1, substeps_coverage = 1, substeps_holdout = 1;
  int substeps_for(const material::LoadPath& p) const {
    return p.set == "paper" ? substeps_paper
                            : (p.set == "holdout" ? substeps_holdout : substeps_coverage);
  }
};

struct SweepInput {
  std::string file;                  ///< where it was read from (messages)
  std::string json;                  ///< the whole input, as given (stored in the database)
  std::vector<double> loop_lengths;  ///< mm, strictly increasing
  std::vector<material::LoadPath> paths;
  /// Indices of `paths` in the shared default set (-1 for explicitly listed paths).
  std::vector<int> path_ids;
  /// The input field each path comes from, for messages: "/steps" (the preset's paths, whose
  /// steps it sets), "/load_paths/coverage", "/load_paths/holdout", "/load_paths/extra" or
  /// "/load_paths" (an explicit list).
  std::vector<std::string> path_fields;
  RunnerKind runner = RunnerKind::kCell;
  /// The cell parameters (schemas/cell.schema.json) as JSON text: the inline "cell" object or
  /// the content of the file it names; "{}" = the cell's defaults.
  std::string cell_json = "{}";
  std::string cell_file;  ///< the cell parameter file, if "cell" named one (messages)
  RetryPolicy retry;
  /// Subtract the residual stress of the cell at F* = I from every step (see
  /// schemas/sweep.schema.json "residual_stress"); applied when the database is assembled.
  /// Default false: the default cell is stress-free (docs/unit-cell.md).
  bool subtract_residual = false;
  bool fit = true;
  fit::FitOptions fit_options;
  /// The energy-based law (issue 11), fitted after the paper's law when `fit` is on; the
  /// input key "energy_fit": false | {options of knit/meso/fit/energy_fit.hpp}.
  bool energy_fit = true;
  fit::EnergyFitOptions energy_fit_options;
  /// Whether the input gave "energy_fit" options (the run's report says when the code's
  /// defaults were used: they are not the default sweep's, which hold the fit within 4.5 %).
  bool energy_fit_given = false;

  /// Canonical JSON of everything that determines the job results (loop lengths, paths,
  /// runner, cell, retry) -- not the fit options: a resumed sweep may refit differently.
  std::string job_definition() const;
};

/// Reads, validates against schemas/sweep.schema.json and checks what the schema cannot
/// (increasing loop lengths, fit options) -- errors name the file and the JSON pointer.
SweepInput load_sweep_input(const std::filesystem::path& file);
/// The same from JSON text (`file` names it in errors).
SweepInput parse_sweep_input(const std::string& text, const std::string& file);

/// A 64-bit FNV-1a variant (offset basis 1469598103934665603, not the standard's
/// 14695981039346656037; docs/sweep.md) as 16 hex digits (fingerprint of a job definition).
std::string fingerprint(const std::string& text);

}  // namespace knit::meso::sweep
