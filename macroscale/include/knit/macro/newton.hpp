// Incremental-iterative solution of f_int(u) = lambda f_ext with prescribed displacements
// ramped by lambda: full Newton-Raphson on the reduced system and adaptive cut-back of the
// load increment when a step does not converge.
//
// Convergence of a step: ||r_free|| <= tolerance * max(||lambda f_ext||, ||f_int on the
// constrained DOFs||) + absolute_tolerance, or a Newton correction ||du|| <= 1e-8 ||u|| while
// the residual is within 1e3 of that (the round-off floor of very stiff problems). A residual
// or reference force that is not finite fails the step (never "converged").
//
// Linear algebra (reduced_tangent.hpp): the scatter map, the sparsity pattern and the symbolic
// factorization are built once per run; each iteration refactorizes numerically. Dense up to
// `dense_limit` unknowns, sparse above (the crossover measured by scripts/bench/solver.sh).
// A hyperelastic material (Material::hyperelastic()) gets the symmetric path: lower triangle,
// LDLT, the inertia of the reduced tangent (negative pivots of D) reported per step, and an
// energy line search; other materials (the unsymmetric eq. 17 response surface) get LU.
//
// Line search, the full Newton step first:
//  * hyperelastic: each load step is first tried with plain Newton (full steps, halved only
//    while they degenerate the geometry); only when that attempt fails is the step repeated
//    with an energy line search on the total potential Pi(u) = Psi(u) - lambda f_ext . u (Psi
//    the strain energy, ShellModel::Evaluation::energy): the full step is taken when Pi does
//    not increase (Armijo, c1 = 1e-4, or a change within round-off of Pi) or when du is not a
//    descent direction (an indefinite tangent past a limit point: Newton then looks for an
//    unstable equilibrium, which Pi cannot rank); otherwise backtracking with the minimum of
//    the quadratic through Pi(0), Pi'(0) and Pi(alpha), alpha in [0.1, 0.5] of the last one.
//    (Searching in every iteration turned the Sze cantilever's 60 iterations into 82: Newton
//    recovers from overshooting steps that raise Pi, the search only slows it down.)
//    `line_search_first` (a case's choice) searches first and tries plain Newton second.
//  * otherwise: when the full step increases ||r|| and does not halve g(alpha) = du . r(u +
//    alpha du), secant iterations on g (Matthies & Strang 1979).
//
// Load stepping stops with a reason (RunReport::reason): the increment cut `max_cutbacks`
// times within one nominal step, the increment below the floor `min_increment`, or the total
// work above `max_total_iterations` Newton iterations. A failure is a status in RunReport,
// never an exception.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>

#include "knit/macro/constraints.hpp"
#include "knit/macro/reduced_tangent.hpp"
#include "knit/macro/shell_model.hpp"

