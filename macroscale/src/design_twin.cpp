// The twin experiment of `knit-macro design` (design_problem.hpp, set_twin_targets; session 37).
#include <cmath>
#include <string>
#include <vector>

#include "knit/macro/design_problem.hpp"

namespace knit::macro {

std::string set_twin_targets(DesignProblem& d) {
  if (d.twin.empty()) return {};
  // The twin-target terms alone, unweighted, with zero targets and no smoothness: the
  // residuals of evaluate_design are then the terms' values, one per applied strain, in order.
  DesignProblem probe = d;
  probe.objectives.clear();
  probe.smoothness = 0.0;
  for (std::size_t k = 0; k < d.objectives.size(); ++k)
    if (d.twin_targets[k]) {
      DesignObjective o = d.objectives[k];
      o.weight = 1.0;
      o.target.assign(o.at_strain.size(), 0.0);
      probe.objectives.push_back(o);
    }
  const DesignEvaluation e = evaluate_design(probe, d.twin, false);
  if (e.status != RunStatus::kCompleted)
    return "the twin's run (the case at the twin's values) failed: " + e.message;
  Eigen::Index r = 0;
  for (std::size_t k = 0; k < d.objectives.size(); ++k)
    if (d.twin_targets[k])
      for (double& t : d.objectives[k].target) {
        if (r >= e.residuals.size() || !std::isfinite(e.residuals(r)))
          return "the twin's run gave no finite value for the term " + d.objectives[k].name;
        t = e.residuals(r++);
      }
  return {};
}

}  // namespace knit::macro
