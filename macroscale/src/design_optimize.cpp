// Projected-gradient descent on the design objective (knit/macro/design_problem.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>

#include "knit/macro/design_problem.hpp"

namespace knit::macro {

DesignResult optimize_design(const DesignProblem& d, const OptimizeOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = d.variables.size();
  DesignResult res;
  for (const auto& v : d.variables) res.x.push_back(v.initial);
  DesignEvaluation cur = evaluate_design(d, res.x);
  if (cur.status != RunStatus::kCompleted) {
    res.status = cur.status;
    res.message = cur.message;
    return res;
  }
  auto record = [&](int it) {
    DesignIteration h;
    h.iteration = it;
    h.J = cur.J;
    h.gradient_norm = cur.gradient.norm();
    h.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    h.x = res.x;
    res.history.push_back(h);
  };
  record(0);
  // Step in "interval units": x_i -= s * range_i^2 * g_i / max_j |range_j g_j|.
  double s = 0.1;
  for (int it = 1; it <= opt.max_iterations; ++it) {
    double gmax = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      gmax = std::max(gmax, std::abs((d.variables[i].upper - d.variables[i].lower) *
                                     cur.gradient(static_cast<Eigen::Index>(i))));
    if (gmax == 0.0) break;
    bool accepted = false, moved = false;
    for (int trial = 0; trial < 30 && !accepted; ++trial) {
      std::vector<double> xt = res.x;
      double dir_dot = 0.0, largest = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const auto& v = d.variables[i];
        const double r = v.upper - v.lower, g = cur.gradient(static_cast<Eigen::Index>(i));
        xt[i] = std::clamp(res.x[i] - s * r * r * g / gmax, v.lower, v.upper);
        dir_dot += g * (xt[i] - res.x[i]);
        largest = std::max(largest, std::abs(xt[i] - res.x[i]) / r);
      }
      if (largest <= opt.x_tolerance) break;
      moved = true;
      const DesignEvaluation e = evaluate_design(d, xt);
      if (e.status == RunStatus::kCompleted && e.J <= cur.J + 1e-4 * dir_dot) {
        res.x = xt;
        cur = e;
        accepted = true;
        s *= 2.0;
      } else {
        s *= 0.5;
      }
    }
    record(it);
    if (!accepted) {
      if (moved) res.message = "no descent step found (the best design is kept)";
      break;
    }
  }
  res.J = cur.J;
  return res;
}

}  // namespace knit::macro
