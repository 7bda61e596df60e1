// Timing of knit tensile cases (hidden: "[.bench]"; run by scripts/bench/database.sh).
// Targets (issue #4): p = 5, one element, 20 steps <= 1 s; p = 7, 4 x 4 elements <= 5 s.
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>

#include "../common/test_material_util.hpp"
#include "knit/macro/case.hpp"
#include "knit/macro/run.hpp"
#include "knit/material/database.hpp"

using namespace knit::macro;
using namespace knit::material;

TEST_CASE("bench: knit tensile cases", "[.bench]") {
  const auto dir = std::filesystem::path(KNIT_BINARY_DIR) / "test_tmp";
  std::filesystem::create_directories(dir);
  const auto db = (dir / "bench_knit_db.h5").string();
  Database d;
  d.provenance = current_provenance();
  for (double l : {4.5, 5.0, 5.5, 6.0, 6.5}) {
    LoopLengthEntry e;
    e.loop_length = l;
    e.surface = testing::make_test_surface(std::pow(4.5 / l, 2));
    d.entries.push_back(e);
  }
  write_database(db, d);
  for (auto [p, n] : {std::pair{5, 1}, std::pair{7, 4}}) {
    std::ostringstream cs;
    cs << R"({"geometry": {"degrees": [1, 1], "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
      "control_points": [[0, 0, 0], [50, 0, 0], [0, 50, 0], [50, 50, 0]], "thickness": 0.76},
      "refinement": {"degree": )"
       << p << R"(, "elements": [)" << n << ", " << n << R"(]},
      "material": {"type": "knit", "database": ")"
       << db << R"(",
        "stitch_value": {"degrees": [1, 0], "knots_u": [0, 0, 1, 1], "knots_v": [0, 1], "values": [4.5, 6.5]},
        "knitting_angle": 0.0},
      "boundary_conditions": [
        {"edge": "v0", "fix": ["x", "y", "z"], "clamp": true},
        {"edge": "v1", "fix": ["x", "z"], "prescribe": {"y": 15.0}, "clamp": true}],
      "solver": {"steps": 20, "tolerance": 1e-9, "max_iterations": 25},
      "output": {"vtk": false, "hdf5": false,
                 "reactions": [{"name": "jaw", "edge": "v1", "component": "y", "rows": 2}]}})";
    const Case c = parse_case(cs.str(), "bench.json");
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    const RunResult r = run_case(c, {});
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    std::printf(
        "knit tensile p = %d, %d x %d elements, 20 steps: %.2f s wall, %.2f s CPU (target <= %s), "
        "status %s, force %.3f N\n",
        p, n, n, s, cpu, p == 5 ? "1 s" : "5 s",
        r.report.status == RunStatus::kCompleted ? "completed" : r.report.message.c_str(),
        r.rows.empty() ? 0.0 : r.rows.back().reactions[0]);
    std::printf("%s\n", c.material->report().c_str());
  }
}
