#include "knit/spline/fit.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>
#include <string>

#include "knit/spline/basis.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::spline {

namespace {

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(10);
  s << x;
  return s.str();
}

void check_weights(const Eigen::VectorXd& w, int n, const char* what) {
  if (w.size() == 0) return;
  if (w.size() != n)
    throw FitError(std::string(what) + ": " + std::to_string(w.size()) + " NURBS weights for " +
                   std::to_string(n) + " basis functions");
  for (int i = 0; i < n; ++i)
    if (!(w(i) > 0.0))
      throw FitError(std::string(what) + ": NURBS weight " + std::to_string(i) +
                     " is not positive");
}

// Non-rational collocation matrix at the Greville abscissae, with the left limit at a C^{-1}
// break for the function that ends there (see fit.hpp).
Eigen::MatrixXd greville_matrix(const BSplineBasis& b) {
  const int n = b.size(), p = b.degree();
  const std::vector<double>& U = b.knots();
  const std::vector<double> g = b.greville();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  double N[kMaxDegree + 1];
  for (int i = 0; i < n; ++i) {
    int span = b.find_span(g[i]);
    if (span - p > i) {
      // g_i is the right end of N_i's support: use the last non-empty span left of g_i.
      span = i + p;
      while (span > p && !(U[span] < U[span + 1])) --span;
    }
    basis_funs(span, g[i], p, U, N);
    for (int j = 0; j <= p; ++j) A(i, span - p + j) = N[j];
  }
  return A;
}

// W(t) = sum_i w_i N_i(t) at the Greville points, with the same limit rule as greville_matrix.
Eigen::VectorXd greville_W(const Eigen::MatrixXd& A, const Eigen::VectorXd& w) {
  return A * w;
}

void check_values(const Eigen::MatrixXd& values, Eigen::Index rows, const char* what) {
  if (values.rows() != rows)
    throw FitError(std::string(what) + ": " + std::to_string(values.rows()) + " values given, " +
                   std::to_string(rows) + " needed (one per Greville point)");
  if (!values.allFinite())
    throw FitError(std::string(what) + ": the values contain NaN or infinity");
}

}  // namespace

Eigen::MatrixXd collocation_matrix(const BSplineBasis& basis, const std::vector<double>& t,
                                   int derivative, const Eigen::VectorXd& weights) {
  const int n = basis.size(), p = basis.degree();
  check_weights(weights, n, "collocation_matrix");
  const SplineCurve c(basis, Eigen::MatrixXd::Zero(n, 1), weights);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(t.size()), n);
  Eigen::MatrixXd R(derivative + 1, p + 1);
  for (size_t k = 0; k < t.size(); ++k) {
    const int first = c.basis_derivatives(t[k], derivative, R);
    B.block(static_cast<Eigen::Index>(k), first, 1, p + 1) = R.row(derivative);
  }
  return B;
}

Eigen::MatrixXd interpolate_at_greville(const BSplineBasis& basis, const Eigen::MatrixXd& values,
                                        const Eigen::VectorXd& weights) {
  const int n = basis.size();
  check_values(values, n, "interpolate_at_greville");
  check_weights(weights, n, "interpolate_at_greville");
  const Eigen::MatrixXd A = greville_matrix(basis);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
  if (weights.size() == 0) return lu.solve(values);
  // Rational: interpolate W f, then divide by the weights.
  const Eigen::VectorXd W = greville_W(A, weights);
  const Eigen::MatrixXd WF = values.array().colwise() * W.array();
  Eigen::MatrixXd Pw = lu.solve(WF);
  return Pw.array().colwise() / weights.array();
}

SplineCurve interpolate_function(const BSplineBasis& basis,
                                 const std::function<Eigen::VectorXd(double)>& f,
                                 const Eigen::VectorXd& weights) {
  const std::vector<double> g = basis.greville();
  Eigen::MatrixXd values;
  for (int i = 0; i < static_cast<int>(g.size()); ++i) {
    const Eigen::VectorXd y = f(g[i]);
    if (i == 0) values.resize(static_cast<Eigen::Index>(g.size()), y.size());
    if (y.size() != values.cols())
      throw FitError("interpolate_function: f returned vectors of different sizes");
    values.row(i) = y.transpose();
  }
  return SplineCurve(basis, interpolate_at_greville(basis, values, weights), weights);
}

