// Unit tests of the rod collocation: quaternion identities, Jacobian vs finite differences,
// rigid-body invariance.
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>

#include "knit/meso/rod/builders.hpp"
#include "knit/meso/rod/quaternion.hpp"
#include "knit/meso/rod/resolution.hpp"
#include "knit/meso/rod/rod_system.hpp"
#include "knit/meso/rod/solver.hpp"

using namespace knit::meso::rod;
using Eigen::Vector3d;

namespace {

RodSpec helix_rod(int p, int elements) {
  auto c = [](double t) -> Vector3d {
    return Vector3d(std::cos(3 * t), std::sin(3 * t), 0.8 * t) * 2.0;
  };
  RodSpec s = interpolated_rod(c, p, elements);
  s.name = "helix";
  return s;
}

/// A cantilever of length 10 (cubic, 8 elements) rolled up by an end moment 1.9 pi EI / L:
/// almost a full circle, hard enough for load stepping to cut back.
void add_rolled_cantilever(RodSystem& sys) {
  const Section sec;
  const double L = 10.0, EI = sec.C_K()(0);
  RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(L, 0, 0), 3, 8, sec);
  s.end.moment = Vector3d(0, -1.9 * std::numbers::pi * EI / L, 0);
  sys.add_rod(s);
}

}  // namespace

TEST_CASE("quaternion: rotation is orthogonal and scale-invariant, log/exp round trip", "[unit]") {
  const Vector3d th(0.3, -1.1, 2.0);
  const Quat<double> q = quat_from_rotation_vector(th);
  const Eigen::Matrix3d R = rotation(q);
  CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-14);
  CHECK(R.determinant() == Approx(1.0));
  CHECK((rotation(Quat<double>(3.7 * q)) - R).norm() < 1e-14);
  CHECK((rotation_vector(q) - th).norm() < 1e-12);
  // -q is the same rotation: the log map picks the sign with |theta| <= pi (session 34, the
  // rod audit: without it -q gave a rotation vector of length 2 pi - |theta|).
  CHECK((rotation_vector(Quat<double>(-q)) - th).norm() < 1e-12);
  const Quat<double> q2 = quat_from_matrix(R);
  CHECK(std::min((q2 - q).norm(), (q2 + q).norm()) < 1e-12);
  // Rodrigues formula for the rotation vector
  const double a = th.norm();
  const Eigen::Matrix3d Rr = Eigen::AngleAxisd(a, th / a).toRotationMatrix();
  CHECK((Rr - R).norm() < 1e-13);
}

TEST_CASE("quaternion: material curvature equals axial(R^T R') and is gauge invariant", "[unit]") {
  auto qf = [](double s) {
    const Quat<double> q = quat_from_rotation_vector(Vector3d(0.4 * s, std::sin(s), 0.2 + s * s));
    return Quat<double>((1.0 + 0.3 * s * s) * q);  // non-unit scale
  };
  const double s = 0.7, h = 1e-6;
  const Quat<double> q = qf(s);
  const Quat<double> dq = (qf(s + h) - qf(s - h)) / (2 * h);
  const Eigen::Matrix3d dR = (rotation(qf(s + h)) - rotation(qf(s - h))) / (2 * h);
  const Eigen::Matrix3d W = rotation(q).transpose() * dR;
  const Vector3d K(W(2, 1), W(0, 2), W(1, 0));
  CHECK((material_curvature(q, dq) - K).norm() < 1e-8);
  CHECK((W + W.transpose()).norm() < 1e-8);
}

TEST_CASE("rod: reference state is an exact equilibrium (stress free)", "[unit]") {
  RodSystem sys;
  RodSpec s = helix_rod(4, 8);
  sys.add_rod(s);
  const Eigen::VectorXd x = sys.initial_state();
  Eigen::VectorXd F;
  sys.residual(x, 0.0, F);
  CHECK(F.cwiseProduct(sys.row_scales()).cwiseAbs().maxCoeff() < 1e-12);
  // reference frame: d3 is the tangent
  for (double xi : {0.0, 0.37, 1.0}) {
    const PointState st = sys.state(0, xi, x);
    CHECK((st.R.col(2) - st.r_xi.normalized()).norm() < 1e-3);
  }
}