namespace knit::macro {

struct SolverOptions {
  int steps = 10;                     ///< nominal load steps from lambda = 0 to 1
  double tolerance = 1e-8;            ///< relative residual tolerance
  double absolute_tolerance = 1e-10;  ///< N, floor of the residual tolerance
  /// The case's force symbol ("N" by default, unit_labels(/units).of("N")), for messages only
  /// (session 49's review: a case in m, kN, kPa was told its out-of-balance force in N).
  std::string force_unit = "N";
  double displacement_tolerance =
      1e-8;                 ///< ||du|| / ||u|| accepted when the residual is at round-off
  int max_iterations = 25;  ///< Newton iterations per step
  int max_cutbacks = 8;     ///< halvings of the increment within one nominal step
  /// Floor of the load increment (in load factor): a step that would need a smaller one stops
  /// the run.
  double min_increment = 1e-9;
  /// Cap on the total work: Newton iterations over the whole run, failed attempts included.
  /// 0: 20 x steps x max_iterations.
  long max_total_iterations = 0;
  bool line_search = true;
  /// Hyperelastic materials: the energy line search from the first attempt of every load step,
  /// plain Newton only when that fails (the default is the other way round; needs line_search). For
  /// shells whose membrane goes slack (bending-dominated, e.g. the hyperbolic paraboloid in
  /// tension): plain Newton's overshooting iterates visit strains far outside the material law's
  /// data before it recovers; the search keeps Pi from rising (docs/solver.md).
  bool line_search_first = false;
  LinearSolver linear_solver = LinearSolver::kAuto;
  /// Dense up to this many unknowns with kAuto. Measured crossover (scripts/bench/solver.sh,
  /// Sze cantilever refinements, 2-core machine): sparse is faster from ~150 unknowns on.
  int dense_limit = 150;
  /// false: LU even for a hyperelastic material (to compare the paths; the line search and
  /// everything else stay the same).
  bool symmetric = true;
  /// Sparse symmetric path: CHOLMOD's supernodal Cholesky while the tangent is positive
  /// definite (SimplicialLDLT otherwise); false: always SimplicialLDLT (to compare the paths).
  bool supernodal = true;
  /// Sparse symmetric path: the tangents the supernodal Cholesky refuses (indefinite) go to
  /// MUMPS's multifrontal LDLT when the build has it; false: to the SimplicialLDLT (to compare
  /// the paths).
  bool multifrontal = true;
  /// Progress of long runs (session 37's red team: a 256 x 256 patch printed nothing for 9.6
  /// min): called with a line after a setup of more than `progress_after` seconds (unknowns,
  /// factorization, seconds) and, within a step, for an iteration that ends more than
  /// `progress_after` seconds after the last line (the iteration, residual, seconds). Empty: no
  /// lines. The per-step lines are the StepCallback's.
  std::function<void(const std::string&)> progress;
  double progress_after = 5.0;
};

struct StepResult {
  int step = 0;           ///< converged step counter (1-based, includes cut-back substeps)
  double lambda = 0.0;    ///< load factor
  int iterations = 0;     ///< Newton iterations
  double residual = 0.0;  ///< final ||r_free||
  double seconds = 0.0;   ///< wall time of the step
  /// Negative pivots of the LDLT of the reduced tangent at the last iterate factorized in
  /// this step (the number of unstable modes; > 0 past a limit or bifurcation point), -1 on
  /// the LU path (unsymmetric material: not available).
  int negative_pivots = -1;
  /// Sign of det of the reduced tangent at that iterate (Factorization::determinant_sign):
  /// +1 or -1; 0 before any factorization. The LU path's stability indicator.
  int determinant_sign = 0;
  Eigen::VectorXd u;     ///< full displacement vector
  Eigen::VectorXd fint;  ///< internal forces (reactions on constrained DOFs)
};

enum class RunStatus { kCompleted, kNotConverged };

/// Why a run stopped (kNone if it completed).
/// kLoadBelowTolerance: the first step "converged" at the undeformed state with no iteration
/// although it is out of balance there (||r|| > 0): the loads lie within the tolerance, and
/// every step would report the undeformed state (session 27: an edge load of 5e-11 N ran with
/// exit 0 and zero displacements under the default absolute_tolerance of 1e-10 N).
enum class StopReason { kNone, kCutbacks, kIncrementFloor, kWorkCap, kLoadBelowTolerance };

/// Where the time of a run went (wall seconds), for benchmarks.
struct SolverStats {
  long iterations = 0;   ///< Newton iterations (tangent + solve), failed attempts included
  long evaluations = 0;  ///< residual-only evaluations (line search, convergence checks)
  /// Tangents completed from the point states of the residual-only evaluation at the same
  /// state (ShellModel::tangent_from) instead of a full evaluation.
  long tangents_reused = 0;
  double setup = 0.0;      ///< scatter map, pattern and symbolic analysis (once)
  double assembly = 0.0;   ///< element tangents and forces + scatter into the reduced matrix
  double solve = 0.0;      ///< numeric factorization and triangular solves
  double residuals = 0.0;  ///< residual-only evaluations
  /// CPU seconds (all threads) of assembly, solve and residuals: on a loaded machine the cost of a
  /// one-thread run, where the wall time also counts the waits for a core.
  double assembly_cpu = 0.0, solve_cpu = 0.0, residuals_cpu = 0.0;
  int unknowns = 0;
  long stored_entries = 0;  ///< of the reduced matrix
  bool sparse = false, symmetric = false;
  bool supernodal = false;  ///< the sparse symmetric path tries the supernodal Cholesky
  std::string ordering;     ///< its fill-reducing ordering (ReducedTangent::ordering())
  /// ReducedTangent::supernodal_failure() and fallback_factorizations() at the end of the run.
  std::string supernodal_failure;
  long fallback_factorizations = 0;
  /// Factorizations by MUMPS's multifrontal LDLT (the indefinite tangents of the supernodal
  /// path), and why MUMPS failed ("" if it did not; the SimplicialLDLT took over from there).
  bool multifrontal = false;  ///< the indefinite tangents go to MUMPS (when the run began)
  long multifrontal_factorizations = 0;
  std::string multifrontal_failure;
  int threads = 1;  ///< assembly threads
};

/// The out-of-balance force, relative to the reference force, above which a step that the
/// absolute tolerance alone accepted is reported (RunReport::loose_steps): 1e-4, 0.01 %, below
/// what a load-strain curve shows (s323_hypar_compression's first steps, at 1.65e-6 of their
/// 2.8e-5 N, are not reported; the red team's 2e-9 N patch, at up to 2.7 %, is).
inline constexpr double kLooseRelativeResidual = 1e-4;

struct RunReport {
  RunStatus status = RunStatus::kCompleted;
  StopReason reason = StopReason::kNone;
  std::string message;  ///< why the run stopped (empty if completed)
  int converged_steps = 0;
  double last_lambda = 0.0;
  /// Stability (symmetric path only): the first converged step with a negative pivot, its
  /// load factor, and the largest count over the run; -1 / 0 if none (or not available).
  int first_unstable_step = -1;
  double first_unstable_lambda = 0.0;
  int max_negative_pivots = -1;
  /// The sign of det K (both paths; the LU path's only indicator): the first converged step
  /// with det K < 0 (-1 if none), its load factor, and how many converged steps had it.
  int first_negative_determinant_step = -1;
  double first_negative_determinant_lambda = 0.0;
  int negative_determinant_steps = 0;
  /// Converged steps whose tangent could not be factorized there (singular): sign unknown (0).
  int unknown_determinant_steps = 0;
  /// Converged steps that only the absolute tolerance let through with an out-of-balance
  /// force above kLooseRelativeResidual of the reference force (loads too small for
  /// /solver/absolute_tolerance), the largest such ratio, its load factor and reference force.
  int loose_steps = 0;
  double loosest_relative_residual = 0.0, loosest_lambda = 0.0, loosest_reference = 0.0;
  SolverStats stats;
};

using StepCallback = std::function<void(const StepResult&)>;

RunReport solve_load_steps(const ShellModel& model, const DofMap& dofs, const Eigen::VectorXd& fext,
                           const SolverOptions& options, const StepCallback& on_step);

/// Energy line search along a Newton direction du: Pi(alpha) = Pi(u + alpha du) (nullopt if
/// the state is invalid), Pi0 = Pi(0), g0 = dPi/dalpha(0) = du . r, Pi_scale the round-off
/// scale of Pi. Tries alpha = 1 first; returns it when Pi decreases by the Armijo condition
/// (within round-off) or when g0 >= 0 (no descent direction); otherwise backtracks (quadratic
/// model, alpha in [0.1, 0.5] of the previous one, at most 10 times).
struct EnergyLineSearch {
  double alpha = 1.0;
  double Pi = 0.0;     ///< Pi(alpha)
  bool valid = false;  ///< Pi(alpha) could be evaluated
  int evaluations = 0;
};
EnergyLineSearch energy_line_search(const std::function<std::optional<double>(double)>& Pi,
                                    double Pi0, double g0, double Pi_scale);

/// The round-off floor of a Newton iteration: the residual norm r (reference force ref) is
/// within 1e3 of the tolerance (f_int's round-off can exceed tolerance * ref on very stiff
/// problems) and the correction is at round-off, du_rel = ||du|| / ||u|| <=
/// displacement_tolerance; or, when r has stopped falling (r >= 0.99 r2, r2 the residual of
/// two iterations before), du_rel <= 100 displacement_tolerance (soft tangents map the floor to
/// larger corrections). The step is then converged; iterating on would only reach
/// max_iterations and cut the step back.
bool at_round_off_floor(double r, double ref, double du_rel, double r2, const SolverOptions& opt);

/// One line on the stability of a run for summaries: "tangent positive definite at every
/// converged step", "unstable from step N (load factor x): k negative pivots at most", or on
/// the LU path "unsymmetric tangent (LU factorization: ...): det K > 0 at every converged step
/// ..." / "det K < 0 from step N ...".
std::string stability_summary(const RunReport& report);

}  // namespace knit::macro
