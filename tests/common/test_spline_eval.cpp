// Evaluation of curves and surfaces: rational partition of unity, every derivative against finite
// differences (curves to 3rd order, surfaces to 2nd, B-spline and NURBS), continuity C^{p-r} at a
// knot of multiplicity r, and exact values at both ends of the domain.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "knit/spline/basis.hpp"
#include "knit/spline/curve.hpp"
#include "knit/spline/knot_vector.hpp"
#include "knit/spline/surface.hpp"

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

// Knots on [2, 5] with a double interior knot, degree p.
std::vector<double> test_knots(int p) {
  std::vector<double> U(p + 1, 2.0);
  for (double k : {2.4, 3.1, 3.1, 4.2}) U.push_back(k);
  U.insert(U.end(), p + 1, 5.0);
  return U;
}

}  // namespace

TEST_CASE("rational curve and surface bases are a non-negative partition of unity",
          "[unit][spline][eval]") {
  const int p = 3;
  const BSplineBasis b(p, test_knots(p));
  const Eigen::VectorXd w = random_matrix(b.size(), 1, 1, 0.2, 3.0);
  const SplineCurve c(b, Eigen::MatrixXd::Zero(b.size(), 1), w);
  Eigen::MatrixXd R(3, p + 1);
  for (int i = 0; i <= 100; ++i) {
    c.basis_derivatives(2.0 + 3.0 * i / 100.0, 2, R);
    CHECK(R.row(0).sum() == Approx(1.0).epsilon(1e-14));
    CHECK(R.row(0).minCoeff() >= 0.0);
    CHECK(std::abs(R.row(1).sum()) < 1e-12);  // derivatives of a constant sum
    CHECK(std::abs(R.row(2).sum()) < 1e-10);
  }
  const BSplineBasis bv(2, uniform_knots(2, 3, -1.0, 1.0));
  const int n = b.size() * bv.size();
  const SplineSurface s(b, bv, Eigen::MatrixXd::Zero(n, 1), random_matrix(n, 1, 2, 0.2, 3.0));
  SurfaceBasis sb;
  for (int i = 0; i <= 12; ++i)
    for (int j = 0; j <= 12; ++j) {
      s.basis(2.0 + 3.0 * i / 12.0, -1.0 + 2.0 * j / 12.0, 2, sb);
      CHECK(sb.R.row(0).sum() == Approx(1.0).epsilon(1e-14));
      CHECK(sb.R.row(0).minCoeff() >= 0.0);
      for (int r = 1; r < 6; ++r) CHECK(std::abs(sb.R.row(r).sum()) < 1e-10);
    }
}

TEST_CASE("curve derivatives up to 3rd order match finite differences", "[unit][spline][eval]") {
  const int p = GENERATE(3, 4, 5);
  const bool rational = GENERATE(false, true);
  const BSplineBasis b(p, test_knots(p));
  const Eigen::MatrixXd P = random_matrix(b.size(), 3, 10 + p);
  const Eigen::VectorXd w =
      rational ? Eigen::VectorXd(random_matrix(b.size(), 1, 20 + p, 0.3, 2.0)) : Eigen::VectorXd();
  const SplineCurve c(b, P, w);
  const double h = 1e-6;
  // Interior points of spans (finite differences must not straddle a knot), and near both ends.
  for (double u : {2.0 + 1e-5, 2.2, 2.9, 3.5, 4.6, 5.0 - 1e-5}) {
    const Eigen::MatrixXd d = c.derivatives(u, 3);
    const Eigen::MatrixXd dp = c.derivatives(u + h, 2), dm = c.derivatives(u - h, 2);
    for (int k = 1; k <= 3; ++k) {
      const Eigen::RowVectorXd fd = (dp.row(k - 1) - dm.row(k - 1)) / (2 * h);
      CHECK((d.row(k) - fd).norm() <
            1e-6 * (1.0 + d.row(k).norm() + d.row(std::min(k + 1, 3)).norm()));
    }
  }
}