// Session 50's red team: a rod pushed through zero length "completed" at an axial strain of
// -3; a converged increment whose smallest stretch is <= 0 now fails (RodSystem::
// min_axial_stretch). Its review: a NaN stays the smallest, also when finite points follow.
TEST_CASE("rod: the smallest axial stretch: 1 in the reference, negative reversed, NaN kept",
          "[unit]") {
  RodSystem sys;
  sys.add_rod(helix_rod(4, 8));
  const Eigen::VectorXd x0 = sys.initial_state();
  CHECK(sys.min_axial_stretch(x0).value == Approx(1.0).epsilon(1e-3));
  // The centerline reflected through its first control point: r' reversed, d3 not.
  Eigen::VectorXd x = x0;
  const Eigen::Vector3d r0 = x0.segment<3>(sys.dof(0, 0, kFieldR));
  for (int a = 0; a < sys.num_control_points(0); ++a)
    x.segment<3>(sys.dof(0, a, kFieldR)) = 2.0 * r0 - x0.segment<3>(sys.dof(0, a, kFieldR));
  CHECK(sys.min_axial_stretch(x).value == Approx(-1.0).epsilon(1e-3));
  // A NaN at the first control point: the first collocation points are NaN, the later finite.
  x = x0;
  x(sys.dof(0, 0, kFieldR)) = std::numeric_limits<double>::quiet_NaN();
  const RodSystem::AxialStretch a = sys.min_axial_stretch(x);
  CHECK(std::isnan(a.value));
  CHECK(a.xi < 0.5);
}

TEST_CASE("rod: Jacobian matches central finite differences", "[unit]") {
  RodSystem sys;
  RodSpec s = helix_rod(3, 5);
  s.start = EndCondition::clamped();
  s.start.displacement = Vector3d(0.1, -0.2, 0.05);
  s.start.rotation = Vector3d(0.3, 0.1, -0.2);
  s.end = EndCondition::free();
  s.end.force = Vector3d(0.3, 0.1, -0.5);
  s.end.moment = Vector3d(-0.1, 0.2, 0.3);
  s.line_force = Vector3d(0.01, 0.02, 0.0);
  s.line_moment = Vector3d(0.0, 0.01, 0.03);
  sys.add_rod(s);
  RodSpec s2 = helix_rod(4, 4);
  s2.start = EndCondition::free();
  s2.start.force = Vector3d(1, 2, 3);
  s2.end = EndCondition::clamped();
  sys.add_rod(s2);
  Eigen::VectorXd x = sys.initial_state();
  Eigen::VectorXd pert = Eigen::VectorXd::Random(x.size());
  x += 0.05 * pert;
  for (int i = 0; i < x.size(); i += kDofsPerPoint) x.segment<6>(i + kFieldN) *= 1.0;
  const double lambda = 0.7;
  Eigen::VectorXd F;
  std::vector<Eigen::Triplet<double>> trip;
  sys.assemble(x, lambda, F, trip);
  Eigen::SparseMatrix<double> J(x.size(), x.size());
  J.setFromTriplets(trip.begin(), trip.end());
  const Eigen::MatrixXd Jd = J;
  Eigen::MatrixXd Jfd(x.size(), x.size());
  const double h = 1e-6;
  Eigen::VectorXd Fp, Fm;
  for (int c = 0; c < x.size(); ++c) {
    Eigen::VectorXd xp = x, xm = x;
    xp(c) += h;
    xm(c) -= h;
    sys.residual(xp, lambda, Fp);
    sys.residual(xm, lambda, Fm);
    Jfd.col(c) = (Fp - Fm) / (2 * h);
  }
  const double err = (Jd - Jfd).cwiseAbs().maxCoeff();
  INFO("max |J - J_fd| = " << err << ", max |J| = " << Jd.cwiseAbs().maxCoeff());
  CHECK(err < 1e-6 * std::max(1.0, Jd.cwiseAbs().maxCoeff()));
}

