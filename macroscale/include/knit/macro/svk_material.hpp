// Plane-stress St. Venant-Kirchhoff material: S = C E with the constant isotropic
// plane-stress tangent (Voigt E11, E22, 2E12):
//   C = E/(1 - nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu)/2]].
// Analytic thickness integration: A = t C, B = 0, D = t^3/12 C (Kiendl et al. 2009, eq. 21).
#pragma once

#include "knit/macro/material.hpp"

namespace knit::macro {

class SaintVenantKirchhoff final : public Material {
 public:
  SaintVenantKirchhoff(double youngs_modulus, double poisson_ratio);
  std::string name() const override { return "saint_venant_kirchhoff"; }
  MaterialResponse evaluate(const Eigen::Vector3d& E, const MaterialPoint& where) const override;
  bool hyperelastic() const override { return true; }
  bool has_analytic_thickness_integration() const override { return true; }
  void thickness_matrices(double thickness, const MaterialPoint& where, Eigen::Matrix3d& A,
                          Eigen::Matrix3d& B, Eigen::Matrix3d& D) const override;
  const Eigen::Matrix3d& C() const { return C_; }

 private:
  Eigen::Matrix3d C_;
};

}  // namespace knit::macro
