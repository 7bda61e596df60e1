// Tensor-product NURBS surfaces in any dimension (paper eqs. 3-4; The NURBS Book Sect. 4.4).
//
// Control points are stored one per row of P, (nu * nv) x dim, with the u index running
// fastest: global index a = i + nu * j for u-function i and v-function j. Local indices of the
// (pu+1)(pv+1) non-zero functions at a point follow the same rule: l = a + (pu+1) * b.
//
// Rational derivatives up to order 2 (The NURBS Book eq. 4.20, Algorithm A4.4):
//   R = wN/W,  R_u = (wN_u - R W_u)/W,  R_uu = (wN_uu - 2 R_u W_u - R W_uu)/W,
//   R_uv = (wN_uv - R_u W_v - R_v W_u - R W_uv)/W.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "knit/spline/bspline_basis.hpp"

namespace knit::spline {

/// Non-zero basis functions of a surface at one point and their derivatives up to order 2.
/// Rows of R: 0 = R, 1 = R_u, 2 = R_v, 3 = R_uu, 4 = R_uv, 5 = R_vv. Columns: local functions.
/// `index(l)` is the global control-point index of local function l. Reuse one object in
/// loops: its storage is only reallocated when the degrees change.
struct SurfaceBasis {
  Eigen::Matrix<double, 6, Eigen::Dynamic> R;
  Eigen::VectorXi index;
  int nderiv = 0;  ///< highest derivative order filled (rows beyond it are unspecified)
};

class SplineSurface {
 public:
  SplineSurface() = default;
  /// P: (nu*nv) x dim control points (u fastest); w: nu*nv weights or empty (B-spline).
  SplineSurface(BSplineBasis bu, BSplineBasis bv, Eigen::MatrixXd P,
                Eigen::VectorXd w = Eigen::VectorXd());

  const BSplineBasis& basis_u() const { return bu_; }
  const BSplineBasis& basis_v() const { return bv_; }
  const Eigen::MatrixXd& control_points() const { return P_; }
  Eigen::MatrixXd& control_points() { return P_; }
  const Eigen::VectorXd& weights() const { return w_; }
  bool rational() const { return rational_; }
  int dim() const { return static_cast<int>(P_.cols()); }
  int size_u() const { return bu_.size(); }
  int size_v() const { return bv_.size(); }
  int size() const { return size_u() * size_v(); }

  /// Non-zero (rational) basis functions and derivatives up to order nder <= 2 at (u, v).
  void basis(double u, double v, int nder, SurfaceBasis& out) const;

  Eigen::VectorXd eval(double u, double v) const;
  /// Rows: S, S_u, S_v, S_uu, S_uv, S_vv (the first 1, 3 or 6 rows for nder = 0, 1, 2).
  Eigen::MatrixXd derivatives(double u, double v, int nder) const;

 private:
  BSplineBasis bu_, bv_;
  Eigen::MatrixXd P_;
  Eigen::VectorXd w_;
  bool rational_ = false;
};

}  // namespace knit::spline
