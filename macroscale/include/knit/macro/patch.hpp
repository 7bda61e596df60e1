// Topology of a single NURBS patch: its four parametric edges, four corners and the rows of
// control points along an edge (row 0 = the edge, interpolatory for open knot vectors;
// row 1 = the second row, which with row 0 fixes the cross-edge slope, i.e. the rotation).
// Control point index a = i + nu * j (u fastest), DOF = 3 a + component.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "knit/spline/surface.hpp"

namespace knit::macro {

enum class Edge { kU0, kU1, kV0, kV1 };

/// "u0", "u1", "v0", "v1" -> Edge; nullopt otherwise.
std::optional<Edge> parse_edge(const std::string& s);
std::string edge_name(Edge e);
/// Parametric corners "u0v0", "u1v0", "u0v1", "u1v1" -> (theta1, theta2).
std::optional<Eigen::Vector2d> parse_corner(const std::string& s);

/// Control-point indices of row `row` (0 = on the edge, 1 = second row) along edge e.
std::vector<int> edge_row(int nu, int nv, Edge e, int row);
/// Control-point index of a corner (theta values 0 or 1).
int corner_control_point(int nu, int nv, const Eigen::Vector2d& corner);
/// A corner region (issue 12, the 3.2.1 mesh study: a corner load spread over a few mm instead
/// of one control point, whose support shrinks with h): the control points whose Greville point
/// -- the reference surface at the Greville abscissae (g_i, g_j), where the control point acts
/// most -- lies within `radius` (mm, straight distance) of the surface corner. Always contains
/// the corner control point (radius 0: that point alone). Ascending indices.
std::vector<int> corner_region(const spline::SplineSurface& s, const Eigen::Vector2d& corner,
                               double radius);

/// Component name "x"/"y"/"z" (or "1"/"2"/"3") -> 0..2, or -1.
int parse_component(const std::string& s);

}  // namespace knit::macro
