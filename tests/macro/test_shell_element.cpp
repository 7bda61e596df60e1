// Shell element: the tangent against finite differences of the residual at a deformed
// state, rigid-body invariance, the membrane patch test, the two thickness integrations.
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <random>

#include "shell_test_util.hpp"

using namespace knit::macro;
namespace spline = knit::spline;
using knit::macro::test::curved_patch;
using knit::macro::test::dense_tangent;

namespace {

Eigen::VectorXd random_displacement(int n, double amp, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(-amp, amp);
  Eigen::VectorXd u(n);
  for (int i = 0; i < n; ++i) u(i) = d(gen);
  return u;
}

/// Max relative deviation of K from central differences of f_int.
double fd_tangent_error(const ShellModel& m, const Eigen::VectorXd& u) {
  ShellModel::Evaluation ev;
  m.evaluate(u, true, ev);
  const Eigen::MatrixXd K = dense_tangent(m, ev);
  Eigen::MatrixXd Kfd(m.num_dofs(), m.num_dofs());
  const double h = 1e-6;
  ShellModel::Evaluation ep, em;
  for (int s = 0; s < m.num_dofs(); ++s) {
    Eigen::VectorXd up = u, um = u;
    up(s) += h;
    um(s) -= h;
    m.evaluate(up, false, ep);
    m.evaluate(um, false, em);
    Kfd.col(s) = (ep.fint - em.fint) / (2 * h);
  }
  return (K - Kfd).cwiseAbs().maxCoeff() / K.cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("shell tangent matches finite differences of the residual at a deformed state",
          "[unit]") {
  const bool rational = GENERATE(false, true);
  auto mat = std::make_shared<SaintVenantKirchhoff>(1000.0, 0.3);
  ShellModel m(curved_patch(2, 3, 2, 1, 2.0, 1.5, 0.4, rational), 0.1, mat);
  // A B-spline patch takes the sum-factorized kernel, a rational one the direct product.
  CHECK(m.sum_factorized() == !rational);
  const Eigen::VectorXd u = random_displacement(m.num_dofs(), 0.1, 7);
  CHECK(fd_tangent_error(m, u) < 1e-6);
}

TEST_CASE("shell tangent of a graded, unsymmetric material matches finite differences", "[unit]") {
  // A nonlinear, unsymmetric plane-stress law exercising the Gauss-3 path with z-dependence.
  struct Nonlinear final : Material {
    std::string name() const override { return "test"; }
    MaterialResponse evaluate(const Eigen::Vector3d& E, const MaterialPoint& w) const override {
      MaterialResponse r;
      const double k = 1.0 + 0.3 * w.theta(0);
      r.S << k * (100 * E(0) + 30 * E(1) + 500 * E(0) * E(0)),
          20 * E(0) + 80 * E(1) + 200 * E(1) * E(1) * E(1), 25 * E(2) + 10 * E(0) * E(2);
      r.C << k * (100 + 1000 * E(0)), k * 30, 0, 20, 80 + 600 * E(1) * E(1), 0, 10 * E(2), 0,
          25 + 10 * E(0);
      return r;
    }
  };
  ShellModel m(curved_patch(2, 2, 1, 2, 1.0, 1.0, 0.3, true), 0.2, std::make_shared<Nonlinear>());
  CHECK(fd_tangent_error(m, random_displacement(m.num_dofs(), 0.08, 3)) < 1e-6);
}

TEST_CASE("rigid-body motions give zero internal forces", "[unit]") {
  auto mat = std::make_shared<SaintVenantKirchhoff>(1000.0, 0.3);
  ShellModel m(curved_patch(3, 2, 2, 2, 2.0, 1.0, 0.5, true), 0.1, mat);
  const Eigen::MatrixXd& P = m.surface().control_points();
  const Eigen::Matrix3d Q =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d c(0.3, -2.0, 1.0);
  Eigen::VectorXd u(m.num_dofs());
  for (int a = 0; a < m.num_control_points(); ++a)
    u.segment<3>(3 * a) = Q * P.row(a).transpose() + c - P.row(a).transpose();
  ShellModel::Evaluation ev;
  m.evaluate(u, false, ev);
  ShellModel::Evaluation ref;
  m.evaluate(random_displacement(m.num_dofs(), 0.05, 1), false, ref);
  CHECK(ev.fint.norm() < 1e-10 * ref.fint.norm());
}

TEST_CASE("membrane patch test: a homogeneous deformation of a flat patch gives uniform strain",
          "[unit]") {
  // Flat, distorted (rational) patch; an affine map x = F X gives E = (F^T F - I)/2 everywhere
  // and no curvature change; interior nodal forces vanish (patch test).
  auto surf = curved_patch(3, 3, 2, 2, 2.0, 1.0, 0.0, true);
  auto mat = std::make_shared<SaintVenantKirchhoff>(1000.0, 0.25);
  ShellModel m(surf, 0.1, mat);
  Eigen::Matrix3d F;
  F << 1.1, 0.05, 0, -0.02, 0.95, 0, 0, 0, 1;
  const Eigen::MatrixXd& P = m.surface().control_points();
  Eigen::VectorXd u(m.num_dofs());
  for (int a = 0; a < m.num_control_points(); ++a)
    u.segment<3>(3 * a) = (F - Eigen::Matrix3d::Identity()) * P.row(a).transpose();
  const Eigen::Matrix3d Eg = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
  for (double s : {0.1, 0.5, 0.93}) {
    for (double t : {0.0, 0.37, 1.0}) {
      const ShellSample smp = m.sample(u, Eigen::Vector2d(s, t));
      // Local frame of a flat patch in the x-y plane: rotate the global strain into (e1, e2).
      const auto d = m.surface().derivatives(s, t, 1);
      const Eigen::Vector3d e1 = d.row(1).transpose().normalized(), e3(0, 0, 1), e2 = e3.cross(e1);
      CHECK(smp.E(0) == Approx(e1.dot(Eg * e1)).margin(1e-12));
      CHECK(smp.E(1) == Approx(e2.dot(Eg * e2)).margin(1e-12));
      CHECK(smp.E(2) == Approx(2 * e1.dot(Eg * e2)).margin(1e-12));
      CHECK(smp.kappa.norm() < 1e-10);
    }
  }
  // Interior nodal forces vanish exactly on an affinely parameterized (parallelogram) patch,
  // where Gauss quadrature with p+1 points integrates the polynomial integrands exactly.
  spline::BSplineBasis bu(3, spline::uniform_knots(3, 3)), bv(3, spline::uniform_knots(3, 2));
  const auto gu = bu.greville(), gv = bv.greville();
  const int nu = bu.size(), nv = bv.size();
  Eigen::MatrixXd Pa(nu * nv, 3);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) Pa.row(i + nu * j) << 2.0 * gu[i] + 0.4 * gv[j], 1.2 * gv[j], 0.0;
  ShellModel ma(spline::SplineSurface(bu, bv, Pa), 0.1, mat);
  Eigen::VectorXd ua(ma.num_dofs());
  for (int a = 0; a < ma.num_control_points(); ++a)
    ua.segment<3>(3 * a) = (F - Eigen::Matrix3d::Identity()) * Pa.row(a).transpose();
  ShellModel::Evaluation ev;
  ma.evaluate(ua, false, ev);
  for (int j = 1; j + 1 < nv; ++j)
    for (int i = 1; i + 1 < nu; ++i)
      CHECK(ev.fint.segment<3>(3 * (i + nu * j)).norm() < 1e-12 * ev.fint.norm());
}

TEST_CASE(
    "membrane strain in the local Cartesian frame: T eps equals the Green strain tensor's "
    "components on a curved, skew-parameterized surface",
    "[unit]") {
  // reference_point's T maps the covariant membrane strain eps_ab = (a_a.a_b - A_a.A_b)/2 to
  // (E11, E22, 2 E12) in (e1, e2). Under an affine map x = F X + c the tangents map as a_a = F A_a,
  // so eps_ab = A_a . G A_b with G = (F^T F - I)/2, and the Cartesian components are e_i . G e_j
  // wherever the surface is curved or its parameter lines are oblique (L21 != 0 in T).
  const auto surf = curved_patch(3, 3, 2, 2, 2.0, 1.3, 0.6, true);
  Eigen::Matrix3d F;
  F << 1.08, 0.07, -0.04, -0.03, 0.93, 0.06, 0.05, -0.02, 1.12;
  const Eigen::Matrix3d G = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
  const Eigen::Vector3d c(0.4, -1.0, 0.25);
  double largest_skew = 0;
  for (double s : {0.05, 0.42, 0.9})
    for (double t : {0.1, 0.63, 0.97}) {
      const SurfaceDerivs dX = surf.derivatives(s, t, 2);
      const ReferencePoint r = reference_point(dX, Eigen::Vector2d(s, t), 2.0);
      SurfaceDerivs dx = dX * F.transpose();
      dx.row(0) += c.transpose();
      const CurrentPoint cur = current_point(dx, r);
      const Eigen::Vector3d E = r.T * cur.eps;
      CHECK(E(0) == Approx(r.e1.dot(G * r.e1)).margin(1e-13));
      CHECK(E(1) == Approx(r.e2.dot(G * r.e2)).margin(1e-13));
      CHECK(E(2) == Approx(2 * r.e1.dot(G * r.e2)).margin(1e-13));
      largest_skew = std::max(largest_skew, std::abs(r.A(2)) / std::sqrt(r.A(0) * r.A(1)));
    }
  CHECK(largest_skew > 0.02);  // the parameter lines are oblique somewhere: T is not diagonal
}

TEST_CASE("3-point thickness integration equals the analytic one for St. Venant-Kirchhoff",
          "[unit]") {
  auto mat = std::make_shared<SaintVenantKirchhoff>(2100.0, 0.3);
  const auto surf = curved_patch(2, 2, 2, 1, 1.0, 1.0, 0.4, false);
  ShellOptions a, g;
  a.integration = ThicknessIntegration::kAnalytic;
  g.integration = ThicknessIntegration::kGauss3;
  ShellModel ma(surf, 0.1, mat, a), mg(surf, 0.1, mat, g);
  const Eigen::VectorXd u = random_displacement(ma.num_dofs(), 0.05, 11);
  ShellModel::Evaluation ea, eg;
  ma.evaluate(u, true, ea);
  mg.evaluate(u, true, eg);
  CHECK((ea.fint - eg.fint).norm() < 1e-12 * ea.fint.norm());
  CHECK((dense_tangent(ma, ea) - dense_tangent(mg, eg)).norm() <
        1e-12 * dense_tangent(ma, ea).norm());
}

TEST_CASE("two assembly threads give the same result as one", "[unit]") {
  auto mat = std::make_shared<SaintVenantKirchhoff>(1000.0, 0.3);
  ShellModel m(curved_patch(2, 2, 3, 2, 2.0, 1.0, 0.3, true), 0.1, mat);
  const Eigen::VectorXd u = random_displacement(m.num_dofs(), 0.05, 5);
  ShellModel::Evaluation e1, e2;
  m.evaluate(u, true, e1);
  m.set_threads(2);
  m.evaluate(u, true, e2);
  // Element results are summed in element order: bitwise the same for any thread count.
  CHECK((e1.fint - e2.fint).norm() == 0.0);
  CHECK(e1.energy == e2.energy);
  CHECK((dense_tangent(m, e1) - dense_tangent(m, e2)).norm() == 0.0);
  m.set_threads(3);
  m.evaluate(u, false, e2);
  CHECK((e1.fint - e2.fint).norm() == 0.0);
}

TEST_CASE("the tangent completed from a residual evaluation's point states is the tangent",
          "[unit]") {
  // ShellModel::tangent_from (Newton's tangent at an accepted trial point) against a full
  // evaluation with tangent: the same operations on the same numbers, bitwise equal.
  auto mat = std::make_shared<SaintVenantKirchhoff>(1000.0, 0.3);
  ShellModel m(curved_patch(2, 3, 2, 2, 2.0, 1.5, 0.4, true), 0.1, mat);
  const Eigen::VectorXd u = random_displacement(m.num_dofs(), 0.1, 11);
  const int threads = GENERATE(1, 2);
  m.set_threads(threads);
  ShellModel::Evaluation full, res, done;
  m.evaluate(u, true, full);
  m.evaluate(u, false, res);
  CHECK_FALSE(res.has_points);
  CHECK_THROWS_AS(m.tangent_from(res, done), std::logic_error);
  m.evaluate(u, false, res, true);
  REQUIRE(res.has_points);
  m.tangent_from(res, done);
  REQUIRE(done.ok);
  CHECK((done.fint - full.fint).norm() == 0.0);
  CHECK(done.energy == full.energy);
  CHECK((dense_tangent(m, done) - dense_tangent(m, full)).norm() == 0.0);
  CHECK(dense_tangent(m, full).norm() > 0.0);
}

TEST_CASE("a degenerate reference geometry is reported with its location", "[unit]") {
  // Collapse the u1 edge to a point: the Jacobian vanishes along theta1 = 1.
  spline::BSplineBasis b(1, {0, 0, 1, 1});
  Eigen::MatrixXd P(4, 3);
  P << 0, 0, 0, 1, 0.5, 0, 0, 1, 0, 1, 0.5, 0;
  auto mat = std::make_shared<SaintVenantKirchhoff>(1000.0, 0.3);
  // Quadrature points do not hit theta1 = 1 exactly, so use a surface degenerate everywhere.
  Eigen::MatrixXd Q(4, 3);
  Q << 0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0;
  try {
    ShellModel m(spline::SplineSurface(b, b, Q), 0.1, mat);
    FAIL("no error");
  } catch (const DegenerateGeometryError& e) {
    CHECK(std::string(e.what()).find("theta1, theta2") != std::string::npos);
  }
}

TEST_CASE("elements sharing their basis tables give the tangent and forces of their own tables",
          "[unit]") {
  // A curved p = 4 B-spline patch of 10 x 10 uniform elements: the interior elements' basis
  // derivatives agree, so ShellOptions::share_bases keeps 81 tables for 100 elements (9 per
  // direction: 4 spans at each edge differ); the internal forces, energy and element tangents at a
  // deformed state agree with those of the model whose elements keep their own tables (the
  // reference) to round-off.
  const spline::SplineSurface flat = curved_patch(4, 4, 10, 10, 1.0, 1.0, 0.3, false);
  auto mat = std::make_shared<SaintVenantKirchhoff>(3.0, 0.3);
  ShellOptions own;
  own.share_bases = false;
  const ShellModel shared(flat, 0.1, mat), reference(flat, 0.1, mat, own);
  CHECK(shared.distinct_bases() == 49);
  CHECK(reference.distinct_bases() == shared.num_elements());
  Eigen::VectorXd u = Eigen::VectorXd::Random(shared.num_dofs()) * 0.05;
  ShellModel::Evaluation a, b;
  shared.evaluate(u, true, a);
  reference.evaluate(u, true, b);
  REQUIRE(a.ok);
  REQUIRE(b.ok);
  CHECK((a.fint - b.fint).norm() <= 1e-13 * b.fint.norm());
  CHECK(std::abs(a.energy - b.energy) <= 1e-13 * std::abs(b.energy));
  double err = 0.0, big = 0.0;
  for (int e = 0; e < shared.num_elements(); ++e) {
    err = std::max(err, (a.Ke[e] - b.Ke[e]).cwiseAbs().maxCoeff());
    big = std::max(big, b.Ke[e].cwiseAbs().maxCoeff());
  }
  CAPTURE(err, big);
  CHECK(err <= 1e-13 * big);
}
