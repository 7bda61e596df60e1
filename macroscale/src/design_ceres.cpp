// The Ceres adapter of `knit-macro design` (knit/macro/design_problem.hpp): the ONLY file of
// macroscale that includes Ceres (tests/common/test_layering.cpp checks it). Ceres sees one
// parameter block x (the design variables) with per-coordinate bounds and one cost function
// whose residuals are the weighted objective terms of evaluate_design() and whose Jacobian
// comes from the state sensitivities (one forward run over all load levels and one
// factorization per level per evaluation).
//
// CHOICE (docs/design.md "The optimizer"): bounded Levenberg-Marquardt on the residuals
// (ceres::Problem, TRUST_REGION / LEVENBERG_MARQUARDT, DENSE_QR) rather than a
// GradientProblem (L-BFGS on J, which has no bounds in Ceres) with a change of variables
// p = lo + (hi - lo)(1 + sin z)/2: the objectives are least squares of few residuals in few
// variables, where Gauss-Newton steps converge in a handful of iterations, the bounds are
// handled by Ceres' projection instead of a map whose derivative vanishes on the bounds
// (where an infeasible target's optimum lies), and the Jacobian costs no more than the
// gradient because the direct sensitivities du/dp are computed anyway.
#include <ceres/ceres.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>

#include "knit/macro/design_problem.hpp"

namespace knit::macro {

namespace {

using Clock = std::chrono::steady_clock;

/// Ceres' gradient tolerance, on J / J0 (optimize_design_ceres scales the residuals).
constexpr double kGradientTolerance = 1e-12;

/// Shared between the cost function and the iteration callback: the last evaluation (Ceres
/// asks for the Jacobian at an accepted point it evaluated before: the cached evaluation
/// answers without a second run) and the best design seen.
struct Tracker {
  const DesignProblem* d = nullptr;
  DesignResult* res = nullptr;
  std::vector<double> last_x;
  DesignEvaluation last;
  bool have_last = false;
  const DesignEvaluation& evaluate(const std::vector<double>& x) {
    if (have_last && x == last_x) return last;
    try {
      last = evaluate_design(*d, x, true);
    } catch (const std::exception& e) {  // never through Ceres: a failed evaluation
      last = DesignEvaluation();
      last.status = RunStatus::kNotConverged;
      last.message = e.what();
    }
    last_x = x;
    have_last = true;
    ++res->evaluations;
    ++res->gradients;
    res->forward_seconds += last.forward_seconds;
    res->gradient_seconds += last.gradient_seconds;
    if (last.status == RunStatus::kCompleted && last.J < res->J) {
      res->J = last.J;
      res->x = x;
      res->terms = last.terms;
      res->reached = last.reached;
      res->gradient = last.gradient;
    }
    return last;
  }
};

class DesignCost : public ceres::CostFunction {
 public:
  /// `scale` multiplies the residuals (and their Jacobian): 1 / sqrt(J0), so that Ceres sees
  /// J / J0 (below, optimize_design_ceres).
  DesignCost(Tracker& t, int residuals, int variables, double scale)
      : t_(t), n_(variables), scale_(scale) {
    set_num_residuals(residuals);
    mutable_parameter_block_sizes()->push_back(variables);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const std::vector<double> x(parameters[0], parameters[0] + n_);
    const DesignEvaluation& e = t_.evaluate(x);
    if (e.status != RunStatus::kCompleted || e.residuals.size() != num_residuals()) return false;
    for (int i = 0; i < num_residuals(); ++i) residuals[i] = scale_ * e.residuals(i);
    if (jacobians && jacobians[0])
      for (int i = 0; i < num_residuals(); ++i)
        for (int k = 0; k < n_; ++k) jacobians[0][i * n_ + k] = scale_ * e.jacobian(i, k);
    return true;
  }

