// Issue 11 on the unit cell: the stress-free reference (the unloaded cell carries no stress;
// the old reference, contact.reference = none, keeps its residual stress), the uniaxial-stress
// path (the lateral stress vanishes at every converged step) and the gradient path (F = I + tH,
// E computed from F) through the sweep's cell runner.
#include <catch2/catch.hpp>
#include <cmath>
#include <iterator>
#include <utility>
#include <vector>

#include "knit/core/errors.hpp"
#include "knit/meso/homog/periodic_cell.hpp"
#include "knit/meso/homog/substeps.hpp"
#include "knit/meso/homog/uniaxial.hpp"
#include "knit/meso/sweep/sweep.hpp"

using namespace knit::meso;

namespace {
homog::CellOptions fast_options() {
  homog::CellOptions o;
  o.elements = 16;
  return o;
}
/// Tolerance of "zero stress" in the stress-free cell [MPa]: the residual of the converged
/// state is exactly zero there (nothing moves), round-off only.
constexpr double kZeroStress = 1e-10;
}  // namespace

TEST_CASE("stress-free reference cell: no stress unloaded, the old reference keeps its residual",
          "[unit]") {
  for (double l : {4.5, 6.5}) {
    INFO("l = " << l);
    homog::PeriodicCell cell(l, fast_options());
    CHECK(cell.contacts().num_reference_pairs() > 0);  // the closed-form loops do overlap
    const homog::StepResult r0 = cell.equilibrate();
    REQUIRE(r0.converged);
    INFO("P = \n" << r0.P);
    CHECK(r0.P.cwiseAbs().maxCoeff() < kZeroStress);
    CHECK(r0.S.cwiseAbs().maxCoeff() < kZeroStress);
    const homog::StepResult r1 = cell.solve(Eigen::Matrix2d::Identity());  // a step of 0 strain
    REQUIRE(r1.converged);
    CHECK(r1.S.cwiseAbs().maxCoeff() < kZeroStress);
    // Small strain: stress of the loaded sign, back to zero when unloaded elastically.
    const homog::StepResult r2 = cell.solve(Eigen::Vector2d(1.02, 1.0).asDiagonal());
    REQUIRE(r2.converged);
    CHECK(r2.S(0, 0) > 0);
  }
  homog::CellOptions old = fast_options();
  old.contact.reference = contact::ContactOptions::Reference::kNone;
  old.geometry.gamma_over_w = 0.25 / 1.26;  // the loop of the old database (before issue 12)
  homog::PeriodicCell cell(4.5, old);
  CHECK(cell.contacts().num_reference_pairs() == 0);
  const homog::StepResult r0 = cell.equilibrate();
  REQUIRE(r0.converged);
  // docs/unit-cell.md: 4.5 mm, the old reference: P11 ~ 0.25, P22 ~ 0.11 MPa
  CHECK(r0.P(0, 0) > 0.15);
  CHECK(r0.P(1, 1) > 0.05);
}

TEST_CASE("cell step: max_cutbacks counts the halvings in a row, not all of a step's", "[unit]") {
  // A course stretch of 0.8 in one step from the unloaded cell needs cut-backs; each halving
  // that converges resets the count (homog/periodic_cell.hpp), so a step whose failures are
  // each followed by a success passes with max_cutbacks 1 however many cut-backs it took in all
  // (session 32, a mutation audit: '>= max_cutbacks' passed every test).
  homog::CellOptions co = fast_options();
  const Eigen::Matrix2d F = Eigen::Vector2d(1.8, 1.0).asDiagonal();
  auto step = [&](int max_cutbacks) {
    co.max_cutbacks = max_cutbacks;
    homog::PeriodicCell cell(4.5, co);
    REQUIRE(cell.equilibrate().converged);
    return cell.solve(F);
  };
  const homog::StepResult r = step(1);
  INFO(r.message);
  CHECK(r.converged);
  CHECK(r.cutbacks >= 2);
  CHECK(r.F.isApprox(F));
  // No cut-back allowed: the first failure ends the step.
  const homog::StepResult none = step(0);
  CHECK_FALSE(none.converged);
  CHECK(none.cutbacks == 1);
  INFO(none.message);
  CHECK(none.message.find("1 failed sub-steps in a row") != std::string::npos);
  CHECK(none.message.find("/solver/max_cutbacks = 0") != std::string::npos);
  CHECK(none.message.find("last failure: ") != std::string::npos);
}

