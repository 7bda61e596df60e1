// The design file of `knit-macro design` (schemas/design.schema.json, docs/design.md): a knit
// case, design variables (control values of the l and/or alpha field with bounds; several
// control values in one variable are tied), objectives and a smoothness penalty. Plain
// structs; the JSON stays in design_problem.cpp.
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "knit/macro/case.hpp"
#include "knit/macro/design_gradient.hpp"

namespace knit::macro {

struct DesignVariableSpec {
  std::string name;
  DesignVariable::Field field = DesignVariable::Field::kStitchValue;
  std::vector<int> indices;  ///< control values moved together (a symmetry tie)
  double lower = 0.0, upper = 0.0;
  double initial = 0.0;     ///< the case's value at these indices
  std::string unit = "mm";  ///< of its values and bounds: mm, or the angle field's deg / rad
};

struct DesignObjective {
  enum class Kind { kReaction, kDisplacement, kStrainVariance, kTargetStrain, kReactionLinearity };
  Kind kind = Kind::kReaction;
  std::string name;
  double weight = 1.0;
  std::vector<double> at_strain, target;
  int reaction = -1;  ///< index into the case's output.reactions
  int point = -1;     ///< index into the case's output.points
  int component = 0;  ///< x, y, z (displacement) or E11, E22, E12 (strain terms)
  /// The component's name as the design file writes it ("x" ... or "E11" ...).
  const std::string& component_name() const;
  Eigen::Vector2d u_range = {0, 1}, v_range = {0, 1};
  /// Strain terms: sample points per direction (a uniform grid over the region; a direction
  /// whose range is a single value -- a section -- has one).
  int samples_u = 11, samples_v = 11;
};

/// The control grid of a designed field (for the smoothness penalty): nu x nv values, u fastest.
struct DesignFieldGrid {
  DesignVariable::Field field = DesignVariable::Field::kStitchValue;
  int nu = 1, nv = 1;
  std::vector<double> values;  ///< the case's values (those of no variable stay fixed)
  /// Greville abscissae of the control values along u (nu) and v (nv): where a control value
  /// sits, so that a field linear in (u, v) has control values linear in them (the smoothness
  /// penalty's second differences are taken over them, session 54).
  std::vector<double> greville_u, greville_v;
};

/// The weights (w_a, w_b, w_c) of the smoothness penalty's second difference of three
/// neighbouring control values at Greville abscissae ga < gb < gc (docs/design.md, "smoothness"):
/// the divided second difference times h^2, h the mean spacing of the field's abscissae, so
/// that it is (1, -2, 1) at uniform spacing and 0 on a linear field at any spacing (session 54's
/// red team: the plain (1, -2, 1) made the clamped ends of a linear grading cost 0.0105, while
/// the docs said a linear grading is free). nullopt where two abscissae coincide (a repeated
/// knot: a jump the field's knots put there, not penalized).
std::optional<std::array<double, 3>> smoothness_weights(double ga, double gb, double gc, double h);

/// `optimizer` of the design file.
struct DesignOptimizerSpec {
  enum class Method { kCeres, kProjectedGradient };
  Method method = Method::kCeres;
  int max_iterations = 30;
  /// Converged when an accepted step lowers J by less than this fraction of J (choice: 1e-6,
  /// the last digits do not matter; a larger value stops a slow tail earlier).
  double function_tolerance = 1e-6;
  /// The step floor: with Ceres its parameter_tolerance (stop when |dx| <= tol (|x| + tol), the
  /// whole vector of variables in their own units); with the projected gradient, when a step
  /// changes no variable by more than this fraction of its interval. Since session 43 in the
  /// design
  /// file: graded_wale stopped there at iteration 17 while J still fell, and the message's
  /// advice (more iterations, a lower function_tolerance) could not move it. Unset: the
  /// caller's OptimizeOptions::x_tolerance (1e-6).
  std::optional<double> x_tolerance;
};

struct DesignProblem {
  std::string file;       ///< the design file
  std::string case_file;  ///< resolved
  Case c;
  std::vector<DesignVariableSpec> variables;
  std::vector<DesignObjective> objectives;
  double smoothness = 0.0;
  std::vector<DesignFieldGrid> fields;  ///< every field that has a variable
  DesignOptimizerSpec optimizer;
  /// `twin` of the design file (session 37): one value per variable, in variable order; empty
  /// without a twin. The reaction and displacement terms then take their targets from the
  /// case run at these values (set_twin_targets), so that the design must recover them: a
  /// twin experiment that stays one on any database (cases/design/uniform_load.json's fixed
  /// target, the 20 % load of l = 6.0 on session 25's database, was met at l = 5.904 on
  /// session 36's).
  std::vector<double> twin;
  /// The objectives whose targets come from the twin (reaction and displacement terms).
  std::vector<bool> twin_targets;
  /// The control values each variable sets, as DesignVariable entries (for case_with_design).
  std::vector<DesignVariable> expanded() const;
};

/// Reads and checks a design file. Every problem throws knit::InputError naming the design
/// file (or the case file, for errors inside the case) and the JSON pointer.
DesignProblem load_design(const std::string& path);

/// The targets of the twin-target terms (DesignProblem::twin_targets) from the case solved at
/// the twin's values: each term's reaction or displacement at each of its applied strains, the
/// same solve the optimizer makes (evaluate_design). Returns "" or, when that solve fails, why
/// (a numerical outcome: knit-macro design then exits with 1). Nothing to do without a twin.
std::string set_twin_targets(DesignProblem& d);

}  // namespace knit::macro

