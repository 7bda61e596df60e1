// The design file of `knit-macro design` (schemas/design.schema.json, docs/design.md): a knit
// case, design variables (control values of the l and/or alpha field with bounds; several
// control values in one variable are tied), objectives and a smoothness penalty. Plain
// structs; the JSON stays in design_problem.cpp.
#pragma once

#include <Eigen/Core>
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
  double initial = 0.0;  ///< the case's value at these indices
};

struct DesignObjective {
  enum class Kind { kReaction, kDisplacement, kStrainVariance, kTargetStrain };
  Kind kind = Kind::kReaction;
  std::string name;
  double weight = 1.0;
  std::vector<double> at_strain, target;
  int reaction = -1;  ///< index into the case's output.reactions
  int point = -1;     ///< index into the case's output.points
  int component = 0;  ///< x, y, z (displacement) or E11, E22, E12 (strain terms)
  Eigen::Vector2d u_range = {0, 1}, v_range = {0, 1};
};

struct DesignProblem {
  std::string file;       ///< the design file
  std::string case_file;  ///< resolved
  Case c;
  std::vector<DesignVariableSpec> variables;
  std::vector<DesignObjective> objectives;
  double smoothness = 0.0;
  /// The control values each variable sets, as DesignVariable entries (for case_with_design).
  std::vector<DesignVariable> expanded() const;
};

/// Reads and checks a design file. Every problem throws knit::InputError naming the design
/// file (or the case file, for errors inside the case) and the JSON pointer.
DesignProblem load_design(const std::string& path);

}  // namespace knit::macro

namespace knit::macro {

/// The weighted least-squares objective of a design at variable values x (one per
/// DesignProblem::variables entry) and its adjoint gradient (design_objective.cpp):
///   J = sum_terms weight sum_k (R(eps_k) - target_k)^2,  lambda_k = eps_k L / Delta_1.
/// This round evaluates reaction terms only; other terms (and a smoothness weight > 0) make
/// the status kNotConverged with a message saying so.
struct DesignEvaluation {
  RunStatus status = RunStatus::kCompleted;
  std::string message;
  double J = 0.0;
  std::vector<std::pair<std::string, double>> terms;  ///< per objective (name, value)
  Eigen::VectorXd gradient;                           ///< dJ/dx
};
DesignEvaluation evaluate_design(const DesignProblem& d, const std::vector<double>& x);

}  // namespace knit::macro

namespace knit::macro {

/// A bounded projected-gradient descent with backtracking (Armijo) on evaluate_design()
/// (design_optimize.cpp). INTERIM stand-in for the Ceres optimizer of issue 13: the first
/// step moves the variable with the largest gradient by 10 % of its bound interval; accepted
/// steps double the next trial, rejected ones halve it. Stops when a step changes no variable
/// by more than `x_tolerance` times its interval, or after `max_iterations`.
struct OptimizeOptions {
  int max_iterations = 30;
  double x_tolerance = 1e-6;
};
struct DesignIteration {
  int iteration = 0;
  double J = 0.0, gradient_norm = 0.0, seconds = 0.0;
  std::vector<double> x;
};
struct DesignResult {
  RunStatus status = RunStatus::kCompleted;
  std::string message;
  std::vector<double> x;  ///< the best design found (inside the bounds)
  double J = 0.0;
  std::vector<DesignIteration> history;
};
DesignResult optimize_design(const DesignProblem& d, const OptimizeOptions& options = {});

}  // namespace knit::macro

namespace knit::macro {

/// The case text with the variables at x and the database path made absolute, so that the
/// file runs as is with `knit-macro run` from any directory.
std::string design_case_text(const DesignProblem& d, const std::vector<double>& x);

}  // namespace knit::macro
