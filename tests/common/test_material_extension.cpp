// The paper's law (eq. 17) beyond its fan of paths: one extension for every strain direction
// (the fan chart blended in angle into a soft SPD compression law), checked on a polar grid
// at every fitted loop length and midway; far extrapolation; non-finite strains.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "knit/material/loop_length_family.hpp"
#include "knit/material/response_surface.hpp"
#include "test_material_util.hpp"

using namespace knit::material;
using knit::material::testing::fd_tangent;
using knit::material::testing::make_test_surface;

namespace {

/// A family like the swept database's: five loop lengths, stiffness falling as (4.5 / l)^2.
LoopLengthFamily test_family() {
  std::vector<double> l = {4.5, 5.0, 5.5, 6.0, 6.5};
  std::vector<ResponseSurfaceData> laws;
  for (double li : l) laws.push_back(make_test_surface(std::pow(4.5 / li, 2)));
  return LoopLengthFamily(l, laws);
}

/// The fitted loop lengths and the midpoints between them.
std::vector<double> test_loop_lengths() {
  return {4.5, 4.75, 5.0, 5.25, 5.5, 5.75, 6.0, 6.25, 6.5};
}

Eigen::Vector3d polar(double r, double deg, double two_e12) {
  const double a = deg * M_PI / 180.0;
  return {r * std::cos(a), r * std::sin(a), two_e12};
}

double norm2(const Eigen::Matrix3d& C) {
  return Eigen::JacobiSVD<Eigen::Matrix3d>(C).singularValues()(0);
}

}  // namespace

TEST_CASE("paper law extension: polar grid, S continuous (Lipschitz), C = FD of S", "[unit]") {
  // Lipschitz bound stated: between neighbouring grid points a, b (1 degree apart, or the next
  // radius), |S(a) - S(b)| <= 1.5 max(|C(a)|, |C(b)|, |C(m)|) |E(a) - E(b)| (m the midpoint,
  // |C| the spectral norm): the mean-value bound with a 50 % margin for C's variation along
  // the segment. A jump in S (the former branch switch: 0.09 MPa at |E| = 0.01 over 2.5
  // degrees) breaks it by orders of magnitude.
  const LoopLengthFamily fam = test_family();
  const std::vector<double> radii = {0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.45, 0.6};
  const double two_e12 = 0.04;
  double worst_ratio = 0.0, worst_fd = 0.0;
  for (double l : test_loop_lengths()) {
    const auto rs = fam.surface(l);
    // Evaluate the grid once.
    std::vector<ResponseEvaluation> grid(radii.size() * 360);
    for (std::size_t i = 0; i < radii.size(); ++i)
      for (int d = 0; d < 360; ++d) grid[i * 360 + d] = rs->evaluate(polar(radii[i], d, two_e12));
    auto check_pair = [&](const Eigen::Vector3d& Ea, const ResponseEvaluation& a,
                          const Eigen::Vector3d& Eb, const ResponseEvaluation& b) {
      const ResponseEvaluation m = rs->evaluate(0.5 * (Ea + Eb));
      const double L = 1.5 * std::max({norm2(a.C), norm2(b.C), norm2(m.C)});
      const double dS = (a.S - b.S).norm(), dE = (Ea - Eb).norm();
      worst_ratio = std::max(worst_ratio, dS / (L * dE));
      if (dS > L * dE) {
        INFO("l = " << l << " E = " << Ea.transpose() << " -> " << Eb.transpose() << " S "
                    << a.S.transpose() << " -> " << b.S.transpose() << " L " << L);
        CHECK(dS <= L * dE);
      }
    };
    for (std::size_t i = 0; i < radii.size(); ++i)
      for (int d = 0; d < 360; ++d) {
        const Eigen::Vector3d E = polar(radii[i], d, two_e12);
        const ResponseEvaluation& ev = grid[i * 360 + d];
        INFO("l = " << l << " r = " << radii[i] << " angle " << d << " flags " << int(ev.flags)
                    << " blend " << ev.blend);
        REQUIRE((ev.flags & kInversionFailed) == 0);
        REQUIRE(ev.S.allFinite());
        // Angular and radial neighbours.
        const int dn = (d + 1) % 360;
        check_pair(E, ev, polar(radii[i], dn, two_e12), grid[i * 360 + dn]);
        if (i + 1 < radii.size())
          check_pair(E, ev, polar(radii[i + 1], d, two_e12), grid[(i + 1) * 360 + d]);
        // C is the exact derivative of S: central differences, step relative to |E|.
        const Eigen::Matrix3d Cfd = fd_tangent(*rs, E, 1e-6 * radii[i]);
        const double err = (ev.C - Cfd).norm() / std::max(1e-3, Cfd.norm());
        worst_fd = std::max(worst_fd, err);
        CHECK(err <= 1e-5);
      }
  }
  WARN("largest |dS| / (1.5 |C| |dE|) on the grid: "
       << worst_ratio << ", largest relative FD error of C: " << worst_fd);
}

