// Ridge functions of the energy-based law (see knit/material/ridge_spline.hpp).
#include <algorithm>
#include <stdexcept>

#include "knit/material/ridge_spline.hpp"
#include "knit/spline/bspline_basis.hpp"
#include "knit/spline/knot_vector.hpp"
#include "knit/spline/quadrature.hpp"

namespace knit::material {

std::vector<double> RidgeGrid::knots() const {
  return spline::uniform_knots(degree, spans, a, b);
}

std::string RidgeGrid::validate() const {
  if (!(std::isfinite(a) && std::isfinite(b))) return "s-range must be finite";
  if (!(a < 0.0 && b > 0.0)) return "s-range [a, b] must contain 0 strictly inside";
  if (spans < 1 || spans > 1000) return "spans must be in 1..1000";
  if (degree < 0 || degree > 5) return "degree of f'' must be in 0..5";
  return {};
}

void ridge_polynomials(const RidgeGrid& grid, const double* coef, std::vector<double>& out) {
  const int p = grid.degree, n = grid.spans, P = p + 2, W = P + 1;
  const double h = grid.h();
  const spline::BSplineBasis basis(p, grid.knots());
  // Taylor coefficients of g = f'' in t per span: c(m, r) = h^r g^(r)(s_m) / r!.
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, p + 1);
  Eigen::MatrixXd ders(p + 1, p + 1);
  for (int m = 0; m < n; ++m) {
    // At the span's own knot (find_span then picks span m, not m - 1 by round-off).
    const int first = basis.eval(basis.knots()[static_cast<std::size_t>(p + m)], p, ders);
    double hr = 1.0, fact = 1.0;
    for (int r = 0; r <= p; ++r) {
      if (r > 0) {
        hr *= h;
        fact *= r;
      }
      double v = 0.0;
      for (int j = 0; j <= p; ++j) v += ders(r, j) * coef[first + j];
      c(m, r) = hr * v / fact;
    }
  }
  // G1(t) = int_0^t g dt' (in t units), G2(t) = int_0^t G1.
  auto G1 = [&](int m, double t) {
    double v = 0.0, tr = t;
    for (int r = 0; r <= p; ++r, tr *= t) v += c(m, r) * tr / (r + 1);
    return v;
  };
  auto G2 = [&](int m, double t) {
    double v = 0.0, tr = t * t;
    for (int r = 0; r <= p; ++r, tr *= t) v += c(m, r) * tr / ((r + 1) * (r + 2));
    return v;
  };
  // f(s_m) = F[m], f'(s_m) = D[m]; f(0) = f'(0) = 0 fixes the span that holds 0.
  std::vector<double> F(n + 1), D(n + 1);
  const int m0 = std::clamp(static_cast<int>(std::floor(-grid.a / h)), 0, n - 1);
  const double t0 = -grid.a / h - m0;
  D[m0] = -h * G1(m0, t0);
  F[m0] = -h * D[m0] * t0 - h * h * G2(m0, t0);
  for (int m = m0; m < n; ++m) {
    D[m + 1] = D[m] + h * G1(m, 1.0);
    F[m + 1] = F[m] + h * D[m] + h * h * G2(m, 1.0);
  }
  for (int m = m0; m > 0; --m) {
    D[m - 1] = D[m] - h * G1(m - 1, 1.0);
    F[m - 1] = F[m] - h * D[m - 1] - h * h * G2(m - 1, 1.0);
  }
  const std::size_t base = out.size();
  out.resize(base + static_cast<std::size_t>((n + 2) * W), 0.0);
  double* q = out.data() + base;
  // Entry 0: left extension, f = F_a + h D_a t + h^2 g_a t^2 / 2 with t = (s - a)/h < 0.
  q[0] = F[0];
  q[1] = h * D[0];
  q[2] = 0.5 * h * h * coef[0];
  for (int m = 0; m < n; ++m) {
    double* e = q + (m + 1) * W;
    e[0] = F[m];
    e[1] = h * D[m];
    for (int r = 0; r <= p; ++r) e[r + 2] = h * h * c(m, r) / ((r + 1) * (r + 2));
  }
  double* e = q + (n + 1) * W;  // right extension about b
  e[0] = F[n];
  e[1] = h * D[n];
  e[2] = 0.5 * h * h * coef[grid.size() - 1];
}

Eigen::Vector3d ridge_eval_any(const RidgeGrid& grid, const double* q, double s) {
  const int P = grid.degree + 2;
  const double inv_h = 1.0 / grid.h();
  double t, p0, p1, p2;
  const double* c = ridge_span(q, P, grid.a, inv_h, grid.spans, s, t);  // sets t first
  horner2(c, P, t, p0, p1, p2);
  return {p0, p1 * inv_h, 2.0 * p2 * inv_h * inv_h};
}

Eigen::Vector3d ridge_eval_reference(const RidgeGrid& grid, const double* coef, double s) {
  const spline::BSplineBasis basis(grid.degree, grid.knots());
  auto g = [&](double x) {
    const Eigen::VectorXd N = basis.eval_all(std::clamp(x, grid.a, grid.b));
    return N.dot(Eigen::Map<const Eigen::VectorXd>(coef, N.size()));
  };
  // Pieces between 0 and s split at every knot; Gauss with degree + 2 points is exact there.
  const double lo = std::min(0.0, s), hi = std::max(0.0, s);
  std::vector<double> cuts = {lo, hi};
  for (int m = 0; m <= grid.spans; ++m) {
    const double x = grid.a + m * grid.h();
    if (x > lo && x < hi) cuts.push_back(x);
  }
  std::sort(cuts.begin(), cuts.end());
  double d1 = 0.0, d0 = 0.0;  // int g, int (s - x) g over [lo, hi]
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const auto q = spline::gauss_legendre(grid.degree + 2, cuts[k], cuts[k + 1]);
    for (std::size_t i = 0; i < q.points.size(); ++i) {
      const double gx = g(q.points[i]);
      d1 += q.weights[i] * gx;
      d0 += q.weights[i] * (s - q.points[i]) * gx;
    }
  }
  const double sign = s < 0.0 ? -1.0 : 1.0;
  return {sign * d0, sign * d1, g(s)};
}

RidgeBasis::RidgeBasis(const RidgeGrid& grid) : grid_(grid) {
  const std::string why = grid.validate();
  if (!why.empty()) throw std::invalid_argument("ridge grid: " + why);
  std::vector<double> e(static_cast<std::size_t>(grid.size()), 0.0);
  for (int i = 0; i < grid.size(); ++i) {
    e[static_cast<std::size_t>(i)] = 1.0;
    ridge_polynomials(grid, e.data(), unit_);
    e[static_cast<std::size_t>(i)] = 0.0;
  }
}

void RidgeBasis::eval(double s, Eigen::Ref<Eigen::Matrix<double, 3, Eigen::Dynamic>> out) const {
  const std::size_t block = static_cast<std::size_t>((grid_.spans + 2) * (grid_.degree + 3));
  for (int i = 0; i < grid_.size(); ++i)
    out.col(i) = ridge_eval_any(grid_, unit_.data() + static_cast<std::size_t>(i) * block, s);
}

}  // namespace knit::material