TEST_CASE("sub-step schedule: grows back after a hard stretch, stops at max_substeps", "[unit]") {
  // A stand-in for the cell: sub-steps that end inside (0.1, 0.1 + 1e-3] converge only when
  // shorter than 1e-3 (one hard stretch); everything else converges. Before session 58 the
  // halved sub-step never grew again and the rest of the step went at ~1/1024: ~900 sub-steps
  // (a held-out twin path at 6.5 mm ran > 16 min in one cell step).
  double lam = 0;
  auto attempt = [&](double next) {
    const bool ok = !(next > 0.1 && next <= 0.1 + 1e-3 && next - lam > 1e-3) &&
                    !(lam < 0.1 && next > 0.1 + 1e-3);
    if (ok) lam = next;
    return ok;
  };
  homog::SubstepLimits lim;
  lim.max_cutbacks = 30;
  const homog::SubstepOutcome m = homog::march_substeps(lim, attempt);
  INFO(m.substeps << " sub-steps, " << m.cutbacks << " cut-backs");
  CHECK(m.stop == homog::SubstepOutcome::Stop::kDone);
  CHECK(m.lam == 1.0);
  CHECK(m.cutbacks >= 10);  // 2^-10 < 1e-3
  CHECK(m.substeps <= 80);  // without the growth: > 900
  // The cap: one sub-step fewer ends the step where it stands, not converged.
  lam = 0;
  lim.max_substeps = m.substeps - 1;
  const homog::SubstepOutcome c = homog::march_substeps(lim, attempt);
  CHECK(c.stop == homog::SubstepOutcome::Stop::kMaxSubsteps);
  CHECK(c.substeps == m.substeps - 1);
  CHECK(c.lam < 1.0);
  // A failure after the sub-step has grown past the rest of the step halves the sub-step
  // tried: halving a grown `inc` instead retried the clipped last sub-step (0.875 -> 1 twice,
  // session 58's review). Attempts fail or converge in a given order (then converge).
  {
    const bool order[] = {false, false, true, false, false, true, true, true, true, true, false};
    std::vector<std::pair<double, double>> tries;
    double at = 0;
    auto scripted = [&](double next) {
      const std::size_t k = tries.size();
      tries.emplace_back(at, next);
      const bool ok = k >= std::size(order) || order[k];
      if (ok) at = next;
      return ok;
    };
    const homog::SubstepOutcome g = homog::march_substeps(homog::SubstepLimits{}, scripted);
    CHECK(g.stop == homog::SubstepOutcome::Stop::kDone);
    REQUIRE(tries.size() == 13);
    CHECK(tries[10] == std::make_pair(0.875, 1.0));  // grown to 0.25, clipped to 0.125: fails
    CHECK(tries[11] == std::make_pair(0.875, 0.9375));
    for (std::size_t k = 1; k < tries.size(); ++k) CHECK(tries[k] != tries[k - 1]);
  }
  // Halvings in a row past max_cutbacks end it; a sub-step below min_substep too.
  lam = 0;
  lim = {};
  lim.max_cutbacks = 3;
  CHECK(homog::march_substeps(lim, attempt).stop == homog::SubstepOutcome::Stop::kCutbacks);
  lam = 0;
  lim.max_cutbacks = 30;
  lim.min_substep = 1e-2;
  CHECK(homog::march_substeps(lim, attempt).stop == homog::SubstepOutcome::Stop::kMinSubstep);
}

TEST_CASE("cell step: max_substeps ends a step that needs more, and says so", "[unit]") {
  homog::CellOptions co = fast_options();
  const Eigen::Matrix2d F = Eigen::Vector2d(1.8, 1.0).asDiagonal();
  auto step = [&](int max_substeps) {
    co.max_substeps = max_substeps;
    homog::PeriodicCell cell(4.5, co);
    REQUIRE(cell.equilibrate().converged);
    return cell.solve(F);
  };
  const homog::StepResult r = step(homog::CellOptions{}.max_substeps);
  INFO(r.message << "; " << r.cutbacks << " cut-backs, " << r.substeps << " sub-steps");
  REQUIRE(r.converged);
  REQUIRE(r.substeps >= 3);
  const homog::StepResult cut = step(r.substeps - 1);
  CHECK_FALSE(cut.converged);
  CHECK(cut.substeps == r.substeps - 1);
  CHECK(cut.message.find("max_substeps") != std::string::npos);
}

TEST_CASE("uniaxial path: the lateral stress vanishes at every converged step", "[unit]") {
  homog::CellOptions co = fast_options();
  for (int axis : {0, 1}) {
    INFO("axis " << axis);
    homog::PeriodicCell cell(4.5, co);
    REQUIRE(cell.equilibrate().converged);
    homog::UniaxialState st;
    const homog::UniaxialOptions uo;
    double l_prev = 1.0;
    for (int k = 1; k <= 3; ++k) {
      const double la = 1.0 + 0.05 * k;
      const homog::UniaxialStep s = homog::solve_uniaxial_step(cell, axis, la, st, uo);
      INFO("step " << k << ": " << s.step.message);
      REQUIRE(s.step.converged);
      const int b = 1 - axis;
      CHECK(std::abs(s.step.S(b, b)) <= uo.tol);  // tolerance 1e-4 MPa (UniaxialOptions::tol)
      CHECK(s.step.F(axis, axis) == la);
      CHECK(s.step.S(axis, axis) > 0);
      CHECK(s.step.F(b, b) < l_prev);  // lateral contraction
      l_prev = s.step.F(b, b);
      CHECK(s.solves <= uo.max_solves);
    }
  }
}