TEST_CASE("paper law extension: compression stiffness SPD, soft, and used far from the fan",
          "[unit]") {
  const LoopLengthFamily fam = test_family();
  for (double l : test_loop_lengths()) {
    const auto rs = fam.surface(l);
    const Eigen::Matrix2d& K = rs->compression_stiffness();
    INFO("l = " << l << " K_c = " << K);
    CHECK((K - K.transpose()).norm() <= 1e-14 * K.norm());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(K);
    CHECK(es.eigenvalues().minCoeff() > 0.0);
    // Never stiffer than the fan's initial stiffness (sym C0's largest eigenvalue).
    const Eigen::Matrix2d C0 = rs->C0().topLeftCorner<2, 2>();
    const double c0max = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(0.5 * (C0 + C0.transpose()))
                             .eigenvalues()
                             .maxCoeff();
    CHECK(es.eigenvalues().maxCoeff() <= c0max * (1 + 1e-12));
    // Biaxial compression (opposite to the fan's bisector): the linear law K_c E exactly.
    const double centre = 0.5 * (rs->range_lo() + rs->range_hi()) + M_PI;
    for (double r : {0.005, 0.1, 0.6}) {
      const Eigen::Vector3d E(r * std::cos(centre), r * std::sin(centre), 0.0);
      const auto ev = rs->evaluate(E);
      CHECK(ev.blend == 1.0);
      CHECK((ev.flags & kCompression) != 0);
      CHECK((ev.S.head<2>() - K * E.head<2>()).norm() <= 1e-14 * r);
      CHECK((ev.C.topLeftCorner<2, 2>() - K).norm() == 0.0);
    }
  }
  // Options: the compression stiffness is configurable and checked.
  ExtensionOptions o;
  o.compression_scale = 0.1;
  const ResponseSurface soft(make_test_surface(), o);
  const ResponseSurface dflt(make_test_surface());
  CHECK(soft.compression_stiffness().norm() ==
        Approx(dflt.compression_stiffness().norm() * 0.1 / ExtensionOptions{}.compression_scale));
  o.compression_scale = 1.5;
  CHECK_THROWS_WITH(ResponseSurface(make_test_surface(), o), Catch::Contains("compression_scale"));
  o = {};
  o.blend_begin_deg = 60;
  CHECK_THROWS_WITH(ResponseSurface(make_test_surface(), o), Catch::Contains("blend_begin_deg"));
}

TEST_CASE("paper law extension: far extrapolation (|E| up to 100) never fails to invert",
          "[unit]") {
  const LoopLengthFamily fam = test_family();
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> angle(-180.0, 180.0), logr(-3.0, 2.0), u(-1.0, 1.0);
  int worst = 0;
  for (double l : {4.5, 5.25, 6.5}) {
    const auto rs = fam.surface(l);
    for (int k = 0; k < 2000; ++k) {
      const double r = std::pow(10.0, logr(gen));
      const Eigen::Vector3d E = polar(r, angle(gen), r * u(gen));
      const auto ev = rs->evaluate(E);
      INFO("l = " << l << " E = " << E.transpose() << " iterations " << ev.iterations);
      REQUIRE((ev.flags & kInversionFailed) == 0);
      REQUIRE(ev.S.allFinite());
      REQUIRE(ev.C.allFinite());
      worst = std::max(worst, ev.iterations);
      if (ev.blend < 1.0) {
        // The fan chart really maps back onto the strain.
        const Eigen::Vector4d X = rs->point(ev.xi);
        CHECK((X.head<2>() - E.head<2>()).norm() <= 1e-10 * (1.0 + r));
      }
    }
  }
  CHECK(worst <= 25);
}

TEST_CASE("paper law: a non-finite strain is flagged, never looked up", "[unit]") {
  // Before: a NaN strain reached the angle table, std::upper_bound returned end() and the
  // guess read past the array (heap-buffer-overflow under ASan).
  const ResponseSurface rs(make_test_surface());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& E :
       {Eigen::Vector3d(nan, 0.1, 0.0), Eigen::Vector3d(0.1, nan, 0.0),
        Eigen::Vector3d(0.1, 0.1, nan), Eigen::Vector3d(inf, 0.0, 0.0),
        Eigen::Vector3d(0.0, -inf, 0.0), Eigen::Vector3d(1e300, 1e300, 0.0)}) {
    const auto ev = rs.evaluate(E);
    INFO("E = " << E.transpose());
    CHECK((ev.flags & kInversionFailed) != 0);
    CHECK((ev.flags & kNonFiniteStrain) != 0);
    CHECK_FALSE(ev.S.allFinite());
    CHECK_FALSE(ev.C.allFinite());
  }
}
