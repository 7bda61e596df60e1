// Newton's method with an exact Jacobian and load stepping with cut-back for a RodSystem.
//
// The Jacobian of the built-in equations is exact (analytic where linear, forward automatic
// differentiation of the quaternion terms; checked against finite differences in
// tests/meso/test_rod_unit.cpp). The unsymmetric sparse system is solved by Eigen::SparseLU.
// Numerical failure is a status in the report, never an exception (design/style.md, habit 4).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "knit/meso/rod/rod_system.hpp"

namespace knit::meso::rod {

struct NewtonOptions {
  /// Converged when the scaled residual max|w_i F_i| <= tol (w = RodSystem::row_scales()).
  double tol = 1e-10;
  int max_iterations = 25;
  /// Declared diverged if the scaled residual exceeds this factor times the initial one.
  double divergence_factor = 1e6;
};

struct NewtonReport {
  bool converged = false;
  int iterations = 0;
  double residual_initial = 0.0;  ///< scaled max-norm before the first iteration
  double residual_final = 0.0;    ///< scaled max-norm at exit
  std::vector<double> history;    ///< scaled max-norm per iteration (starting with the initial)
  std::string message;            ///< why it stopped ("converged", "singular Jacobian", ...)
};

/// Solves R(x, lambda) = 0 for x (updated in place; on failure x holds the last iterate).
/// extra: caller terms added at every iteration (contact, custom end rows).
NewtonReport solve_newton(const RodSystem& sys, Eigen::VectorXd& x, double lambda,
                          const std::vector<ExternalContribution*>& extra = {},
                          const NewtonOptions& opt = {});

/// Full residual (built-in + extra) and its Jacobian (for FD checks and custom solvers).
void assemble_all(const RodSystem& sys, const Eigen::VectorXd& x, double lambda,
                  const std::vector<ExternalContribution*>& extra, Eigen::VectorXd& F,
                  Eigen::SparseMatrix<double>& J);

struct PathOptions {
  int steps = 10;  ///< equal load steps from lambda_start to lambda_end
  double lambda_start = 0.0;
  double lambda_end = 1.0;
  int max_cutbacks = 10;  ///< successive halvings of an increment before giving up
  bool predictor = true;  ///< secant extrapolation from the previous increment
  /// Floor of the load increment, relative to the nominal one (lambda_end - lambda_start) /
  /// steps: a failed increment that would have to be cut below it stops the path. Unlike
  /// max_cutbacks (successive halvings, reset by every success), the floor holds over the
  /// whole path, so a path cannot creep on with ever smaller increments (choice: 1e-4).
  double min_increment = 1e-4;
  /// Cap on the total work: Newton iterations over the whole path, all increments and
  /// cut-backs included. 0 = automatic, kWorkFactor x steps x newton.max_iterations (room
  /// for every nominal step to be cut back several times).
  long max_total_iterations = 0;
  static constexpr long kWorkFactor = 10;
  NewtonOptions newton;

  /// The cap in effect (max_total_iterations or its automatic value).
  long work_cap() const;
  /// Empty if the options are usable, else the reason (naming the option).
  std::string validate() const;
};

/// How a load path ended.
enum class PathStop {
  kCompleted,   ///< lambda_end reached
  kStartState,  ///< the start state did not converge
  kCutbacks,    ///< max_cutbacks successive halvings of one increment failed
  kStepFloor,   ///< the increment would fall below min_increment x nominal
  kWorkCap,     ///< max_total_iterations Newton iterations spent
  kBadOptions   ///< PathOptions::validate() refused the options
};
std::string to_string(PathStop s);

struct StepRecord {
  double lambda = 0.0;
  int iterations = 0;
  double residual = 0.0;
};

struct PathReport {
  bool completed = false;                ///< lambda_end reached
  PathStop stop = PathStop::kCompleted;  ///< why the path ended (see message)
  double lambda_reached = 0.0;           ///< last converged load factor
  int increments = 0;  ///< converged increments (including cut-back sub-increments)
  int cutbacks = 0;
  int total_iterations = 0;
  std::vector<StepRecord> steps;  ///< one per converged increment
  std::string message;
};

/// Called after each of the `steps` target load factors has converged (not for sub-increments).
using StepCallback = std::function<void(int step, double lambda, const Eigen::VectorXd& x)>;

/// Load stepping: x must hold a converged state at lambda_start (e.g. initial_state() at 0).
/// A failed increment is halved (x restored) up to max_cutbacks times in a row; after a success
/// the increment grows back towards the nominal one. The path also stops (report.stop says
/// which) when an increment would fall below the floor min_increment, or when the total
/// Newton iterations reach work_cap(); x then holds the last converged state.
PathReport solve_path(const RodSystem& sys, Eigen::VectorXd& x, const PathOptions& opt,
                      const StepCallback& on_step = {},
                      const std::vector<ExternalContribution*>& extra = {});

}  // namespace knit::meso::rod
