#include "knit/spline/bspline_basis.hpp"

#include "knit/spline/basis.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::spline {

BSplineBasis::BSplineBasis(int p, std::vector<double> U) : p_(p), U_(std::move(U)) {
  validate_knots(U_, p_, -1, true);
  if (p_ > kMaxDegree)
    throw KnotVectorError(KnotError::kDegreeTooHigh, "degree " + std::to_string(p_) +
                                                         " exceeds the supported maximum " +
                                                         std::to_string(kMaxDegree));
}

int BSplineBasis::find_span(double u) const {
  return spline::find_span(size(), p_, u, U_);
}

int BSplineBasis::eval(double u, int nder, Eigen::Ref<Eigen::MatrixXd> ders) const {
  const int span = find_span(u);
  ders_basis_funs(span, u, p_, nder, U_, ders);
  return span - p_;
}

Eigen::VectorXd BSplineBasis::eval_all(double u, int derivative) const {
  Eigen::MatrixXd d(derivative + 1, p_ + 1);
  const int first = eval(u, derivative, d);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(size());
  for (int j = 0; j <= p_; ++j) out(first + j) = d(derivative, j);
  return out;
}

std::vector<double> BSplineBasis::greville() const {
  const int n = size();
  std::vector<double> g(n);
  for (int i = 0; i < n; ++i) {
    if (p_ == 0) {
      g[i] = 0.5 * (U_[i] + U_[i + 1]);
      continue;
    }
    double s = 0.0;
    for (int k = 1; k <= p_; ++k) s += U_[i + k];
    g[i] = s / p_;
  }
  return g;
}

std::vector<double> BSplineBasis::breakpoints() const {
  std::vector<double> b;
  for (int i = p_; i <= size(); ++i)
    if (b.empty() || U_[i] != b.back()) b.push_back(U_[i]);
  return b;
}

}  // namespace knit::spline