TEST_CASE("sweep cell runner: uniaxial and gradient paths record F, E, S consistently", "[unit]") {
  sweep::SweepInput in = sweep::parse_sweep_input(
      R"({"loop_lengths": [4.5], "cell": {"analysis": {"elements": 16}}, "fit": false,
          "load_paths": [{"kind": "uniaxial", "axis": "wale", "E": 0.1, "steps": 2},
                         {"kind": "gradient", "H": [[0.05, 0.2], [0.0, -0.03]], "steps": 3,
                          "set": "holdout"}]})",
      "paths.json");
  const sweep::PathRunner run = sweep::cell_runner(in);
  const auto uni = run(4.5, in.paths[0]);
  REQUIRE(uni.raw.status == std::vector<int>{0, 0});
  for (int k = 0; k < 2; ++k) {
    CHECK(std::abs(uni.raw.S(k, 0)) <= homog::UniaxialOptions{}.tol);  // lateral S11
    const double F22 = 1.0 + (k + 1) / 2.0 * (std::sqrt(1.2) - 1.0);   // prescribed stretch
    CHECK(uni.raw.F(k, 3) == Approx(F22).epsilon(1e-14));
    CHECK(uni.raw.E(k, 1) == Approx(0.5 * (F22 * F22 - 1.0)).epsilon(1e-12));
    CHECK(uni.raw.F(k, 0) < 1.0);  // found lateral stretch: contraction
    CHECK(uni.raw.F(k, 1) == 0.0);
  }
  CHECK(uni.raw.E(1, 1) == Approx(0.1).epsilon(1e-12));  // the end strain is exact
  const auto grad = run(4.5, in.paths[1]);
  REQUIRE(grad.raw.status == std::vector<int>{0, 0, 0});
  for (int k = 0; k < 3; ++k) {
    const double t = (k + 1) / 3.0;
    const Eigen::Matrix2d F = Eigen::Matrix2d::Identity() + t * in.paths[1].H;
    CHECK(grad.raw.F(k, 0) == Approx(F(0, 0)).epsilon(1e-14));
    CHECK(grad.raw.F(k, 1) == Approx(F(0, 1)).epsilon(1e-14));
    CHECK(grad.raw.F(k, 2) == 0.0);
    CHECK(grad.raw.F(k, 3) == Approx(F(1, 1)).epsilon(1e-14));
    const Eigen::Matrix2d E = knit::material::green_lagrange(F);
    CHECK(grad.raw.E(k, 0) == Approx(E(0, 0)).epsilon(1e-12));
    CHECK(grad.raw.E(k, 1) == Approx(E(1, 1)).epsilon(1e-12));
    CHECK(grad.raw.E(k, 2) == Approx(E(0, 1)).epsilon(1e-12));
  }
  CHECK(grad.raw.S(2, 2) > 0);  // positive shear
}

