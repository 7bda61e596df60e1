// Gauss-Legendre quadrature of any order, and its mapping to knot spans.
//
// Nodes are the roots of the Legendre polynomial P_n, found by Newton's method from the
// Chebyshev-like initial guess cos(pi (i - 1/4) / (n + 1/2)) (Abramowitz & Stegun 25.4.29;
// Press et al., Numerical Recipes, Sect. 4.6). Exact for polynomials of degree 2n - 1.
#pragma once

#include <vector>

namespace knit::spline {

struct QuadratureRule {
  std::vector<double> points;   ///< abscissae
  std::vector<double> weights;  ///< weights (sum = interval length)
};

/// n-point Gauss-Legendre rule on [-1, 1] (n >= 1).
QuadratureRule gauss_legendre(int n);
/// n-point rule on [a, b].
QuadratureRule gauss_legendre(int n, double a, double b);
/// n points in every non-empty span of the knot vector U (concatenated, in increasing order).
QuadratureRule gauss_legendre_on_spans(int n, const std::vector<double>& U);

}  // namespace knit::spline
