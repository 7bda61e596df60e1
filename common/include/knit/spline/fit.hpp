// Fitting splines to data: interpolation at the Greville abscissae and linear least squares.
//
// References: The NURBS Book, 2nd ed., Sect. 9.2 (global interpolation, Algorithm A9.1 with the
// parameters chosen as the Greville abscissae, eq. 9.8 averaging) and Sect. 9.4.1 (least-squares
// curve approximation, eqs. 9.63-9.67; here solved by a column-pivoting QR of the weighted
// collocation matrix instead of the normal equations, for accuracy). Tensor-product
// interpolation (Sect. 9.2.5): the curve problem in u for every row, then in v.
//
// The Greville abscissae g_i = (u_{i+1} + ... + u_{i+p}) / p of a clamped knot vector satisfy the
// Schoenberg-Whitney condition N_i(g_i) != 0, so the collocation matrix is non-singular and any
// function in the spline space is reproduced exactly. At an interior knot of multiplicity p+1
// (a C^{-1} break) two Greville points coincide with the break: the first takes the left limit of
// the basis, the second the right limit (values given there are read as those limits).
//
// Rational spaces (fixed weights w): the rational basis R_i = w_i N_i / W spans {g / W : g in the
// B-spline space}, so interpolating f in it is interpolating W f in the B-spline space and
// dividing the coefficients by w_i. For least squares the rational basis is used directly.
//
// Failure: inputs that cannot determine the control points (a basis function without data in its
// support, fewer independent samples than unknowns, mismatched sizes) throw FitError with a
// message that names the basis function. The residual of a least-squares fit is reported in the
// result (a poor fit is a numerical outcome for the caller to judge, not an exception).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <map>
#include <stdexcept>
#include <vector>

#include "knit/spline/curve.hpp"
#include "knit/spline/surface.hpp"

namespace knit::spline {

/// The data (or the requested fit) cannot determine the control points.
class FitError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Dense collocation matrix B(k, i) = N_i(t_k) (or the rational R_i if `weights` is given),
/// the `derivative`-th derivative if requested.
Eigen::MatrixXd collocation_matrix(const BSplineBasis& basis, const std::vector<double>& t,
                                   int derivative = 0, const Eigen::VectorXd& weights = {});

// --- Interpolation at the Greville abscissae --------------------------------------------------

/// Control points (n x dim) of the spline in the space of `basis` (rational with `weights` if
/// given) that takes values(i, :) at the Greville abscissa basis.greville()[i].
Eigen::MatrixXd interpolate_at_greville(const BSplineBasis& basis, const Eigen::MatrixXd& values,
                                        const Eigen::VectorXd& weights = {});
/// The spline curve interpolating f at the Greville abscissae (f returns a dim-vector).
SplineCurve interpolate_function(const BSplineBasis& basis,
                                 const std::function<Eigen::VectorXd(double)>& f,
                                 const Eigen::VectorXd& weights = {});

/// Tensor-product interpolation: values ((nu*nv) x dim, u index fastest: row i + nu*j) at
/// (g^u_i, g^v_j) -> control points in the same layout as SplineSurface.
Eigen::MatrixXd interpolate_at_greville(const BSplineBasis& bu, const BSplineBasis& bv,
                                        const Eigen::MatrixXd& values,
                                        const Eigen::VectorXd& weights = {});
SplineSurface interpolate_function(const BSplineBasis& bu, const BSplineBasis& bv,
                                   const std::function<Eigen::VectorXd(double, double)>& f,
                                   const Eigen::VectorXd& weights = {});

// --- Linear least squares ---------------------------------------------------------------------

struct LeastSquaresOptions {
  /// Per-sample weights c_k >= 0 (minimize sum_k c_k |s(t_k) - Q_k|^2); empty: all 1.
  Eigen::VectorXd data_weights;
  /// NURBS weights of the basis (fixed; the fit is linear in the control points); empty: B-spline.
  Eigen::VectorXd basis_weights;
  /// Control points held fixed: global index -> value (1 x dim).
  std::map<int, Eigen::RowVectorXd> fixed;
  /// Curves only: fix P_0 and P_{n-1} to the first samples at the ends of the domain, so that the
  /// fit interpolates the end points (The NURBS Book Sect. 9.4.1). Such samples must exist.
  bool interpolate_ends = false;
  /// Relative pivot threshold below which the QR declares the problem rank-deficient.
  double rank_tolerance = 1e-12;
};

struct LeastSquaresResult {
  Eigen::MatrixXd P;          ///< control points (n x dim; surfaces: u index fastest)
  double rms_residual = 0.0;  ///< sqrt(sum_k c_k |r_k|^2 / sum_k c_k), r_k = s(t_k) - Q_k
  double max_residual = 0.0;  ///< max_k |r_k| over samples with c_k > 0
  int rank = 0;               ///< numerical rank of the weighted collocation matrix (free columns)
};

/// Least-squares curve: samples values(k, :) at parameters t[k].
LeastSquaresResult least_squares(const BSplineBasis& basis, const std::vector<double>& t,
                                 const Eigen::MatrixXd& values,
                                 const LeastSquaresOptions& options = {});
/// Least-squares tensor-product surface: scattered samples values(k, :) at (u[k], v[k]).
LeastSquaresResult least_squares(const BSplineBasis& bu, const BSplineBasis& bv,
                                 const std::vector<double>& u, const std::vector<double>& v,
                                 const Eigen::MatrixXd& values,
                                 const LeastSquaresOptions& options = {});

}  // namespace knit::spline
