// The active-set nonnegative quadratic program of the ridge-family fit
// (knit/meso/fit/nnls.hpp): its KKT conditions, hand-solved cases, and the exact optimum that
// Ceres' bounded trust region missed.
#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <catch2/catch.hpp>
#include <random>

#include "knit/meso/fit/nnls.hpp"

using knit::meso::fit::kkt_violation;
using knit::meso::fit::nnls_normal;

namespace {

/// A random symmetric positive definite n x n matrix with condition number ~ `cond` and a
/// right-hand side whose unconstrained solution has both signs.
void random_problem(int n, double cond, unsigned seed, Eigen::MatrixXd& M, Eigen::VectorXd& b) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N01;
  Eigen::MatrixXd A(n, n);
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r) A(r, c) = N01(rng);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd Q = qr.householderQ();
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) d(i) = std::pow(cond, -double(i) / std::max(1, n - 1));
  M = Q * d.asDiagonal() * Q.transpose();
  M = 0.5 * (M + M.transpose()).eval();
  b.resize(n);
  for (int i = 0; i < n; ++i) b(i) = N01(rng);
}

double objective(const Eigen::MatrixXd& M, const Eigen::VectorXd& b, const Eigen::VectorXd& x) {
  return 0.5 * x.dot(M * x) - b.dot(x);
}

}  // namespace

TEST_CASE("nnls: a 2 x 2 case solved by hand", "[unit]") {
  // M = [[2, 1], [1, 2]], b = (1, -3): unconstrained x = (5/3, -7/3); with x >= 0 the
  // second is at its bound and the first solves 2 x1 = 1: x = (0.5, 0), g = (0, 3.5) >= 0.
  Eigen::MatrixXd M(2, 2);
  M << 2, 1, 1, 2;
  const Eigen::Vector2d b(1, -3);
  const auto r = nnls_normal(M, b);
  REQUIRE(r.converged);
  CHECK(r.x(0) == Approx(0.5).margin(1e-15));
  CHECK(r.x(1) == 0.0);
  CHECK(r.passive == 1);
  CHECK(r.kkt <= 1e-15);
  // Every coefficient wants to be positive: the unconstrained solution.
  const Eigen::Vector2d b2(3, 3);
  const auto r2 = nnls_normal(M, b2);
  CHECK(r2.x(0) == Approx(1.0));
  CHECK(r2.x(1) == Approx(1.0));
  // None does: x = 0.
  const auto r3 = nnls_normal(M, Eigen::Vector2d(-1, -1));
  CHECK(r3.x.isZero(0.0));
  CHECK(r3.iterations == 0);
}

TEST_CASE("nnls: the KKT conditions hold at the end, on random problems", "[unit]") {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const int n = 10 + 15 * int(seed % 4);
    const double cond = seed % 2 ? 1e3 : 1e8;
    Eigen::MatrixXd M;
    Eigen::VectorXd b;
    random_problem(n, cond, seed, M, b);
    const auto r = nnls_normal(M, b);
    INFO("seed " << seed << " n " << n << " cond " << cond << ": " << r.reason);
    REQUIRE(r.converged);
    CHECK((r.x.array() >= 0.0).all());
    CHECK(r.kkt <= 1e-9);
    CHECK(r.kkt == kkt_violation(M, b, r.x));
    // No feasible perturbation lowers the objective: each coordinate moved by +-1e-6 (kept
    // >= 0) and the projection of a random direction.
    const double f = objective(M, b, r.x);
    for (int i = 0; i < n; ++i)
      for (double h : {1e-6, -1e-6}) {
        Eigen::VectorXd y = r.x;
        y(i) = std::max(0.0, y(i) + h);
        CHECK(objective(M, b, y) >= f - 1e-12 * (1.0 + std::abs(f)));
      }
  }
}