namespace knit::macro {

/// The weighted least-squares objective of a design at variable values x (one per
/// DesignProblem::variables entry), as residuals r (J = sum r^2) with their Jacobian dr/dx
/// from the state sensitivities (design_objective.cpp, knit/macro/design_sensitivity.hpp):
///   reaction, displacement: r_k = sqrt(w) (q(eps_k) - target_k), lambda_k = eps_k L / Delta_1
///   strain_variance:        r_i = sqrt(w / n) (E_i - mean E) over the n samples of the region
///                           (sum r^2 = w x the variance)
///   target_strain:          r_i = sqrt(w / n) (E_i - target_k)
///   reaction_linearity:     r_k = sqrt(w) (R(eps_k) - eps_k / eps_K R(eps_K)), k < K: the
///                           load-strain curve's distance from the straight line through the
///                           origin and its last point eps_K (the largest strain)
///   smoothness:             r = sqrt(w_s) (v_{i-1} - 2 v_i + v_{i+1}), second differences of
///                           each designed field's control values along u and along v
/// One forward run over all levels, one factorization per level.
struct DesignEvaluation {
  RunStatus status = RunStatus::kCompleted;
  std::string message;
  double J = 0.0;
  std::vector<std::pair<std::string, double>> terms;  ///< per objective (name, sum r^2)
  /// Per objective, at each of its at_strain levels: the reaction (N) or displacement (mm)
  /// reached, the mean of the strain over the samples (target_strain) or its standard
  /// deviation there (strain_variance; session 40); empty for reaction_linearity (what
  /// summary.txt reports beside the targets).
  std::vector<std::vector<double>> reached;
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian;  ///< dr/dx (residuals x variables); empty without gradient
  Eigen::VectorXd gradient;  ///< dJ/dx = 2 jacobian^T r
  double forward_seconds = 0.0, gradient_seconds = 0.0;
};
DesignEvaluation evaluate_design(const DesignProblem& d, const std::vector<double>& x,
                                 bool with_gradient = true);

}  // namespace knit::macro

