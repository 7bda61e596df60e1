// The fold guard of the load stepping (knit/macro/fold_guard.hpp).
#include "knit/macro/fold_guard.hpp"

#include <sstream>

#include "knit/spline/knot_vector.hpp"

namespace knit::macro {

FoldGuard::FoldGuard(const ShellModel& model) : model_(model), nq_(model.num_quadrature_points()) {
  for (const double tv : spline::unique_knots(model.surface().basis_v().knots()))
    for (const double tu : spline::unique_knots(model.surface().basis_u().knots()))
      corners_.emplace_back(tu, tv);
  accepted_.resize(nq_ + corners_.size());
  checked_.resize(accepted_.size());
  for (int q = 0; q < nq_; ++q) accepted_[q] = model.quadrature_point(q).e3;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.num_dofs());
  for (std::size_t k = 0; k < corners_.size(); ++k)
    accepted_[nq_ + k] = model.normals(zero, corners_[k]).second;
}

int FoldGuard::check(const Eigen::VectorXd& u, const std::vector<kernel::PointState>& points) {
  for (int q = 0; q < nq_; ++q) checked_[q] = Eigen::Map<const Eigen::Vector3d>(points[q].a3);
  for (std::size_t k = 0; k < corners_.size(); ++k)
    checked_[nq_ + k] = model_.normals(u, corners_[k]).first;
  for (std::size_t q = 0; q < accepted_.size(); ++q)
    if (!(checked_[q].dot(accepted_[q]) > 0.0)) return static_cast<int>(q);
  return -1;
}

Eigen::Vector2d FoldGuard::where(int q) const {
  return q < nq_ ? Eigen::Vector2d(model_.quadrature_point(q).theta)
                 : corners_[static_cast<std::size_t>(q - nq_)];
}

std::string FoldGuard::describe(int q) const {
  const Eigen::Vector2d t = where(q);
  std::ostringstream s;
  s << "the surface folds over itself: its normal at (theta1, theta2) = (" << t(0) << ", " << t(1)
    << ") turned by 90 degrees or more within the step (an inverted or folded configuration, "
       "which the strains do not see)";
  return s.str();
}

}  // namespace knit::macro
