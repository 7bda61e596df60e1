// One ridge function of the energy-based law (knit/material/energy_law.hpp): a convex scalar
// function f(s) given by its second derivative as a B-spline on a UNIFORM clamped knot vector
// over [a, b],
//
//   f''(s) = g(s) = sum_i a_i N_i,p(clamp(s, a, b)),     f(0) = f'(0) = 0,
//
// with f' and f its exact antiderivatives (piecewise polynomials of degree p+1, p+2). Beyond
// [a, b], g keeps its end value, so f continues as a quadratic (a smooth convex extension,
// C2 across a and b because g is continuous there). a_i >= 0 makes f convex (B-spline basis
// functions are nonnegative, The NURBS Book Sect. 2.3, property P2.1).
//
// Representation for fast evaluation: per span m (s in [a + m h, a + (m+1) h], h = (b-a)/n)
// the Taylor coefficients q_r of f in the local coordinate t = (s - a)/h - m in [0, 1], so
//   f = sum_r q_r t^r,   f' = (df/dt)/h,   f'' = (d2f/dt2)/h^2,
// evaluated by Horner's rule with derivatives (all three in one pass). Two more entries hold
// the extensions: entry 0 (s < a, t = (s - a)/h < 0) and entry n + 1 (s > b, t = (s - b)/h).
// The map a_i -> q is linear, so the same layout with other coefficients gives d/dl of f.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

namespace knit::material {

/// Layout of one ridge function: range, spans and degree of f''.
struct RidgeGrid {
  double a = -1.0, b = 1.0;                    ///< s-range of the B-spline of f'' (a < 0 < b)
  int spans = 8;                               ///< uniform knot spans on [a, b]
  int degree = 3;                              ///< p, degree of f''
  int size() const { return spans + degree; }  ///< number of B-spline coefficients
  double h() const { return (b - a) / spans; }
  /// Clamped uniform knot vector of f'' (degree + 1 repeated end knots).
  std::vector<double> knots() const;
  /// Empty if valid, else the reason.
  std::string validate() const;
};

/// Per-span coefficients of f (spans + 2 entries of degree + 3 values, see above) for the
/// B-spline coefficients `coef` of f'' (size grid.size()). Appends to `out`.
void ridge_polynomials(const RidgeGrid& grid, const double* coef, std::vector<double>& out);

/// Horner's rule with two derivatives for sum_r c_r t^r, r = 0..P: p0 = value, p1 = first
/// derivative, 2 p2 = second derivative (Numerical Recipes ddpoly).
inline void horner2(const double* c, int P, double t, double& p0, double& p1, double& p2) {
  p0 = c[P];
  p1 = 0.0;
  p2 = 0.0;
  for (int r = P - 1; r >= 0; --r) {
    p2 = p2 * t + p1;
    p1 = p1 * t + p0;
    p0 = p0 * t + c[r];
  }
}

/// Entry of the span (or extension) that holds s and the local coordinate t there.
inline const double* ridge_span(const double* q, int P, double a, double inv_h, int spans, double s,
                                double& t) {
  const double u = (s - a) * inv_h;  // s finite (the caller checks)
  const double uc = u < -1.0 ? -1.0 : (u > spans ? static_cast<double>(spans) : u);
  const int m = static_cast<int>(std::floor(uc));
  t = u - (m < 0 ? 0 : m);  // the extensions keep their end as origin
  return q + (m + 1) * (P + 1);
}

/// (f, f', f'') at s from one function's block of coefficients (as written by
/// ridge_polynomials). Inline: the inner loop of every material evaluation.
template <int P>  // P = degree + 2: the polynomial degree of f
inline void ridge_eval(const double* q, double a, double inv_h, int spans, double s, double& f,
                       double& df, double& ddf) {
  double t, p1, p2;
  const double* c = ridge_span(q, P, a, inv_h, spans, s, t);  // sets t: before horner2 reads it
  horner2(c, P, t, f, p1, p2);
  df = p1 * inv_h;
  ddf = 2.0 * p2 * inv_h * inv_h;
}

/// Reference evaluation (slow, for tests and the fit): (f, f', f'') at s for coefficients
/// coef by direct B-spline evaluation and Gauss quadrature of the integrals from 0.
Eigen::Vector3d ridge_eval_reference(const RidgeGrid& grid, const double* coef, double s);

/// The linear maps coef -> f(s), f'(s), f''(s): f(s) = sum_i coef_i F_i(s) etc. Used by the
/// fit (the law is linear in its coefficients). Precomputes the unit polynomials once.
class RidgeBasis {
 public:
  explicit RidgeBasis(const RidgeGrid& grid);
  const RidgeGrid& grid() const { return grid_; }
  /// Rows 0, 1, 2: F_i(s), F'_i(s), F''_i(s) = N_i(clamp(s, a, b)), i = 0..grid.size()-1.
  void eval(double s, Eigen::Ref<Eigen::Matrix<double, 3, Eigen::Dynamic>> out) const;

 private:
  RidgeGrid grid_;
  std::vector<double> unit_;  ///< grid.size() blocks of polynomials, one per unit coefficient
};

/// (f, f', f'') from one block of ridge_polynomials(), any degree (not the fast path).
Eigen::Vector3d ridge_eval_any(const RidgeGrid& grid, const double* q, double s);

}  // namespace knit::material
