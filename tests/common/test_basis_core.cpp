// Core B-spline/NURBS evaluation: partition of unity, derivatives against finite differences,
// the exact quarter circle, evaluation at both ends of the domain.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include "knit/spline/basis.hpp"
#include "knit/spline/bspline_basis.hpp"
#include "knit/spline/curve.hpp"
#include "knit/spline/knot_vector.hpp"
#include "knit/spline/quadrature.hpp"
#include "knit/spline/surface.hpp"

using namespace knit::spline;

TEST_CASE("basis functions are a non-negative partition of unity", "[unit][spline]") {
  const int p = GENERATE(0, 1, 2, 3, 5, 7);
  std::vector<double> U(p + 1, 0.0);
  for (double k : {0.1, 0.35, 0.35, 0.6, 0.9}) U.push_back(k);
  U.insert(U.end(), p + 1, 1.0);
  if (p == 0) U = {0.0, 0.1, 0.35, 0.6, 0.9, 1.0};
  BSplineBasis basis(p, U);
  for (int i = 0; i <= 200; ++i) {
    const double u = i / 200.0;
    const Eigen::VectorXd N = basis.eval_all(u);
    CHECK(N.sum() == Approx(1.0).margin(1e-14));
    CHECK(N.minCoeff() >= -1e-15);
  }
}

TEST_CASE("find_span is correct at both ends of the domain", "[unit][spline]") {
  const std::vector<double> U = {0, 0, 0, 0.5, 1, 1, 1};
  const int n = num_basis(U, 2);
  CHECK(find_span(n, 2, 0.0, U) == 2);
  CHECK(find_span(n, 2, 1.0, U) == 3);
  CHECK(find_span(n, 2, 0.5, U) == 3);
  BSplineBasis b(2, U);
  const Eigen::VectorXd N1 = b.eval_all(1.0);
  CHECK(N1(n - 1) == Approx(1.0));
  const Eigen::VectorXd N0 = b.eval_all(0.0);
  CHECK(N0(0) == Approx(1.0));
}

TEST_CASE("basis derivatives match finite differences", "[unit][spline]") {
  const int p = GENERATE(2, 3, 4, 6);
  BSplineBasis b(p, uniform_knots(p, 4));
  const double h = 1e-6;
  for (double u : {0.05, 0.3, 0.61, 0.93}) {
    for (int k = 1; k <= 3; ++k) {
      const Eigen::VectorXd d = b.eval_all(u, k);
      const Eigen::VectorXd fd = (b.eval_all(u + h, k - 1) - b.eval_all(u - h, k - 1)) / (2 * h);
      CHECK((d - fd).cwiseAbs().maxCoeff() < 1e-5 * std::max(1.0, d.cwiseAbs().maxCoeff()));
    }
  }
}

TEST_CASE("the unrolled cubic and quartic kernels equal the general one bit for bit",
          "[unit][spline]") {
  // ders_basis_funs has fixed-degree paths for (p, nder) = (3, 2) and (4, 2) (the yarns'
  // closest-point search); nder = 3 takes the general path, whose first three rows are the same
  // operations in the same order.
  const int p = GENERATE(3, 4);
  std::vector<double> U(p + 1, 0.0);
  for (double k : {0.07, 0.3, 0.3, 0.55, 0.81}) U.push_back(k);
  U.insert(U.end(), p + 1, 1.0);
  for (double u = 0.0; u <= 1.0; u += 0.0137) {
    const int span = find_span(static_cast<int>(U.size()) - p - 1, p, u, U);
    Eigen::MatrixXd fixed(3, p + 1), general(4, p + 1);
    ders_basis_funs(span, u, p, 2, U, fixed);
    ders_basis_funs(span, u, p, 3, U, general);
    INFO("p = " << p << ", u = " << u);
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j <= p; ++j)
        CHECK(std::memcmp(&fixed(k, j), &general(k, j), sizeof(double)) == 0);
  }
}

TEST_CASE("a quadratic NURBS quarter circle is exact", "[unit][spline]") {
  // Initializer lists, not the comma initializer: with that, GCC 12 -O2 warned
  // -Wmaybe-uninitialized inside Eigen's DenseStorage here (a false positive).
  const Eigen::MatrixXd P{{1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}};
  const Eigen::VectorXd w{{1.0, std::sqrt(0.5), 1.0}};
  SplineCurve c(BSplineBasis(2, {0, 0, 0, 1, 1, 1}), P, w);
  for (int i = 0; i <= 100; ++i) {
    const Eigen::MatrixXd d = c.derivatives(i / 100.0, 2);
    CHECK(std::abs(d.row(0).norm() - 1.0) < 1e-14);
    CHECK(std::abs(d.row(0).dot(d.row(1))) < 1e-13);  // tangent orthogonal to radius
  }
}

TEST_CASE("rational surface derivatives match finite differences", "[unit][spline]") {
  BSplineBasis bu(2, {0, 0, 0, 0.4, 1, 1, 1}), bv(3, {0, 0, 0, 0, 1, 1, 1, 1});
  const int n = bu.size() * bv.size();
  Eigen::MatrixXd P = Eigen::MatrixXd::Random(n, 3);
  Eigen::VectorXd w = Eigen::VectorXd::Random(n).cwiseAbs().array() + 0.5;
  SplineSurface s(bu, bv, P, w);
  const double h = 1e-5;
  for (auto [u, v] : {std::pair{0.1, 0.2}, {0.5, 0.77}, {0.9, 0.05}}) {
    const Eigen::MatrixXd d = s.derivatives(u, v, 2);
    const Eigen::MatrixXd du = (s.derivatives(u + h, v, 1) - s.derivatives(u - h, v, 1)) / (2 * h);
    const Eigen::MatrixXd dv = (s.derivatives(u, v + h, 1) - s.derivatives(u, v - h, 1)) / (2 * h);
    CHECK((d.row(1) - du.row(0)).norm() < 1e-7);
    CHECK((d.row(2) - dv.row(0)).norm() < 1e-7);
    CHECK((d.row(3) - du.row(1)).norm() < 1e-5);
    CHECK((d.row(4) - dv.row(1)).norm() < 1e-5);
    CHECK((d.row(5) - dv.row(2)).norm() < 1e-5);
  }
}

TEST_CASE("Gauss-Legendre rules integrate polynomials of degree 2n-1 exactly",
          "[unit][quadrature]") {
  const int n = GENERATE(1, 2, 3, 5, 8, 12);
  const QuadratureRule q = gauss_legendre(n, 0.0, 2.0);
  for (int k = 0; k <= 2 * n - 1; ++k) {
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += q.weights[i] * std::pow(q.points[i], k);
    CHECK(s == Approx(std::pow(2.0, k + 1) / (k + 1)).epsilon(1e-13));
  }
}
