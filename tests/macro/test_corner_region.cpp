// Corner conditions spread over a region (issue 12, the 3.2.1 mesh study): "radius" selects the
// control points whose Greville point lies within that distance of the corner; the reaction
// with the same radius sums the pad's forces; bad radii are refused with their JSON pointer.
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>

#include "knit/core/errors.hpp"
#include "knit/macro/case.hpp"
#include "knit/macro/patch.hpp"
#include "knit/macro/run.hpp"
#include "verification_case.hpp"

using namespace knit::macro;
using nlohmann::json;

namespace {

/// The corner-driven diagonal test (50 x 50 mm, St. Venant-Kirchhoff) at degree p, h x h.
json diagonal(int p, int h) {
  json j = test::verification_case("diagonal_svk.json");
  j["refinement"] = {{"degree", p}, {"elements", {h, h}}};
  j["solver"]["steps"] = 4;
  return j;
}

std::string error_of(const json& j) {
  try {
    setup_problem(parse_case(j.dump(), "bad.json"));
  } catch (const knit::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("corner region: control points whose Greville point is within the radius", "[unit]") {
  // p = 2, 4 elements on [0, 50]: Greville points at 0, 6.25, 18.75, 31.25, 43.75, 50 mm.
  const Case c = parse_case(diagonal(2, 4).dump(), "diag.json");
  const int nu = c.surface.size_u();
  REQUIRE(nu == 6);
  const Eigen::Vector2d c11(1, 1), c00(0, 0);
  CHECK(corner_region(c.surface, c11, 0.0) == std::vector<int>{35});
  // 6.25 mm along each edge is inside 7 mm, the diagonal neighbour (8.84 mm) is not.
  CHECK(corner_region(c.surface, c11, 7.0) == std::vector<int>{29, 34, 35});
  CHECK(corner_region(c.surface, c11, 9.0) == std::vector<int>{28, 29, 34, 35});
  CHECK(corner_region(c.surface, c00, 7.0) == std::vector<int>{0, 1, 6});
}

TEST_CASE("corner pad: prescribed on the region, reaction summed over it, still symmetric",
          "[unit]") {
  json j = diagonal(3, 2);
  j["boundary_conditions"][2]["radius"] = 15.0;
  j["output"]["reactions"][0]["radius"] = 15.0;
  j["output"]["reactions"][1]["radius"] = 15.0;
  const Case c = parse_case(j.dump(), "pad.json");
  REQUIRE(c.bcs[2].radius == 15.0);
  const RunResult r = run_case(c, {});
  REQUIRE(r.report.status == RunStatus::kCompleted);
  // The same run with the reaction of the corner control point alone: a part of the pad's load.
  json k = j;
  k["output"]["reactions"][0].erase("radius");
  const RunResult r1 = run_case(parse_case(k.dump(), "pad1.json"), {});
  REQUIRE(r1.report.status == RunStatus::kCompleted);
  const StepRow& last = r.rows.back();
  CHECK(last.reactions[0] > 0.0);
  CHECK(last.reactions[0] == Approx(last.reactions[1]).epsilon(1e-8));  // diagonal symmetry
  CHECK(r1.rows.back().reactions[0] < 0.9 * last.reactions[0]);
  // The pad moves as a whole: the corner moves by the prescribed displacement.
  CHECK(last.applied == Approx(10.0));
}

TEST_CASE("corner radius: refused on edges, negative, and on edge reactions", "[unit]") {
  json j = diagonal(2, 1);
  j["boundary_conditions"][0]["radius"] = 3.0;  // the "all" entry
  CHECK(error_of(j).find("/boundary_conditions/0/radius") != std::string::npos);
  j = diagonal(2, 1);
  j["boundary_conditions"][2]["radius"] = -1.0;
  CHECK(error_of(j).find("/boundary_conditions/2/radius") != std::string::npos);
  j = diagonal(2, 1);
  j["output"]["reactions"][0] = {
      {"name", "e"}, {"edge", "u1"}, {"component", "x"}, {"radius", 2.0}};
  CHECK(error_of(j).find("/output/reactions/0/radius") != std::string::npos);
}
