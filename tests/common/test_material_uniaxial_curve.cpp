// The law's own uniaxial response beside the cell's (knit/material/uniaxial_curve.hpp): which
// states a comparison keeps and where the law departs most.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "knit/material/uniaxial_curve.hpp"

using namespace knit::material;

TEST_CASE("uniaxial curve: the largest departure over the kept states", "[unit]") {
  // Cell stresses 0.05, 0.5, 1, 2, 4 MPa; the law 3, 0.6, 1.5, 1.8, 4.4 (ratios 60, 1.2, 1.5,
  // 0.9, 1.1). The first state is below 10 % of the largest (0.4 MPa) and is not compared.
  const UniaxialCurve c{
      {0.05, 0.1, 0.2, 0.3, 0.4}, {0.05, 0.5, 1.0, 2.0, 4.0}, {3.0, 0.6, 1.5, 1.8, 4.4}};
  const double inf = std::numeric_limits<double>::infinity();
  UniaxialDeviation d = uniaxial_deviation(c, inf);
  CHECK(d.states == 4);
  CHECK(d.deviation == Approx(0.5));
  CHECK(d.ratio == Approx(1.5));
  CHECK(d.strain == 0.2);
  // Only the states up to a strain: at most 0.15 keeps the second (ratio 1.2).
  d = uniaxial_deviation(c, 0.15);
  CHECK(d.states == 1);
  CHECK(d.deviation == Approx(0.2));
  CHECK(d.strain == 0.1);
  // Below every kept state: nothing compared.
  CHECK(uniaxial_deviation(c, 0.08).states == 0);
  CHECK(uniaxial_deviation(c, 0.08).deviation == 0.0);
  // A share of 0 keeps the slack start, whose ratio (60) then is the largest.
  d = uniaxial_deviation(c, inf, 0.0);
  CHECK(d.states == 5);
  CHECK(d.ratio == Approx(60.0));
  // The share is of the path's largest stress over every state, not over those kept by the
  // strain: up to 0.25, the 0.5 MPa state is kept (>= 0.4), the 0.05 MPa one is not.
  CHECK(uniaxial_deviation(c, 0.25).states == 2);
}

TEST_CASE("uniaxial curve: a state without the law's answer is the largest departure", "[unit]") {
  const UniaxialCurve c{{0.1, 0.2, 0.3}, {1.0, 2.0, 3.0}, {1.1, std::nan(""), 2.4}};
  const UniaxialDeviation d = uniaxial_deviation(c, 1.0);
  CHECK(d.states == 3);
  CHECK(std::isinf(d.deviation));
  CHECK(std::isnan(d.ratio));
  CHECK(d.strain == 0.2);
  // An empty curve and one whose cell stress is zero everywhere compare nothing.
  CHECK(uniaxial_deviation(UniaxialCurve{}, 1.0).states == 0);
  CHECK(uniaxial_deviation(UniaxialCurve{{0.1}, {0.0}, {1.0}}, 1.0).states == 0);
}
