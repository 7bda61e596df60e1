// Verification of the rod solver against closed-form and literature values.
//  * roll-up of a cantilever by an end moment (exact circle; e.g. Simo & Vu-Quoc 1986, Sect. 7.1)
//  * the elastica of a cantilever under a dead end shear force, PL^2/EI = 4
//    (Mattiasson 1981, Int. J. Numer. Meth. Eng. 17, Table 1: w/L = 0.67, -u/L = 0.329)
//  * shear locking at d/L = 0.01 (Timoshenko tip deflection PL^3/3EI + PL/(kappa G A))
//  * h- and p-convergence on the roll-up (smooth, exact solution known everywhere)
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "knit/meso/rod/builders.hpp"
#include "knit/meso/rod/solver.hpp"

using namespace knit::meso::rod;
using Eigen::Vector3d;

namespace {

constexpr double kL = 10.0;

Section slender() {
  Section s;  // yarn material, d/L = 0.01
  s.d = 0.01 * kL;
  return s;
}

/// Max-norm error of the centerline against the exact circle of curvature theta/L (bending in
/// the x-z plane, moment about -y), sampled densely, relative to L.
double rollup_error(const RodSystem& sys, const Eigen::VectorXd& x, double theta) {
  double err = 0.0;
  const double k = theta / kL;
  for (int i = 0; i <= 200; ++i) {
    const double xi = i / 200.0, s = xi * kL;
    const Vector3d ex = theta == 0.0 ? Vector3d(s, 0, 0)
                                     : Vector3d(std::sin(k * s) / k, 0, (1 - std::cos(k * s)) / k);
    err = std::max(err, (sys.position(0, xi, x) - ex).norm());
  }
  return err / kL;
}

double solve_rollup(int p, int elements, double theta, int steps) {
  RodSystem sys;
  const Section sec = slender();
  RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(kL, 0, 0), p, elements, sec);
  s.end.moment = Vector3d(0, -theta * sec.C_K()(0) / kL, 0);
  sys.add_rod(s);
  Eigen::VectorXd x = sys.initial_state();
  PathOptions po;
  po.steps = steps;
  const PathReport rep = solve_path(sys, x, po);
  REQUIRE(rep.completed);
  return rollup_error(sys, x, theta);
}

}  // namespace

TEST_CASE("rod: cantilever rolled up to a full circle by an end moment", "[verification]") {
  RodSystem sys;
  const Section sec = slender();
  const double EI = sec.C_K()(0);
  RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(kL, 0, 0), 4, 16, sec);
  const double theta_max = 2 * std::numbers::pi;
  s.end.moment = Vector3d(0, -theta_max * EI / kL, 0);  // M L / EI = 2 pi at lambda = 1
  sys.add_rod(s);
  Eigen::VectorXd x = sys.initial_state();
  PathOptions po;
  po.steps = 20;
  double worst = 0.0;
  int checked = 0;
  const PathReport rep = solve_path(sys, x, po, [&](int, double lambda, const Eigen::VectorXd& xs) {
    const double th = lambda * theta_max;
    const Vector3d tip = sys.position(0, 1.0, xs) - Vector3d(kL, 0, 0);
    const Vector3d ex(kL * (std::sin(th) / th - 1.0), 0.0, kL * (1.0 - std::cos(th)) / th);
    const double rel = (tip - ex).norm() / ex.norm();
    worst = std::max(worst, rel);
    ++checked;
    INFO("theta = " << th << ": -u = " << -tip.x() << " (exact " << -ex.x() << "), w = " << tip.z()
                    << " (exact " << ex.z() << ")");
    CHECK(rel < 0.005);
  });
  REQUIRE(rep.completed);
  CHECK(checked == 20);
  // Full circle: the tip returns to the clamp.
  CHECK((sys.position(0, 1.0, x)).norm() / kL < 0.005);
  WARN("roll-up: worst relative tip error over 20 steps = " << worst);
}

TEST_CASE("rod: elastica of a cantilever under a dead end shear force, PL^2/EI = 4",
          "[verification]") {
  const Section sec = slender();  // d/L = 0.01: also a shear-locking check at a coarse mesh
  const double EI = sec.C_K()(0);
  for (int elements : {8, 16}) {
    RodSystem sys;
    RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(kL, 0, 0), 4, elements, sec);
    s.end.force = Vector3d(0, 0, 4.0 * EI / (kL * kL));
    sys.add_rod(s);
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.steps = 8;
    REQUIRE(solve_path(sys, x, po).completed);
    const Vector3d tip = (sys.position(0, 1.0, x) - Vector3d(kL, 0, 0)) / kL;
    INFO(elements << " elements: w/L = " << tip.z() << ", -u/L = " << -tip.x());
    CHECK(tip.z() == Approx(0.670).epsilon(0.01));
    CHECK(-tip.x() == Approx(0.329).epsilon(0.01));
    // The internal force is constant (= F) along the rod: the collocated equilibrium holds at
    // the Greville points only, so at the clamp it is met up to the discretization error.
    const PointState st = sys.state(0, 0.0, x);
    CHECK((st.n - s.end.force).norm() < 0.01 * s.end.force.norm());
  }
}

