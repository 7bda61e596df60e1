// Speed benchmark (hidden; run by scripts/bench/rod.sh): a 3-D rod with 100 control points,
// 20 load steps. Target (issue #5): <= 0.5 s on one core.
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iostream>

#include "knit/meso/rod/builders.hpp"
#include "knit/meso/rod/solver.hpp"

using namespace knit::meso::rod;
using Eigen::Vector3d;

TEST_CASE("rod benchmark: 3-D helix, 100 control points, 20 load steps", "[.bench]") {
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  auto c = [](double t) -> Vector3d {
    return Vector3d(2 * std::cos(6 * t), 2 * std::sin(6 * t), 8 * t);
  };
  RodSpec s = interpolated_rod(c, 4, 96);  // 100 control points, yarn section
  s.name = "helix";
  const double EI = s.section.C_K()(0);
  s.end.force = Vector3d(0.5, -0.3, 1.0) * EI;
  s.end.moment = Vector3d(0.2, 0.4, -0.3) * EI;
  RodSystem sys;
  sys.add_rod(s);
  Eigen::VectorXd x = sys.initial_state();
  PathOptions po;
  po.steps = 20;
  const PathReport rep = solve_path(sys, x, po);
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  REQUIRE(rep.completed);
  const Vector3d tip = sys.position(0, 1.0, x) - sys.reference_position(0, 1.0);
  std::cout << "rod: 100 control points, 20 steps: " << cpu << " s CPU, " << sec
            << " s wall (target <= 0.5 s on one core); " << rep.total_iterations
            << " Newton iterations, " << rep.cutbacks
            << " cut-backs, |tip displacement| = " << tip.norm() << " mm\n";
  // CPU time: the wall time on a shared machine says little.
  CHECK(cpu < 0.5);
}
