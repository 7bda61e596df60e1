// Through-thickness integration (section.hpp, paper eq. 14 with 3 Gauss points): the section
// tangents A = dn/deps, B = dn/dkappa = dm/deps, D = dm/dkappa against central differences of
// the resultants, and psi's gradient (n, m) for a hyperelastic material, on a nonlinear
// material whose response depends on z, so that every block of the tangent is nonzero.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "knit/macro/section.hpp"

using namespace knit::macro;

namespace {

/// A nonlinear plane-stress law, graded through the thickness (k(z)), hyperelastic unless
/// `unsymmetric`: W = k(z) (a.E)^2/2 + b (E1^4 + E2^4)/4 + c E1 E3^2 / 2 + d E1 E2, S = dW/dE,
/// C = dS/dE; `unsymmetric` adds e E3^2 to S2 alone (C23 != C32, no energy).
struct GradedLaw final : Material {
  explicit GradedLaw(bool unsym) : unsymmetric(unsym) {}
  bool unsymmetric;
  std::string name() const override { return "graded"; }
  bool hyperelastic() const override { return !unsymmetric; }
  MaterialResponse evaluate(const Eigen::Vector3d& E, const MaterialPoint& w) const override {
    const double k = 100.0 * (1.0 + 2.0 * w.z + 3.0 * w.z * w.z);
    const Eigen::Vector3d a(1.0, 0.6, -0.3);
    const double b = 900.0, c = 250.0, d = 40.0, ae = a.dot(E);
    MaterialResponse r;
    r.W = 0.5 * k * ae * ae + 0.25 * b * (std::pow(E(0), 4) + std::pow(E(1), 4)) +
          0.5 * c * E(0) * E(2) * E(2) + d * E(0) * E(1);
    r.S = k * ae * a;
    r.S(0) += b * std::pow(E(0), 3) + 0.5 * c * E(2) * E(2) + d * E(1);
    r.S(1) += b * std::pow(E(1), 3) + d * E(0);
    r.S(2) += c * E(0) * E(2);
    r.C = k * a * a.transpose();
    r.C(0, 0) += 3 * b * E(0) * E(0);
    r.C(1, 1) += 3 * b * E(1) * E(1);
    r.C(0, 1) += d;
    r.C(1, 0) += d;
    r.C(0, 2) += c * E(2);
    r.C(2, 0) += c * E(2);
    r.C(2, 2) += c * E(0);
    if (unsymmetric) {
      const double e = 300.0;
      r.S(1) += e * E(2) * E(2);
      r.C(1, 2) += 2 * e * E(2);
      r.W = std::numeric_limits<double>::quiet_NaN();
    }
    return r;
  }
};

/// Largest |analytic - central difference| of a block over the block's largest entry.
double relative_gap(const Eigen::Matrix3d& analytic, const Eigen::Matrix3d& fd) {
  return (analytic - fd).cwiseAbs().maxCoeff() / analytic.cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("section tangents A, B, D and psi's gradient match central differences", "[unit]") {
  // Hyperelastic (symmetric C, psi defined) and unsymmetric (B != B^T: dn/dkappa and dm/deps
  // are the same unsymmetric block, not transposes of each other).
  const bool unsymmetric = GENERATE(false, true);
  const GradedLaw mat(unsymmetric);
  const double t = 0.76;  // 2 d for the paper's yarn (mm)
  const Eigen::Vector3d eps(0.12, -0.05, 0.08), kap(0.9, -0.4, 0.6);
  const SectionResponse r =
      integrate_section(mat, ThicknessIntegration::kGauss3, t, eps, kap, MaterialPoint{});
  // Every block is nonzero, so a dropped or swapped one shows.
  REQUIRE(r.B.cwiseAbs().maxCoeff() > 1e-3 * r.A.cwiseAbs().maxCoeff());
  REQUIRE(r.D.cwiseAbs().maxCoeff() > 1e-3 * r.A.cwiseAbs().maxCoeff() * t * t);

  const double h = 1e-6;
  Eigen::Matrix3d dn_de, dn_dk, dm_de, dm_dk;
  Eigen::Vector3d dpsi_de, dpsi_dk;
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d dj = h * Eigen::Vector3d::Unit(j);
    const auto ep = integrate_section(mat, ThicknessIntegration::kGauss3, t, eps + dj, kap, {});
    const auto em = integrate_section(mat, ThicknessIntegration::kGauss3, t, eps - dj, kap, {});
    const auto kp = integrate_section(mat, ThicknessIntegration::kGauss3, t, eps, kap + dj, {});
    const auto km = integrate_section(mat, ThicknessIntegration::kGauss3, t, eps, kap - dj, {});
    dn_de.col(j) = (ep.n - em.n) / (2 * h);
    dm_de.col(j) = (ep.m - em.m) / (2 * h);
    dn_dk.col(j) = (kp.n - km.n) / (2 * h);
    dm_dk.col(j) = (kp.m - km.m) / (2 * h);
    dpsi_de(j) = (ep.psi - em.psi) / (2 * h);
    dpsi_dk(j) = (kp.psi - km.psi) / (2 * h);
  }
  CHECK(relative_gap(r.A, dn_de) < 1e-7);
  CHECK(relative_gap(r.B, dn_dk) < 1e-7);
  CHECK(relative_gap(r.B, dm_de) < 1e-7);
  CHECK(relative_gap(r.D, dm_dk) < 1e-7);
  if (unsymmetric) {
    REQUIRE((r.B - r.B.transpose()).cwiseAbs().maxCoeff() > 1e-3 * r.B.cwiseAbs().maxCoeff());
    CHECK(std::isnan(r.psi));
  } else {
    CHECK((dpsi_de - r.n).norm() < 1e-7 * r.n.norm());
    CHECK((dpsi_dk - r.m).norm() < 1e-7 * r.m.norm());
  }
}