Eigen::MatrixXd interpolate_at_greville(const BSplineBasis& bu, const BSplineBasis& bv,
                                        const Eigen::MatrixXd& values,
                                        const Eigen::VectorXd& weights) {
  const int nu = bu.size(), nv = bv.size();
  const Eigen::Index dim = values.cols();
  check_values(values, static_cast<Eigen::Index>(nu) * nv, "interpolate_at_greville (surface)");
  check_weights(weights, nu * nv, "interpolate_at_greville (surface)");
  const Eigen::MatrixXd Au = greville_matrix(bu), Av = greville_matrix(bv);
  // F(i, j) per coordinate; rational: multiply by W(g_i, g_j) = sum w_ab N_a(g_i) N_b(g_j).
  Eigen::MatrixXd F = values;
  if (weights.size() > 0) {
    const Eigen::Map<const Eigen::MatrixXd> w(weights.data(), nu, nv);
    const Eigen::MatrixXd W = Au * w * Av.transpose();
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) F.row(i + nu * j) *= W(i, j);
  }
  // Solve Au X Av^T = F per coordinate: X = Au^{-1} F Av^{-T}.
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu_u(Au), lu_v(Av);
  Eigen::MatrixXd P(static_cast<Eigen::Index>(nu) * nv, dim);
  for (Eigen::Index d = 0; d < dim; ++d) {
    const Eigen::Map<const Eigen::MatrixXd> Fd(F.col(d).data(), nu, nv);
    const Eigen::MatrixXd Y = lu_u.solve(Fd);                         // nu x nv
    const Eigen::MatrixXd X = lu_v.solve(Y.transpose()).transpose();  // nu x nv
    P.col(d) = Eigen::Map<const Eigen::VectorXd>(X.data(), static_cast<Eigen::Index>(nu) * nv);
  }
  if (weights.size() > 0) P = P.array().colwise() / weights.array();
  return P;
}

SplineSurface interpolate_function(const BSplineBasis& bu, const BSplineBasis& bv,
                                   const std::function<Eigen::VectorXd(double, double)>& f,
                                   const Eigen::VectorXd& weights) {
  const std::vector<double> gu = bu.greville(), gv = bv.greville();
  const int nu = bu.size(), nv = bv.size();
  Eigen::MatrixXd values;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const Eigen::VectorXd y = f(gu[i], gv[j]);
      if (values.size() == 0) values.resize(static_cast<Eigen::Index>(nu) * nv, y.size());
      if (y.size() != values.cols())
        throw FitError("interpolate_function: f returned vectors of different sizes");
      values.row(i + nu * j) = y.transpose();
    }
  return SplineSurface(bu, bv, interpolate_at_greville(bu, bv, values, weights), weights);
}

// --- Least squares ----------------------------------------------------------------------------

namespace {

// Shared solver: B (N x n) collocation matrix, Q (N x dim) data, c data weights, fixed points.
// `describe(i)` names basis function i and its support for error messages.
LeastSquaresResult solve_least_squares(const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                                       const LeastSquaresOptions& o,
                                       const std::map<int, Eigen::RowVectorXd>& fixed,
                                       const std::function<std::string(int)>& describe,
                                       const char* what) {
  const Eigen::Index N = B.rows(), n = B.cols(), dim = Q.cols();
  Eigen::VectorXd c = o.data_weights.size() ? o.data_weights : Eigen::VectorXd::Ones(N);
  if (c.size() != N)
    throw FitError(std::string(what) + ": " + std::to_string(c.size()) + " data weights for " +
                   std::to_string(N) + " samples");
  for (Eigen::Index k = 0; k < N; ++k)
    if (!(c(k) >= 0.0) || !std::isfinite(c(k)))
      throw FitError(std::string(what) + ": data weight " + std::to_string(k) +
                     " is negative or not finite");
  if (!Q.allFinite())
    throw FitError(std::string(what) + ": the sample values contain NaN or infinity");
  // Free columns.
  std::vector<int> free_cols;
  Eigen::MatrixXd Pfix = Eigen::MatrixXd::Zero(n, dim);
  for (const auto& [idx, val] : fixed) {
    if (idx < 0 || idx >= n)
      throw FitError(std::string(what) + ": fixed control point " + std::to_string(idx) +
                     " does not exist");
    if (val.size() != dim)
      throw FitError(std::string(what) + ": fixed control point " + std::to_string(idx) + " has " +
                     std::to_string(val.size()) + " coordinates, the data " + std::to_string(dim));
    Pfix.row(idx) = val;
  }
  for (int i = 0; i < n; ++i)
    if (!fixed.count(i)) free_cols.push_back(i);
  // Every free basis function needs data in its support (a necessary condition, with a message
  // that says where data are missing).
  for (int i : free_cols) {
    bool seen = false;
    for (Eigen::Index k = 0; k < N && !seen; ++k) seen = c(k) > 0.0 && B(k, i) != 0.0;
    if (!seen)
      throw FitError(std::string(what) + ": " + describe(i) +
                     " has no data in its support; add samples there or use a coarser basis");
  }
  const Eigen::Index nf = static_cast<Eigen::Index>(free_cols.size());
  LeastSquaresResult res;
  res.P = Pfix;
  if (nf > 0) {
    const Eigen::VectorXd sc = c.cwiseSqrt();
    Eigen::MatrixXd A(N, nf);
    for (Eigen::Index f = 0; f < nf; ++f) A.col(f) = sc.cwiseProduct(B.col(free_cols[f]));
    const Eigen::MatrixXd rhs = sc.asDiagonal() * (Q - B * Pfix);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    qr.setThreshold(o.rank_tolerance);
    res.rank = static_cast<int>(qr.rank());
    if (res.rank < nf)
      throw FitError(
          std::string(what) + ": the samples determine only " + std::to_string(res.rank) +
          " of the " + std::to_string(nf) +
          " free control points (rank-deficient collocation matrix: the Schoenberg-Whitney "
          "condition fails; add samples or use a coarser basis)");
    const Eigen::MatrixXd X = qr.solve(rhs);
    for (Eigen::Index f = 0; f < nf; ++f) res.P.row(free_cols[f]) = X.row(f);
  }
  const Eigen::MatrixXd r = B * res.P - Q;
  double sw = 0.0, s2 = 0.0;
  for (Eigen::Index k = 0; k < N; ++k) {
    if (c(k) <= 0.0) continue;
    const double rk = r.row(k).norm();
    sw += c(k);
    s2 += c(k) * rk * rk;
    res.max_residual = std::max(res.max_residual, rk);
  }
  res.rms_residual = sw > 0.0 ? std::sqrt(s2 / sw) : 0.0;
  return res;
}

}  // namespace

