#include <Eigen/Dense>

#include "knit/meso/rod/builders.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::meso::rod {

RodSpec straight_rod(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int p, int elements,
                     const Section& section) {
  RodSpec s;
  s.basis = spline::BSplineBasis(p, spline::uniform_knots(p, elements));
  const auto g = s.basis.greville();
  s.r0.resize(s.basis.size(), 3);
  for (int i = 0; i < s.basis.size(); ++i) s.r0.row(i) = (a + g[i] * (b - a)).transpose();
  s.section = section;
  return s;
}

RodSpec interpolated_rod(const std::function<Eigen::Vector3d(double)>& c, int p, int elements,
                         const Section& section) {
  RodSpec s;
  s.basis = spline::BSplineBasis(p, spline::uniform_knots(p, elements));
  const auto g = s.basis.greville();
  const int n = s.basis.size();
  Eigen::MatrixXd A(n, n), Y(n, 3);
  for (int i = 0; i < n; ++i) {
    A.row(i) = s.basis.eval_all(g[i]).transpose();
    Y.row(i) = c(g[i]).transpose();
  }
  s.r0 = A.partialPivLu().solve(Y);
  s.section = section;
  return s;
}

}  // namespace knit::meso::rod