TEST_CASE("surface derivatives up to 2nd order match finite differences", "[unit][spline][eval]") {
  const bool rational = GENERATE(false, true);
  const BSplineBasis bu(3, test_knots(3)), bv(2, {0, 0, 0, 0.3, 0.3, 1, 1, 1});
  const int n = bu.size() * bv.size();
  const Eigen::MatrixXd P = random_matrix(n, 3, 41);
  const Eigen::VectorXd w =
      rational ? Eigen::VectorXd(random_matrix(n, 1, 42, 0.3, 2.0)) : Eigen::VectorXd();
  const SplineSurface s(bu, bv, P, w);
  const double h = 1e-6;
  for (auto [u, v] : {std::pair{2.1, 0.1}, {3.3, 0.5}, {4.9, 0.95}, {2.0 + 1e-5, 1.0 - 1e-5}}) {
    const Eigen::MatrixXd d = s.derivatives(u, v, 2);
    const Eigen::MatrixXd du = (s.derivatives(u + h, v, 1) - s.derivatives(u - h, v, 1)) / (2 * h);
    const Eigen::MatrixXd dv = (s.derivatives(u, v + h, 1) - s.derivatives(u, v - h, 1)) / (2 * h);
    const double scale = 1.0 + d.norm();
    CHECK((d.row(1) - du.row(0)).norm() < 1e-7 * scale);  // S_u
    CHECK((d.row(2) - dv.row(0)).norm() < 1e-7 * scale);  // S_v
    CHECK((d.row(3) - du.row(1)).norm() < 1e-6 * scale);  // S_uu
    CHECK((d.row(4) - dv.row(1)).norm() < 1e-6 * scale);  // S_uv = d/dv S_u
    CHECK((d.row(4) - du.row(2)).norm() < 1e-6 * scale);  // S_uv = d/du S_v
    CHECK((d.row(5) - dv.row(2)).norm() < 1e-6 * scale);  // S_vv
    // The basis rows reproduce derivatives() and the evaluation with nder = 0/1 agrees.
    CHECK((s.derivatives(u, v, 0).row(0) - d.row(0)).norm() < 1e-14);
    CHECK((s.derivatives(u, v, 1).row(2) - d.row(2)).norm() < 1e-13);
  }
}

TEST_CASE("a knot of multiplicity r gives continuity C^(p-r)", "[unit][spline][eval]") {
  // Left and right limits at the knot are the two polynomial pieces evaluated exactly there.
  const int p = 4;
  for (int r = 1; r <= p; ++r) {
    std::vector<double> U(p + 1, 0.0);
    U.insert(U.end(), r, 0.5);
    U.insert(U.end(), p + 1, 1.0);
    const BSplineBasis b(p, U);
    const Eigen::MatrixXd P = random_matrix(b.size(), 2, 100 + r);
    const int right = b.find_span(0.5), left = p;  // spans [0, 0.5) and [0.5, 1)
    REQUIRE(right == p + r);
    Eigen::MatrixXd Nl(p + 1, p + 1), Nr(p + 1, p + 1);
    ders_basis_funs(left, 0.5, p, p, U, Nl);
    ders_basis_funs(right, 0.5, p, p, U, Nr);
    const Eigen::MatrixXd dl = Nl * P.middleRows(left - p, p + 1);
    const Eigen::MatrixXd dr = Nr * P.middleRows(right - p, p + 1);
    for (int k = 0; k <= p - r; ++k)
      CHECK((dl.row(k) - dr.row(k)).norm() < 1e-9 * (1.0 + dl.row(k).norm()));
    // The (p-r+1)-th derivative jumps (random control points: generically non-zero).
    CHECK((dl.row(p - r + 1) - dr.row(p - r + 1)).norm() > 1e-3);
    // The public evaluation at the knot takes the right limit.
    const Eigen::MatrixXd d = SplineCurve(b, P).derivatives(0.5, p);
    CHECK((d - dr).norm() < 1e-9 * (1.0 + dr.norm()));
  }
}

