// The periodic unit cell and its homogenized stresses (paper Sect. 2.1.2, eqs. 7-9):
// residual stress at zero strain, the pure-shear strain identity, 4.5 mm stiffer than 6.5 mm,
// non-negative friction dissipation, the energy balance of the boundary work, mirror symmetry
// of +-gamma, the full cell Jacobian (contact with friction, periodic rows) against finite
// differences, and a step that meets a limit point ending instead of sub-stepping for ever.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <string>

#include "knit/material/load_paths.hpp"
#include "knit/meso/homog/path.hpp"

using namespace knit::meso::homog;

namespace {

CellOptions fast_options() {
  CellOptions o;
  o.elements = 16;
  o.newton.tol = 1e-8;
  return o;
}

PathSpec biaxial(double e11, double e22, int steps) {
  PathSpec p;
  p.eps11 = e11;
  p.eps22 = e22;
  p.steps = steps;
  return p;
}

PathSpec shear(double gamma, int steps) {
  PathSpec p;
  p.kind = PathSpec::Kind::kShear;
  p.gamma = gamma;
  p.steps = steps;
  return p;
}

}  // namespace

TEST_CASE("pure shear: E11 = E22 = 0 and E12 = sin(gamma)/2, biaxial E", "[unit]") {
  for (double g : {0.1, 0.5, -0.7}) {
    const Eigen::Matrix2d E = green_lagrange(path_F(shear(g, 1), 1.0));
    CHECK(std::abs(E(0, 0)) < 1e-15);
    CHECK(std::abs(E(1, 1)) < 1e-15);
    CHECK(E(0, 1) == Approx(0.5 * std::sin(g)));
  }
  const Eigen::Matrix2d E = green_lagrange(path_F(biaxial(0.2, -0.1, 1), 1.0));
  CHECK(E(0, 0) == Approx(0.5 * (1.2 * 1.2 - 1)));
  CHECK(E(1, 1) == Approx(0.5 * (0.9 * 0.9 - 1)));
}

TEST_CASE("zero macroscopic strain: only the documented residual stress", "[unit]") {
  for (double l : {4.5, 6.5}) {
    PeriodicCell cell(l, fast_options());
    const StepResult r0 = cell.equilibrate();
    REQUIRE(r0.converged);
    INFO("l = " << l << " P = \n" << r0.P);
    // docs/unit-cell.md: residual stress below 0.3 MPa (initial overlaps beyond the allowance g0)
    CHECK(r0.P.cwiseAbs().maxCoeff() < 0.3);
    // In-plane symmetry of the cell: no shear stress at rest.
    CHECK(std::abs(r0.P(0, 1)) < 1e-6);
    CHECK(std::abs(r0.P(1, 0)) < 1e-6);
    // Solving again at F* = I changes nothing.
    const StepResult r1 = cell.solve(Eigen::Matrix2d::Identity());
    REQUIRE(r1.converged);
    CHECK((r1.P - r0.P).norm() < 1e-6);
  }
}

TEST_CASE("4.5 mm cell is stiffer than 6.5 mm in both directions", "[unit]") {
  double dS[2][2];
  const double ls[2] = {4.5, 6.5};
  for (int a = 0; a < 2; ++a)
    for (int dir = 0; dir < 2; ++dir) {
      PeriodicCell cell(ls[a], fast_options());
      const PathResult r = run_path(cell, biaxial(dir == 0 ? 0.15 : 0, dir == 1 ? 0.15 : 0, 5));
      REQUIRE(r.completed);
      dS[a][dir] = r.steps.back().S(dir, dir) - r.steps.front().S(dir, dir);
    }
  INFO("dS11: " << dS[0][0] << " vs " << dS[1][0] << "; dS22: " << dS[0][1] << " vs " << dS[1][1]);
  CHECK(dS[0][0] > dS[1][0]);
  CHECK(dS[0][1] > dS[1][1]);
  CHECK(dS[1][0] > 0);
  CHECK(dS[1][1] > 0);
}

