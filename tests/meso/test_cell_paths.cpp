// Issue 11 on the unit cell: the stress-free reference (the unloaded cell carries no stress;
// the old reference, contact.reference = none, keeps its residual stress), the uniaxial-stress
// path (the lateral stress vanishes at every converged step) and the gradient path (F = I + tH,
// E computed from F) through the sweep's cell runner.
#include <catch2/catch.hpp>
#include <cmath>

#include "knit/core/errors.hpp"
#include "knit/meso/homog/periodic_cell.hpp"
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
