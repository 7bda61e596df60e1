// Nonnegative quadratic program of the ridge-family energy fit (docs/database.md, "Fit of the
// ridge family"): the law is linear in its coefficients and convex for every x >= 0, so its fit
// is
//
//   min_x  1/2 x^T M x - b^T x   subject to  x >= 0,      M symmetric positive definite,
//
// the normal-equation form of nonnegative least squares. Solved exactly by the active-set
// method of Lawson & Hanson ("Solving Least Squares Problems", 1974, ch. 23, algorithm NNLS) in
// the normal-equation form of Bro & de Jong ("A fast non-negativity-constrained least squares
// algorithm", J. Chemometrics 11, 1997): variables enter the passive (free) set one at a time,
// each passive subproblem is an unconstrained solve with M restricted to the passive set
// (its Cholesky factor grows by one row when a variable enters and is refactored when
// variables leave), and a step that would make a passive variable negative is cut at the bound.
// It ends at a point that satisfies the Karush-Kuhn-Tucker conditions to round-off:
//   g = M x - b,  g_i = 0 where x_i > 0,  g_i >= 0 where x_i = 0.
// Why not Ceres with parameter bounds (what the fit used until session 14): its projected
// trust-region steps stopped (function tolerance) at a KKT violation of 5 % of |b| on the
// default database's 42-function fit, with an objective 1.8 % of |optimum| above the optimum.
#pragma once

#include <Eigen/Core>
#include <string>

namespace knit::meso::fit {

struct NnlsResult {
  Eigen::VectorXd x;   ///< the minimizer (x >= 0 exactly)
  int iterations = 0;  ///< passive-set solves
  int passive = 0;     ///< coefficients > 0 at the end
  double kkt = 0.0;    ///< kkt_violation(M, b, x)
  bool converged = false;
  std::string reason;  ///< why not converged (empty if converged)
};

/// Largest violation of the KKT conditions above, relative to max(|b|_inf, tiny):
/// max_i (x_i > 0 ? |g_i| : max(0, -g_i)) / |b|_inf.
double kkt_violation(const Eigen::MatrixXd& M, const Eigen::VectorXd& b, const Eigen::VectorXd& x);

/// The minimizer of 1/2 x^T M x - b^T x over x >= 0 (M symmetric positive definite; the full
/// matrix is read). max_iterations <= 0: 20 n + 50 passive-set solves. Throws std::invalid_argument
/// on mismatched sizes or non-finite entries.
NnlsResult nnls_normal(const Eigen::MatrixXd& M, const Eigen::VectorXd& b, int max_iterations = 0);

}  // namespace knit::meso::fit