TEST_CASE("rod: rigid-body motions of a stressed state give zero residual", "[unit]") {
  // A loaded cantilever in equilibrium, then the whole state moved rigidly (r -> Q r + c,
  // q -> q_Q q, n -> Q n, m -> Q m): all field equations (balance, constitutive, gauge) stay
  // satisfied; only the end rows (support and dead loads are not co-rotated) change.
  RodSystem sys;
  RodSpec s = helix_rod(3, 6);
  const double EI = s.section.C_K()(0);
  s.end.force = Vector3d(0.2, -0.1, 0.3) * EI;
  s.end.moment = Vector3d(0.1, 0.1, -0.2) * EI;
  sys.add_rod(s);
  Eigen::VectorXd x = sys.initial_state();
  PathOptions po;
  po.steps = 4;
  REQUIRE(solve_path(sys, x, po).completed);
  const Quat<double> qQ = quat_from_rotation_vector(Vector3d(0.5, -0.3, 1.2));
  const Eigen::Matrix3d Q = rotation(qQ);
  const Vector3d c(1.0, -2.0, 0.5);
  Eigen::VectorXd y = x;
  for (int a = 0; a < sys.num_control_points(0); ++a) {
    y.segment<3>(sys.dof(0, a, kFieldR)) = Q * x.segment<3>(sys.dof(0, a, kFieldR)) + c;
    y.segment<4>(sys.dof(0, a, kFieldQ)) =
        qmul(qQ, Quat<double>(x.segment<4>(sys.dof(0, a, kFieldQ))));
    y.segment<3>(sys.dof(0, a, kFieldN)) = Q * x.segment<3>(sys.dof(0, a, kFieldN));
    y.segment<3>(sys.dof(0, a, kFieldM)) = Q * x.segment<3>(sys.dof(0, a, kFieldM));
  }
  Eigen::VectorXd F;
  sys.residual(y, 1.0, F);
  const Eigen::VectorXd Fs = F.cwiseProduct(sys.row_scales());
  const int n = sys.num_control_points(0);
  double worst = 0.0;
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < kRowsPerPoint; ++k) {
      const bool end_row = (j == 0 || j == n - 1) && k < kRowStrain;
      if (!end_row) worst = std::max(worst, std::abs(Fs(sys.row(0, j, kRowForce) + k)));
    }
  CHECK(worst < 1e-10);
  // the stressed state is far from the reference: the check is not trivial
  CHECK(x.segment<3>(sys.dof(0, n - 1, kFieldN)).norm() > 0.1 * EI);
}

TEST_CASE("rod: load stepping cuts back a too large increment, failure is a status", "[unit]") {
  const auto make = add_rolled_cantilever;
  {
    RodSystem sys;
    make(sys);
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.steps = 1;
    po.newton.max_iterations = 8;
    const PathReport rep = solve_path(sys, x, po);
    CHECK(rep.completed);
    CHECK(rep.cutbacks > 0);
    CHECK(rep.lambda_reached == 1.0);
  }
  {
    RodSystem sys;
    make(sys);
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.steps = 1;
    po.max_cutbacks = 0;
    po.newton.max_iterations = 3;
    const PathReport rep = solve_path(sys, x, po);
    CHECK_FALSE(rep.completed);
    CHECK(rep.lambda_reached == 0.0);
    CHECK(!rep.message.empty());
    // x is restored to the last converged state
    CHECK((x - sys.initial_state()).norm() < 1e-12);
  }
}