TEST_CASE("energy balance: boundary work = stored energy + friction work, D never negative",
          "[unit]") {
  CellOptions o = fast_options();
  o.elements = 32;  // the balance holds to ~1 % from 32 elements on (docs/unit-cell.md)
  // The default gamma / w and the calibration window's upper part (docs/unit-cell.md,
  // "Calibration"): with friction at work (D is 0.03 % of W at 0.225, 4.5 % at 0.25). Measured
  // (session 57): off by 3.5 % and 0.8 %; with the elastic stick energy counted on the
  // closest point's arc instead of the slave's slip (before session 57), 3.5 % and -6.3 %.
  const double gamma_over_w = GENERATE(0.225, 0.25);
  INFO("gamma / w = " << gamma_over_w);
  o.geometry.gamma_over_w = gamma_over_w;
  PeriodicCell cell(4.5, o);
  double U0 = 0, D_prev = 0;
  bool monotone = true;
  const PathResult r = run_path(cell, biaxial(0.2, 0.05, 8), [&](int k, const StepResult& s) {
    if (k == 0) U0 = cell.strain_energy() + cell.contacts().energy(cell.system(), cell.state());
    if (s.dissipation < D_prev - 1e-15) monotone = false;
    if (cell.contacts().last_increment_dissipation() < 0) monotone = false;
    D_prev = s.dissipation;
  });
  REQUIRE(r.completed);
  CHECK(monotone);
  const auto& d = cell.dimensions();
  const double V = d.w * d.c * cell.thickness();
  const double Wb = boundary_work(r.steps, d.w, d.c, cell.thickness()) * V;
  const double Ws = stress_work(r.steps) * V;
  CHECK(Ws == Approx(Wb).epsilon(1e-12));  // eq. 8 is the boundary force over the face area
  const double U = cell.strain_energy() + cell.contacts().energy(cell.system(), cell.state());
  const double D = r.steps.back().dissipation - r.steps.front().dissipation;
  INFO("W = " << Wb << " dU = " << U - U0 << " D = " << D);
  CHECK(D >= 0);
  CHECK(Wb > 0);
  // Collocation is not variational and the work is integrated by the trapezoidal rule: a few %.
  CHECK(std::abs(Wb - (U - U0 + D)) < 0.04 * Wb);
}

TEST_CASE("mirror-symmetric shear paths give mirror-symmetric stresses", "[unit]") {
  Eigen::Matrix2d S[2];
  for (int s = 0; s < 2; ++s) {
    PeriodicCell cell(4.5, fast_options());
    const PathResult r = run_path(cell, shear(s == 0 ? 0.3 : -0.3, 4));
    REQUIRE(r.completed);
    S[s] = r.steps.back().S;
  }
  INFO("S(+g) =\n" << S[0] << "\nS(-g) =\n" << S[1]);
  const double tol = 2e-3 * S[0].cwiseAbs().maxCoeff();
  CHECK(std::abs(S[0](0, 0) - S[1](0, 0)) < tol);
  CHECK(std::abs(S[0](1, 1) - S[1](1, 1)) < tol);
  CHECK(std::abs(S[0](0, 1) + S[1](0, 1)) < tol);
  CHECK(std::abs(S[0](1, 0) + S[1](1, 0)) < tol);
  CHECK(S[0](0, 1) > 0);
}

