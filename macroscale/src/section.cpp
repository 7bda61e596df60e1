#include "knit/macro/section.hpp"

#include <cmath>

namespace knit::macro {

SectionResponse integrate_section(const Material& material, ThicknessIntegration mode, double t,
                                  const Eigen::Vector3d& eps, const Eigen::Vector3d& kappa,
                                  MaterialPoint where) {
  SectionResponse r;
  if (mode == ThicknessIntegration::kAnalytic) {
    where.z = 0.0;
    material.thickness_matrices(t, where, r.A, r.B, r.D);
    r.n = r.A * eps + r.B * kappa;
    r.m = r.B * eps + r.D * kappa;
    if (material.hyperelastic()) r.psi = 0.5 * eps.dot(r.n) + 0.5 * kappa.dot(r.m);
    return r;
  }
  static const double zeta[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)};
  static const double wq[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  double psi = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double z = 0.5 * t * zeta[k], w = 0.5 * t * wq[k];
    where.z = z;
    const MaterialResponse s = material.evaluate(eps + z * kappa, where);
    r.n += w * s.S;
    r.m += (w * z) * s.S;
    r.A += w * s.C;
    r.B += (w * z) * s.C;
    r.D += (w * z * z) * s.C;
    psi += w * s.W;
  }
  if (material.hyperelastic()) r.psi = psi;
  return r;
}

}  // namespace knit::macro
