#include "knit/macro/svk_material.hpp"

namespace knit::macro {

SaintVenantKirchhoff::SaintVenantKirchhoff(double E, double nu) {
  const double f = E / (1.0 - nu * nu);
  C_ << f, f * nu, 0.0, f * nu, f, 0.0, 0.0, 0.0, f * 0.5 * (1.0 - nu);
}

MaterialResponse SaintVenantKirchhoff::evaluate(const Eigen::Vector3d& E,
                                                const MaterialPoint&) const {
  MaterialResponse r;
  r.S = C_ * E;
  r.C = C_;
  r.W = 0.5 * E.dot(r.S);  // W = E^T C E / 2 in Voigt form (2E12 pairs with S12)
  return r;
}

void SaintVenantKirchhoff::thickness_matrices(double t, const MaterialPoint&, Eigen::Matrix3d& A,
                                              Eigen::Matrix3d& B, Eigen::Matrix3d& D) const {
  A = t * C_;
  B.setZero();
  D = (t * t * t / 12.0) * C_;
}

}  // namespace knit::macro