TEST_CASE("cell Jacobian (rod + periodic rows + frictional contact) matches finite differences",
          "[unit]") {
  PeriodicCell cell(4.5, fast_options());
  REQUIRE(cell.equilibrate().converged);
  Eigen::Matrix2d F;
  F << 1.06, 0.05, 0.0, 0.98;
  REQUIRE(cell.solve(F).converged);
  // After a converged step the slipping pairs sit exactly on the Coulomb cone, where the
  // residual has a kink: compare at a perturbed state instead (pairs well inside stick or slip).
  const auto& sys = cell.system();
  Eigen::VectorXd x0 = cell.state();
  std::srand(7);
  for (int a = 0; a < sys.num_control_points(0); ++a)
    for (int c = 0; c < 3; ++c)
      x0(sys.dof(0, a, knit::meso::rod::kFieldR, c)) +=
          2e-3 * (std::rand() / double(RAND_MAX) - 0.5);
  Eigen::VectorXd R;
  Eigen::SparseMatrix<double> J;
  knit::meso::rod::assemble_all(sys, x0, 1.0, cell.contributions(), R, J);
  const Eigen::MatrixXd Jd(J);
  double err = 0, scale = 0;
  const double h = 1e-6;
  // Every column: all control points and all 13 unknowns of each (r, q, n, m). Session 39's
  // audit: every third point, r and three components of q left the periodic rows' entries in
  // the last point's columns (r_N, q_N, n_N, m_N) and in m_0 and q_0's fourth component unchecked.
  int columns = 0;
  for (int k = 0; k < sys.num_dofs(); ++k) {
    ++columns;
    Eigen::VectorXd xp = x0, xm = x0;
    xp(k) += h;
    xm(k) -= h;
    Eigen::VectorXd Rp, Rm;
    Eigen::SparseMatrix<double> Jt;
    knit::meso::rod::assemble_all(sys, xp, 1.0, cell.contributions(), Rp, Jt);
    knit::meso::rod::assemble_all(sys, xm, 1.0, cell.contributions(), Rm, Jt);
    const Eigen::VectorXd fd = (Rp - Rm) / (2 * h);
    err = std::max(err, (fd - Jd.col(k)).cwiseAbs().maxCoeff());
    scale = std::max(scale, fd.cwiseAbs().maxCoeff());
  }
  INFO("max |J - FD| = " << err << " of " << scale << " over " << columns << " columns");
  CHECK(columns == 13 * sys.num_control_points(0));
  CHECK(err < 1e-5 * scale);
}

TEST_CASE("a step that meets a limit point ends, not converged, instead of sub-stepping for ever",
          "[case]") {
  // Session 12 (docs/unit-cell.md): course compression with shear at 4.5 mm stopped at 0.9412 of
  // a step; each sub-step that converges resets the count of halvings, so the sub-steps shrank
  // below round-off and the same state "converged" for ever (the sweep hung). Now the step fails
  // with a message. Since session 57 (the courses +-2 searched) that path passes; here biaxial
  // compression at 5 mm (12 elements), F = (1 - 0.9 k / 3) I, k = 1, 2, 3: step 3 stops at
  // 0.0372 of its increment (knit-meso path --loop-length 5 --biaxial -0.9 -0.9 --steps 3;
  // until session 58, when a sub-step did not grow back after a cut-back, step 2 at 0.9655).
  CellOptions o;
  o.elements = 12;
  PeriodicCell cell(5.0, o);
  REQUIRE(cell.equilibrate().converged);
  int failed_step = 0;
  std::string message;
  for (int k = 1; k <= 3 && failed_step == 0; ++k) {
    const StepResult r = cell.solve((1.0 - 0.9 * k / 3.0) * Eigen::Matrix2d::Identity());
    if (!r.converged) failed_step = k, message = r.message;
  }
  INFO(message);
  CHECK(failed_step == 3);
  CHECK(message.find("limit point") != std::string::npos);
  // Where within the step it stuck, said as such (session 48's walkthrough read "at load
  // fraction 0.11" of step 6 of 6 as a contradiction).
  CHECK(message.find("of the step, stuck at 0.03") != std::string::npos);
  CHECK(message.find("of the way from the step's start to its end") != std::string::npos);
}

TEST_CASE("a periodic cell is refused where its loop does not interlock", "[unit]") {
  // Every entry (path, cell, the sweep's loop lengths) builds a PeriodicCell; one of 3 mm has
  // no crossing with the next course (session 27: exit 0 with S22 = 0.0006 MPa at 50 %).
  CHECK_THROWS_AS(PeriodicCell(3.0), knit::meso::cell::GeometryError);
  CHECK_THROWS_WITH(PeriodicCell(3.0), Catch::Contains("does not interlock with the next course"));
  CHECK_NOTHROW(PeriodicCell(4.5));
}