TEST_CASE("sweep cell runner: raw P is the cell's, raw S is sym(F^-1 P), the residual is S(I)",
          "[unit]") {
  // What the database stores against an independent run of the same cell (session 32, a
  // mutation audit: the cell's unsymmetrized S, the P row with P12 and P21 swapped, or the
  // residual's S22 taken from S11 passed every test). The old reference (contact.reference
  // none) and the loop of before issue 12 (gamma = 0.198 w), so that the unloaded cell carries
  // a residual stress with S11 != S22 (about 0.27 and 0.11 MPa), and a gradient path with shear.
  sweep::SweepInput in = sweep::parse_sweep_input(
      R"({"loop_lengths": [4.5], "fit": false,
          "cell": {"analysis": {"elements": 16}, "contact": {"reference": "none"},
                   "loop": {"gamma_over_w": 0.198}},
          "load_paths": [{"kind": "gradient", "H": [[0.05, 0.3], [0.0, 0.04]], "steps": 3}]})",
      "raw.json");
  const sweep::PathOutcome out = sweep::cell_runner(in)(4.5, in.paths[0]);
  REQUIRE(out.raw.status == std::vector<int>{0, 0, 0});
  homog::CellOptions co = fast_options();
  co.contact.reference = contact::ContactOptions::Reference::kNone;
  co.geometry.gamma_over_w = 0.198;
  homog::PeriodicCell cell(4.5, co);
  const homog::StepResult eq = cell.equilibrate();
  REQUIRE(eq.converged);
  // The residual: the equilibrated cell's (S11, S22, S12), S12 symmetrized; S11 != S22 here.
  CHECK(out.residual(0) == Approx(eq.S(0, 0)).epsilon(1e-12));
  CHECK(out.residual(1) == Approx(eq.S(1, 1)).epsilon(1e-12));
  CHECK(out.residual(2) == Approx(0.5 * (eq.S(0, 1) + eq.S(1, 0))).margin(1e-12));
  CHECK(std::abs(eq.S(0, 0) - eq.S(1, 1)) > 0.05);
  for (int k = 0; k < 3; ++k) {
    INFO("step " << k + 1);
    const homog::StepResult s =
        cell.solve(Eigen::Matrix2d::Identity() + (k + 1) / 3.0 * in.paths[0].H);
    REQUIRE(s.converged);
    // P row (P11, P12, P21, P22) as the cell gives it; the shear makes P12 and P21 differ.
    CHECK(out.raw.P(k, 0) == Approx(s.P(0, 0)).epsilon(1e-10));
    CHECK(out.raw.P(k, 1) == Approx(s.P(0, 1)).epsilon(1e-10));
    CHECK(out.raw.P(k, 2) == Approx(s.P(1, 0)).epsilon(1e-10));
    CHECK(out.raw.P(k, 3) == Approx(s.P(1, 1)).epsilon(1e-10));
    CHECK(std::abs(s.P(0, 1) - s.P(1, 0)) > 0.01);
    // S = sym(F^-1 P) of the stored rows, by hand.
    Eigen::Matrix2d F, P;
    F << out.raw.F(k, 0), out.raw.F(k, 1), out.raw.F(k, 2), out.raw.F(k, 3);
    P << out.raw.P(k, 0), out.raw.P(k, 1), out.raw.P(k, 2), out.raw.P(k, 3);
    const Eigen::Matrix2d A = F.inverse() * P, S = 0.5 * (A + A.transpose());
    CHECK(out.raw.S(k, 0) == Approx(S(0, 0)).epsilon(1e-12));
    CHECK(out.raw.S(k, 1) == Approx(S(1, 1)).epsilon(1e-12));
    CHECK(out.raw.S(k, 2) == Approx(S(0, 1)).epsilon(1e-12));
    // F^-1 P is not symmetric in the cell's discretization: the symmetrization matters.
    CHECK(std::abs(A(0, 1) - A(1, 0)) > 1e-4 * std::abs(A(0, 1)));
  }
}

TEST_CASE("sweep cell runner: a loop length the cell cannot be built for is an input error",
          "[unit]") {
  // Before: every case of a 1 mm loop failed with the same geometry error, one by one, and the
  // database was written with a loop length holding no state. Now the runner refuses the input
  // before any case runs, naming the loop length's JSON pointer.
  sweep::SweepInput in = sweep::parse_sweep_input(
      R"({"loop_lengths": [4.5, 5.0, 5.5, 6.0, 6.5], "cell": {"analysis": {"elements": 16}}})",
      "short.json");
  CHECK_NOTHROW(sweep::cell_runner(in));  // the paper's range builds
  in.loop_lengths = {4.5, 1.0};
  CHECK_THROWS_AS(sweep::cell_runner(in), knit::InputError);
  CHECK_THROWS_WITH(sweep::cell_runner(in),
                    Catch::Contains("short.json: /loop_lengths/1: the unit cell of loop length 1 "
                                    "mm (yarn diameter") &&
                        Catch::Contains("could not match the loop length"));
}

// Session 34 (the rod/contact/cell audit): without the Illinois halving of the regula falsi
// the lateral-stress iteration of a course stretch to 1.3 in 5 steps (5, 8, 8, 7 and 3 cell
// solves) ran out of solves at its second step (16), and no test saw it.
TEST_CASE("uniaxial path: a course stretch to 1.3 in 5 steps needs at most 10 solves a step",
          "[unit]") {
  homog::PeriodicCell cell(4.5, fast_options());
  REQUIRE(cell.equilibrate().converged);
  homog::UniaxialState st;
  const homog::UniaxialOptions uo;
  int total = 0;
  for (int k = 1; k <= 5; ++k) {
    const homog::UniaxialStep s = homog::solve_uniaxial_step(cell, 0, 1.0 + 0.06 * k, st, uo);
    INFO("step " << k << ": " << s.solves << " solves, " << s.step.message);
    REQUIRE(s.step.converged);
    CHECK(s.solves <= 10);
    CHECK(std::abs(s.lateral_stress) <= uo.tol);
    total += s.solves;
  }
  CHECK(total <= 35);
}
