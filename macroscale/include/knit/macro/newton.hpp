// Incremental-iterative solution of f_int(u) = lambda f_ext with prescribed displacements
// ramped by lambda: full Newton-Raphson on the reduced system, an optional line search on
// the energy-like function g(alpha) = du . r(u + alpha du) (secant, Matthies & Strang 1979),
// and adaptive cut-back of the load increment when a step does not converge.
//
// Convergence of a step: ||r_free|| <= tolerance * max(||lambda f_ext||, ||f_int on the
// constrained DOFs||) + absolute_tolerance, or a Newton correction ||du|| <= 1e-8 ||u|| while
// the residual is within 1e3 of that (the round-off floor of very stiff problems). Dense LU
// (partial pivoting) up to `dense_limit` unknowns, sparse LU above; both accept the unsymmetric
// tangents of the knit response-surface material. A failure is a status in RunReport, never an
// exception.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>

#include "knit/macro/constraints.hpp"
#include "knit/macro/shell_model.hpp"

namespace knit::macro {

struct SolverOptions {
  int steps = 10;                     ///< nominal load steps from lambda = 0 to 1
  double tolerance = 1e-8;            ///< relative residual tolerance
  double absolute_tolerance = 1e-10;  ///< N, floor of the residual tolerance
  double displacement_tolerance =
      1e-8;                 ///< ||du|| / ||u|| accepted when the residual is at round-off
  int max_iterations = 25;  ///< Newton iterations per step
  int max_cutbacks = 8;     ///< halvings of the increment within one nominal step
  bool line_search = true;
  int dense_limit = 2500;  ///< dense LU up to this many unknowns
};

struct StepResult {
  int step = 0;           ///< converged step counter (1-based, includes cut-back substeps)
  double lambda = 0.0;    ///< load factor
  int iterations = 0;     ///< Newton iterations
  double residual = 0.0;  ///< final ||r_free||
  double seconds = 0.0;   ///< wall time of the step
  Eigen::VectorXd u;      ///< full displacement vector
  Eigen::VectorXd fint;   ///< internal forces (reactions on constrained DOFs)
};

enum class RunStatus { kCompleted, kNotConverged };

struct RunReport {
  RunStatus status = RunStatus::kCompleted;
  std::string message;  ///< why the run stopped (empty if completed)
  int converged_steps = 0;
  double last_lambda = 0.0;
};

using StepCallback = std::function<void(const StepResult&)>;

RunReport solve_load_steps(const ShellModel& model, const DofMap& dofs, const Eigen::VectorXd& fext,
                           const SolverOptions& options, const StepCallback& on_step);

}  // namespace knit::macro
