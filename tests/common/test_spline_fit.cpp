// Greville interpolation reproduces every function of the spline space; least squares recovers a
// spline from noise-free samples; rank-deficient data give clear errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "knit/spline/fit.hpp"
#include "knit/spline/knot_vector.hpp"

using namespace knit::spline;

namespace {

Eigen::MatrixXd random_matrix(Eigen::Index r, Eigen::Index c, unsigned seed, double lo = -1.0,
                              double hi = 1.0) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> d(lo, hi);
  Eigen::MatrixXd M(r, c);
  for (Eigen::Index i = 0; i < M.size(); ++i) M.data()[i] = d(gen);
  return M;
}

}  // namespace

TEST_CASE("Greville interpolation reproduces any curve of the space", "[unit][spline][fit]") {
  const int p = GENERATE(1, 2, 3, 5);
  const bool rational = GENERATE(false, true);
  std::vector<double> U(p + 1, 0.0);
  for (double k : {0.1, 0.3, 0.3, 0.55, 0.8}) U.push_back(k);
  U.insert(U.end(), p + 1, 1.0);
  if (p == 1) U = {0, 0, 0.1, 0.3, 0.55, 0.8, 1, 1};
  const BSplineBasis b(p, U);
  const Eigen::MatrixXd P = random_matrix(b.size(), 3, 1 + p);
  const Eigen::VectorXd w =
      rational ? Eigen::VectorXd(random_matrix(b.size(), 1, 5, 0.3, 2.0)) : Eigen::VectorXd();
  const SplineCurve c(b, P, w);
  const SplineCurve f = interpolate_function(
      b, [&](double u) { return c.eval(u); }, w);
  CHECK((f.control_points() - P).cwiseAbs().maxCoeff() < 1e-12);
  // Polynomials of degree <= p are in the (non-rational) space: reproduced everywhere.
  const SplineCurve poly = interpolate_function(
      b, [&](double u) { return Eigen::VectorXd::Constant(1, std::pow(u - 0.4, p) + u); });
  for (int i = 0; i <= 50; ++i) {
    const double u = i / 50.0;
    CHECK(std::abs(poly.eval(u)(0) - (std::pow(u - 0.4, p) + u)) < 1e-12);
  }
}

TEST_CASE("Greville interpolation across a C^-1 break takes one-sided limits",
          "[unit][spline][fit]") {
  const BSplineBasis b(2, {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1});
  const Eigen::MatrixXd P = random_matrix(b.size(), 2, 3);
  const SplineCurve c(b, P);
  const std::vector<double> g = b.greville();
  REQUIRE(g[2] == 0.5);
  REQUIRE(g[3] == 0.5);
  Eigen::MatrixXd values(b.size(), 2);
  for (int i = 0; i < b.size(); ++i) values.row(i) = c.eval(g[i]).transpose();
  values.row(2) = P.row(2);  // left limit at the break is the last control point of the left piece
  CHECK((interpolate_at_greville(b, values) - P).cwiseAbs().maxCoeff() < 1e-13);
}

