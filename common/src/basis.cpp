#include "knit/spline/basis.hpp"

#include <cassert>
#include <type_traits>

namespace knit::spline {

void basis_funs(int span, double u, int p, const std::vector<double>& U, double* N) {
  // Algorithm A2.2 (BasisFuns), The NURBS Book p. 70.
  double left[kMaxDegree + 1], right[kMaxDegree + 1];
  N[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = u - U[span + 1 - j];
    right[j] = U[span + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
}

namespace {

// Algorithm A2.3 (DersBasisFuns), The NURBS Book p. 72, for a degree P and an order ND that are
// either ints or std::integral_constant: with constants the compiler unrolls the loops (the
// cell's closest-point search evaluates quartic bases with two derivatives millions of times),
// with the same operations in the same order, so the results are bitwise the same.
template <class P, class ND>
void ders_basis_funs_impl(int span, double u, P p, ND nder, const std::vector<double>& U,
                          Eigen::Ref<Eigen::MatrixXd> ders) {
  double ndu[kMaxDegree + 1][kMaxDegree + 1];
  double a[2][kMaxDegree + 1];
  double left[kMaxDegree + 1], right[kMaxDegree + 1];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = u - U[span + 1 - j];
    right[j] = U[span + j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];  // lower triangle: knot differences
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;  // upper triangle: basis functions
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j) ders(0, j) = ndu[j][p];
  const int n = nder < p ? nder : p;
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= n; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = (rk >= -1) ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders(k, r) = d;
      std::swap(s1, s2);
    }
  }
  double f = p;
  for (int k = 1; k <= n; ++k) {
    for (int j = 0; j <= p; ++j) ders(k, j) *= f;
    f *= (p - k);
  }
  for (int k = n + 1; k <= nder; ++k)
    for (int j = 0; j <= p; ++j) ders(k, j) = 0.0;
}

template <int V>
using Int = std::integral_constant<int, V>;

}  // namespace

void ders_basis_funs(int span, double u, int p, int nder, const std::vector<double>& U,
                     Eigen::Ref<Eigen::MatrixXd> ders) {
  assert(p <= kMaxDegree && "knit: degree above kMaxDegree");
  assert(ders.rows() == nder + 1 && ders.cols() == p + 1);
  if (p == 4 && nder == 2) return ders_basis_funs_impl(span, u, Int<4>{}, Int<2>{}, U, ders);
  if (p == 3 && nder == 2) return ders_basis_funs_impl(span, u, Int<3>{}, Int<2>{}, U, ders);
  ders_basis_funs_impl(span, u, p, nder, U, ders);
}

void rationalize_1d(const double* w, Eigen::Ref<Eigen::MatrixXd> ders) {
  // R^(k) = (w N^(k) - sum_{i=1..k} C(k,i) W^(i) R^(k-i)) / W   (Leibniz rule on W R = w N).
  const int nder = static_cast<int>(ders.rows()) - 1;
  const int nf = static_cast<int>(ders.cols());
  double W[kMaxDerivative + 1];
  assert(nder <= kMaxDerivative);
  for (int k = 0; k <= nder; ++k) {
    W[k] = 0.0;
    for (int j = 0; j < nf; ++j) {
      ders(k, j) *= w[j];
      W[k] += ders(k, j);
    }
  }
  for (int k = 0; k <= nder; ++k) {
    for (int j = 0; j < nf; ++j) {
      double v = ders(k, j);
      double binom = 1.0;
      for (int i = 1; i <= k; ++i) {
        binom = binom * (k - i + 1) / i;
        v -= binom * W[i] * ders(k - i, j);
      }
      ders(k, j) = v / W[0];
    }
  }
}

}  // namespace knit::spline
