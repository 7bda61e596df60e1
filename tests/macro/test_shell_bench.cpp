// Timing of the paper's tensile test (50 x 50 mm, SVK stand-in material), printed by
// scripts/bench/macro_shell.sh; hidden from the normal test run.
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>

#include "knit/macro/constraints.hpp"
#include "knit/macro/newton.hpp"
#include "knit/macro/refinement.hpp"
#include "shell_test_util.hpp"

using namespace knit::macro;
namespace spline = knit::spline;

namespace {
double tensile_seconds(int p, int h, int steps, int threads, int& iterations, double& cpu) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  spline::BSplineBasis b(1, {0, 0, 1, 1});
  Eigen::MatrixXd P(4, 3);
  P << 0, 0, 0, 50, 0, 0, 0, 50, 0, 50, 50, 0;
  const auto surf = refine_patch(spline::SplineSurface(b, b, P), p, h, h);
  ShellModel model(surf, 0.76, std::make_shared<SaintVenantKirchhoff>(10.0, 0.3));
  model.set_threads(threads);
  Constraints c(model.num_dofs());
  const int nu = surf.size_u(), nv = surf.size_v();
  for (int row : {0, 1}) {
    for (int a : edge_row(nu, nv, Edge::kV0, row))
      for (int i = 0; i < 3; ++i) c.fix(3 * a + i);
    for (int a : edge_row(nu, nv, Edge::kV1, row)) {
      c.fix(3 * a);
      c.prescribe(3 * a + 1, 15.0);
      c.fix(3 * a + 2);
    }
  }
  const DofMap dofs(c);
  SolverOptions opt;
  opt.steps = steps;
  iterations = 0;
  const RunReport rep = solve_load_steps(model, dofs, Eigen::VectorXd::Zero(model.num_dofs()), opt,
                                         [&](const StepResult& s) { iterations += s.iterations; });
  REQUIRE(rep.status == RunStatus::kCompleted);
  cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

TEST_CASE("benchmark: tensile patch, p = 5 with 1 element and p = 7 with 4 x 4, 20 steps",
          "[.bench]") {
  for (int threads : {1, 2}) {
    int it1 = 0, it2 = 0;
    double c1 = 0, c2 = 0;
    const double t1 = tensile_seconds(5, 1, 20, threads, it1, c1);
    const double t2 = tensile_seconds(7, 4, 20, threads, it2, c2);
    std::printf(
        "macro_shell threads=%d  p=5 h=1x1 20 steps: wall %.3f s, cpu %.3f s (%d Newton "
        "iterations)  target <= 0.2 s\n",
        threads, t1, c1, it1);
    std::printf(
        "macro_shell threads=%d  p=7 h=4x4 20 steps: wall %.3f s, cpu %.3f s (%d Newton "
        "iterations)  target <= 2 s\n",
        threads, t2, c2, it2);
  }
}