TEST_CASE("rod: load stepping stops at the step floor and at the work cap, and says which",
          "[unit]") {
  // Issue 14: a path that only converges with ever smaller increments used to sub-step
  // forever (the successive-halving limit resets after every success).
  RodSystem sys;
  add_rolled_cantilever(sys);
  PathOptions def;
  CHECK(def.work_cap() == PathOptions::kWorkFactor * def.steps * def.newton.max_iterations);
  {  // one Newton iteration never converges: halvings until the floor
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.steps = 1;
    po.max_cutbacks = 1000;
    po.min_increment = 1e-2;
    po.newton.max_iterations = 1;
    const PathReport rep = solve_path(sys, x, po);
    CHECK_FALSE(rep.completed);
    CHECK(rep.stop == PathStop::kStepFloor);
    CHECK(rep.message.rfind("step floor: ", 0) == 0);
    CHECK(rep.cutbacks == 7);  // 1/2^7 < 1e-2 <= 1/2^6
    CHECK((x - sys.initial_state()).norm() < 1e-12);
  }
  {  // the work cap: total Newton iterations over the path
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.steps = 1;
    po.max_cutbacks = 1000;
    po.min_increment = 1e-12;
    po.max_total_iterations = 5;
    po.newton.max_iterations = 3;  // the full increment fails: cut-backs, until the cap
    const PathReport rep = solve_path(sys, x, po);
    CHECK_FALSE(rep.completed);
    CHECK(rep.stop == PathStop::kWorkCap);
    CHECK(rep.message.rfind("work cap: ", 0) == 0);
    CHECK(rep.total_iterations <= po.max_total_iterations + po.newton.max_iterations);
  }
  {  // options are checked
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.min_increment = std::nan("");
    CHECK(solve_path(sys, x, po).stop == PathStop::kBadOptions);
  }
}

TEST_CASE("section: yarn defaults reproduce the values of design/notes.md", "[unit]") {
  const Section s;  // d = 0.38 mm, E = 800 MPa, nu = 0.3
  CHECK(s.A() == Approx(0.1134).epsilon(1e-3));
  CHECK(s.I() == Approx(1.024e-3).epsilon(1e-3));
  CHECK(s.J() == Approx(2.047e-3).epsilon(1e-3));
  CHECK(s.C_Gamma()(2) == Approx(90.7).epsilon(1e-3));
  CHECK(s.C_K()(0) == Approx(0.819).epsilon(1e-3));
  CHECK(s.shear_factor() == Approx(6 * 1.3 / 8.8));
  CHECK(s.C_Gamma()(0) == Approx(800.0 / 2.6 * (6 * 1.3 / 8.8) * s.A()));
  CHECK(s.C_K()(2) == Approx(800.0 / 2.6 * s.J()));
}

// The resolution check's second mesh (session 28): every span halved, the same reference
// centerline, loads and end conditions, and again a stress-free reference state.
TEST_CASE("rod: the bisected system keeps the geometry and doubles the spans", "[unit]") {
  RodSystem sys;
  RodSpec s = helix_rod(3, 5);
  s.end.force = Vector3d(0.0, 1e-4, 2e-4);
  s.line_force = Vector3d(1e-5, 0.0, 0.0);
  sys.add_rod(s);
  const RodSystem fine = bisected(sys);
  REQUIRE(fine.num_rods() == 1);
  CHECK(fine.spec(0).basis.degree() == 3);
  CHECK(fine.num_control_points(0) == 3 + 10);
  CHECK(fine.spec(0).name == "helix");
  CHECK((fine.spec(0).end.force - s.end.force).norm() == 0.0);
  CHECK((fine.spec(0).line_force - s.line_force).norm() == 0.0);
  // Gauss quadrature of |r0_xi| (not a polynomial) per span: twice the spans, a finer sum.
  CHECK(fine.reference_length(0) == Approx(sys.reference_length(0)).epsilon(1e-8));
  for (double xi : {0.0, 0.13, 0.5, 0.77, 1.0})
    CHECK((fine.reference_position(0, xi) - sys.reference_position(0, xi)).norm() < 1e-12);
  Eigen::VectorXd F;
  fine.residual(fine.initial_state(), 0.0, F);
  CHECK(F.cwiseProduct(fine.row_scales()).cwiseAbs().maxCoeff() < 1e-12);
}