TEST_CASE("rod: no shear locking at d/L = 0.01 (mixed collocation, coarse meshes)",
          "[verification]") {
  const Section sec = slender();
  const double EI = sec.C_K()(0), GAs = sec.C_Gamma()(0);
  const double P = 1e-4 * EI / (kL * kL);  // linear regime
  const double w_timo = P * kL * kL * kL / (3 * EI) + P * kL / GAs;
  for (int p : {2, 3, 4}) {
    for (int elements : {2, 4}) {
      RodSystem sys;
      RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(kL, 0, 0), p, elements, sec);
      s.end.force = Vector3d(0, 0, P);
      sys.add_rod(s);
      Eigen::VectorXd x = sys.initial_state();
      REQUIRE(solve_newton(sys, x, 1.0).converged);
      const double w = sys.position(0, 1.0, x).z();
      INFO("p = " << p << ", " << elements << " elements: w / w_Timoshenko = " << w / w_timo);
      // A locking discretization would give w / w_T of order (d/L)^2 ~ 1e-4 here.
      CHECK(w / w_timo == Approx(1.0).epsilon(p == 2 ? 0.04 : 1e-6));
    }
  }
}

TEST_CASE("rod: optimal h- and p-convergence on the roll-up", "[verification]") {
  const double theta = std::numbers::pi / 2;
  // h-refinement: collocation rates in the max norm are p for even and p - 1 for odd degrees
  // (Auricchio et al. 2010, M3AS 20); we observe at least these.
  for (int p : {2, 3, 4}) {
    const double e1 = solve_rollup(p, 4, theta, 2), e2 = solve_rollup(p, 8, theta, 2),
                 e3 = solve_rollup(p, 16, theta, 2);
    const double rate = std::log2(e2 / e3);
    const int expected = p % 2 == 0 ? p : p - 1;
    INFO("p = " << p << ": errors " << e1 << ", " << e2 << ", " << e3 << "; rate " << rate);
    CHECK(rate > expected - 0.2);
    CHECK(e1 > e2);
  }
  // p-refinement at 2 elements: the error drops by a factor > 3 per two degrees (observed:
  // 0.096, 0.024, 2.6e-4, 2.4e-6 for p = 2, 4, 6, 8).
  double prev = solve_rollup(2, 2, theta, 2);
  for (int p : {4, 6, 8}) {
    const double e = solve_rollup(p, 2, theta, 2);
    INFO("p = " << p << ": error " << e << " (previous " << prev << ")");
    CHECK(e < 0.3 * prev);
    prev = e;
  }
}

TEST_CASE("rod: prescribed end rotation and end displacement", "[verification]") {
  const Section sec = slender();
  {
    // End rotation theta about -y, end position free and unloaded: pure bending into an arc of
    // curvature theta/L with the end moment EI theta / L.
    RodSystem sys;
    RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(kL, 0, 0), 4, 16, sec);
    const double theta = 1.5 * std::numbers::pi;
    s.end.fix_rotation = true;
    s.end.rotation = Vector3d(0, -theta, 0);
    sys.add_rod(s);
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.steps = 10;
    REQUIRE(solve_path(sys, x, po).completed);
    CHECK(rollup_error(sys, x, theta) < 1e-4);
    const PointState st = sys.state(0, 1.0, x);
    CHECK(st.m.y() == Approx(-theta * sec.C_K()(0) / kL).epsilon(1e-4));
  }
  {
    // Axial end displacement delta with both ends clamped: n = EA delta / L (linear elastic
    // in the Biot-type strain Gamma_3 = |r'| - 1 for a straight rod).
    RodSystem sys;
    RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(kL, 0, 0), 3, 4, sec);
    const double delta = 0.05 * kL;
    s.end = EndCondition::clamped();
    s.end.displacement = Vector3d(delta, 0, 0);
    sys.add_rod(s);
    Eigen::VectorXd x = sys.initial_state();
    REQUIRE(solve_newton(sys, x, 1.0).converged);
    const double EA = sec.C_Gamma()(2);
    for (double xi : {0.0, 0.3, 1.0})
      CHECK(sys.state(0, xi, x).n.x() == Approx(EA * delta / kL).epsilon(1e-10));
    CHECK(sys.position(0, 0.5, x).x() == Approx(0.5 * (kL + delta)).epsilon(1e-12));
  }
}
