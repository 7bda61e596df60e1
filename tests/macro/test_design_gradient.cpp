// The adjoint gradient of a reaction with respect to control values of the l and alpha fields
// equals central finite differences of the whole solve (issue 13 acceptance, relative 1e-5).
// A load level on a step of the forward run is taken from that step, one off it solved alone.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "knit/core/errors.hpp"
#include "knit/macro/design_gradient.hpp"
#include "knit/macro/design_sensitivity.hpp"
#include "knit/macro/run.hpp"
#include "knit_test_database.hpp"

using namespace knit::macro;

namespace {

std::string gradient_database() {
  return knit::testing::write_knit_test_database("design_gradient_db.h5", {4.5, 5.5, 6.5});
}

/// A 20 x 10 mm patch (p = 2, one element), u0 held, u1 pulled by 2 mm along x (10 %) with
/// the lateral motion free; l and alpha linear across u; `reaction` the output reaction.
std::string tiny_case(
    const std::string& db,
    const std::string& reaction = R"({"name": "fx", "edge": "u1", "component": "x"})") {
  return R"({"geometry": {"degrees": [1, 1], "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
      "control_points": [[0, 0, 0], [20, 0, 0], [0, 10, 0], [20, 10, 0]], "thickness": 0.76},
    "refinement": {"degree": 2, "elements": [1, 1]},
    "material": {"type": "knit", "database": ")" +
         db + R"(",
      "stitch_value": {"degrees": [1, 0], "knots_u": [0, 0, 1, 1], "knots_v": [0, 1],
                       "values": [5.0, 6.0]},
      "knitting_angle": {"degrees": [1, 0], "knots_u": [0, 0, 1, 1], "knots_v": [0, 1],
                         "values": [0.2, 0.5]}},
    "boundary_conditions": [{"all": true, "fix": ["z"]},
      {"edge": "u0", "fix": ["x", "y"]}, {"edge": "u1", "prescribe": {"x": 2.0}}],
    "solver": {"steps": 2, "tolerance": 1e-13, "max_iterations": 40},
    "output": {"vtk": false, "hdf5": false,
               "reactions": [)" +
         reaction + "]}}";
}

}  // namespace

TEST_CASE("design gradient: adjoint reaction gradient equals finite differences of the solve",
          "[case]") {
  // An edge reaction, and a corner's over its pad of 12 mm (3 of the 9 control points besides
  // the corner's; session 31: the design read the corner control point alone, 0.10 N where the
  // run reports 0.29 N, and its gradient was consistent with that wrong value).
  const std::string reaction =
      GENERATE(std::string(R"({"name": "fx", "edge": "u1", "component": "x"})"),
               std::string(R"({"name": "fc", "corner": "u1v1", "component": "x", "radius": 12})"));
  INFO("reaction " << reaction);
  const std::string text = tiny_case(gradient_database(), reaction);
  using F = DesignVariable::Field;
  const std::vector<DesignVariable> vars = {
      {F::kStitchValue, 0}, {F::kStitchValue, 1}, {F::kKnittingAngle, 0}, {F::kKnittingAngle, 1}};
  const std::vector<double> p = design_values(text, "tiny.json", vars);
  for (double lambda : {1.0, 0.5}) {
    INFO("load factor " << lambda);
    const ReactionGradient g = reaction_gradient(text, "tiny.json", vars, 0, lambda);
    REQUIRE(g.status == RunStatus::kCompleted);
    // J(q): the reaction at lambda from the run's load stepping (2 steps: lambda = 0.5, 1).
    auto J = [&](const std::vector<double>& q) {
      const RunResult r = run_case(case_with_design(text, "tiny.json", vars, q), {});
      REQUIRE(r.report.status == RunStatus::kCompleted);
      for (const auto& row : r.rows)
        if (std::abs(row.lambda - lambda) < 1e-12) return row.reactions[0];
      FAIL("no step at the load factor");
      return 0.0;
    };
    CHECK(J(p) == Approx(g.J).epsilon(1e-10));
    for (std::size_t j = 0; j < vars.size(); ++j) {
      const double h = 1e-3;
      std::vector<double> pp = p, pm = p;
      pp[j] += h;
      pm[j] -= h;
      const double fd = (J(pp) - J(pm)) / (2 * h);
      INFO("variable " << j << ": adjoint " << g.dJ(j) << ", finite difference " << fd
                       << ", relative difference " << std::abs(g.dJ(j) - fd) / std::abs(fd));
      CHECK(g.dJ(j) == Approx(fd).epsilon(1e-5));
      CHECK(std::abs(fd) > 1e-6);  // the check means something
    }
  }
}

