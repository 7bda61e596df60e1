// Design variables: control values of the knit material's l and alpha fields in the case
// text, and the gradient of one reaction with respect to them (issue 13, docs/design.md).
// The state sensitivities themselves are in knit/macro/design_sensitivity.hpp.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "knit/macro/case.hpp"
#include "knit/macro/newton.hpp"

namespace knit::macro {

/// One design variable: a control value of the stitch-value (l) or knitting-angle (alpha)
/// field of the case's knit material (index into the field's "values" array, in the units
/// written there, e.g. deg when the field says "unit": "deg").
struct DesignVariable {
  enum class Field { kStitchValue, kKnittingAngle };
  Field field = Field::kStitchValue;
  int index = 0;
};

/// The case text with the design variables set to `values` (parsed and validated like any
/// case). Throws knit::InputError naming the field if a variable is not a control value of a
/// spline field of the case.
Case case_with_design(const std::string& case_text, const std::string& file,
                      const std::vector<DesignVariable>& vars, const std::vector<double>& values);
/// The same text without parsing the case (the design loop parses it once, in DesignSolve).
std::string case_text_with_design(const std::string& case_text, const std::string& file,
                                  const std::vector<DesignVariable>& vars,
                                  const std::vector<double>& values);
/// The current values of the design variables in the case text.
std::vector<double> design_values(const std::string& case_text, const std::string& file,
                                  const std::vector<DesignVariable>& vars);

struct ReactionGradient {
  RunStatus status = RunStatus::kCompleted;
  std::string message;
  double J = 0.0;      ///< the reaction (N) at the load factor
  Eigen::VectorXd dJ;  ///< dJ/dp (N per unit of the control value)
};

/// J = output.reactions[reaction] of the case at load factor `lambda` (prescribed displacements
/// and dead loads scaled by lambda; the state depends on lambda alone) and its adjoint
/// gradient (DesignSolve, knit/macro/design_sensitivity.hpp). Throws knit::InputError for bad
/// variables; a solve that does not complete gives its status.
ReactionGradient reaction_gradient(const std::string& case_text, const std::string& file,
                                   const std::vector<DesignVariable>& vars, int reaction,
                                   double lambda = 1.0);

}  // namespace knit::macro