TEST_CASE("evaluation exactly at both ends of the domain", "[unit][spline][eval]") {
  const bool rational = GENERATE(false, true);
  const int p = 3;
  const BSplineBasis b(p, test_knots(p));
  const int n = b.size();
  const Eigen::MatrixXd P = random_matrix(n, 3, 7);
  const Eigen::VectorXd w =
      rational ? Eigen::VectorXd(random_matrix(n, 1, 8, 0.3, 2.0)) : Eigen::VectorXd();
  const SplineCurve c(b, P, w);
  // Clamped: the curve interpolates the end control points exactly.
  CHECK((c.eval(2.0) - P.row(0).transpose()).norm() < 1e-15);
  CHECK((c.eval(5.0) - P.row(n - 1).transpose()).norm() < 1e-15);
  // End tangents (The NURBS Book eq. 3.7 / 4.9): c'(a) = p/(u_{p+1}-u_1) (w_1/w_0) (P_1 - P_0).
  const Eigen::VectorXd w1 = rational ? w : Eigen::VectorXd::Ones(n);
  const Eigen::RowVectorXd t0 = p / (2.4 - 2.0) * (w1(1) / w1(0)) * (P.row(1) - P.row(0));
  const Eigen::RowVectorXd t1 =
      p / (5.0 - 4.2) * (w1(n - 2) / w1(n - 1)) * (P.row(n - 1) - P.row(n - 2));
  CHECK((c.derivatives(2.0, 1).row(1) - t0).norm() < 1e-12 * (1.0 + t0.norm()));
  CHECK((c.derivatives(5.0, 1).row(1) - t1).norm() < 1e-12 * (1.0 + t1.norm()));
  // The basis at the ends: one function is 1, the last span is used at the upper end.
  CHECK(b.find_span(5.0) == n - 1);
  CHECK(b.eval_all(5.0)(n - 1) == 1.0);
  CHECK(b.eval_all(2.0)(0) == 1.0);
  // Surface corners.
  const BSplineBasis bv(2, uniform_knots(2, 2, -1.0, 1.0));
  const int nv = bv.size();
  const Eigen::MatrixXd Ps = random_matrix(n * nv, 2, 9);
  const Eigen::VectorXd ws =
      rational ? Eigen::VectorXd(random_matrix(n * nv, 1, 10, 0.3, 2.0)) : Eigen::VectorXd();
  const SplineSurface s(b, bv, Ps, ws);
  CHECK((s.eval(2.0, -1.0) - Ps.row(0).transpose()).norm() < 1e-15);
  CHECK((s.eval(5.0, -1.0) - Ps.row(n - 1).transpose()).norm() < 1e-15);
  CHECK((s.eval(2.0, 1.0) - Ps.row(n * (nv - 1)).transpose()).norm() < 1e-15);
  CHECK((s.eval(5.0, 1.0) - Ps.row(n * nv - 1).transpose()).norm() < 1e-15);
  // Derivatives at a corner are finite and agree with a one-sided difference.
  const Eigen::MatrixXd d = s.derivatives(5.0, 1.0, 2);
  CHECK(d.allFinite());
  const double h = 1e-6;
  const Eigen::RowVectorXd fdu = (s.eval(5.0, 1.0) - s.eval(5.0 - h, 1.0)).transpose() / h;
  CHECK((d.row(1) - fdu).norm() < 1e-4 * (1.0 + d.row(1).norm()));
}

TEST_CASE("derivative orders outside the supported range are rejected", "[unit][spline][eval]") {
  const BSplineBasis b(2, uniform_knots(2, 2));
  const SplineCurve c(b, Eigen::MatrixXd::Zero(b.size(), 2), Eigen::VectorXd::Ones(b.size()));
  CHECK_THROWS_AS(c.derivatives(0.5, kMaxDerivative + 1), std::invalid_argument);
  CHECK_THROWS_AS(c.derivatives(0.5, -1), std::invalid_argument);
  Eigen::MatrixXd R(2, 2);
  CHECK_THROWS_AS(c.basis_derivatives(0.5, 1, R), std::invalid_argument);
  // Non-rational curves have no such limit: derivatives above p vanish.
  const SplineCurve nr(b, Eigen::MatrixXd::Ones(b.size(), 1));
  CHECK(nr.derivatives(0.3, 6).bottomRows(4).norm() == 0.0);
  const SplineSurface s(b, b, Eigen::MatrixXd::Zero(b.size() * b.size(), 1));
  SurfaceBasis sb;
  CHECK_THROWS_AS(s.basis(0.5, 0.5, 3, sb), std::invalid_argument);
}
