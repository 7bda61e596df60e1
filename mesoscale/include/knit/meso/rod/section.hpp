// Linear elastic cross-section of a Simo-Reissner rod (paper Sect. 2.1.2; Simo & Vu-Quoc 1986).
//
// Material stress resultants from material strains (hyperelastic, St. Venant-Kirchhoff type):
//   N = C_Gamma Gamma,  C_Gamma = diag(G A_s, G A_s, E A)       (Gamma = R^T r' - e3)
//   M = C_K K,          C_K     = diag(E I, E I, G J)            (K = axial(R^T R') - K0)
// The third material axis e3 is the rod axis (tangent direction of the unstrained rod);
// e1, e2 span the cross-section.
//
// Circle of diameter d: A = pi d^2/4, I = pi d^4/64, J = 2 I, G = E / (2 (1 + nu)).
// Shear correction factor (choice, documented): kappa = 6 (1 + nu) / (7 + 6 nu), Cowper (1966)
// for a solid circle; A_s = kappa A. Yarn defaults (design/notes.md): d = 0.38 mm,
// E = 800 MPa, nu = 0.3 (the paper gives no nu). Units: mm, N, MPa.
#pragma once

#include <Eigen/Core>

namespace knit::meso::rod {

/// Cowper's shear correction factor of a solid circular section.
inline double circle_shear_factor(double nu) {
  return 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu);
}

struct Section {
  double E = 800.0;     ///< Young's modulus [MPa]
  double nu = 0.3;      ///< Poisson's ratio [-] (choice; the paper gives none)
  double d = 0.38;      ///< diameter [mm]
  double kappa = -1.0;  ///< shear correction factor; < 0 means Cowper's circle value

  double G() const { return E / (2.0 * (1.0 + nu)); }
  double A() const;
  double I() const;  ///< second moment of area about a diameter
  double J() const;  ///< polar moment (= 2 I)
  double shear_factor() const { return kappa < 0.0 ? circle_shear_factor(nu) : kappa; }

  /// diag(G A_s, G A_s, E A) [N]
  Eigen::Vector3d C_Gamma() const;
  /// diag(E I, E I, G J) [N mm^2]
  Eigen::Vector3d C_K() const;
};

}  // namespace knit::meso::rod
