// Constraints and the DOF map: ties join DOFs into groups, a group with a prescribed member
// takes its value, and a group whose members are prescribed different values is an error
// that names a DOF (session 31: a mutation that disabled that check survived every test).
#include <catch2/catch.hpp>

#include "knit/macro/constraints.hpp"

using namespace knit::macro;

TEST_CASE("DOF map: tied groups share one unknown or one prescribed value", "[unit]") {
  Constraints c(9);
  c.tie(0, 3);
  c.tie(3, 6);  // 0, 3, 6: one free group
  c.tie(1, 4);
  c.prescribe(4, 0.25);  // 1, 4: prescribed through the tie
  c.fix(2);
  const DofMap d(c);
  CHECK(d.num_free() == 4);  // {0, 3, 6}, 5, 7, 8
  CHECK(d.free_index(0) == d.free_index(3));
  CHECK(d.free_index(3) == d.free_index(6));
  CHECK(d.free_index(0) >= 0);
  CHECK(d.constrained(1));
  CHECK(d.value(1) == 0.25);
  CHECK(d.value(4) == 0.25);
  CHECK(d.constrained(2));
  CHECK(d.value(2) == 0.0);
  // The same value on two members of a group is no conflict.
  Constraints same(6);
  same.tie(0, 3);
  same.prescribe(0, 1.0);
  same.prescribe(3, 1.0);
  CHECK_NOTHROW(DofMap(same));
}

TEST_CASE("DOF map: a tied group prescribed two values is refused, naming a DOF", "[unit]") {
  Constraints c(6);
  c.tie(3, 0);
  c.prescribe(0, 1.0);
  c.prescribe(3, 2.0);
  CHECK_THROWS_AS(DofMap(c), ConstraintConflict);
  CHECK_THROWS_WITH(DofMap(c), Catch::Contains("is tied to a DOF with a different prescribed "
                                               "value"));
}