namespace knit::macro {

/// The optimizers of `knit-macro design` (design file key `optimizer`):
///  * "ceres" (default; design_ceres.cpp, the only macroscale file that sees Ceres): bounded
///    Levenberg-Marquardt (ceres::Problem, one parameter block with per-coordinate bounds)
///    on the residuals and their Jacobian of evaluate_design();
///  * "projected_gradient" (design_optimize.cpp; the interim optimizer, kept to compare): a
///    bounded projected-gradient descent with Armijo backtracking on J; the first step moves
///    the variable with the largest gradient by 10 % of its bound interval; accepted steps
///    double the next trial, rejected ones halve it.
/// Both stop when a step changes no variable by more than `x_tolerance` times its interval,
/// when an accepted step lowers J by less than `function_tolerance` times J, or after
/// `max_iterations`. The result's status: kConverged (J at most `feasible` x J0: the targets
/// are met; J and J0 here without the smoothness penalty, a regularization), kIterationLimit,
/// kInfeasible (converged with J above `feasible` x J0 and a variable on a bound: the target is out
/// of reach inside the bounds in the direction J falls from there, a local verdict, since J need
/// not be convex in the variables; the best design is kept), kTargetNotMet (the same inside the
/// bounds: a local minimum, or a loose function tolerance; the best design is kept) or kFailed (a
/// solve failed). The two misses say why in DesignResult::message.
struct OptimizeOptions {
  int max_iterations = 30;
  double x_tolerance = 1e-6;
  double function_tolerance = 1e-6;
  /// J / J0 below which a converged design counts as meeting its targets.
  double feasible = 1e-6;
  /// Called with each history row as it is recorded (knit-macro design prints it: progress
  /// while it optimizes; session 42's red team: the rows were printed after the optimization,
  /// and an interrupted design left nothing).
  std::function<void(const struct DesignIteration&)> on_iteration;
};
enum class DesignStatus { kConverged, kIterationLimit, kInfeasible, kTargetNotMet, kFailed };
/// "converged", "iteration limit", "infeasible target", "target not met", "failed".
std::string to_string(DesignStatus s);
struct DesignIteration {
  int iteration = 0;
  double J = 0.0, gradient_norm = 0.0, seconds = 0.0;
  std::vector<double> x;
};
struct DesignResult {
  DesignStatus status = DesignStatus::kConverged;
  std::string message;
  std::vector<double> x;  ///< the best design found (inside the bounds)
  double J = 0.0, J0 = 0.0;
  std::vector<std::pair<std::string, double>> terms0, terms;  ///< at the start and the best
  std::vector<std::vector<double>> reached;  ///< DesignEvaluation::reached of the best design
  Eigen::VectorXd gradient;  ///< dJ/dx at the best design (empty if none was evaluated)
  std::vector<DesignIteration> history;
  int evaluations = 0;  ///< objective evaluations (each one forward run)
  /// Wall seconds over all evaluations: forward solves, and the sensitivities (gradients).
  double forward_seconds = 0.0, gradient_seconds = 0.0;
  int gradients = 0;  ///< evaluations with a gradient
};
/// Runs the optimizer the design file names (options.max_iterations from the file).
DesignResult optimize_design(const DesignProblem& d, const OptimizeOptions& options = {});
DesignResult optimize_design_projected(const DesignProblem& d, const OptimizeOptions& options);
DesignResult optimize_design_ceres(const DesignProblem& d, const OptimizeOptions& options);
/// How the optimizer stopped: by its tolerances, at its iteration limit, or by a failure of
/// the solver itself (Ceres' FAILURE: e.g. the runs of several trial designs in a row failed).
enum class SolverEnd { kConverged, kIterationLimit, kFailed };
/// Sets the status from the termination and the bounds (shared by both optimizers): kFailed
/// for a failed solver, whatever the count of evaluations before it (session 35: a failure
/// after the first evaluation said "iteration limit"); the best design so far is kept.
void classify_result(const DesignProblem& d, const OptimizeOptions& options, SolverEnd end,
                     DesignResult& r);
/// Where a stop inside or on the bounds stands (session 40's walkthrough: an alpha design
/// started at alpha = 0, where J is even in alpha and its gradient 6e-17, was called "infeasible
/// target: the targets lie outside the bounds"; a stop with |dJ/dl| = 794 N^2/mm pointing into
/// the bounds was called the same). With s_i = |dJ/dx_i| (upper_i - lower_i), the first-order
/// change of J over variable i's whole interval, and the projected gradient (a component on a
/// bound that points out of the bounds counts 0):
///  * kStationary: every s_i <= 1e-9 J at a design that never left the start: the gradient
///    vanishes there (a symmetry point, or objectives that do not depend on the variables);
///    where the optimizer moved, a vanishing gradient is a minimum (kInside);
///  * kNotStationary: a variable whose gradient does not point out of the bounds has
///    |dJ/dx_i| times the room left towards the bound it descends to > 1e-2 J: J still
///    decreases inside the bounds;
///  * kPushesOut: otherwise, with a variable on a bound whose gradient points out of the bounds
///    by s_i > 1e-9 J: the bounds keep the targets out of reach;
///  * kInside: otherwise (a minimum inside the bounds as far as the gradient tells);
///  * kUnknown: no gradient of the best design (classify_result then goes by the bounds alone).
enum class DesignStop { kStationary, kNotStationary, kPushesOut, kInside, kUnknown };
DesignStop design_stop(const DesignProblem& d, const std::vector<double>& x,
                       const Eigen::VectorXd& gradient, double J);

struct RunResult;  // knit/macro/run.hpp
/// What `knit-macro design` ends with, once its outputs are written: exit code 0 and no reason
/// for a converged design or an infeasible target whose final run (the best design, run to the
/// case's full load) is a plain success; 1 and the reason for an iteration limit or a failed
/// optimization, and for a final run that stopped, whose material failed or whose outputs are
/// not finite (the design's result is its final run; session 23, before: exit 0).
struct DesignVerdict {
  int exit_code = 0;
  std::string reason;  ///< empty for exit code 0
};
DesignVerdict design_verdict(const DesignResult& r, const RunResult& final_run);

}  // namespace knit::macro

namespace knit::macro {

/// The case text with the variables at x and the database path made absolute, so that the
/// file runs as is with `knit-macro run` from any directory.
std::string design_case_text(const DesignProblem& d, const std::vector<double>& x);
/// Where the final run (run/, the case's own load steps) has no state at an objective's strain
/// (session 40's walkthrough: a target at 20 % with steps of 1.5 % had no row or field there):
/// one note per such strain, naming the objective, the nearest steps and how to get one (a
/// step count); and where the step exists but /output/every writes no fields at it. The
/// values the design reached are solved at the objective's strain itself either way.
std::vector<std::string> final_run_step_notes(const DesignProblem& d);

}  // namespace knit::macro
