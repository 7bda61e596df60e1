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

TEST_CASE("DOF map: a tied group prescribed two values is refused, naming both DOFs", "[unit]") {
  Constraints c(6);
  c.tie(3, 0);
  c.prescribe(0, 1.0);
  c.prescribe(3, 2.0);
  CHECK_THROWS_AS(DofMap(c), ConstraintConflict);
  CHECK_THROWS_WITH(DofMap(c), Catch::Equals("DOF 3 (control point 1, component x), prescribed "
                                             "2, is tied to DOF 0 (control point 0, component "
                                             "x), prescribed 1: a tied group takes one value"));
  try {
    DofMap m(c);
  } catch (const ConstraintConflict& e) {
    CHECK(e.dof() == 3);
    CHECK(e.other() == 0);  // the member that gave the group its value (session 40)
  }
}

// Session 34 (the design audit's mutant 101): one DOF prescribed two different values is
// refused as soon as the second comes (Constraints::prescribe), the same value twice is not;
// with that check off the second value silently replaced the first.
TEST_CASE("constraints: one DOF prescribed two different values is refused", "[unit]") {
  Constraints c(3);
  c.prescribe(0, 1.0);
  CHECK_NOTHROW(c.prescribe(0, 1.0));
  CHECK_THROWS_AS(c.prescribe(0, 2.0), ConstraintConflict);
  CHECK_THROWS_WITH(c.prescribe(0, 2.0), Catch::Contains("DOF 0 (control point 0, component x) "
                                                         "is prescribed twice"));
}

// Session 34 (the design audit's mutant 107): ties count as supports in the rigid-mode check
// (a tie u_a = u_b removes the modes that move a and b differently; a clamped edge is such
// ties). Two fixed points on the x axis leave the rotation about it, which moves each point
// along z by its y; tying the z of two free points at y = 1 and y = 2 removes it. Without the
// tie rows the check reported that rotation although the ties hold it.
TEST_CASE("DofMap: a tie between two free DOFs removes the rigid mode that separates them",
          "[unit]") {
  Eigen::MatrixXd X(4, 3);
  X << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 2, 0;
  Constraints c(12);
  for (int d = 0; d < 6; ++d) c.fix(d);  // points 0 and 1, all components
  {
    const auto mode = DofMap(c).unconstrained_rigid_mode(X);
    REQUIRE(mode.has_value());
    CHECK_THAT(*mode, Catch::StartsWith("rotation about the direction (1, 0, 0)") ||
                          Catch::StartsWith("rotation about the direction (-1, 0, 0)"));
  }
  c.tie(3 * 2 + 2, 3 * 3 + 2);  // z of points 2 and 3
  CHECK_FALSE(DofMap(c).unconstrained_rigid_mode(X).has_value());
}