// Session 28: the gap |x_s - x_m| - d has no sign, and one large step let the yarns of a 4.5 mm
// cell slip through each other: course stretch F11 = 1.8 in one step gave S = (-1.2, -3.8) MPa,
// compression under tension, for (8.7, 15.4) MPa in 40 steps, converged and exit 0. Wale
// stretch F22 = 1.8 in one step converged with the yarns sunk 0.93 d into each other, S = (8.7,
// 10.2) MPa for (17.8, 17.2). Both states are now refused and the step cut back
// (contact_set.hpp, pass-through guard and ContactOptions::max_overlap).
TEST_CASE("a step whose yarns pass through each other is cut back, not accepted", "[case]") {
  for (const int axis : {0, 1}) {
    INFO("stretch along " << (axis == 0 ? "the course" : "the wale"));
    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    F(axis, axis) = 1.8;
    PeriodicCell one(4.5, fast_options());
    REQUIRE(one.equilibrate().converged);
    const StepResult r1 = one.solve(F);
    PeriodicCell many(4.5, fast_options());
    REQUIRE(many.equilibrate().converged);
    StepResult rn;
    for (int k = 1; k <= 40; ++k) {
      Eigen::Matrix2d Fk = Eigen::Matrix2d::Identity();
      Fk(axis, axis) = 1.0 + 0.8 * k / 40.0;
      rn = many.solve(Fk);
      REQUIRE(rn.converged);
      CHECK(rn.pass_throughs == 0);  // small steps: the guard does not fire
    }
    INFO(r1.message);
    CHECK(r1.pass_throughs > 0);  // the full step went through and was cut back
    CHECK(r1.converged);          // ... and its sub-steps reach F
    // At the stresses of the small steps (friction's path dependence: a few %).
    CHECK(r1.S(0, 0) == Approx(rn.S(0, 0)).epsilon(0.1));
    CHECK(r1.S(1, 1) == Approx(rn.S(1, 1)).epsilon(0.1));
  }
}

// Session 30, a helper's mutation testing: a transposed P (eq. 8) and S = P F^-1 instead of
// F^-1 P (eq. 9) survived every test, since the biaxial energy balance does no work with the
// off-diagonal P and the mirror test cannot tell them apart; a wrong periodic offset of the
// contacts (F^T for F) was caught only by accident.
TEST_CASE("shear path: stress work equals boundary work (eq. 8), S is the sweep's F^-1 P (eq. 9)",
          "[unit]") {
  PeriodicCell cell(4.5, fast_options());
  const PathResult r = run_path(cell, shear(0.35, 4));
  REQUIRE(r.completed);
  const auto& d = cell.dimensions();
  const double Wb = boundary_work(r.steps, d.w, d.c, cell.thickness());
  const double Ws = stress_work(r.steps);
  INFO("Ws = " << Ws << " Wb = " << Wb);
  CHECK(Wb > 0);
  CHECK(Ws == Approx(Wb).epsilon(1e-12));
  for (const StepResult& s : r.steps) {
    const Eigen::Matrix2d S_sweep = knit::material::second_piola_kirchhoff(s.F, s.P);
    const Eigen::Matrix2d S_sym = 0.5 * (s.S + s.S.transpose());
    INFO("S =\n" << s.S << "\nsweep's S =\n" << S_sweep);
    CHECK((S_sym - S_sweep).cwiseAbs().maxCoeff() <= 1e-12 * (1 + S_sweep.cwiseAbs().maxCoeff()));
  }
  // The converged cell's F^-1 P is nearly symmetric (docs/unit-cell.md: within a few % of
  // max |S| at 20 deg); S = P F^-1 was not (33 %).
  const Eigen::Matrix2d& S = r.steps.back().S;
  CHECK(std::abs(S(0, 1) - S(1, 0)) <= 0.05 * S.cwiseAbs().maxCoeff());
}