LeastSquaresResult least_squares(const BSplineBasis& basis, const std::vector<double>& t,
                                 const Eigen::MatrixXd& values,
                                 const LeastSquaresOptions& options) {
  const char* what = "least_squares (curve)";
  if (static_cast<Eigen::Index>(t.size()) != values.rows())
    throw FitError(std::string(what) + ": " + std::to_string(t.size()) + " parameters but " +
                   std::to_string(values.rows()) + " sample values");
  for (size_t k = 0; k < t.size(); ++k)
    if (!std::isfinite(t[k]) || t[k] < basis.lo() || t[k] > basis.hi())
      throw FitError(std::string(what) + ": parameter " + std::to_string(k) + " (" + fmt(t[k]) +
                     ") is outside the domain [" + fmt(basis.lo()) + ", " + fmt(basis.hi()) + "]");
  const Eigen::MatrixXd B = collocation_matrix(basis, t, 0, options.basis_weights);
  std::map<int, Eigen::RowVectorXd> fixed = options.fixed;
  if (options.interpolate_ends) {
    const int n = basis.size();
    for (auto [idx, end] : {std::pair{0, basis.lo()}, std::pair{n - 1, basis.hi()}}) {
      size_t k = 0;
      while (k < t.size() && t[k] != end) ++k;
      if (k == t.size())
        throw FitError(std::string(what) + ": interpolate_ends needs a sample at the domain end " +
                       fmt(end));
      fixed[idx] = values.row(static_cast<Eigen::Index>(k));
    }
  }
  const std::vector<double>& U = basis.knots();
  const int p = basis.degree();
  auto describe = [&](int i) {
    return "basis function " + std::to_string(i) + " (support [" + fmt(U[i]) + ", " +
           fmt(U[i + p + 1]) + "])";
  };
  return solve_least_squares(B, values, options, fixed, describe, what);
}

LeastSquaresResult least_squares(const BSplineBasis& bu, const BSplineBasis& bv,
                                 const std::vector<double>& u, const std::vector<double>& v,
                                 const Eigen::MatrixXd& values,
                                 const LeastSquaresOptions& options) {
  const char* what = "least_squares (surface)";
  const Eigen::Index N = values.rows();
  if (static_cast<Eigen::Index>(u.size()) != N || static_cast<Eigen::Index>(v.size()) != N)
    throw FitError(std::string(what) + ": " + std::to_string(u.size()) + " u and " +
                   std::to_string(v.size()) + " v parameters but " + std::to_string(N) +
                   " sample values");
  if (options.interpolate_ends)
    throw FitError(std::string(what) +
                   ": interpolate_ends applies to curves; fix surface control points with `fixed`");
  const int nu = bu.size(), nv = bv.size(), n = nu * nv;
  check_weights(options.basis_weights, n, what);
  for (Eigen::Index k = 0; k < N; ++k)
    if (!(u[k] >= bu.lo() && u[k] <= bu.hi() && v[k] >= bv.lo() && v[k] <= bv.hi()))
      throw FitError(std::string(what) + ": sample " + std::to_string(k) + " (" + fmt(u[k]) + ", " +
                     fmt(v[k]) + ") is outside the domain");
  const SplineSurface s(bu, bv, Eigen::MatrixXd::Zero(n, 1), options.basis_weights);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(N, n);
  SurfaceBasis sb;
  for (Eigen::Index k = 0; k < N; ++k) {
    s.basis(u[k], v[k], 0, sb);
    for (Eigen::Index l = 0; l < sb.index.size(); ++l) B(k, sb.index(l)) = sb.R(0, l);
  }
  const std::vector<double>&U = bu.knots(), &V = bv.knots();
  const int pu = bu.degree(), pv = bv.degree();
  auto describe = [&](int a) {
    const int i = a % nu, j = a / nu;
    return "basis function (" + std::to_string(i) + ", " + std::to_string(j) + ") (support [" +
           fmt(U[i]) + ", " + fmt(U[i + pu + 1]) + "] x [" + fmt(V[j]) + ", " + fmt(V[j + pv + 1]) +
           "])";
  };
  return solve_least_squares(B, values, options, options.fixed, describe, what);
}

}  // namespace knit::spline