// Session 29: the check compared displacements only, and a twisted rod does not move. A straight
// rod twisted by M L / GJ = 1.655 rad (94.8 degrees; uniform torsion, exact) on one element of
// degree 2: the rotations change by 5.4 % on bisection, and the check said 0 %.
TEST_CASE("rod: the resolution check compares rotations (uniform torsion, M L / GJ)", "[unit]") {
  const Section sec;
  const double L = 10.0, GJ = sec.C_K()(2);
  const double twist = 1.655;
  auto check = [&](int p, int elements) {
    RodSystem sys;
    RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(L, 0, 0), p, elements, sec);
    s.end.moment = Vector3d(twist * GJ / L, 0, 0);
    sys.add_rod(s);
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.steps = 4;
    REQUIRE(solve_path(sys, x, po).completed);
    return check_resolution(sys, x, po, {{0, 1.0}, {0, 0.5}});
  };
  const ResolutionCheck fine = check(3, 8);
  REQUIRE(fine.checked);
  CHECK(fine.angle_max == Approx(twist).epsilon(1e-4));  // the bisected mesh's tip: M L / GJ
  CHECK(fine.u_max < 1e-10);
  CHECK(fine.difference < kResolutionTolerance);
  const ResolutionCheck coarse = check(2, 1);
  REQUIRE(coarse.checked);
  INFO(coarse.describe());
  CHECK(coarse.displacement_difference < 1e-6);  // nothing moves on either mesh
  CHECK(coarse.rotation_difference > kResolutionTolerance);
  CHECK(coarse.difference == coarse.rotation_difference);
  CHECK(coarse.describe().find("and the rotations by") != std::string::npos);
}

// Session 29 (a helper's fuzzing audit): the reference frame's interpolation was a dense LU of
// n x n (5,000 elements: 90 s and 1.8 GB; the schema allows 1e6). Beyond 2,000 control points it
// is a sparse LU. Its director d3 is the centerline's tangent (the frame it interpolates).
TEST_CASE("rod: a long curve's reference frame (sparse interpolation) follows the tangent",
          "[unit]") {
  for (int elements : {100, 2500}) {
    RodSystem sys;
    sys.add_rod(helix_rod(3, elements));
    INFO(elements);
    CHECK(sys.num_control_points(0) == elements + 3);
    const Eigen::VectorXd x0 = sys.initial_state();
    double worst = 0.0;
    for (int k = 0; k <= 200; ++k) {
      const PointState ps = sys.state(0, k / 200.0, x0);
      worst = std::max(worst, (ps.R.col(2) - ps.r_xi.normalized()).norm());
    }
    CHECK(worst < 1e-6);
  }
}

TEST_CASE("rod: after a cut-back the increment grows back, and the predictor saves iterations",
          "[unit]") {
  // The rolled-up cantilever. Session 33: deleting either the growth after an easy step or the
  // secant predictor failed no test.
  RodSystem sys;
  add_rolled_cantilever(sys);
  auto path = [&](int steps, int max_iterations, bool predictor) {
    Eigen::VectorXd x = sys.initial_state();
    PathOptions po;
    po.steps = steps;
    po.newton.max_iterations = max_iterations;
    po.predictor = predictor;
    const PathReport rep = solve_path(sys, x, po);
    REQUIRE(rep.completed);
    std::vector<double> lambdas;
    for (const auto& r : rep.steps) lambdas.push_back(r.lambda);
    return std::pair(rep, lambdas);
  };
  {
    // One step, at most 5 iterations: 1 and 0.5 fail, 0.25 converges in 5 iterations (<= 6, an
    // easy step), so the increment doubles to 0.5: 0.75 fails, 0.5 converges, 1 fails, 0.75 and
    // 1 converge. Without the growth the increment stays 0.25 and only the first two fail.
    const auto [rep, lambdas] = path(1, 5, true);
    CHECK(lambdas == std::vector<double>{0.25, 0.5, 0.75, 1.0});
    CHECK(rep.cutbacks == 4);
  }
  // Four steps of 0.25: the secant predictor from the last converged increment saves an
  // iteration (at 0.5: 5 instead of 6), with the same converged states.
  const auto with = path(4, 8, true).first, without = path(4, 8, false).first;
  CHECK(with.cutbacks == 0);
  CHECK(without.cutbacks == 0);
  CHECK(with.total_iterations < without.total_iterations);
}

