// Geometry of the single-jersey unit cell (paper Sect. 2.1.2, eq. 5; Sect. 3.1.1; design notes
// "Mesoscale").
//
// Closed-form loop centerline (choice, notes.md), s in [0, 1] for one loop of one course:
//   x(s) = w s + gamma sin(4 pi s),  y(s) = (h/2) cos(2 pi s),  z(s) = (d/2) cos(4 pi s).
// s = 0 and s = 1 are the tops of the needle-loop heads (x = 0 and x = w), s = 1/2 the bottom of
// the sinker loop ("foot"), s = 1/4 and 3/4 the legs. The cell is periodic with period w along
// the course (x) and the next course is the copy shifted by c along the wale (y).
//
// Dimensions (fact for 4.5 and 6.5 mm, paper Sect. 3.1.1; rule for the rest, notes.md):
//   w(l) linear between (4.5, 1.26) and (6.5, 1.41);  c = l^2 / (18.27 w) (notes.md). At 4.5 and
//   6.5 mm the published values are returned verbatim (the rule gives 0.8797 and 1.6401).
//
// Representation (eq. 5): four quartic B-spline curves with 12 control points each. Choice: the
// loop is split into its four quarters s in [k/4, (k+1)/4] (head-right -> leg -> foot-left,
// foot-right -> leg -> head-left, ...), each interpolated at its Greville abscissae, so that the
// pieces join exactly (C0 by construction, the closed form being smooth the kinks are at the
// level of the fit error). The loop height h is then solved (secant) so that the summed arc length
// of the four splines equals l to 1e-12 relative. The analysis curve is one open quartic
// B-spline over the whole loop with n_el elements, built the same way (its own h, so its
// length is l exactly too): see analysis_curve().
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "knit/spline/curve.hpp"

