// Running a case (`knit-macro run CASE.json [--output DIR]`): set up the shell, the DOF map
// and the loads, solve with load stepping, and write one output directory:
//   load_strain.csv   one row per converged step (load factor, applied displacement and
//                     strain, reactions, displacements of named points, iterations, residual,
//                     seconds, negative pivots of the tangent: > 0 marks an unstable state)
//   results.pvd       ParaView collection of vtk/step_NNNN.vtu (deformed mid-surface grid with
//                     displacement, E11/E22/E12, curvature change, n, m, material fields)
//   results.h5        the same fields, the case JSON and provenance (when HDF5 is available)
//   case.json         the case as read
// The directory is built as DIR.partial-<pid> and renamed to DIR at the end, so it is never
// half-written; a run that stops early still writes every converged step (status in the
// summary) and the caller returns exit code 1. So does a run in which the material failed to
// evaluate somewhere (Material::failed_evaluations() > 0, e.g. response-surface inversions that
// did not converge): its results are not trustworthy, even if every step converged; the
// message says so on stderr and in summary.txt, and the outputs are kept.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "knit/macro/case.hpp"
#include "knit/macro/constraints.hpp"
#include "knit/macro/newton.hpp"
#include "knit/macro/shell_model.hpp"

namespace knit::macro {

struct Problem {
  std::unique_ptr<ShellModel> model;
  DofMap dofs;
  Eigen::VectorXd fext;  ///< dead loads at load factor 1
  /// Input that runs but is very likely not what was meant, each "POINTER: what" (a load on
  /// held degrees of freedom only); run_case reports them as warnings.
  std::vector<std::string> warnings;
};

/// The gauge length against the jaws (session 53): for an applied displacement on an edge whose
/// opposite edge an edge condition fixes or prescribes in the same component, "POINTER: what"
/// if the gauge length differs from the distance between the two edges along that component
/// (the mean of each edge's control points) by more than kGaugeJawTolerance of it, or if the
/// opposite edge is prescribed a nonzero displacement there too (the curve's strain leaves that
/// jaw's motion out); else empty. The strain in load_strain.csv is the applied displacement
/// over the gauge length, so a gauge that is not the jaws' distance scales every strain of the
/// curve without a word. Not judged: a corner (the paper's corner-loaded cases take half the
/// diagonal), an opposite edge held by a symmetry plane or not held (a half model's jaws are
/// not both in the patch), a component that does not separate the edges (a load along them),
/// and edges not straight across the component (a curved edge's control points).
std::string gauge_length_warning(const Case& c);
inline constexpr double kGaugeJawTolerance = 0.01;

/// Builds the model, constraints and loads. Throws knit::InputError for a degenerate geometry
/// (zero Jacobian, with its location), contradictory constraints and missing supports (an
/// unconstrained rigid-body motion).
Problem setup_problem(const Case& c);

/// One row of load_strain.csv.
struct StepRow {
  int step = 0;
  double lambda = 0.0;
  double applied = 0.0, strain = 0.0;   ///< if the case names an applied displacement
  std::vector<double> reactions;        ///< one per output.reactions entry (N)
  std::vector<Eigen::Vector3d> points;  ///< displacement of each output point (mm)
  int iterations = 0;
  double residual = 0.0, seconds = 0.0;
  int negative_pivots = -1;  ///< of the reduced tangent (StepResult), -1 if not available
  int determinant_sign = 0;  ///< sign of det of the reduced tangent (StepResult)
};

/// The control points a reaction output sums over: the first `rows` rows of its edge, or its
/// corner's pad (corner_region(radius)).
std::vector<int> reaction_points(const ShellModel& m, const ReactionOutput& r);

/// Sum of f(3 a + component) over the control points a.
double sum_over(const Eigen::VectorXd& f, const std::vector<int>& points, int component);

/// A support reaction (N): the internal force less the dead load applied at its control
/// points, sum_a f_int - lambda f_ext (session 36: the load there was left in, so an area
/// load's share of a supported row showed as an imbalance of 3 % at 2 x 2 elements).
inline double support_reaction(const Eigen::VectorXd& fint, const Eigen::VectorXd& fext,
                               double lambda, const std::vector<int>& points, int component) {
  return sum_over(fint, points, component) - lambda * sum_over(fext, points, component);
}

/// Default cap on the estimated size of a run's output directory (estimate_output_bytes):
/// above it the run is refused before any work; above a tenth of the cap it warns.
inline constexpr std::uint64_t kDefaultMaxOutputBytes = 2'000'000'000;  // 2 GB

struct RunOptions {
  std::filesystem::path output_dir;  ///< empty: no files are written (tests)
  std::ostream* progress = nullptr;  ///< one line per converged step
  std::ostream* warnings = nullptr;  ///< e.g. a large estimated output
  /// Cap on the estimated output size (0: none); knit-macro run --max-output-size.
  std::uint64_t max_output_bytes = kDefaultMaxOutputBytes;
};

/// Estimated size in bytes of the output directory of a case, an upper bound for a run without
/// cut-backs (docs/io.md, "Output size"): output steps x (grid samples x fields x bytes per
/// value + each file's and HDF5 dataset's overhead) + 1 % + 48 kB, with
///   output steps = ceil(solver.steps / output.every) (cut-backs may add a few),
///   fields       = 3 coordinates + 3 displacements + 12 strains/curvatures/stress resultants
///                  + the material's extra fields, base64 float64 in VTU (10.7 bytes each),
///                  and 9 + 12 + extra float64 per sample in HDF5 (held in memory until the end).
std::uint64_t estimate_output_bytes(const Case& c);

struct RunResult {
  RunReport report;
  /// Material::failed_evaluations() at the end of the run; > 0 means not trustworthy.
  long failed_material_evaluations = 0;
  /// Material::warning() at the end of the run (empty: none).
  std::string material_warning;
  /// load_drop_message() of each reaction whose load falls between converged steps
  /// (load_drop.hpp): warnings, not failures (a buckling test may drop on purpose).
  std::vector<std::string> load_drops;
  /// Problem::warnings of the case (input that runs but is likely not what was meant).
  std::vector<std::string> input_warnings;
  /// solver_fallback_message() of the run: the supernodal Cholesky failed where it was wanted
  /// and Eigen's SimplicialLDLT factorized instead (slower); "" if not. A warning.
  std::string solver_warning;
  /// Empty, or where the written output fields held a non-finite number (results_writer.hpp:
  /// the output grid reached a strain where the material's stress is not finite).
  std::string output_failure;
  /// False when the run wrote no output directory (none asked for, or a run without a
  /// converged step that left an earlier output in place).
  bool wrote_outputs = false;
  /// The outputs written replaced an earlier output of the same directory (what a stopped
  /// run's message says: session 40's red team found a complete earlier output replaced by a
  /// stopped run's, unsaid).
  bool replaced_earlier = false;
  /// Where the completed earlier output went when a run that did not succeed replaced it
  /// (DIR.last-completed; session 46), else empty.
  std::filesystem::path earlier_kept_in;
  /// Plain success: every step converged, the material never failed and every output value is
  /// finite.
  bool succeeded() const {
    return report.status == RunStatus::kCompleted && failed_material_evaluations == 0 &&
           output_failure.empty();
  }
  std::vector<StepRow> rows;
  Eigen::VectorXd u;  ///< displacement of the last converged step
};

RunResult run_case(const Case& c, const RunOptions& options);

/// "completed with N failed material evaluations; results are not trustworthy" (or
/// "stopped ..." for a run that did not complete); empty if n == 0.
std::string material_failure_message(const RunReport& report, long n);

/// "the supernodal Cholesky (CHOLMOD) failed in <what>: <status>; N factorizations were made by
/// Eigen's SimplicialLDLT instead ..." from the run's SolverStats; "" if it never failed.
std::string solver_fallback_message(const SolverStats& stats);

/// Why a run is not a plain success (RunResult::succeeded()): the stop message (with what to
/// change when Newton gave up), the material's failures and the output failure, joined by "; ";
/// empty if it succeeded.
std::string run_failure_message(const RunResult& r);

/// Every warning of a finished run, one line each, without the "warning: " prefix: the input
/// warnings, the load drops, the solver's fallback and each line of the material's warning
/// (knit-macro design's summary.txt; session 47).
std::vector<std::string> run_warning_lines(const RunResult& r);

}  // namespace knit::macro
