// Refinement of B-spline/NURBS curves and surfaces that leaves the geometry unchanged:
// knot insertion (h-refinement), degree elevation (p-refinement) and their combination
// ("k-refinement": elevate first, then insert knots, which keeps the highest continuity).
//
// References: L. Piegl & W. Tiller, The NURBS Book, 2nd ed. (1997), Chapter 5:
//   Algorithm A5.1 (CurveKnotIns), p. 151: insert one knot value r times into a curve.
//   Algorithm A5.3 (SurfaceKnotIns), p. 155: the same for every row/column of a surface net,
//                  with the alphas computed once per direction.
//   Algorithm A5.4 (RefineKnotVectCurve), p. 164: insert many knots at once.
//   Algorithm A5.9 (DegreeElevateCurve), p. 206: degree elevation by Bezier decomposition,
//                  Bezier degree elevation (eq. 5.36) and knot removal, in one sweep.
//   (A5.5/A5.10 for surfaces apply A5.4/A5.9 to every row or column of the net.)
//
// Rational curves and surfaces are refined in homogeneous coordinates Pw = (w P, w)
// (The NURBS Book Sect. 4.2), so NURBS geometry is reproduced exactly.
//
// Implementation note: the 1-D kernels below operate on a "strip" of control points: a matrix
// whose rows are the control points along the refined direction and whose columns are any number
// of coordinates. A surface is refined in u by putting the homogeneous coordinates of all its
// v-rows side by side in the columns; every row operation then acts on all curves at once with
// the coefficients computed once, which is exactly Algorithm A5.3 (and A5.5, A5.10).
//
// Limitations (checked, with a clear exception): knots are inserted strictly inside the domain;
// the multiplicity after insertion may not exceed p; degree elevation needs every interior knot
// multiplicity <= p (no C^{-1} breaks inside the domain).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "knit/spline/curve.hpp"
#include "knit/spline/surface.hpp"

namespace knit::spline {

/// Parametric direction of a surface.
enum class Direction { kU = 0, kV = 1 };

/// A knot vector together with a strip of (homogeneous) control points, one per row.
struct KnotStrip {
  std::vector<double> U;
  Eigen::MatrixXd Pw;
};

/// Algorithm A5.1 (CurveKnotIns): inserts u, r times, into (p, U, Pw). Requires
/// U[p] < u < U[n] and mult(u) + r <= p. Every column of Pw is treated as a coordinate.
KnotStrip curve_knot_ins(int p, const std::vector<double>& U, const Eigen::MatrixXd& Pw, double u,
                         int r);

/// Algorithm A5.4 (RefineKnotVectCurve): inserts all knots of X (sorted here; repeated values
/// allowed) at once. Requires every X strictly inside the domain and resulting multiplicities <= p.
KnotStrip refine_knot_vect(int p, const std::vector<double>& U, const Eigen::MatrixXd& Pw,
                           std::vector<double> X);

/// Algorithm A5.9 (DegreeElevateCurve): raises the degree from p to p + t (t >= 0). Every
/// interior knot's multiplicity grows by t, so the continuity C^{p-r} at a knot of
/// multiplicity r is preserved. Requires interior multiplicities <= p.
KnotStrip degree_elevate(int p, const std::vector<double>& U, const Eigen::MatrixXd& Pw, int t);

// --- Curves -----------------------------------------------------------------------------------

/// Inserts the knot u `times` times (Algorithm A5.1). The curve is unchanged.
SplineCurve insert_knot(const SplineCurve& c, double u, int times = 1);
/// Inserts all knots in X at once (Algorithm A5.4). The curve is unchanged.
SplineCurve insert_knots(const SplineCurve& c, const std::vector<double>& X);
/// Raises the degree by t >= 0 (Algorithm A5.9). The curve is unchanged.
SplineCurve elevate_degree(const SplineCurve& c, int t);
/// k-refinement: elevates the degree to p (throws if the curve's degree is already above p),
/// then inserts (multiplicity 1) every uniform breakpoint a + (b-a) k / elements, k
/// = 1..elements-1, that is not already a breakpoint (a breakpoint within 1e-10 (b-a) counts as
/// present). Existing breakpoints are kept, so a curve that starts with one element ends up with
/// exactly `elements` uniform elements; otherwise the element count is that of the union.
SplineCurve refine(const SplineCurve& c, int p, int elements);

// --- Surfaces ---------------------------------------------------------------------------------

/// Inserts a knot in direction dir `times` times (Algorithm A5.3).
SplineSurface insert_knot(const SplineSurface& s, Direction dir, double u, int times = 1);
inline SplineSurface insert_knot_u(const SplineSurface& s, double u, int times = 1) {
  return insert_knot(s, Direction::kU, u, times);
}
inline SplineSurface insert_knot_v(const SplineSurface& s, double v, int times = 1) {
  return insert_knot(s, Direction::kV, v, times);
}
/// Inserts all knots in X in direction dir (Algorithm A5.4 applied to every row: A5.5).
SplineSurface insert_knots(const SplineSurface& s, Direction dir, const std::vector<double>& X);
/// Raises the degrees by tu and tv (Algorithm A5.9 applied to every row/column: A5.10).
SplineSurface elevate_degree(const SplineSurface& s, int tu, int tv);
/// k-refinement of both directions to degree p with elements_u x elements_v uniform elements
/// (same rules as the curve version, applied per direction).
SplineSurface refine(const SplineSurface& s, int p, int elements_u, int elements_v);

/// The uniform breakpoints a + (b-a) k / elements (k = 1..elements-1) of the basis' domain that
/// are not already breakpoints of `basis` (within 1e-10 (b-a)): the knots refine() inserts.
std::vector<double> missing_uniform_breakpoints(const BSplineBasis& basis, int elements);

}  // namespace knit::spline
