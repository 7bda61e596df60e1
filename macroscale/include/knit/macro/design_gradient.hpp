// The adjoint gradient of a reaction-load objective with respect to control values of the
// knit material's design fields (issue 13, docs/design.md "The adjoint gradient").
//
// The macroscale law has no history, so the converged state u at the end of the case's load
// path (lambda = 1) depends on the design p alone. With the free unknowns u_f, u = Z u_f + g
// (DofMap::expand) and the reduced equilibrium r(u_f, p) = Z^T (f_int(u, p) - f_ext) = 0, the
// reaction J = c^T f_int(u, p) (c sums one component over an edge's control points) has
//
//   dJ/dp_j = c^T df_int/dp_j - psi^T Z^T df_int/dp_j,     (Z^T K Z)^T psi = Z^T K^T c,
//
// one extra linear solve with the tangent K = df_int/du at the converged state. The explicit
// derivative df_int/dp_j at fixed u is f_int evaluated with the stress field dS/dp_j in place
// of S (f_int is linear in S at fixed kinematics, eqs. 10-15). For an angle control value
// dS/dalpha = -G_S S + C G_E E (analytic through T(alpha), eqs. 20-22) times the field's basis
// function; for a stitch-value control value dS/dl is a central difference of the knit
// material at fixed strain (INTERIM, until the energy law's dS/dl lands).
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
/// The current values of the design variables in the case text.
std::vector<double> design_values(const std::string& case_text, const std::string& file,
                                  const std::vector<DesignVariable>& vars);

struct ReactionGradient {
  RunStatus status = RunStatus::kCompleted;
  std::string message;
  double J = 0.0;      ///< the reaction (N) at lambda = 1
  Eigen::VectorXd dJ;  ///< dJ/dp (N per unit of the control value)
};

struct GradientOptions {
  /// Relative step of the material's central difference in a stitch-value variable.
  double material_step = 1e-5;
};

/// J = output.reactions[reaction] of the case at load factor `lambda` (prescribed displacements
/// and dead loads scaled by lambda; the state depends on lambda alone) and its adjoint
/// gradient. The reaction must be an edge reaction. Throws knit::InputError for bad variables;
/// a solve that does not complete gives its status.
ReactionGradient reaction_gradient(const std::string& case_text, const std::string& file,
                                   const std::vector<DesignVariable>& vars, int reaction,
                                   double lambda = 1.0, const GradientOptions& options = {});

}  // namespace knit::macro