TEST_CASE("design gradient: a variable outside the field names the field", "[unit]") {
  const std::string text = tiny_case(gradient_database());
  try {
    (void)design_values(text, "tiny.json", {{DesignVariable::Field::kStitchValue, 2}});
    FAIL("no error");
  } catch (const knit::InputError& e) {
    CHECK(e.pointer() == "/material/stitch_value/values");
    // Index 2 of a 2-value field: refused as such (session 31: with the bound test at '>', the
    // index read past the end, the JSON array grew a null and another error gave the same
    // pointer).
    CHECK_THAT(e.what(), Catch::Contains("control value 2 is outside the field's 2 values"));
  }
}

// A load level that falls on a step of the forward run is that step's state, within round-off
// of its load factor; a level off every step is solved on its own (design_sensitivity.hpp,
// docs/design.md "Cost": lambda_k / lambda_max = i / steps). Session 32, a mutation audit: the
// capture's tolerance (1e-9 lambda_max) could be changed without a test failing, since a level
// taken from a nearby step and one solved separately agree to the solver's tolerance. Here
// the solver's tolerance is loose (1e-2), so a state depends on the path that reached it: a
// level taken from the run's step 0.5 and one solved from 0 in its own 2 steps differ by
// ~5e-5, far more than the round-off the comparison allows. Checked at lambda_max = 1 and 1e-3
// (the capture's tolerance is relative to lambda_max) for a level one ulp above the step
// (taken from it) and one a relative 1e-7 above it (solved on its own).
TEST_CASE("design solve: a level on a load step is that step's state, one off it is solved",
          "[case]") {
  std::string text = tiny_case(gradient_database());
  const std::string tight = R"("tolerance": 1e-13)";
  text.replace(text.find(tight), tight.size(), R"("tolerance": 0.01)");
  const Case c = parse_case(text, "tiny.json");
  for (double L : {1.0, 1e-3}) {
    INFO("largest level " << L);
    const double on = std::nextafter(0.5 * L, 1.0), off = 0.5 * L * (1 + 1e-7);
    // The reactions of `knit-macro run` on the case scaled to L (steps 0.5 L, L), and on the
    // cases scaled to `off` and to `on` (each solved from 0 in 2 steps).
    const RunResult run = run_case(scaled_case(c, L), {});
    REQUIRE(run.rows.size() == 2);
    const double step = run.rows[0].reactions[0], end = run.rows[1].reactions[0];
    const double alone_off = run_case(scaled_case(c, off), {}).rows.back().reactions[0];
    const double alone_on = run_case(scaled_case(c, on), {}).rows.back().reactions[0];
    CHECK(std::abs(alone_on - step) > 1e-7 * std::abs(step));  // the paths differ
    CHECK(std::abs(alone_off - step) > 1e-7 * std::abs(step));
    const DesignSolve s(text, "tiny.json", {}, {L, on, off}, false);
    REQUIRE(s.status() == RunStatus::kCompleted);
    const ReactionOutput& ro = s.case_().output.reactions[0];
    CHECK(s.reaction(s.level(L), ro).value == Approx(end).epsilon(1e-12));
    CHECK(s.reaction(s.level(on), ro).value == Approx(step).epsilon(1e-12));
    CHECK(s.reaction(s.level(off), ro).value == Approx(alone_off).epsilon(1e-12));
  }
}
