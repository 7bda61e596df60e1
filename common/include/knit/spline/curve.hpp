// NURBS curves in any dimension (a scalar field, a 3-D centerline, a 4-D quaternion curve).
//
// c(u) = sum_i R_i(u) P_i, R_i = w_i N_i / sum_j w_j N_j  (paper eqs. 1-2; The NURBS Book eq. 4.1)
// Derivatives of the rational curve follow Algorithm A4.2 (RatCurveDerivs), p. 127, here through
// the derivatives of the rational basis functions (identical result).
#pragma once

#include <Eigen/Core>

#include "knit/spline/bspline_basis.hpp"

namespace knit::spline {

class SplineCurve {
 public:
  SplineCurve() = default;
  /// P: n x dim control points (one per row). w: n weights (> 0), or empty for a B-spline.
  SplineCurve(BSplineBasis basis, Eigen::MatrixXd P, Eigen::VectorXd w = Eigen::VectorXd());

  const BSplineBasis& basis() const { return basis_; }
  int degree() const { return basis_.degree(); }
  const std::vector<double>& knots() const { return basis_.knots(); }
  const Eigen::MatrixXd& control_points() const { return P_; }
  Eigen::MatrixXd& control_points() { return P_; }
  /// Weights (all ones for a non-rational curve).
  const Eigen::VectorXd& weights() const { return w_; }
  bool rational() const { return rational_; }
  int dim() const { return static_cast<int>(P_.cols()); }
  int size() const { return static_cast<int>(P_.rows()); }

  Eigen::VectorXd eval(double u) const;
  /// Row k (k = 0..nder) holds the k-th parametric derivative c^(k)(u).
  Eigen::MatrixXd derivatives(double u, int nder) const;
  /// Derivatives 0..nder of the p+1 non-zero (rational) basis functions into R; returns the
  /// index of the first one. Allocation-free.
  int basis_derivatives(double u, int nder, Eigen::Ref<Eigen::MatrixXd> R) const;

 private:
  BSplineBasis basis_;
  Eigen::MatrixXd P_;
  Eigen::VectorXd w_;
  bool rational_ = false;
};

}  // namespace knit::spline
