// Resolution check of a rod case by bisection (session 28).
//
// Collocation satisfies the strong form only at its points, and a coarse discretization can
// converge to an answer that is far off with nothing in the Newton iterations to show it: the
// cantilever elastica of cases/rod (reference tip deflection w = 6.70 mm, Mattiasson 1981) gave
// w = 0.0022 mm on one element of degree 2 and w = -0.40 mm (the wrong sign) on one of degree 3,
// both with exit 0 before session 28. A residual between the collocation points did not
// separate these from good meshes (the force-row residual of the 8-element degree-4 mesh, which
// is within 0.04 %, was 0.2 of |n|/L), so the check is the classic one: solve again with every
// knot span halved and compare the displacements of the output points.
//
//   displacements: max_i |u_i - u_i'| / max(max_i |u_i'|, 1e-6 L)
//   rotations:     max_i angle(Lambda_i^T Lambda_i') / max(max_i angle(Lambda_i'), 1e-6 rad)
//   difference = the larger of the two
//     u on the case's mesh, u' on the bisected mesh, Lambda = R R0^T the rotation from the
//     reference directors to the current ones, i over the output points of the case and the
//     knot breakpoints and span midpoints of every rod, L the longest rod's length (the floors
//     keep a case in which nothing moves, or nothing turns, from comparing round-off with
//     round-off). Rotations since session 29: a rod twisted by 190 degrees on one element of
//     degree 2 ended 24 degrees short, its displacements zero on both meshes.
//
// The bisected mesh keeps the degree, the geometry (knot insertion, The NURBS Book A5.4) and
// every load and end condition. It costs one more solve on twice the elements.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "knit/meso/rod/rod_system.hpp"
#include "knit/meso/rod/solver.hpp"

namespace knit::meso::rod {

/// Above this difference the case's mesh is called under-resolved (a warning of
/// `knit-meso rod`; choice: 1 %, the accuracy the verification cases are held to).
inline constexpr double kResolutionTolerance = 0.01;
/// The displacement scale's floor, relative to the longest rod.
inline constexpr double kDisplacementFloor = 1e-6;
/// The rotation scale's floor [rad].
inline constexpr double kRotationFloor = 1e-6;

/// A point on a rod: rod index and parameter.
struct RodPoint {
  int rod = 0;
  double xi = 0.0;
};

/// The same system with every non-empty knot span of every rod halved (knot insertion; the
/// geometry, sections, loads and end conditions are unchanged; reference frames rebuilt).
RodSystem bisected(const RodSystem& sys);

struct ResolutionCheck {
  bool checked = false;     ///< false when the bisected run did not complete the path
  double difference = 0.0;  ///< the larger of the two below, at the case's final load factor
  double displacement_difference = 0.0;  ///< as above
  double rotation_difference = 0.0;      ///< as above
  double u_max = 0.0;                    ///< max_i |u_i'| [mm]
  double floor = 0.0;                    ///< 1e-6 L [mm], the scale when u_max is below it
  double angle_max = 0.0;                ///< max_i angle(Lambda_i') [rad]
  std::string note;                      ///< why not checked (when checked is false)
  /// "changes by 12 % (max |u| 6.7 mm)" or "not checked: ..."
  std::string describe() const;
};

/// Solves the bisected system along `path` and compares the displacements at `points` with
/// those of the state x of sys at the path's end (a completed path of the case).
ResolutionCheck check_resolution(const RodSystem& sys, const Eigen::VectorXd& x,
                                 const PathOptions& path, const std::vector<RodPoint>& points);

}  // namespace knit::meso::rod
