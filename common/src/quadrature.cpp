#include "knit/spline/quadrature.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "knit/spline/knot_vector.hpp"

namespace knit::spline {

QuadratureRule gauss_legendre(int n) {
  if (n < 1) throw std::invalid_argument("Gauss-Legendre rule needs at least one point");
  QuadratureRule q;
  q.points.resize(n);
  q.weights.resize(n);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      // Three-term recurrence for P_n(x) and its derivative.
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) p0 = 1.0, p1 = x;
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      if (n == 1) dp = 1.0;
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    // Recompute the derivative at the converged root for the weight.
    double p0 = 1.0, p1 = x;
    for (int k = 2; k <= n; ++k) {
      const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    dp = (n == 1) ? 1.0 : n * (x * p1 - p0) / (x * x - 1.0);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    q.points[i] = -x;
    q.points[n - 1 - i] = x;
    q.weights[i] = w;
    q.weights[n - 1 - i] = w;
  }
  if (n % 2 == 1) q.points[n / 2] = 0.0;
  return q;
}

QuadratureRule gauss_legendre(int n, double a, double b) {
  QuadratureRule q = gauss_legendre(n);
  const double h = 0.5 * (b - a), c = 0.5 * (a + b);
  for (int i = 0; i < n; ++i) {
    q.points[i] = c + h * q.points[i];
    q.weights[i] *= h;
  }
  return q;
}

QuadratureRule gauss_legendre_on_spans(int n, const std::vector<double>& U) {
  QuadratureRule out;
  const std::vector<double> b = unique_knots(U);
  for (size_t e = 0; e + 1 < b.size(); ++e) {
    const QuadratureRule q = gauss_legendre(n, b[e], b[e + 1]);
    out.points.insert(out.points.end(), q.points.begin(), q.points.end());
    out.weights.insert(out.weights.end(), q.weights.begin(), q.weights.end());
  }
  return out;
}

}  // namespace knit::spline