 private:
  Tracker& t_;
  int n_;
  double scale_;
};

class History : public ceres::IterationCallback {
 public:
  History(DesignResult& r, Tracker& t, const std::vector<double>& x, Clock::time_point t0,
          double j0, std::function<void(const DesignIteration&)> on_iteration)
      : r_(r), t_(t), x_(x), t0_(t0), j0_(j0), on_iteration_(std::move(on_iteration)) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    // A rejected step leaves x where it was (its cost is the trial's): not a history point.
    if (s.iteration > 0 && !s.step_is_successful) return ceres::SOLVER_CONTINUE;
    DesignIteration h;
    h.iteration = s.iteration;
    // Ceres' cost is (1/2) sum (scale r)^2 = J / (2 J0): J = 2 cost J0 (not / scale^2, which
    // overflows for a J0 below 1e-308; the review of session 42).
    h.J = 2.0 * s.cost * j0_;
    // |dJ/dp| (DesignEvaluation::gradient) at the accepted design, as the projected-gradient method
    // reports it (session 37's red team: Ceres' gradient_norm of a bounded problem is |x - P(x -
    // g)|, the step to the bounds' projection, so 2 x it read 2.0 at l = 5.5 with upper bound 6.5
    // where |dJ/dl| is 13 to 397, and 200.067 by the other method). The accepted design is the last
    // one evaluated, so the cached evaluation answers (update_state_every_iteration: x_ is it).
    const DesignEvaluation& e = t_.evaluate(x_);
    h.gradient_norm = e.status == RunStatus::kCompleted ? e.gradient.norm()
                                                        : std::numeric_limits<double>::quiet_NaN();
    h.seconds = std::chrono::duration<double>(Clock::now() - t0_).count();
    h.x = x_;
    r_.history.push_back(h);
    if (on_iteration_) on_iteration_(h);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  DesignResult& r_;
  Tracker& t_;
  const std::vector<double>& x_;
  Clock::time_point t0_;
  double j0_;  ///< J0, or 1 where the residuals are not scaled
  std::function<void(const DesignIteration&)> on_iteration_;
};

}  // namespace

DesignResult optimize_design_ceres(const DesignProblem& d, const OptimizeOptions& opt) {
  const auto t0 = Clock::now();
  DesignResult res;
  std::vector<double> x;
  for (const auto& v : d.variables) x.push_back(v.initial);
  res.x = x;
  res.J = std::numeric_limits<double>::infinity();
  Tracker t;
  t.d = &d;
  t.res = &res;
  const DesignEvaluation& e0 = t.evaluate(x);
  if (e0.status != RunStatus::kCompleted) {
    res.status = DesignStatus::kFailed;
    res.message = e0.message;
    res.history.clear();
    return res;
  }
  res.J0 = e0.J;
  res.terms0 = e0.terms;
  const int n = static_cast<int>(x.size());
  ceres::Problem problem;
  // Ceres sees J / J0 (session 42's red team): its tolerances are absolute in places (the
  // gradient's; and a bounded problem measures the gradient as |x - P(x - g)|, which is 0 in
  // floating point once g is below the round-off of x), so a design whose weights were scaled
  // by 1e-16 stopped at its start, 'target not met', where the same design with weight 1
  // converged. Scaled, every weight gives the same steps.
  const double scale = e0.J > 0.0 && std::isfinite(e0.J) ? 1.0 / std::sqrt(e0.J) : 1.0;
  problem.AddResidualBlock(new DesignCost(t, static_cast<int>(e0.residuals.size()), n, scale),
                           nullptr, x.data());
  for (int i = 0; i < n; ++i) {
    problem.SetParameterLowerBound(x.data(), i, d.variables[static_cast<std::size_t>(i)].lower);
    problem.SetParameterUpperBound(x.data(), i, d.variables[static_cast<std::size_t>(i)].upper);
  }
  ceres::Solver::Options o;
  o.minimizer_type = ceres::TRUST_REGION;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.linear_solver_type = ceres::DENSE_QR;
  o.max_num_iterations = opt.max_iterations;
  o.parameter_tolerance = opt.x_tolerance;
  o.function_tolerance = opt.function_tolerance;  // relative change of J
  // Of J / J0 (the residuals' scale above).
  o.gradient_tolerance = kGradientTolerance;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  o.num_threads = 1;
  o.update_state_every_iteration = true;
  History history(res, t, x, t0, scale == 1.0 ? 1.0 : e0.J, opt.on_iteration);
  o.callbacks.push_back(&history);
  ceres::Solver::Summary summary;
  ceres::Solve(o, &problem, &summary);
  const bool failed =
      summary.termination_type == ceres::FAILURE || summary.termination_type == ceres::USER_FAILURE;
  if (failed) {
    // Levenberg-Marquardt fails after several trial designs in a row whose runs failed: say
    // what the last of them said, beside Ceres' own words.
    res.message = t.have_last && t.last.status != RunStatus::kCompleted && !t.last.message.empty()
                      ? "the last trial design's run failed: " + t.last.message +
                            " (Ceres: " + summary.message + ")"
                      : summary.message;
  }
  // A converged J = 0 (an exact target) ends by the function tolerance as well.
  classify_result(d, opt,
                  failed                                           ? SolverEnd::kFailed
                  : summary.termination_type == ceres::CONVERGENCE ? SolverEnd::kConverged
                                                                   : SolverEnd::kIterationLimit,
                  res);
  if (res.message.empty() && summary.termination_type != ceres::CONVERGENCE)
    res.message = summary.message;
  else if (res.status != DesignStatus::kConverged && !failed) {  // why it stopped (session 40)
    // Without Ceres' final period: the message goes on ("...: 50.; outputs in", session 56).
    std::string said = summary.message;
    while (!said.empty() && (said.back() == '.' || said.back() == ' ')) said.pop_back();
    res.message += (res.message.empty() ? "" : "; ") + ("Ceres: " + said);
  }
  return res;
}

}  // namespace knit::macro