TEST_CASE("tensor-product Greville interpolation reproduces any surface of the space",
          "[unit][spline][fit]") {
  const bool rational = GENERATE(false, true);
  const BSplineBasis bu(3, uniform_knots(3, 4)), bv(2, {0, 0, 0, 0.2, 0.7, 0.7, 1, 1, 1});
  const int n = bu.size() * bv.size();
  const Eigen::MatrixXd P = random_matrix(n, 4, 8);
  const Eigen::VectorXd w =
      rational ? Eigen::VectorXd(random_matrix(n, 1, 9, 0.3, 2.0)) : Eigen::VectorXd();
  const SplineSurface s(bu, bv, P, w);
  const SplineSurface f = interpolate_function(
      bu, bv, [&](double u, double v) { return s.eval(u, v); }, w);
  CHECK((f.control_points() - P).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("least squares recovers a curve from noise-free samples", "[unit][spline][fit]") {
  const bool rational = GENERATE(false, true);
  const BSplineBasis b(3, {0, 0, 0, 0, 0.25, 0.5, 0.5, 0.75, 1, 1, 1, 1});
  const Eigen::MatrixXd P = random_matrix(b.size(), 3, 12);
  const Eigen::VectorXd w =
      rational ? Eigen::VectorXd(random_matrix(b.size(), 1, 13, 0.3, 2.0)) : Eigen::VectorXd();
  const SplineCurve c(b, P, w);
  std::vector<double> t;
  for (int k = 0; k <= 80; ++k) t.push_back(std::pow(k / 80.0, 1.3));
  Eigen::MatrixXd Q(t.size(), 3);
  for (size_t k = 0; k < t.size(); ++k) Q.row(k) = c.eval(t[k]).transpose();
  LeastSquaresOptions o;
  o.basis_weights = w;
  o.data_weights = random_matrix(t.size(), 1, 4, 0.5, 3.0);
  const LeastSquaresResult r = least_squares(b, t, Q, o);
  CHECK(r.rank == b.size());
  CHECK((r.P - P).cwiseAbs().maxCoeff() < 1e-11);
  CHECK(r.rms_residual < 1e-12);
  CHECK(r.max_residual < 1e-12);
}

TEST_CASE("least squares with data weights: the weighted mean and the weighted RMS",
          "[unit][spline][fit]") {
  // One constant (degree 0 on [0, 1]) fitted to y = 0 and 1 with data weights 1 and 3: the
  // minimizer of sum c_k (P - y_k)^2 is the weighted mean P = 0.75, and the RMS residual is
  // sqrt((1 x 0.75^2 + 3 x 0.25^2) / 4) = sqrt(0.1875) (fit.hpp). Session 32, a mutation audit:
  // squared weights (P = 0.9) and an RMS over the sample count (0.612) survived every test,
  // whose data were exact, so that the weights changed nothing.
  const BSplineBasis b(0, {0, 1});
  LeastSquaresOptions o;
  o.data_weights = Eigen::Vector2d(1.0, 3.0);
  const LeastSquaresResult r = least_squares(b, {0.2, 0.7}, Eigen::Vector2d(0.0, 1.0), o);
  CHECK(r.P(0, 0) == Approx(0.75).epsilon(1e-14));
  CHECK(r.rms_residual == Approx(std::sqrt(0.1875)).epsilon(1e-14));
  CHECK(r.max_residual == Approx(0.75).epsilon(1e-14));
}

TEST_CASE("least squares: a sample of weight 0 is no data", "[unit][spline][fit]") {
  // Session 33 (the fit audit): an outlier of weight 0 counted in max_residual, and a support
  // whose only samples weigh 0 was taken as seen, passed the suite. A line through (0.1, 0.1)
  // and (0.9, 0.9) with an outlier (0.5, 10) of weight 0: the line is exact, residual 0.
  const BSplineBasis b(1, {0, 0, 1, 1});
  LeastSquaresOptions o;
  o.data_weights = Eigen::Vector3d(1.0, 0.0, 1.0);
  const LeastSquaresResult r =
      least_squares(b, {0.1, 0.5, 0.9}, Eigen::Vector3d(0.1, 10.0, 0.9), o);
  CHECK(r.max_residual < 1e-12);
  CHECK(r.rms_residual < 1e-12);
  // Two linear spans; the second's only sample weighs 0: its function has no data.
  const BSplineBasis b2(1, {0, 0, 0.5, 1, 1});
  o.data_weights = Eigen::Vector3d(1.0, 1.0, 0.0);
  CHECK_THROWS_WITH(
      least_squares(b2, {0.0, 0.25, 0.9}, Eigen::Vector3d(1.0, 1.0, 1.0), o),
      Catch::Contains("basis function 2") && Catch::Contains("no data in its support"));
}

TEST_CASE("least squares with interpolated ends and noisy data", "[unit][spline][fit]") {
  const BSplineBasis b(3, uniform_knots(3, 3));
  std::vector<double> t;
  Eigen::MatrixXd Q(61, 1);
  const Eigen::MatrixXd noise = random_matrix(61, 1, 77, -0.01, 0.01);
  for (int k = 0; k <= 60; ++k) {
    t.push_back(k / 60.0);
    Q(k, 0) = std::sin(3.0 * t.back()) + noise(k, 0);
  }
  LeastSquaresOptions o;
  o.interpolate_ends = true;
  const LeastSquaresResult r = least_squares(b, t, Q, o);
  const SplineCurve c(b, r.P);
  CHECK(c.eval(0.0)(0) == Q(0, 0));
  CHECK(c.eval(1.0)(0) == Q(60, 0));
  CHECK(r.rms_residual > 1e-4);  // noise is not interpolated
  CHECK(r.rms_residual < 0.02);
  CHECK(r.max_residual < 0.05);
  // Without data at the end, interpolate_ends is an error.
  const std::vector<double> t2(t.begin(), t.end() - 1);
  CHECK_THROWS_AS(least_squares(b, t2, Q.topRows(60), o), FitError);
}

TEST_CASE("least squares recovers a surface from scattered noise-free samples",
          "[unit][spline][fit]") {
  const bool rational = GENERATE(false, true);
  const BSplineBasis bu(3, uniform_knots(3, 3)), bv(2, uniform_knots(2, 4));
  const int n = bu.size() * bv.size();
  const Eigen::MatrixXd P = random_matrix(n, 2, 31);
  const Eigen::VectorXd w =
      rational ? Eigen::VectorXd(random_matrix(n, 1, 32, 0.3, 2.0)) : Eigen::VectorXd();
  const SplineSurface s(bu, bv, P, w);
  const Eigen::MatrixXd uv = random_matrix(400, 2, 33, 0.0, 1.0);
  std::vector<double> u(400), v(400);
  Eigen::MatrixXd Q(400, 2);
  for (int k = 0; k < 400; ++k) {
    u[k] = uv(k, 0);
    v[k] = uv(k, 1);
    Q.row(k) = s.eval(u[k], v[k]).transpose();
  }
  LeastSquaresOptions o;
  o.basis_weights = w;
  o.fixed[0] = P.row(0);
  const LeastSquaresResult r = least_squares(bu, bv, u, v, Q, o);
  CHECK((r.P - P).cwiseAbs().maxCoeff() < 1e-10);
  CHECK(r.max_residual < 1e-12);
}

TEST_CASE("least squares reports rank-deficient data clearly", "[unit][spline][fit]") {
  const BSplineBasis b(2, uniform_knots(2, 4));
  // No data in the last two spans: functions 4 and 5 have no data in their supports.
  std::vector<double> t = {0.0, 0.1, 0.2, 0.3, 0.4, 0.45};
  const Eigen::MatrixXd Q = Eigen::MatrixXd::Ones(t.size(), 1);
  try {
    least_squares(b, t, Q);
    FAIL("expected FitError");
  } catch (const FitError& e) {
    CHECK_THAT(e.what(), Catch::Contains("basis function 4 (support [0.5, 1])") &&
                             Catch::Contains("no data in its support"));
  }
  // Every function sees data, but two samples cannot determine three linear functions.
  const BSplineBasis b1(1, {0, 0, 0.5, 1, 1});
  CHECK_THROWS_WITH(least_squares(b1, {0.25, 0.75}, Eigen::MatrixXd::Ones(2, 1)),
                    Catch::Contains("rank-deficient"));
  // A surface function without data names its (i, j) index.
  const BSplineBasis bu(1, {0, 0, 0.5, 1, 1});
  CHECK_THROWS_WITH(
      least_squares(bu, bu, {0.1, 0.2, 0.3}, {0.1, 0.3, 0.2}, Eigen::MatrixXd::Ones(3, 1)),
      Catch::Contains("basis function (2, 0)"));
  // Sizes and domains.
  CHECK_THROWS_AS(least_squares(b, {0.5}, Eigen::MatrixXd::Ones(2, 1)), FitError);
  CHECK_THROWS_AS(least_squares(b, {1.5}, Eigen::MatrixXd::Ones(1, 1)), FitError);
  CHECK_THROWS_AS(interpolate_at_greville(b, Eigen::MatrixXd::Ones(2, 1)), FitError);
}
