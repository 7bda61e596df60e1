// The converged states of one design at the objectives' load levels and their sensitivities
// to the control values of the l and alpha fields (issue 13; docs/design.md "The adjoint").
//
// The macroscale law has no history, so the state at load factor lambda depends on lambda
// and the design p alone. With the free unknowns u_f (u = Z u_f + lambda g, DofMap::expand)
// equilibrium is r(u_f, p) = Z^T (f_int(u, p) - lambda f_ext) = 0 (eqs. 10-15), hence
//
//   K_ff du_f/dp_j = -Z^T D_j,   K_ff = Z^T K Z,   D_j = df_int/dp_j at fixed u,
//
// with K = df_int/du at the converged state. Per load level: ONE assembly and factorization of
// K_ff (the Newton solver's ReducedTangent: LDLT for the hyperelastic energy law, LU for the
// paper law) and one back-substitution per control value. Any quantity q(u, p) of the state
// then has dq/dp_j = dq/du du/dp_j + dq/dp_j|_u; this is the adjoint formula
// dq/dp = dq/dp|_u - psi^T Z^T D with K_ff^T psi = Z^T dq/du evaluated column by column,
// which is cheaper for least squares (Ceres needs every residual's gradient, and the
// residuals -- strain samples -- outnumber the control values).
//
// D_j is f_int assembled with dS/dp_j in place of S (f_int is linear in S at fixed
// kinematics): for a stitch-value control value dS/dp_j = dS/dl N_j(theta)
// (KnitMaterial::dS_dl: analytic for the energy law, a central difference for the paper
// law), for an angle control value dS/dp_j = (-G_S S + C G_E E) N_j(theta) (eqs. 20-22;
// N_j the field's basis function, in rad per unit of the written value).
//
// The forward run: the case scaled to the largest level (prescribed displacements and dead
// loads times lambda_max) with the case's load stepping; the states at the other levels are
// taken from its steps when a level falls on a step (lambda_k / lambda_max = i / steps),
// otherwise the case is solved once more up to that level.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "knit/macro/case.hpp"
#include "knit/macro/design_gradient.hpp"
#include "knit/macro/run.hpp"

namespace knit::macro {

/// A quantity of the state and its derivative with respect to the control values.
struct Sensitive {
  double value = 0.0;
  Eigen::RowVectorXd d;
};

class DesignSolve {
 public:
  /// Solves the case (its text already holds the design values) at every load factor of
  /// `levels` (> 0); with `sensitivities`, also du/dp at each. Throws knit::InputError for a
  /// bad case or variable; a solve that fails is status() (then no level is usable).
  DesignSolve(const std::string& case_text, const std::string& file,
              const std::vector<DesignVariable>& vars, const std::vector<double>& levels,
              bool sensitivities = true);
  ~DesignSolve();
  DesignSolve(const DesignSolve&) = delete;
  DesignSolve& operator=(const DesignSolve&) = delete;

  RunStatus status() const { return status_; }
  const std::string& message() const { return message_; }
  const Case& case_() const { return c_; }
  /// Index of a load factor among the levels (exact match as given).
  int level(double lambda) const;

  /// output.reactions entry (an edge or a corner reaction, N) at a level.
  Sensitive reaction(int level, const ReactionOutput& r) const;
  /// Displacement component (0..2: x, y, z; mm) of the mid-surface at theta.
  Sensitive displacement(int level, const Eigen::Vector2d& theta, int component) const;
  /// Membrane strain at theta in the local Cartesian frame (0..2: E11, E22, E12; E12 the
  /// tensor component, half the Voigt shear; what `knit-macro run` writes).
  Sensitive strain(int level, const Eigen::Vector2d& theta, int component) const;

  /// Wall seconds of the forward solves and of the sensitivities (assembly, factorization,
  /// D and the back-substitutions), for the benchmark.
  double forward_seconds() const { return forward_seconds_; }
  double sensitivity_seconds() const { return sensitivity_seconds_; }

 private:
  struct Level {
    double lambda = 0.0;
    Eigen::VectorXd u, fint;
    Eigen::MatrixXd du;  ///< du/dp (num_dofs x control values)
    Eigen::MatrixXd df;  ///< total df_int/dp = K du/dp + D
  };
  void sensitivities(Level& L, const std::vector<DesignVariable>& vars);

  Case c_;
  std::unique_ptr<Problem> problem_;
  std::vector<Level> levels_;
  RunStatus status_ = RunStatus::kCompleted;
  std::string message_;
  bool with_d_ = true;
  double forward_seconds_ = 0.0, sensitivity_seconds_ = 0.0;
};

/// The case with its prescribed displacements and dead loads scaled by lambda: its state at
/// load factor 1 is the original case's state at lambda (the law has no history).
Case scaled_case(Case c, double lambda);

}  // namespace knit::macro
