// The design objective and its adjoint gradient (knit/macro/design_problem.hpp).
#include <cmath>

#include "knit/macro/design_problem.hpp"

namespace knit::macro {

DesignEvaluation evaluate_design(const DesignProblem& d, const std::vector<double>& x) {
  DesignEvaluation out;
  out.gradient = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d.variables.size()));
  if (d.smoothness > 0.0) {
    out.status = RunStatus::kNotConverged;
    out.message = "the smoothness penalty is not implemented yet";
    return out;
  }
  // The case text at x (every control value of a variable set to its value).
  const auto vars = d.expanded();
  std::vector<double> values;
  for (std::size_t k = 0; k < d.variables.size(); ++k)
    for (std::size_t i = 0; i < d.variables[k].indices.size(); ++i) values.push_back(x.at(k));
  const std::string text = case_with_design(d.c.text, d.case_file, vars, values).text;
  const double delta1 = d.c.output.applied ? d.c.output.applied->value : 0.0;
  for (const auto& o : d.objectives) {
    if (o.kind != DesignObjective::Kind::kReaction) {
      out.status = RunStatus::kNotConverged;
      out.message = "objective \"" + o.name + "\": only reaction terms are evaluated so far";
      return out;
    }
    double term = 0.0;
    for (std::size_t k = 0; k < o.at_strain.size(); ++k) {
      const double lambda = o.at_strain[k] * d.c.output.applied->gauge_length / delta1;
      const ReactionGradient g = reaction_gradient(text, d.case_file, vars, o.reaction, lambda);
      if (g.status != RunStatus::kCompleted) {
        out.status = g.status;
        out.message = "objective \"" + o.name + "\" at strain " + std::to_string(o.at_strain[k]) +
                      ": " + g.message;
        return out;
      }
      const double r = g.J - o.target[k];
      term += o.weight * r * r;
      // Chain rule to the variables: a variable moves all its control values.
      Eigen::Index c = 0;
      for (std::size_t v = 0; v < d.variables.size(); ++v)
        for (std::size_t i = 0; i < d.variables[v].indices.size(); ++i, ++c)
          out.gradient(static_cast<Eigen::Index>(v)) += 2.0 * o.weight * r * g.dJ(c);
    }
    out.terms.emplace_back(o.name, term);
    out.J += term;
  }
  return out;
}

}  // namespace knit::macro