namespace knit::meso::cell {

/// Published and interpolated cell dimensions (mm).
struct CellDimensions {
  double loop_length = 0;  ///< l
  double w = 0;            ///< wale width (period along x)
  double c = 0;            ///< course height (period along y)
};

/// w and c from l (the 4.5 and 6.5 mm cells exactly, the rest by the notes' rule).
/// Throws std::invalid_argument for l <= 0.
CellDimensions cell_dimensions(double loop_length);

/// The loop lengths whose w and c are published (the paper's cells, notes.md); between them
/// cell_dimensions interpolates, outside it extrapolates.
inline constexpr double kPublishedLoopLengthMin = 4.5, kPublishedLoopLengthMax = 6.5;

/// A warning for a loop length outside [kPublishedLoopLengthMin, kPublishedLoopLengthMax]
/// (session 42's metamorphic red team: 12 mm ran without a word, its wale stress 1.6 times the
/// 4.5 mm cell's); empty inside.
std::string loop_length_range_warning(double loop_length);

/// Parameters of the closed-form loop.
struct LoopShape {
  double w = 1.26, h = 1.49, d = 0.38, gamma = 0.25;
  /// k-th derivative (k = 0..2) of the centerline w.r.t. s.
  Eigen::Vector3d point(double s, int k = 0) const;
  /// Arc length over s in [0,1] by Gauss-Legendre quadrature (converged to 1e-13).
  double length() const;
};

struct GeometryOptions {
  double d = 0.38;  ///< yarn diameter (mm)
  /// gamma = gamma_over_w * w. Choice (issue 12 calibration, docs/unit-cell.md "Calibration"):
  /// 0.225 at every loop length: 4.5 mm stiffer than 6.5 mm wale-wise over E22 = 0.05-0.40 (as
  /// in both directions in the paper) for every g0, k_N, mu in their ranges; course-wise
  /// stiffening curves. (Before: 0.25 / 1.26 = 0.198, notes.md's gamma = 0.25 at w = 1.26.)
  double gamma_over_w = 0.225;
  int pieces = 4;              ///< eq. 5: four curves
  int degree = 4;              ///< eq. 5: p = 4
  int ctrl_per_piece = 12;     ///< eq. 5: n = 12
  double length_rtol = 1e-12;  ///< |L_spline - l| / l after the h solve
};

/// The cell geometry: the four curves of eq. 5 and the data of the JSON summary.
struct CellGeometry {
  CellDimensions dim;
  LoopShape shape;                          ///< with the h that makes the spline length l
  std::vector<spline::SplineCurve> pieces;  ///< parameter xi in [0,1] each
  double measured_length = 0;               ///< summed spline arc length
  int h_iterations = 0;
};

/// The loop-length match failed: the loop is too short for w and d, or an absurd diameter
/// made the residual NaN. The commands turn it into an input error (loop_length_message).
class GeometryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Builds the cell for loop length l. Throws std::invalid_argument on bad options and
/// GeometryError when no loop of that length exists.
CellGeometry make_cell_geometry(double loop_length, const GeometryOptions& opt = {});

/// "no cell geometry for 2.5 mm with yarn diameter 0.38 mm: <why>": the message of the
/// --loop-length error of `knit-meso cell` and `knit-meso path`.
std::string loop_length_message(double loop_length, double d, const GeometryError& e);

/// Which of the loop's inputs makes it impossible, for the commands' error (session 29: a
/// config file's /yarn/d = 1.5 mm was reported at --loop-length). Given the failing options
/// and which of d and gamma/w were chosen by the user (not defaults), returns kDiameter or
/// kGamma when that value alone fails (the loop builds and interlocks with the default in its
/// place), else kLoopLength.
enum class GeometryBlame { kLoopLength, kDiameter, kGamma };
GeometryBlame geometry_blame(double loop_length, const GeometryOptions& failing, bool d_chosen,
                             bool gamma_chosen);

/// Arc length of a spline curve (Gauss-Legendre, `npts` points per knot span).
double spline_length(const spline::SplineCurve& curve, int npts = 12);

/// Interpolates f at the Greville abscissae of an open uniform basis of degree p with n control
/// points on [0,1] (The NURBS Book Sect. 9.2.1, with Greville parameters).
spline::SplineCurve interpolate_greville(int p, int n,
                                         const std::function<Eigen::Vector3d(double)>& f);

/// One open quartic B-spline over the whole loop (s in [0,1]) with `elements` uniform elements
/// and degree p, interpolating the closed form at its Greville points, with h re-solved so that
/// its length is l (rtol 1e-12). r(1) = r(0) + (w,0,0) holds exactly.
struct AnalysisCurve {
  spline::SplineCurve curve;
  LoopShape shape;
  double length = 0;
};
AnalysisCurve analysis_curve(const CellDimensions& dim, int elements, int p = 4,
                             const GeometryOptions& opt = {});

/// A crossing of two yarn centerlines in the x-y projection.
struct Crossing {
  double s_self = 0;             ///< parameter on the cell's loop (s in [0,1))
  double s_other = 0;            ///< parameter on the neighbour (its own s)
  int shift_i = 0, shift_j = 0;  ///< neighbour = loop shifted by (i w, j c, 0)
  double dz = 0;               ///< z_self - z_other at the crossing (> 0: the cell's yarn in front)
  const char* part_self = "";  ///< "head", "leg" or "foot"
  const char* part_other = "";
};

/// All crossings of the loop with the next course (shift_j = +1, any shift_i) in projection.
/// Computed on the closed form (dense polyline of `samples` chords, then Newton on the two
/// parameters).
std::vector<Crossing> crossings_with_next_course(const LoopShape& shape, double c,
                                                 int samples = 1200);

/// A single-jersey loop passes through the loop of the next course: its centreline crosses
/// the next course's in projection at kStitchCrossings points. A loop length whose closed form
/// crosses it at any other count (none at 20 mm, where the loops no longer reach each other)
/// is not a knit: the message says so, nullopt when the count is right. Counted on a polyline
/// of 300 chords (about 2 ms; every PeriodicCell is checked). Session 27: loop lengths of 3.0
/// and 20 mm ran with exit 0, a cell without wale strength (S22 = 0.0006 MPa at 50 %).
inline constexpr int kStitchCrossings = 4;
inline constexpr int kInterlockChords = 300;  ///< polyline of the count (1200 for positions)
std::optional<std::string> interlock_defect(const LoopShape& shape, double c);

/// Minimum distance between the cell's centerline and its periodic images (i w, j c), |i|,|j| <= 2
/// (for j = 0 only parts of the yarn more than 0.3 apart in s count), on the closed form.
struct Clearance {
  double min_distance = 0;  ///< centerline to centerline (mm)
  double clearance = 0;     ///< min_distance - d (< 0: initial overlap)
  double s_self = 0, s_other = 0;
  int shift_i = 0, shift_j = 0;
};
Clearance minimum_clearance(const LoopShape& shape, double c);

/// Part of the loop at parameter s: "head" (|s - k| < 1/8), "foot" (|s - 1/2| < 1/8), else "leg".
const char* loop_part(double s);

}  // namespace knit::meso::cell