TEST_CASE("nnls: equals brute force over every passive set of a small problem", "[unit]") {
  // For n = 8 the optimum is the best of the 2^8 passive sets whose solution is feasible.
  for (unsigned seed = 21; seed <= 26; ++seed) {
    Eigen::MatrixXd M;
    Eigen::VectorXd b;
    random_problem(8, 1e4, seed, M, b);
    double best = 0.0;  // x = 0
    for (int mask = 1; mask < 256; ++mask) {
      std::vector<int> P;
      for (int i = 0; i < 8; ++i)
        if (mask & (1 << i)) P.push_back(i);
      Eigen::MatrixXd MP(P.size(), P.size());
      Eigen::VectorXd bP(P.size());
      for (std::size_t r = 0; r < P.size(); ++r) {
        bP(r) = b(P[r]);
        for (std::size_t c = 0; c < P.size(); ++c) MP(r, c) = M(P[r], P[c]);
      }
      const Eigen::VectorXd xP = MP.llt().solve(bP);
      if ((xP.array() < 0.0).any()) continue;
      Eigen::VectorXd x = Eigen::VectorXd::Zero(8);
      for (std::size_t r = 0; r < P.size(); ++r) x(P[r]) = xP(r);
      best = std::min(best, objective(M, b, x));
    }
    const auto r = nnls_normal(M, b);
    REQUIRE(r.converged);
    CHECK(objective(M, b, r.x) == Approx(best).epsilon(1e-10));
  }
}

TEST_CASE("nnls: bad input and an iteration limit are reported", "[unit]") {
  Eigen::MatrixXd M = Eigen::MatrixXd::Identity(3, 3);
  CHECK_THROWS_AS(nnls_normal(M, Eigen::VectorXd::Ones(2)), std::invalid_argument);
  M(1, 1) = std::nan("");
  CHECK_THROWS_AS(nnls_normal(M, Eigen::VectorXd::Ones(3)), std::invalid_argument);
  Eigen::VectorXd b;
  random_problem(30, 1e3, 5, M, b);
  const auto r = nnls_normal(M, b, 2);
  CHECK_FALSE(r.converged);
  CHECK(r.reason.find("no convergence in 2") != std::string::npos);
  // Not positive definite: the passive solve says so.
  Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(2, 2);
  const auto z = nnls_normal(Z, Eigen::Vector2d(1, 1));
  CHECK_FALSE(z.converged);
  CHECK(z.reason.find("not positive definite") != std::string::npos);
}

TEST_CASE("nnls: the KKT violation by hand, relative to the largest |b_i|", "[unit]") {
  // g = M x - b. A variable at its bound violates by max(0, -g_i) (it would lower the
  // objective by growing), a positive one by |g_i|; the worst over the largest |b_i|.
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(2, 2);
  CHECK(kkt_violation(I, Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 0)) == 1.0);
  // b = (2, -1) at x = 0: g = (-2, 1); the first wants to grow by 2, the second is content.
  CHECK(kkt_violation(I, Eigen::Vector2d(2, -1), Eigen::Vector2d(0, 0)) == 1.0);
  // b = (4, -1) at x = (3, 0): g = (-1, 1); the positive first is off by 1, of |b|max = 4.
  CHECK(kkt_violation(I, Eigen::Vector2d(4, -1), Eigen::Vector2d(3, 0)) == 0.25);
  // ... and at x = (5, 0) by 1 the other way (|g|, not -g, for a positive variable).
  CHECK(kkt_violation(I, Eigen::Vector2d(4, -1), Eigen::Vector2d(5, 0)) == 0.25);
  // A variable at its bound with g > 0 is no violation, however large g.
  CHECK(kkt_violation(I, Eigen::Vector2d(4, -100), Eigen::Vector2d(4, 0)) == 0.0);
  // The optimum of the 2 x 2 case above: none.
  Eigen::MatrixXd M(2, 2);
  M << 2, 1, 1, 2;
  CHECK(kkt_violation(M, Eigen::Vector2d(1, -3), Eigen::Vector2d(0.5, 0)) == 0.0);
  // b = 0 does not divide by zero.
  CHECK(std::isfinite(kkt_violation(I, Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0))));
}
