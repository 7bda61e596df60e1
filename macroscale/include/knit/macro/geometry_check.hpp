// Load-time check of the reference surface of a shell patch: the surface Jacobian
// J = |A1 x A2| (A_a = dX/dtheta_a, paper eq. 10) must not vanish and the normal
// A3 = A1 x A2 / J must not flip anywhere in the patch -- at the quadrature points, where the
// shell integrates, and on the element boundaries (corners and edges), where outputs are
// sampled and the boundary conditions act. A degenerate corner (two coincident control points)
// has J = 0 only there, so checking the quadrature points alone lets it pass.
//
// Sample set (choice): per knot span in each direction the span ends and max(p + 1, n) Gauss
// points (n = 0: the shell's quadrature); the tensor grid of these abscissae. The case loader
// checks the analysis surface with n = 0 and the input surface (the same geometry, before
// refinement, usually a few spans) with dense_samples_per_span(), up to 24 points per span: a
// fold narrower than the spacing of the shell's quadrature points passed before (session 27:
// a one-span cubic folded over theta1 in (0.451, 0.549) ran "completed" with exit 0). Sampling
// is not a proof: a fold narrower than about 1/24 of an input knot span still passes. J <= 1e-10
// scale^2 (the tolerance of reference_point(), scale = diagonal of the control net's bounding box)
// is degenerate; a normal that turns by more than 90 degrees between neighbouring samples
// (A3 . A3' <= 0) is a fold.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "knit/spline/surface.hpp"

namespace knit::macro {

struct GeometryDefect {
  Eigen::Vector2d theta = Eigen::Vector2d::Zero();  ///< parametric location
  double jacobian = 0.0;                            ///< |A1 x A2| there
  std::string message;  ///< one line: what and where ("... at the corner (0, 1)")
};

/// The patch's size: the diagonal of its control net's bounding box (the surface lies inside
/// it), mm. The scale of the defect tolerances here and of the case's length bounds
/// (thickness, gauge length, a knit patch against one loop).
double patch_size(const spline::SplineSurface& surface);

/// The patch's width: the shorter of its two parameter lines through the middle (u and v at
/// the middle of the other's range), each the length of a 64-segment polyline on the surface,
/// mm. Unlike the bounding box it does not depend on how the patch lies in space (the review
/// of session 46: a 20 x 1 mm strip turned 45 deg has a bounding box of 14.8 x 14.8 mm).
double patch_width(const spline::SplineSurface& surface);

/// The first defect of the reference surface, or nothing; `samples_per_span` Gauss points per
/// knot span and direction, at least p + 1.
std::optional<GeometryDefect> find_geometry_defect(const spline::SplineSurface& surface,
                                                   int samples_per_span = 0);

/// Dense sampling of the input surface: kDenseSamplesPerSpan per span and direction, fewer when
/// the patch has so many spans that the grid would pass kMaxDenseSamples points.
inline constexpr int kDenseSamplesPerSpan = 24;
inline constexpr double kMaxDenseSamples = 4.0e5;
int dense_samples_per_span(const spline::SplineSurface& surface);

/// The area of the reference surface, integral of |A1 x A2| by `points_per_span` Gauss points
/// per knot span and direction (0: p + 1, the shell's quadrature), mm^2.
double reference_area(const spline::SplineSurface& surface, int points_per_span = 0);
/// The case loader refuses a surface one of whose elements' area the shell's quadrature (p + 1
/// Gauss points per direction) misses by more than this, relative to the area with
/// kAreaExtraPoints more points (choice: the paper's cases reach 8e-5, a weight ratio of 10 on
/// one element 5e-3). Element by element: on a whole-patch measure a bad corner element of a
/// fine mesh passed (review of session 28: 0.88 % off in an 8 x 8 mesh, 1.4e-4 in all).
inline constexpr double kMaxAreaQuadratureError = 1e-3;
inline constexpr int kAreaExtraPoints = 8;
struct AreaQuadratureDefect {
  Eigen::Vector2d lo, hi;  ///< the element [lo(0), hi(0)] x [lo(1), hi(1)] in (theta1, theta2)
  double error = 0.0;      ///< relative area error of the shell's quadrature there
};
/// The first element whose area the shell's quadrature misses by more than
/// kMaxAreaQuadratureError, or nothing.
std::optional<AreaQuadratureDefect> area_quadrature_defect(const spline::SplineSurface& surface);

/// Why an edge cannot carry a symmetry condition of plane normal `component` (0, 1, 2 = x, y,
/// z), or "": the edge row's control points `row0` must lie in one plane x_component = const
/// (within kSymmetryPlaneTolerance of the patch's size), and the control net must leave it
/// along its normal, the second row `row1` offset from the edge row along the normal (off it
/// by at most kSymmetryAngleTolerance of that offset, an angle in rad). Tolerances (choice):
/// far above round-off and CAD export (1e-5 mm on a 25 mm roof was refused at 1e-6, the
/// session's review), far below a wrong plane (an offset of order 1). The condition holds
/// u_component = 0 on the edge and ties the other components of the second row to the edge row,
/// which keeps a symmetric state only under both (session 39's walkthrough: planes y and z swapped
/// on a quarter cylinder ran with exit 0, the radius varying 19.19-20.03 mm where it is 18.58
/// everywhere).
inline constexpr double kSymmetryPlaneTolerance = 1e-4;
inline constexpr double kSymmetryAngleTolerance = 1e-3;
std::string symmetry_plane_problem(const spline::SplineSurface& surface,
                                   const std::vector<int>& row0, const std::vector<int>& row1,
                                   int component, const std::string& length_unit = "mm");

}  // namespace knit::macro
