// Shared setup of the knit-material tests (eq. 17 and energy law): the stitch-value field graded
// linearly in theta1 and a material point at given parameters.
#pragma once

#include <Eigen/Core>

#include "knit/macro/knit_material.hpp"

namespace knit::testing {

/// l graded linearly from l0 (theta1 = 0) to l1 (theta1 = 1), constant in theta2.
inline macro::ScalarFieldSpec graded_stitch_value(double l0 = 4.5, double l1 = 6.5) {
  macro::ScalarFieldSpec l;
  l.degree_u = 1;
  l.knots_u = {0, 0, 1, 1};
  l.values = {l0, l1};
  return l;
}

/// A knitting angle bilinear on [0, 1]^2 with the corner values (0, 0) 0.2, (1, 0) 0.5,
/// (0, 1) -0.9, (1, 1) 1.3 (u index fastest, docs/case-format.md), and its value computed
/// independently of the spline code.
struct BilinearAngle {
  static constexpr double a00 = 0.2, a10 = 0.5, a01 = -0.9, a11 = 1.3;
  static macro::ScalarFieldSpec spec() {
    macro::ScalarFieldSpec a;
    a.degree_u = a.degree_v = 1;
    a.knots_u = a.knots_v = {0, 0, 1, 1};
    a.values = {a00, a10, a01, a11};
    return a;
  }
  static double at(double u, double v) {
    return (1 - u) * (1 - v) * a00 + u * (1 - v) * a10 + (1 - u) * v * a01 + u * v * a11;
  }
};

/// A material point at (theta1, theta2), no bound quadrature point.
inline macro::MaterialPoint at(double t1, double t2) {
  macro::MaterialPoint p;
  p.theta = {t1, t2};
  return p;
}

/// Central differences of a material at E (step h): C = dS/dE and S = dW/dE (NaN unless the
/// law is hyperelastic).
struct CentralDifferences {
  Eigen::Matrix3d C;
  Eigen::Vector3d S;
};
inline CentralDifferences central_differences(const macro::Material& m, const Eigen::Vector3d& E,
                                              const macro::MaterialPoint& p, double h) {
  CentralDifferences d;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d Ep = E, Em = E;
    Ep(c) += h;
    Em(c) -= h;
    const auto rp = m.evaluate(Ep, p), rm = m.evaluate(Em, p);
    d.C.col(c) = (rp.S - rm.S) / (2 * h);
    d.S(c) = (rp.W - rm.W) / (2 * h);
  }
  return d;
}

}  // namespace knit::testing
