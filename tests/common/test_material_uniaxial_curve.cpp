// The law's own uniaxial response beside the cell's (knit/material/uniaxial_curve.hpp): which
// states a comparison keeps and where the law departs most.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "knit/material/uniaxial_curve.hpp"

using namespace knit::material;

TEST_CASE("uniaxial curve: the largest departure over the kept states", "[unit]") {
  // Cell stresses 0.05, 0.5, 1, 2, 4 MPa; the law 3, 0.6, 1.5, 1.8, 4.4 (ratios 60, 1.2, 1.5,
  // 0.9, 1.1). Over the whole curve the first state is below 10 % of the largest (0.4 MPa) and
  // is not compared.
  const UniaxialCurve c{
      {0.05, 0.1, 0.2, 0.3, 0.4}, {0.05, 0.5, 1.0, 2.0, 4.0}, {3.0, 0.6, 1.5, 1.8, 4.4}};
  const double inf = std::numeric_limits<double>::infinity();
  UniaxialDeviation d = uniaxial_deviation(c, inf);
  CHECK(d.states == 4);
  CHECK(d.deviation == Approx(0.5));
  CHECK(d.ratio == Approx(1.5));
  CHECK(d.strain == 0.2);
  // The share is of the largest cell stress up to the strain (session 41's review): up to 0.1
  // that is 0.5 MPa, so the first state (0.05 >= 0.05) is compared too, and its ratio 60 is
  // the largest.
  d = uniaxial_deviation(c, 0.1);
  CHECK(d.states == 2);
  CHECK(d.ratio == Approx(60.0));
  CHECK(d.strain == 0.05);
  // Between two states the curve interpolated there is one more state: at 0.25, cell 1.5 and
  // law 1.65 (ratio 1.1); the share 0.15 MPa leaves the first state out. The largest
  // departure stays the 0.2 state's.
  d = uniaxial_deviation(c, 0.25);
  CHECK(d.states == 3);
  CHECK(d.ratio == Approx(1.5));
  // Interpolated at 0.15 (cell 0.75, law 1.05: 1.4), with the 0.1 state (1.2) and the first
  // (0.05 < 0.075, left out).
  d = uniaxial_deviation(c, 0.15);
  CHECK(d.states == 2);
  CHECK(d.ratio == Approx(1.4));
  CHECK(d.strain == 0.15);
  // Below every state: nothing compared.
  CHECK(uniaxial_deviation(c, 0.04).states == 0);
  CHECK(uniaxial_deviation(c, 0.04).deviation == 0.0);
  // A share of 0 keeps the slack start on the whole curve too.
  d = uniaxial_deviation(c, inf, 0.0);
  CHECK(d.states == 5);
  CHECK(d.ratio == Approx(60.0));
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
