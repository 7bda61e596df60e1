// Test helper: a valid energy-based law without the fitter (default directions, random
// nonnegative coefficients over 4.5-6.5 mm, cubic in l). Shared by the common and macro tests.
#pragma once

#include <random>

#include "knit/material/energy_law.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::material::testing {

inline EnergyLawData make_test_energy_law(unsigned seed = 7, double floor = 0.02) {
  EnergyLawData d;
  d.directions = default_ridge_directions();
  d.s_degree = 3;
  d.s_spans = 8;
  const int G = d.functions();
  d.s_range.resize(G, 2);
  for (int g = 0; g < G; ++g) d.s_range.row(g) << -0.3 - 0.01 * g, 0.45 + 0.01 * g;
  d.l_degree = 3;
  d.l_knots = spline::uniform_knots(3, 1, 4.5, 6.5);
  d.l_min = 4.5;
  d.l_max = 6.5;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  d.coefficients.resize(G, d.n_s() * d.n_l());
  for (int g = 0; g < G; ++g)
    for (int c = 0; c < d.coefficients.cols(); ++c)
      d.coefficients(g, c) = u(gen) < 0.2 ? 0.0 : 2.0 * u(gen);  // some exact zeros
  d.floor = floor;
  d.box_min << -0.3, -0.3, -0.5;
  d.box_max << 0.45, 0.45, 0.5;
  return d;
}

}  // namespace knit::material::testing
