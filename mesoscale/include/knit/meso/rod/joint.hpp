// Joints between rod ends as ExternalContributions: a rigid connection of two rod ends, with
// an optional prescribed gap, which is also the periodic boundary condition of a unit cell
// (the end of a yarn and the start of its periodic image, gap = F* times the period).
//
// For ends a and b (both EndCondition::custom()), with s = +1 at an end and -1 at a start:
//   rows of end a, force group:   r_b - r_a - g(lambda) = 0          (position; g defaults to
//                                                                     the reference gap)
//   rows of end a, moment group:  vec( conj(q_a q0a^*) (q_b q0b^*) ) = 0   (same incremental
//                                  rotation R_b R0b^T = R_a R0a^T; q0 = reference quaternions)
//   rows of end b, force group:   s_a n_a + s_b n_b = 0               (force transmitted)
//   rows of end b, moment group:  s_a m_a + s_b m_b = 0               (moment transmitted; for a
//                                  gap this is the periodicity of m, not a moment balance about
//                                  a point)
// A plain continuation (end of rod a = start of rod b) gives n_a(end) = n_b(start) and
// m_a(end) = m_b(start). Jacobian exact (checked by finite differences in the tests).
#pragma once

#include <Eigen/Core>
#include <functional>

#include "knit/meso/rod/rod_system.hpp"

namespace knit::meso::rod {

struct JointEnd {
  int rod = 0;
  End end = End::kEnd;
};

class Joint : public ExternalContribution {
 public:
  using Gap = std::function<Eigen::Vector3d(double lambda)>;
  /// Sets the row scales of the 12 rows. Throws std::invalid_argument if an end is not custom.
  Joint(RodSystem& sys, JointEnd a, JointEnd b, Gap gap = {});
  void add(const RodSystem& sys, const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& residual,
           std::vector<Eigen::Triplet<double>>& jac) override;

 private:
  struct Side {
    JointEnd e;
    double xi = 0.0, sign = 1.0;
    PointBasis b;
    Quat<double> q0;  // normalized reference quaternion at the end
  };
  Side a_, b_;
  Gap gap_;
  Eigen::Vector3d ref_gap_;
};

}  // namespace knit::meso::rod
