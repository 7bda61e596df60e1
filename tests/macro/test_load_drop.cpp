// Load drops of a displacement-controlled run (knit/macro/load_drop.hpp, session 37).
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "knit/macro/load_drop.hpp"

namespace {

using knit::macro::Case;
using knit::macro::StepRow;

// A tensile case: displacement along y, a jaw reaction in y, a lateral reaction in x.
Case tensile_case() {
  Case c;
  knit::macro::AppliedDisplacement a;
  a.component = 1;
  a.value = 10.0;
  a.gauge_length = 50.0;
  c.output.applied = a;
  knit::macro::ReactionOutput jaw, lateral;
  jaw.name = "jaw", jaw.component = 1;
  lateral.name = "lateral", lateral.component = 0;
  c.output.reactions = {jaw, lateral};
  return c;
}

std::vector<StepRow> rows_of(const std::vector<double>& jaw, const std::vector<double>& lateral) {
  std::vector<StepRow> rows;
  for (size_t k = 0; k < jaw.size(); ++k) {
    StepRow r;
    r.step = int(k) + 1;
    r.lambda = double(k + 1) / double(jaw.size());
    r.applied = 10.0 * r.lambda;
    r.strain = r.applied / 50.0;
    r.reactions = {jaw[k], lateral[k]};
    rows.push_back(r);
  }
  return rows;
}

}  // namespace

TEST_CASE("load drop: a monotone tensile curve has none, a snap is found with its steps") {
  const Case c = tensile_case();
  CHECK(find_load_drops(c, rows_of({1, 2, 4, 8, 17.1}, {0, -1, -2, -1, 0})).empty());
  // The issue-11 snap of the paper's law: 17.1 N to 5.7 N, then a smaller second drop.
  const auto d = find_load_drops(c, rows_of({1, 9, 17.1, 5.7, 6.0, 5.9}, {0, 0, 0, 0, 0, 0}));
  REQUIRE(d.size() == 1);
  CHECK(d[0].reaction == "jaw");
  CHECK(d[0].count == 2);
  CHECK(d[0].from_step == 3);
  CHECK(d[0].to_step == 4);
  CHECK(d[0].from_load == 17.1);
  CHECK(d[0].to_load == 5.7);
  CHECK(d[0].largest == Approx(11.4).epsilon(1e-12));
  CHECK(d[0].max_load == 17.1);
  CHECK(d[0].from_strain == Approx(0.1).epsilon(1e-12));
  CHECK(d[0].to_strain == Approx(10.0 * 4.0 / 6.0 / 50.0).epsilon(1e-12));
  const std::string m = knit::macro::load_drop_message(d[0]);
  CHECK(m.find("'jaw' falls from 17.1 to 5.7 N") != std::string::npos);
  // In the case's force unit (session 49: a case in kN read N).
  const std::string kn = knit::macro::load_drop_message(d[0], 0.01, "kN");
  CHECK_THAT(kn, Catch::Contains("falls from 17.1 to 5.7 kN (by 11.4 kN; ") &&
                     Catch::Contains("% of its largest 17.1 kN)") && !Catch::Contains(" N"));
  CHECK(m.find("between step 3") != std::string::npos);
  CHECK(m.find("; the largest of 2 drops in all, the first between step 3 and step 4") !=
        std::string::npos);
}

TEST_CASE("load drop: the magnitude along the pull counts, lateral reactions do not") {
  const Case c = tensile_case();
  // The fixed jaw's reaction is negative and grows in magnitude: no drop.
  CHECK(find_load_drops(c, rows_of({-1, -2, -4}, {0, 0, 0})).empty());
  // Negative and shrinking: a drop.
  CHECK(find_load_drops(c, rows_of({-1, -4, -2}, {0, 0, 0})).size() == 1);
  // A change of sign is judged along the load's direction (the sign of its largest value), not
  // by magnitude (session 39's walkthrough: 0.146 -> -0.530 -> -0.508 -> 0.148 N named the
  // last step a fall "from -0.5077 to 0.1477" and missed nothing else; by magnitude a sign
  // flip through a smaller value hides a drop).
  {
    const auto d = find_load_drops(c, rows_of({0.146, -0.530, -0.508, 0.148}, {0, 0, 0, 0}));
    REQUIRE(d.size() == 1);
    CHECK(d[0].direction == -1.0);
    CHECK(d[0].count == 2);  // -0.530 -> -0.508 and -0.508 -> 0.148 fall along -x
    CHECK(d[0].from_load == -0.508);
    CHECK(d[0].to_load == 0.148);
    CHECK(d[0].largest == Approx(0.656).epsilon(1e-12));
    const std::string m = knit::macro::load_drop_message(d[0]);
    CHECK(m.find("falls from -0.508 to 0.148 N (by 0.656 N along its largest load, -0.53 N; ") !=
          std::string::npos);
    // The largest is named as such, and the first drop (-0.530 -> -0.508) is located too.
    CHECK(d[0].first_from_step == d[0].from_step - 1);
    CHECK(m.find("the largest of 2 drops in all, the first between step " +
                 std::to_string(d[0].from_step - 1) + " and step " +
                 std::to_string(d[0].from_step)) != std::string::npos);
    // A positive load through zero: 2 -> -1 is a drop of 3 although |F| falls by 1 only.
    const auto e = find_load_drops(c, rows_of({1, 2, -1, 3}, {0, 0, 0, 0}));
    REQUIRE(e.size() == 1);
    CHECK(e[0].largest == Approx(3.0).epsilon(1e-12));
    CHECK(e[0].count == 1);
  }
  // The lateral reaction falls (Poisson contraction relaxing): not a load drop.
  CHECK(find_load_drops(c, rows_of({1, 2, 3}, {5, 1, 0})).empty());
  // Without an applied displacement (force control) nothing is judged.
  Case force = tensile_case();
  force.output.applied.reset();
  CHECK(find_load_drops(force, rows_of({1, 17.1, 5.7}, {0, 0, 0})).empty());
}

TEST_CASE("load drop: the threshold is relative to the largest load") {
  const Case c = tensile_case();
  const double tol = knit::macro::kLoadDropTolerance;
  // A decrement of half the threshold is round-off of the Newton solve, not a drop ...
  CHECK(find_load_drops(c, rows_of({100, 100 - 0.5 * tol * 100, 101}, {0, 0, 0})).empty());
  // ... twice the threshold is one.
  CHECK(find_load_drops(c, rows_of({100, 100 - 2.0 * tol * 101, 101}, {0, 0, 0})).size() == 1);
  // Loads that are zero throughout have no drop (no division by the largest load).
  CHECK(find_load_drops(c, rows_of({0, 0, 0}, {0, 0, 0})).empty());
  // Round-off of a reaction that is zero (a free edge; session 38's red team): below the
  // solve's absolute tolerance (1e-10 N) nothing is judged, above it the relative rule holds.
  CHECK(c.solver.absolute_tolerance == 1e-10);
  CHECK(find_load_drops(c, rows_of({-1.776e-15, 4.441e-16, 0}, {0, 0, 0})).empty());
  CHECK(find_load_drops(c, rows_of({1e-9, 2e-9, 0.5e-9}, {0, 0, 0})).size() == 1);
}
