#include "knit/spline/curve.hpp"

#include <stdexcept>

#include "knit/spline/basis.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::spline {

SplineCurve::SplineCurve(BSplineBasis basis, Eigen::MatrixXd P, Eigen::VectorXd w)
    : basis_(std::move(basis)), P_(std::move(P)), w_(std::move(w)) {
  if (P_.rows() != basis_.size())
    throw KnotVectorError(KnotError::kCountMismatch,
                          "curve: " + std::to_string(P_.rows()) +
                              " control points but the knot vector defines " +
                              std::to_string(basis_.size()) +
                              " basis functions (knots must number control points + degree + 1)");
  rational_ = w_.size() > 0;
  if (!rational_) {
    w_ = Eigen::VectorXd::Ones(P_.rows());
  } else {
    if (w_.size() != P_.rows())
      throw std::invalid_argument("curve: " + std::to_string(w_.size()) + " weights for " +
                                  std::to_string(P_.rows()) + " control points");
    for (int i = 0; i < w_.size(); ++i)
      if (!(w_(i) > 0.0))
        throw std::invalid_argument("curve: weight " + std::to_string(i) + " is not positive");
  }
}

int SplineCurve::basis_derivatives(double u, int nder, Eigen::Ref<Eigen::MatrixXd> R) const {
  // Cheap guards: the rational quotient rule uses stack buffers of kMaxDerivative + 1 entries.
  if (nder < 0 || (rational_ && nder > kMaxDerivative))
    throw std::invalid_argument("curve: derivative order " + std::to_string(nder) + " outside 0.." +
                                std::to_string(kMaxDerivative));
  if (R.rows() != nder + 1 || R.cols() != degree() + 1)
    throw std::invalid_argument("curve: basis_derivatives needs a (nder+1) x (p+1) matrix");
  const int first = basis_.eval(u, nder, R);
  if (rational_) rationalize_1d(w_.data() + first, R);
  return first;
}

Eigen::MatrixXd SplineCurve::derivatives(double u, int nder) const {
  const int p = degree();
  Eigen::MatrixXd R(nder + 1, p + 1);
  const int first = basis_derivatives(u, nder, R);
  return R * P_.middleRows(first, p + 1);
}

Eigen::VectorXd SplineCurve::eval(double u) const {
  return derivatives(u, 0).row(0).transpose();
}

}  // namespace knit::spline