TEST_CASE("rigid rotation of a stretched cell: S does not change (objectivity)", "[unit]") {
  // Stretched first (at rest S = 0, which any S = P, P F^-1 would keep; review of session 30),
  // then rotated rigidly by 2.5 ... 10 deg: S(R U) = S(U) (measured ~1e-11 MPa; S = P F^-1
  // differs by 5e-4 ... 2e-3, S = P by 0.04 ... 0.14).
  PeriodicCell cell(4.5, fast_options());
  REQUIRE(cell.equilibrate().converged);
  Eigen::Matrix2d U = Eigen::Matrix2d::Identity();
  StepResult rU;
  for (int k = 1; k <= 4; ++k) {
    U.diagonal() << 1.0 + 0.025 * k, 1.0 + 0.0125 * k;
    rU = cell.solve(U);
    REQUIRE(rU.converged);
  }
  REQUIRE(rU.S.cwiseAbs().maxCoeff() > 0.01);  // a stressed state
  for (int k = 1; k <= 4; ++k) {
    const double a = k * 2.5 * M_PI / 180.0;
    Eigen::Matrix2d R;
    R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    const StepResult r = cell.solve(R * U);
    REQUIRE(r.converged);
    INFO("rotation " << k * 2.5 << " deg: S =\n" << r.S << "\nunrotated\n" << rU.S);
    CHECK((r.S - rU.S).cwiseAbs().maxCoeff() <= 1e-6);
  }
}

// Session 34 (the rod/contact/cell audit): the wale-direction force n2 taken from the contacts
// with the course above alone (not the mean of above and below) moved P22 by 0.5 %, and the
// yarn-end imbalance written as |nB + nA| (2 |n1|) instead of |nB - nA|; no test saw either.
TEST_CASE("homogenization: n2 is the mean of the forces from the courses above and below",
          "[unit]") {
  PeriodicCell cell(4.5, fast_options());
  const PathResult r = run_path(cell, biaxial(0.15, 0.0, 5));
  REQUIRE(r.completed);
  const StepResult& s = r.steps.back();
  Eigen::Vector3d up = Eigen::Vector3d::Zero(), down = Eigen::Vector3d::Zero();
  for (const auto& p : cell.contacts().active_pairs(cell.system(), cell.state())) {
    // Weighted by the course's distance, the virial of the lattice shift j A2 (only j = +-1
    // press on this path; the test at wale compression above has j = +-2).
    if (p.course > 0) up += p.course * p.weight * p.f;
    if (p.course < 0) down += -p.course * p.weight * p.f;
  }
  REQUIRE(up.norm() > 0.0);
  REQUIRE((up + down).norm() > 1e-3 * up.norm());  // the two sides differ: the mean matters
  CHECK((s.n2 - 0.5 * (up - down)).norm() < 1e-12 * up.norm());
  // Periodic yarn ends carry (nearly) the same force: their imbalance |nB - nA|, the net
  // contact load not applied (docs/unit-cell.md, imbalance_N), is a small part of n1 (0.037 N
  // against 0.64 N here).
  CHECK(s.imbalance < 0.1 * s.n1.norm());
}