// Session 34 (the rod audit): the rod case's line_moment and a load on a free start end could
// change sign and no test saw it (the Jacobian test takes the load factor as given).

TEST_CASE("rod: a distributed moment bends a cantilever by m L^2 / (2 EI) at its tip", "[unit]") {
  // Clamped at x = 0, a dead line moment (0, -m, 0): no force anywhere, so the bending moment is
  // m (L - s) whatever the shape, the curvature m (L - s) / EI, and the tangent turns about -y
  // by theta(s) = (m / EI) (L s - s^2 / 2), towards +z: tip (int cos theta, 0, int sin theta).
  const Section sec;
  const double L = 10.0, EI = sec.C_K()(0), m = 0.5 * EI / (L * L);
  RodSystem sys;
  RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(L, 0, 0), 4, 16, sec);
  s.line_moment = Vector3d(0, -m, 0);
  sys.add_rod(s);
  Eigen::VectorXd x = sys.initial_state();
  PathOptions po;
  po.steps = 2;
  REQUIRE(solve_path(sys, x, po).completed);
  const double theta_tip = m * L * L / (2.0 * EI);
  REQUIRE(theta_tip == Approx(0.25));
  Vector3d tip = Vector3d::Zero();  // Simpson's rule
  const int n = 2000;
  for (int i = 0; i <= n; ++i) {
    const double si = L * i / n, th = m / EI * (L * si - 0.5 * si * si);
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    tip += w * L / (3.0 * n) * Vector3d(std::cos(th), 0.0, std::sin(th));
  }
  const PointState end = sys.state(0, 1.0, x);
  CHECK((end.r - tip).norm() < 1e-6 * L);
  CHECK(end.R.col(2).z() == Approx(std::sin(theta_tip)).epsilon(1e-6));
  CHECK(end.R.col(2).x() == Approx(std::cos(theta_tip)).epsilon(1e-6));
}

TEST_CASE("rod: a force on a free start end deflects it by P L^3 / (3 EI) + P L / (G As)",
          "[unit]") {
  // Clamped at the end x = L, free at the start x = 0, which carries P e_z: the linear cantilever
  // (Timoshenko: bending and shear), P small enough for the rotation (P L^2 / 2 EI = 5e-4) to
  // leave it linear to ~1e-6; the internal force at the loaded start balances it, n(0) = -P.
  const Section sec;
  const double L = 10.0, EI = sec.C_K()(0), GAs = sec.C_Gamma()(0), P = 1e-3 * EI / (L * L);
  RodSystem sys;
  RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(L, 0, 0), 4, 16, sec);
  s.start = EndCondition::free();
  s.start.force = Vector3d(0, 0, P);
  s.end = EndCondition::clamped();
  sys.add_rod(s);
  Eigen::VectorXd x = sys.initial_state();
  PathOptions po;
  po.steps = 1;
  REQUIRE(solve_path(sys, x, po).completed);
  const PointState start = sys.state(0, 0.0, x);
  CHECK(start.r.z() == Approx(P * L * L * L / (3.0 * EI) + P * L / GAs).epsilon(1e-4));
  CHECK((start.n - Vector3d(0, 0, -P)).norm() < 1e-8 * P);
}

