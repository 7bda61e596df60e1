// Active-set nonnegative quadratic program (knit/meso/fit/nnls.hpp; Lawson & Hanson 1974,
// ch. 23; Bro & de Jong 1997).
#include "knit/meso/fit/nnls.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace knit::meso::fit {

double kkt_violation(const Eigen::MatrixXd& M, const Eigen::VectorXd& b, const Eigen::VectorXd& x) {
  const Eigen::VectorXd g = M * x - b;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    worst = std::max(worst, x(i) > 0.0 ? std::abs(g(i)) : std::max(0.0, -g(i)));
  const double scale = std::max(b.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
  return worst / scale;
}

namespace {

/// The Cholesky factor L (lower, L L^T = M_PP) of the passive set P, in the order of P, kept
/// in one preallocated n x n buffer: a variable that enters appends a row (O(k^2), the common
/// step); variables that leave make it refactor (O(k^3)).
class PassiveFactor {
 public:
  PassiveFactor(const Eigen::MatrixXd& M, const Eigen::VectorXd& b)
      : M_(M), b_(b), L_(M.rows(), M.cols()), y_(M.rows()) {}

  /// Appends variable j to P. False if M_PP would not be positive definite.
  bool append(std::vector<int>& P, int j) {
    const auto k = static_cast<Eigen::Index>(P.size());
    for (Eigen::Index c = 0; c < k; ++c) y_(c) = M_(P[c], j);
    auto l = y_.head(k);
    L_.topLeftCorner(k, k).triangularView<Eigen::Lower>().solveInPlace(l);
    const double d2 = M_(j, j) - l.squaredNorm();
    if (!(d2 > 0.0)) return false;
    L_.row(k).head(k) = l.transpose();
    L_(k, k) = std::sqrt(d2);
    P.push_back(j);
    return true;
  }

  /// Refactors for the passive set P (after variables left it).
  bool refactor(const std::vector<int>& P) {
    const auto k = static_cast<Eigen::Index>(P.size());
    for (Eigen::Index c = 0; c < k; ++c)
      for (Eigen::Index r = c; r < k; ++r) L_(r, c) = M_(P[r], P[c]);
    Eigen::Ref<Eigen::MatrixXd> block = L_.topLeftCorner(k, k);
    const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(block);  // in place: no allocation
    return llt.info() == Eigen::Success;
  }

  /// s = argmin over P (s_i = 0 off P) of 1/2 s^T M s - b^T s: L L^T s_P = b_P.
  bool solve(const std::vector<int>& P, Eigen::VectorXd& s) {
    const auto k = static_cast<Eigen::Index>(P.size());
    for (Eigen::Index c = 0; c < k; ++c) y_(c) = b_(P[c]);
    auto y = y_.head(k);
    const auto Lk = L_.topLeftCorner(k, k).triangularView<Eigen::Lower>();
    Lk.solveInPlace(y);
    Lk.transpose().solveInPlace(y);
    s.setZero();
    for (Eigen::Index c = 0; c < k; ++c) s(P[c]) = y(c);
    return y.allFinite();
  }

 private:
  const Eigen::MatrixXd& M_;
  const Eigen::VectorXd& b_;
  Eigen::MatrixXd L_;
  Eigen::VectorXd y_;
};

}  // namespace

NnlsResult nnls_normal(const Eigen::MatrixXd& M, const Eigen::VectorXd& b, int max_iterations) {
  const Eigen::Index n = b.size();
  if (M.rows() != n || M.cols() != n)
    throw std::invalid_argument("nnls_normal: M must be square with the size of b");
  if (!M.allFinite() || !b.allFinite())
    throw std::invalid_argument("nnls_normal: M and b must be finite");
  NnlsResult out;
  out.x = Eigen::VectorXd::Zero(n);
  if (n == 0) {
    out.converged = true;
    return out;
  }
  // Session 34: 3 n + 50 (Lawson and Hanson's usual bound) stopped the energy fit with a
  // smoothing of 1e-10 or less (3 loop lengths, 675 coefficients: 2,500-4,200 solves; the
  // default 1e-9 took 1,650 of the 2,075).
  const int limit = max_iterations > 0 ? max_iterations : static_cast<int>(20 * n + 50);
  // A variable enters only if its descent direction is clearly positive: the gradient's round-off
  // is ~ eps * |M|_inf * |x|_inf + eps * |b|_inf.
  const double bmax = b.cwiseAbs().maxCoeff();
  const double mmax = M.cwiseAbs().maxCoeff();
  std::vector<char> passive(static_cast<std::size_t>(n), 0),
      refused(static_cast<std::size_t>(n), 0);
  std::vector<int> P;
  P.reserve(static_cast<std::size_t>(n));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), s(n), w = b;
  PassiveFactor factor(M, b);
  auto fail = [&](const std::string& why) {
    out.x = x;
    out.reason = why;
    out.kkt = kkt_violation(M, b, x);
    out.passive = static_cast<int>(P.size());
    return out;
  };
  for (;;) {
    const double tol =
        64.0 * std::numeric_limits<double>::epsilon() * (mmax * x.cwiseAbs().maxCoeff() + bmax);
    Eigen::Index j = -1;
    double wmax = tol;
    for (Eigen::Index i = 0; i < n; ++i)
      if (!passive[i] && !refused[i] && w(i) > wmax) {
        wmax = w(i);
        j = i;
      }
    if (j < 0) break;  // KKT: every variable at its bound has g = -w >= -tol
    passive[j] = 1;
    if (!factor.append(P, static_cast<int>(j)))
      return fail("the passive-set matrix is not positive definite (is M?)");
    for (;;) {
      if (++out.iterations > limit)
        return fail("no convergence in " + std::to_string(limit) + " passive-set solves");
      if (!factor.solve(P, s)) return fail("the passive-set solve is not finite");
      double alpha = 1.0;
      Eigen::Index block = -1;
      for (int i : P)
        if (s(i) <= 0.0) {
          const double d = x(i) - s(i);  // x_i >= 0 >= s_i: d > 0, or d = 0 with x_i = s_i = 0
          const double a = d > 0.0 ? x(i) / d : 0.0;
          if (a < alpha) {
            alpha = a;
            block = i;
          }
        }
      if (block < 0) {
        x = s;
        break;
      }
      // Step to the first bound met; the variables that reach it leave the passive set.
      x += alpha * (s - x);
      x(block) = 0.0;
      P.erase(std::remove_if(P.begin(), P.end(),
                             [&](int i) {
                               if (x(i) > 0.0) return false;
                               x(i) = 0.0;
                               passive[i] = 0;
                               return true;
                             }),
              P.end());
      if (P.empty()) break;
      if (!factor.refactor(P))
        return fail("the passive-set matrix is not positive definite (is M?)");
    }
    if (passive[j]) {
      std::fill(refused.begin(), refused.end(), 0);
    } else {
      // The entering variable was pushed back to its bound (its gain was round-off, or another
      // bound cut the step first): skip it until a variable enters for good, so that the same
      // choice is not made forever. The caller judges the end point by its KKT violation.
      refused[j] = 1;
    }
    w = b - M * x;
  }
  // A variable skipped above that still wants to enter means the method stalled.
  const double tol =
      64.0 * std::numeric_limits<double>::epsilon() * (mmax * x.cwiseAbs().maxCoeff() + bmax);
  for (Eigen::Index i = 0; i < n; ++i)
    if (refused[i] && w(i) > tol)
      return fail("stalled: coefficient " + std::to_string(i) +
                  " would lower the objective but cannot enter the passive set");
  out.x = x;
  out.passive = static_cast<int>(P.size());
  out.kkt = kkt_violation(M, b, x);
  out.converged = true;
  return out;
}

}  // namespace knit::meso::fit
