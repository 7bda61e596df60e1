// A one-dimensional B-spline basis: a degree and a validated, clamped knot vector.
//
// References: The NURBS Book, Sect. 2.2-2.3 (Algorithms A2.1-A2.3); Greville abscissae
// (The NURBS Book eq. (9.8) with the averaging of p consecutive knots).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace knit::spline {

class BSplineBasis {
 public:
  BSplineBasis() = default;
  /// Validates U for degree p (clamped, non-decreasing, multiplicities); throws KnotVectorError.
  BSplineBasis(int p, std::vector<double> U);

  int degree() const { return p_; }
  const std::vector<double>& knots() const { return U_; }
  /// Number of basis functions n = U.size() - p - 1.
  int size() const { return static_cast<int>(U_.size()) - p_ - 1; }
  double lo() const { return U_[p_]; }
  double hi() const { return U_[size()]; }

  /// Algorithm A2.1, correct at u = hi().
  int find_span(double u) const;
  /// Derivatives 0..nder of the p+1 non-zero functions at u into ders ((nder+1) x (p+1)).
  /// Returns the index of the first non-zero function (span - p). Allocation-free.
  int eval(double u, int nder, Eigen::Ref<Eigen::MatrixXd> ders) const;
  /// All n basis function values at u (dense, for interpolation matrices and tests).
  Eigen::VectorXd eval_all(double u, int derivative = 0) const;

  /// Greville abscissae g_i = (u_{i+1} + ... + u_{i+p}) / p (for p = 0: span midpoints).
  std::vector<double> greville() const;
  /// Distinct knot values (element boundaries).
  std::vector<double> breakpoints() const;
  /// Number of non-empty knot spans.
  int num_elements() const { return static_cast<int>(breakpoints().size()) - 1; }

 private:
  int p_ = 0;
  std::vector<double> U_;
};

}  // namespace knit::spline
