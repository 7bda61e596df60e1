// Hidden timing of the hot-path kernels (run: bin/test_common "[.bench]" -s). Prints ns per call.
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>

#include "knit/spline/curve.hpp"
#include "knit/spline/knot_vector.hpp"
#include "knit/spline/surface.hpp"

using namespace knit::spline;

TEST_CASE("spline kernel timings", "[.bench][spline]") {
  using clock = std::chrono::steady_clock;
  const int N = 2000000;
  {
    const BSplineBasis b(3, uniform_knots(3, 8));
    const int n = b.size() * b.size();
    const SplineSurface s(b, b, Eigen::MatrixXd::Random(n, 3), Eigen::VectorXd::Constant(n, 1.3));
    SurfaceBasis sb;
    double acc = 0.0;
    const auto t0 = clock::now();
    for (int k = 0; k < N; ++k) {
      const double u = (k % 997) / 997.0, v = (k % 991) / 991.0;
      s.basis(u, v, 2, sb);
      acc += sb.R(4, 5);
    }
    const double ns = std::chrono::duration<double, std::nano>(clock::now() - t0).count() / N;
    std::printf("SplineSurface::basis (p = 3, NURBS, nder = 2): %.1f ns/call (checksum %g)\n", ns,
                acc);
    CHECK(ns > 0.0);
  }
  {
    const BSplineBasis b(4, uniform_knots(4, 12));
    const SplineCurve c(b, Eigen::MatrixXd::Random(b.size(), 3),
                        Eigen::VectorXd::Constant(b.size(), 0.7));
    Eigen::MatrixXd R(4, 5);
    double acc = 0.0;
    const auto t0 = clock::now();
    for (int k = 0; k < N; ++k) {
      c.basis_derivatives((k % 997) / 997.0, 3, R);
      acc += R(3, 2);
    }
    const double ns = std::chrono::duration<double, std::nano>(clock::now() - t0).count() / N;
    std::printf(
        "SplineCurve::basis_derivatives (p = 4, NURBS, nder = 3): %.1f ns/call (checksum %g)\n", ns,
        acc);
    CHECK(ns > 0.0);
  }
}