// Session 34 (the rod audit): the row weights make the residual dimensionless for Newton's
// convergence test (docs/rod.md); a curvature row weighted 1 instead of L (L times looser)
// survived every test. The same rod and state in mm and in m (lengths / 1000, E and line
// forces * 1e6 and 1e3, moments / 1000, forces unchanged) must give the same scaled residual.
TEST_CASE("rod: the scaled residual does not depend on the length unit", "[unit]") {
  const double k = 1e-3;  // mm -> m
  Section mm;
  Section m = mm;
  m.E = mm.E / (k * k);
  m.d = mm.d * k;
  const auto scaled_residual = [](const Section& sec, double unit) {
    RodSystem sys;
    RodSpec s = straight_rod(Vector3d::Zero(), Vector3d(10.0 * unit, 0, 0), 4, 6, sec);
    s.end.force = Vector3d(0.01, 0.02, -0.03);          // N
    s.end.moment = Vector3d(0.05, -0.02, 0.04) * unit;  // N mm -> N m
    s.line_force = Vector3d(1e-3, -2e-3, 3e-3) / unit;  // N/mm -> N/m
    s.line_moment = Vector3d(2e-3, 1e-3, -1e-3);        // N mm/mm = N
    sys.add_rod(s);
    Eigen::VectorXd x = sys.initial_state();
    // A state away from equilibrium in every field, the same in both units.
    for (int a = 0; a < s.basis.size(); ++a) {
      const double t = 0.37 * a + 0.2;
      x.segment<3>(sys.dof(0, a, kFieldR)) +=
          unit * Vector3d(0.1 * t, -0.05 * t * t, 0.2 * std::sin(t));
      x.segment<4>(sys.dof(0, a, kFieldQ)) += Eigen::Vector4d(0.01 * t, 0.02, -0.03 * t, 0.01);
      x.segment<3>(sys.dof(0, a, kFieldN)) += Vector3d(0.3 * t, -0.2, 0.1 * t * t);
      x.segment<3>(sys.dof(0, a, kFieldM)) += unit * Vector3d(-0.1, 0.2 * t, 0.05);
    }
    Eigen::VectorXd F;
    sys.residual(x, 0.7, F);
    return Eigen::VectorXd(F.cwiseProduct(sys.row_scales()));
  };
  const Eigen::VectorXd a = scaled_residual(mm, 1.0), b = scaled_residual(m, k);
  REQUIRE(a.size() == b.size());
  REQUIRE(a.norm() > 0.0);
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    INFO("row " << i);
    CHECK(b(i) == Approx(a(i)).epsilon(1e-9).margin(1e-12 * a.norm()));
  }
}

// Session 34 (the rod audit): the reference frame is rotation-minimizing (parallel transported,
// docs/rod.md): its directors do not twist about the tangent. A sign error in the transport
// added a smooth twist that the circular section's stiffnesses cannot see; only the d1
// director of the output moved.
TEST_CASE("rod: the reference frame of a helix does not twist about its tangent", "[unit]") {
  RodSystem sys;
  sys.add_rod(helix_rod(4, 24));
  const Eigen::VectorXd x = sys.initial_state();
  double twist = 0.0, bend = 0.0;
  for (int i = 0; i <= 200; ++i) {
    const PointState s = sys.state(0, i / 200.0, x);
    const Vector3d K = material_curvature(s.q, s.q_xi) / s.jac;
    twist = std::max(twist, std::abs(K(2)));
    bend = std::max(bend, K.head<2>().norm());
  }
  INFO("largest twist " << twist << " 1/mm, bending curvature " << bend << " 1/mm");
  CHECK(bend > 0.1);
  CHECK(twist < 1e-4 * bend);
}

// Session 34 (the rod audit): Newton stops as "diverged" once the scaled residual exceeds
// divergence_factor times the initial one; without the check it ran on to its iteration limit
// and said so. The rolled-up cantilever in one step from the straight rod: the residual first
// rises (history[1] > history[0]), so a factor 1 stops it there, at iteration 1.
TEST_CASE("rod: Newton stops as diverged when the residual rises past the factor", "[unit]") {
  RodSystem sys;
  add_rolled_cantilever(sys);
  Eigen::VectorXd x = sys.initial_state();
  NewtonOptions o;
  const NewtonReport free_run = solve_newton(sys, x, 1.0, {}, o);
  REQUIRE(free_run.history.size() > 2);
  REQUIRE(free_run.history[1] > free_run.history[0]);
  x = sys.initial_state();
  o.divergence_factor = 1.0;
  const NewtonReport stopped = solve_newton(sys, x, 1.0, {}, o);
  CHECK_FALSE(stopped.converged);
  CHECK(stopped.message == "diverged");
  CHECK(stopped.iterations == 1);
}