// Session 56's red team: n1 held the yarn's force where it crosses the cell's vertical faces,
// but not the contact forces between the cell's yarn and the stitches left and right of it
// (copies k = +-1 along the course), which cross those faces too. Where stitches of a course
// press on each other (laterally compressed, at the end of the 4.5 mm uniaxial wale path) P11
// was -0.0009 MPa where dU/dF11 / V is -2.11. The identity (mu = 0, elastic): P = (1/V) dU/dF,
// U the rods' strain energy plus the contact energy, by central differences; collocation is not
// variational, so within a few % (1.6 % at 32 elements, 1.0 % at 64).
TEST_CASE(
    "homogenization: P is the derivative of the cell's energy where stitches press on "
    "each other",
    "[unit]") {
  CellOptions o = fast_options();
  o.elements = 32;
  o.contact.friction.mu = 0.0;
  PeriodicCell cell(4.5, o);
  REQUIRE(cell.equilibrate().converged);
  // Lateral compression under wale stretch: the stitches left and right (k != 0) press; wale
  // compression (session 57's red team): the courses two away (|j| = 2) press as well, which
  // only the search of every course within reach sees (before, -0.05 MPa for -4.8 at E22 = -0.26).
  const int variant = GENERATE(0, 1);
  Eigen::Matrix2d F;
  if (variant == 0)
    F << 0.81255, 0.0, 0.0, 1.30384;  // (E11, E22) = (-0.17, 0.35)
  else
    F << 1.0, 0.0, 0.0, 0.7;  // E22 = -0.255
  const int axis = variant;   // the compressed direction
  StepResult s;
  for (int k = 1; k <= 10; ++k) {
    s = cell.solve(Eigen::Matrix2d::Identity() + (F - Eigen::Matrix2d::Identity()) * (k / 10.0));
    REQUIRE(s.converged);
  }
  int across = 0;  // pairs that carry force with the stitches left and right, or two courses away
  for (const auto& p : cell.contacts().active_pairs(cell.system(), cell.state()))
    across += (variant == 0 ? p.k != 0 : std::abs(p.course) >= 2) && p.f.norm() > 0.0;
  INFO("variant " << variant << ": " << across << " pairs");
  REQUIRE(across > 0);
  const auto& d = cell.dimensions();
  const double V = d.w * d.c * cell.thickness(), h = 1e-4;
  const auto energy = [&] {
    return cell.strain_energy() + cell.contacts().energy(cell.system(), cell.state());
  };
  const auto snap = cell.snapshot();
  Eigen::Matrix2d dU = Eigen::Matrix2d::Zero();
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      double U[2];
      for (int side = 0; side < 2; ++side) {
        cell.restore(snap);
        Eigen::Matrix2d G = F;
        G(i, j) += side == 0 ? h : -h;
        REQUIRE(cell.solve(G).converged);
        U[side] = energy();
      }
      dU(i, j) = (U[0] - U[1]) / (2.0 * h * V);
    }
  INFO("P =\n" << s.P << "\n(1/V) dU/dF =\n" << dU);
  CHECK(dU(axis, axis) < -1.0);  // the compression is carried (MPa)
  CHECK((s.P - dU).cwiseAbs().maxCoeff() <= 0.03 * s.P.cwiseAbs().maxCoeff());
}

// Session 56's red team: on a closed strain loop that ends stress-free the net work of the
// homogenized stress is the friction dissipation, but the reported dissipation was about twice
// it (0.0921 against 0.0442 N mm): the slip was taken as the arc of the closest point along
// the master's centerline, 1 / (1 - q) times the slave's own slip (q ~ 0.5 inside the loops'
// bends). Loop I -> diag(1.2, 1) -> diag(1.2, 1.2) -> I, 20 steps a leg, work by the trapezoidal
// rule: with mu = 0 it closes (the control), with mu = 0.15 D is the net work within 10 %
// (-4.9 % measured; collocation and the stick force, which is no potential, leave the rest).
TEST_CASE("closed strain loop: the net work is the friction dissipation", "[unit]") {
  for (const double mu : {0.0, 0.15}) {
    INFO("mu = " << mu);
    CellOptions o = fast_options();
    o.elements = 32;
    o.contact.friction.mu = mu;
    PeriodicCell cell(4.5, o);
    StepResult prev = cell.equilibrate();
    REQUIRE(prev.converged);
    const double D0 = prev.dissipation;
    const auto& d = cell.dimensions();
    const double V = d.w * d.c * cell.thickness();
    Eigen::Matrix2d a = Eigen::Matrix2d::Identity(), b = a, c = a;
    b(0, 0) = 1.2;
    c(0, 0) = c(1, 1) = 1.2;
    double W = 0.0, leg = 0.0;
    const Eigen::Matrix2d corners[4] = {a, b, c, a};
    for (int l = 0; l < 3; ++l)
      for (int k = 1; k <= 20; ++k) {
        const StepResult s = cell.solve(corners[l] + (corners[l + 1] - corners[l]) * (k / 20.0));
        REQUIRE(s.converged);
        W += 0.5 * V * ((s.P + prev.P).array() * (s.F - prev.F).array()).sum();
        prev = s;
        if (l == 0) leg = W;
      }
    const double D = prev.dissipation - D0;
    INFO("net work " << W << " N mm, dissipation " << D << " N mm, first leg " << leg);
    CHECK(leg > 0.0);
    if (mu == 0.0) {
      CHECK(std::abs(W) < 0.01 * leg);
      CHECK(D == 0.0);
    } else {
      CHECK(W > 0.0);
      CHECK(std::abs(D - W) < 0.10 * W);
    }
  }
}
