// Test helper: a valid energy-based law without the fitter (default directions, random
// nonnegative coefficients over 4.5-6.5 mm, cubic in l). Shared by the common and macro tests.
#pragma once

#include <random>
#include <utility>

#include "knit/material/energy_law.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::material::testing {

/// S = dW/de and C = dS/de of a response `eval(e)` (any type with W, S, C) against central
/// differences of W and S at e with step h: {|S_fd - S| / (1 + |S|), |C_fd - C| / (1 + |C|)}.
template <class Eval>
std::pair<double, double> fd_errors(const Eval& eval, const Eigen::Vector3d& e, double h) {
  const auto r = eval(e);
  Eigen::Matrix3d Cfd;
  Eigen::Vector3d Sfd;
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d(j) = h;
    const auto p = eval(e + d), m = eval(e - d);
    Sfd(j) = (p.W - m.W) / (2 * h);
    Cfd.col(j) = (p.S - m.S) / (2 * h);
  }
  return {(Sfd - r.S).norm() / (1.0 + r.S.norm()), (Cfd - r.C).norm() / (1.0 + r.C.norm())};
}

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

/// A valid network-family law (knit/material/convex_network.hpp): random parameters with the
/// weights V, w, w1 >= 0 (some exact zeros), three knots over 4.5-6.5 mm, magnitudes chosen so
/// that strains |e| <~ 0.6 reach all three pieces of the activation.
inline EnergyLawData make_test_network_law(unsigned seed = 7, double floor = 0.02, int h1 = 6,
                                           int h2 = 4) {
  EnergyLawData d;
  d.family = EnergyFamily::kNetwork;
  d.network.shape.h1 = h1;
  d.network.shape.h2 = h2;
  d.network.l_knots = {4.5, 5.5, 6.5};
  const NetworkShape& sh = d.network.shape;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  d.network.theta.resize(3, sh.size());
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < sh.size(); ++k) {
      double v;
      if (sh.nonnegative(k))
        v = u(gen) < 0.15 ? 0.0 : (k >= sh.w() ? 3.0 : 1.0) * u(gen);
      else if (k < sh.b0() || (k >= sh.a1() && k < sh.b1()))
        v = 3.0 * n(gen);  // first-layer and passthrough weights (1/strain)
      else if (k >= sh.L())
        v = 0.5 * n(gen);
      else
        v = 2.0 * u(gen) - 1.0;  // biases
      d.network.theta(j, k) = v;
    }
  d.l_min = 4.5;
  d.l_max = 6.5;
  d.floor = floor;
  d.box_min << -0.3, -0.3, -0.5;
  d.box_max << 0.45, 0.45, 0.5;
  return d;
}

}  // namespace knit::material::testing
