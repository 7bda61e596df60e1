// The fold guard of the load stepping (session 27; moved out of the Newton loop in session 28).
//
// Green-Lagrange strains do not see a mirrored (inverted) configuration, so Newton converges to
// one: the s312 patch compressed by 30 % inverted at its corners from step 18 (62 of 1,600
// output cells with negative area, exit 0, before session 27). The guard keeps the unit normal
// a3 of the last accepted state at every quadrature point and at every element corner (the grid
// of the knot breakpoints: an inversion starts at the patch's corners, outside the quadrature
// points' reach; the reference normals A3 at first). A converged state whose normal turned by
// 90 degrees or more at one of these points within the step is not accepted: the load stepping
// cuts the step back, and a fold that persists stops the run. A rotation by 90 degrees or more
// within one step at a point is also far beyond what the stepping resolves anywhere else, so
// cutting the step back lets a genuine large rotation through.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "knit/macro/shell_model.hpp"

namespace knit::macro {

class FoldGuard {
 public:
  /// The reference normals of `model` (which must outlive the guard).
  explicit FoldGuard(const ShellModel& model);

  /// The first check point whose normal at displacement u turned by 90 degrees or more from
  /// the accepted normals, or -1. `points` are the model's point states at u (an Evaluation
  /// with keep_points): their a3 are the quadrature points' normals.
  int check(const Eigen::VectorXd& u, const std::vector<kernel::PointState>& points);
  /// The state of the last check() becomes the accepted one.
  void accept() { accepted_.swap(checked_); }
  /// Where check point q lies: (theta1, theta2).
  Eigen::Vector2d where(int q) const;
  /// The message of a fold at check point q.
  std::string describe(int q) const;

 private:
  const ShellModel& model_;
  int nq_ = 0;
  std::vector<Eigen::Vector2d> corners_;
  std::vector<Eigen::Vector3d> accepted_, checked_;
};

}  // namespace knit::macro
