// Test helper: a valid response surface without the fitter (Schoenberg quasi-interpolation of
// a known law on the default fan of load paths: control point (i, j) takes the strain of the
// fan at the Greville abscissae (g_i, g_j) and the law's stress there), and the test databases
// built from it. Shared by the common and macro material tests.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "knit/material/database.hpp"
#include "knit/material/load_paths.hpp"
#include "knit/material/response_surface.hpp"
#include "knit/spline/bspline_basis.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::material::testing {

/// Orthotropic stiffening test law (tensor strains -> S11, S22, S12), scaled by k.
inline Eigen::Vector3d test_law(const Eigen::Vector3d& E, double k = 1.0) {
  return k * Eigen::Vector3d(0.5 * E(0) + 0.1 * E(1) + 8.0 * E(0) * E(0) * E(0),
                             0.1 * E(0) + 1.0 * E(1) + 12.0 * E(1) * E(1) * E(1),
                             0.3 * E(2) + 4.0 * E(2) * E(2) * E(2));
}

/// Strain of the default fan at (xi1, xi2): end point on the L polyline, proportional F.
inline Eigen::Vector2d fan_strain(double xi1, double xi2) {
  const double leg = 0.5, s = 2 * leg * xi1;
  Eigen::Vector2d end =
      s <= leg ? Eigen::Vector2d(0.35, -0.15 + s) : Eigen::Vector2d(0.35 - (s - leg), 0.35);
  LoadPath p;
  p.target = end;
  const Eigen::Matrix2d E = green_lagrange(deformation_gradient(p, xi2));
  return {E(0, 0), E(1, 1)};
}

/// Sets E and S of every row of `r` from its F and P (eq. 9: E = (F^T F - I) / 2, S =
/// sym(F^-1 P)), as the sweep writes them: the reader refuses a converged step whose E or S
/// is not its F's and P's (session 54).
inline void set_strain_and_stress(RawPath& r) {
  r.E.resize(r.F.rows(), 3);
  r.S.resize(r.F.rows(), 3);
  for (Eigen::Index s = 0; s < r.F.rows(); ++s) {
    Eigen::Matrix2d F, P;
    F << r.F(s, 0), r.F(s, 1), r.F(s, 2), r.F(s, 3);
    P << r.P(s, 0), r.P(s, 1), r.P(s, 2), r.P(s, 3);
    const Eigen::Matrix2d E = green_lagrange(F), S = second_piola_kirchhoff(F, P);
    r.E.row(s) << E(0, 0), E(1, 1), E(0, 1);
    r.S.row(s) << S(0, 0), S(1, 1), S(0, 1);
  }
}

inline ResponseSurfaceData make_test_surface(double k = 1.0, int n = 11, int p = 3) {
  ResponseSurfaceData d;
  d.degree1 = d.degree2 = d.shear_degree = p;
  d.knots1 = d.knots2 = d.shear_knots = spline::uniform_knots(p, n - p);
  const auto g = spline::BSplineBasis(p, d.knots1).greville();
  d.E_ctrl.resize(n * n, 2);
  d.S_ctrl.resize(n * n, 2);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d E = fan_strain(g[i], g[j]);
      const Eigen::Vector3d S = test_law({E(0), E(1), 0.0}, k);
      d.E_ctrl.row(i + n * j) = E.transpose();
      d.S_ctrl.row(i + n * j) << S(0), S(1);
    }
  d.E12_ctrl.resize(n);
  d.S12_ctrl.resize(n);
  for (int i = 0; i < n; ++i) {
    d.E12_ctrl(i) = 0.3 * g[i];
    d.S12_ctrl(i) = test_law({0, 0, d.E12_ctrl(i)}, k)(2);
  }
  return d;
}

/// Central finite differences of S with respect to (E11, E22, 2E12), step h.
inline Eigen::Matrix3d fd_tangent(const ResponseSurface& rs, const Eigen::Vector3d& E,
                                  double h = 1e-7) {
  Eigen::Matrix3d C;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d Ep = E, Em = E;
    Ep(c) += h;
    Em(c) -= h;
    C.col(c) = (rs.evaluate(Ep).S - rs.evaluate(Em).S) / (2 * h);
  }
  return C;
}

/// A database as the tests write it (provenance, generator "test", the sweep input, the yarn
/// diameter), without loop-length entries.
inline Database make_test_database(std::string sweep_input = "{}") {
  Database db;
  db.provenance = current_provenance();
  db.generator = "test";
  db.sweep_input = std::move(sweep_input);
  db.yarn = {{"diameter", 0.38}};
  return db;
}

/// A loop-length entry with the 5 mm-like cell of the database tests (w, c, t in mm), no data.
inline LoopLengthEntry make_test_entry(double loop_length = 5.0) {
  LoopLengthEntry e;
  e.loop_length = loop_length;
  e.cell = {1.26, 0.88, 0.76};
  return e;
}

/// The stiffening test law fitted at every loop length, scaled by k = (4.5/l)^2 (no cells).
inline Database make_test_law_database(const std::vector<double>& loop_lengths = {4.5, 5.0, 5.5,
                                                                                  6.0, 6.5}) {
  Database db = make_test_database();
  for (double l : loop_lengths) {
    LoopLengthEntry e;
    e.loop_length = l;
    e.surface = make_test_surface(std::pow(4.5 / l, 2));
    db.entries.push_back(e);
  }
  return db;
}

}  // namespace knit::material::testing
