// Through-thickness integration of a plane-stress material into shell resultants
// (paper eq. 14 with 3 Gauss points, notes.md "Macroscale"):
//
//   E(z) = eps + z kappa,  z_k = (t/2){-sqrt(0.6), 0, +sqrt(0.6)},  w_k = (t/2){5/9, 8/9, 5/9}
//   n = sum_k w_k S(E_k),  m = sum_k w_k z_k S(E_k)
//   dn/deps = A = sum w C,  dn/dkappa = dm/deps = B = sum w z C,  dm/dkappa = D = sum w z^2 C
//   psi = sum w W(E_k)  (strain energy per unit area of a hyperelastic material, dpsi/deps = n,
//                        dpsi/dkappa = m)
//
// Everything in the local Cartesian Voigt frame (E11, E22, 2E12). The analytic path
// (n = A eps + B kappa, m = B eps + D kappa with the material's own A, B, D) exists to check the
// numerical one: for a linear material the 3-point rule is exact (integrands of degree <= 2).
#pragma once

#include <Eigen/Core>
#include <limits>

#include "knit/macro/material.hpp"

namespace knit::macro {

enum class ThicknessIntegration {
  kGauss3,    ///< 3-point Gauss rule through the thickness (the path the knit material uses)
  kAnalytic,  ///< the material's closed-form A, B, D (linear materials only)
};

struct SectionResponse {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();  ///< membrane forces (N/mm)
  Eigen::Vector3d m = Eigen::Vector3d::Zero();  ///< bending moments (N mm/mm)
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero(), B = Eigen::Matrix3d::Zero(),
                  D = Eigen::Matrix3d::Zero();
  /// Strain energy per unit reference area (N mm/mm^2), psi = sum_k w_k W(E_k) with the same
  /// 3 Gauss points (analytic: eps.A eps/2 + eps.B kappa + kappa.D kappa/2); NaN unless the
  /// material is hyperelastic.
  double psi = std::numeric_limits<double>::quiet_NaN();
};

/// Resultants and their tangents at one mid-surface point with Cartesian membrane strain
/// `eps` and curvature change `kappa` (Voigt), thickness t (mm).
SectionResponse integrate_section(const Material& material, ThicknessIntegration mode, double t,
                                  const Eigen::Vector3d& eps, const Eigen::Vector3d& kappa,
                                  MaterialPoint where);

}  // namespace knit::macro
