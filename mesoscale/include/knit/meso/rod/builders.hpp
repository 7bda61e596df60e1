// Convenience constructors of RodSpec geometries.
#pragma once

#include <Eigen/Core>
#include <functional>

#include "knit/meso/rod/rod_system.hpp"

namespace knit::meso::rod {

/// Straight rod from a to b: degree p, `elements` uniform spans, uniform parameterization
/// (control points at the Greville abscissae, so |r0_xi| = |b - a| is constant).
RodSpec straight_rod(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int p, int elements,
                     const Section& section = {});

/// Rod interpolating a parametric curve c(t), t in [0, 1], at the Greville abscissae of a
/// uniform degree-p basis with `elements` spans (the basis parameter is t).
RodSpec interpolated_rod(const std::function<Eigen::Vector3d(double)>& c, int p, int elements,
                         const Section& section = {});

}  // namespace knit::meso::rod
