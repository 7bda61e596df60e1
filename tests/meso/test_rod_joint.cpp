// Hooks for the unit cell: several rods in one system, custom end rows filled by a Joint
// (rigid connection / periodicity with a gap), external line loads through an
// ExternalContribution. Jacobians against finite differences; a joined rod equals one rod.
#include <catch2/catch.hpp>
#include <cmath>

#include "knit/meso/rod/builders.hpp"
#include "knit/meso/rod/joint.hpp"
#include "knit/meso/rod/solver.hpp"

using namespace knit::meso::rod;
using Eigen::Vector3d;

namespace {

Vector3d helix(double t) {
  return Vector3d(2 * std::cos(3 * t), 2 * std::sin(3 * t), 3 * t);
}

/// A uniform dead line force on every interior collocation point, through the hook.
struct LineLoad : ExternalContribution {
  int rod;
  Vector3d f;
  LineLoad(int r, Vector3d v) : rod(r), f(v) {}
  void add(const RodSystem& sys, const Eigen::VectorXd&, double lambda, Eigen::VectorXd& F,
           std::vector<Eigen::Triplet<double>>&) override {
    const int n = sys.num_control_points(rod);
    for (int j = 1; j < n - 1; ++j) F.segment<3>(sys.row(rod, j, kRowForce)) += lambda * f;
  }
};

Eigen::MatrixXd fd_jacobian(const RodSystem& sys, const Eigen::VectorXd& x, double lambda,
                            const std::vector<ExternalContribution*>& extra) {
  Eigen::MatrixXd J(x.size(), x.size());
  Eigen::VectorXd Fp, Fm;
  Eigen::SparseMatrix<double> dummy;
  const double h = 1e-6;
  for (int c = 0; c < x.size(); ++c) {
    Eigen::VectorXd xp = x, xm = x;
    xp(c) += h;
    xm(c) -= h;
    assemble_all(sys, xp, lambda, extra, Fp, dummy);
    assemble_all(sys, xm, lambda, extra, Fm, dummy);
    J.col(c) = (Fp - Fm) / (2 * h);
  }
  return J;
}

}  // namespace

TEST_CASE("joint: Jacobian of two joined rods with a gap matches finite differences", "[unit]") {
  RodSystem sys;
  RodSpec a = interpolated_rod([](double t) -> Vector3d { return helix(0.5 * t); }, 3, 3);
  a.end = EndCondition::custom();
  RodSpec b = interpolated_rod(
      [](double t) -> Vector3d { return helix(0.5 + 0.5 * t) + Vector3d(0.1, 0, 0); }, 3, 3);
  b.d1_hint = Vector3d(1, 1, 0);
  b.start = EndCondition::custom();
  b.end.force = Vector3d(0.1, 0.2, 0.3);
  const int ia = sys.add_rod(a), ib = sys.add_rod(b);
  Joint joint(sys, {ia, End::kEnd}, {ib, End::kStart},
              [](double l) -> Vector3d { return Vector3d(0.1 + l, 0, 0); });
  Eigen::VectorXd x = sys.initial_state() + 0.05 * Eigen::VectorXd::Random(sys.num_dofs());
  const std::vector<ExternalContribution*> extra{&joint};
  Eigen::VectorXd F;
  Eigen::SparseMatrix<double> J;
  assemble_all(sys, x, 0.4, extra, F, J);
  const Eigen::MatrixXd Jd = J, Jfd = fd_jacobian(sys, x, 0.4, extra);
  CHECK((Jd - Jfd).cwiseAbs().maxCoeff() < 1e-6 * std::max(1.0, Jd.cwiseAbs().maxCoeff()));
  // Reference state with the reference gap... here the gap is prescribed as 0.1 + lambda:
  // at lambda = 0 the reference state is an equilibrium.
  Eigen::VectorXd x0 = sys.initial_state();
  assemble_all(sys, x0, 0.0, extra, F, J);
  CHECK(F.cwiseProduct(sys.row_scales()).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("joint: a helix made of two joined rods deforms like one rod", "[verification]") {
  const Section sec;  // yarn
  const double EI = sec.C_K()(0);
  const Vector3d P = Vector3d(0.3, -0.2, 0.5) * EI, M = Vector3d(0.1, 0.2, 0.0) * EI;
  const Vector3d q = Vector3d(0.01, 0.0, -0.02) * EI;
  // One rod.
  RodSystem one;
  RodSpec s = interpolated_rod(helix, 4, 32, sec);
  s.end.force = P;
  s.end.moment = M;
  one.add_rod(s);
  LineLoad l1(0, q);
  Eigen::VectorXd x1 = one.initial_state();
  PathOptions po;
  po.steps = 5;
  REQUIRE(solve_path(one, x1, po, {}, {&l1}).completed);
  // Two rods, the second with a differently twisted reference frame (circular section: the
  // physics is the same).
  RodSystem two;
  RodSpec a = interpolated_rod([](double t) -> Vector3d { return helix(0.5 * t); }, 4, 16, sec);
  a.end = EndCondition::custom();
  RodSpec b =
      interpolated_rod([](double t) -> Vector3d { return helix(0.5 + 0.5 * t); }, 4, 16, sec);
  b.d1_hint = Vector3d(0.3, -1, 0.2);
  b.start = EndCondition::custom();
  b.end.force = P;
  b.end.moment = M;
  const int ia = two.add_rod(a), ib = two.add_rod(b);
  Joint joint(two, {ia, End::kEnd}, {ib, End::kStart});
  // The parameterizations differ by a factor 2 (xi in [0,1] covers half the helix): the line
  // load per unit reference length is the same.
  LineLoad la(ia, q), lb(ib, q);
  Eigen::VectorXd x2 = two.initial_state();
  const PathReport rep = solve_path(two, x2, po, {}, {&joint, &la, &lb});
  REQUIRE(rep.completed);
  const Vector3d tip1 = one.position(0, 1.0, x1), tip2 = two.position(ib, 1.0, x2);
  const Vector3d u1 = tip1 - one.reference_position(0, 1.0);
  INFO("tip one rod " << tip1.transpose() << ", two rods " << tip2.transpose()
                      << ", |u| = " << u1.norm());
  CHECK((tip1 - tip2).norm() < 1e-3 * u1.norm());
  const Vector3d mid1 = one.position(0, 0.5, x1), mid2 = two.position(ia, 1.0, x2);
  CHECK((mid1 - mid2).norm() < 1e-3 * u1.norm());
  // Force transmitted through the joint: continuous.
  CHECK((two.state(ia, 1.0, x2).n - two.state(ib, 0.0, x2).n).norm() < 1e-10);
}
