// The knitting map (issue 13, docs/design.md "The knitting map"): from the stitch-value field
// l(theta) and the knitting-angle field alpha(theta) of a planar knit case to the table a
// flat-knitting machine with per-stitch yarn delivery needs: course by course and needle by
// needle, the loop length of each stitch.
//
// Layout (all in the patch's plane z = const, mm):
//  * the course direction d1 is the global in-plane direction of the courses, phi = angle(e1)
//    + alpha (alpha about the surface normal, paper eqs. 19-20; e1 = a1/|a1|); a flat machine
//    knits straight courses, so phi must be constant over the patch within a tolerance
//    (otherwise the map is refused with the reason); d2 = z x d1 is the wale direction;
//  * courses are stacked along d2 from the patch's lowest point; course k is the chord of the
//    patch along d1 at its centre line; its stitches are laid side by side from the chord's
//    start, each as wide as the wale width w(l) at its centre, while the centre lies inside the
//    chord (a uniform chord of length W holds round(W/w) stitches);
//  * the course height is the mean course height c(l) of the course's stitches (a course is
//    one row on the machine); where c(l) varies along a course the mismatch is reported
//    (short rows that would absorb it are not generated);
//  * the needle of a stitch: each course is centred about its chord's midpoint, measured in the
//    course's mean stitch width from the midpoint of the patch's extent along d1; the machine
//    needs `needles` needles (the widest course in needles); courses with fewer stitches leave
//    their outer needles out of work (fully fashioned narrowing).
// w(l) and c(l) interpolate the database's cell parameters (per loop length /loop_k attributes
// wale_width, course_height) piecewise linearly in l.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "knit/macro/case.hpp"

namespace knit::material {
struct Database;
}

namespace knit::macro {

/// w(l) and c(l) from the database's cell parameters, piecewise linear in l (mm).
class CellTable {
 public:
  CellTable() = default;
  /// Throws knit::InputError(db_file, "/loop_k", ...) if a cell parameter is not positive.
  CellTable(const material::Database& db, const std::string& db_file);
  double wale_width(double l) const { return interpolate(w_, l); }
  double course_height(double l) const { return interpolate(c_, l); }
  /// The smallest w and c of the table (piecewise linear: no smaller value in between).
  double min_wale_width() const;
  double min_course_height() const;
  /// The largest w and c of the table (the bracket of the layout's fixed points).
  double max_wale_width() const;
  double max_course_height() const;
  const std::vector<double>& loop_lengths() const { return l_; }
  /// The cell parameters' sane range (mm): a stitch is a yarn loop of a textile; anything
  /// outside is a damaged database (session 29: w = 1e-9 mm made the map run without end).
  static constexpr double kMinCellSize = 1e-3, kMaxCellSize = 1e3;

 private:
  double interpolate(const std::vector<double>& y, double l) const;
  std::vector<double> l_, w_, c_;
};

struct KnitMapOptions {
  /// Largest allowed deviation of the course direction from its mean over the patch (deg), in
  /// (0, 90): deviations are between lines, at most 90 deg (`--angle-tolerance` checks it).
  double angle_tolerance_deg = 2.0;
  /// Samples per patch edge for the boundary polygon (chords of the courses).
  int boundary_samples = 400;
  /// Largest number of stitches a map may have, estimated before the layout from the patch's
  /// extent and the smallest w and c (session 29: a 500 m x 500 m patch, about 2e11 stitches,
  /// ran without limit in time and memory). 1e7 stitches: a CSV of about 0.5 GB, a panel of
  /// about 3.5 x 3 m at 4.5 mm. `knit-macro knitmap --max-stitches`.
  double max_stitches = 1e7;
};

/// The tolerance of rule 5's rounding of a course's first stitch to a needle, in stitches
/// (docs/design.md, "Needles"): f_k = floor(r_k + 0.5 + kNeedleRoundingTolerance). A thousandth
/// of a stitch (about a micrometre) is far below what a machine places, so a patch turned by a
/// few microradians keeps its needle count (session 49's red team: with 1e-6, a 40 x 30 mm
/// patch at a knitting angle of pi - 3e-6 moved some courses by a needle and needed 41 needles
/// for its courses of 40 stitches).
inline constexpr double kNeedleRoundingTolerance = 1e-3;

/// A map whose fabric is taller (wider) than the patch across (along) the courses by more than
/// this fraction of the patch's extent is warned of: a patch about one course tall or one
/// stitch wide (docs/design.md, "Warnings").
inline constexpr double kNarrowPatchMismatch = 0.25;

struct KnitStitch {
  int course = 0, needle = 0;                          ///< 1-based
  double l = 0.0;                                      ///< loop length (mm)
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< stitch centre (x, y), mm
};

struct KnitCourse {
  int index = 0;                       ///< 1-based
  int first_needle = 0, stitches = 0;  ///< needles first_needle .. first_needle + stitches - 1
  double height = 0.0;                 ///< mean c(l) of its stitches (mm)
  double t = 0.0;                      ///< centre line along d2 from the patch's lowest point
  double height_mismatch = 0.0;        ///< max |c(l_i) - height| / height over its stitches
};

struct KnitMap {
  std::vector<KnitStitch> stitches;  ///< course by course, needle by needle
  std::vector<KnitCourse> courses;
  int needles = 0;
  double yarn_length = 0.0;           ///< sum of l (mm)
  double course_direction_deg = 0.0;  ///< phi: angle of d1 from the x axis
  double angle_spread_deg = 0.0;      ///< max deviation of the course direction from phi
  double max_height_mismatch = 0.0;   ///< max over the courses
  double l_min = 0.0, l_max = 0.0;
  std::vector<std::string> warnings;
};

/// Lays out the map of a loaded case. Throws knit::InputError naming c.file and the JSON
/// pointer if the material is not "knit", the patch is not planar (z = const), or the course
/// direction varies beyond the tolerance.
KnitMap make_knitmap(const Case& c, const CellTable& cells, const KnitMapOptions& options = {});

/// Reads the case (load_case) and its database's cell parameters. Throws knit::InputError.
struct KnitMapInput {
  Case c;
  CellTable cells;
  std::string database;  ///< resolved path
  /// The database's date_utc (when it was written; "" for a file without it), in summary.txt
  /// as `database_date_utc:` so that a map of another database is told apart (session 50's
  /// red team: the report showed knitting maps of an earlier database as the current one's).
  std::string database_date_utc;
};
KnitMapInput load_knitmap_input(const std::string& case_file);

/// The totals as "key: value" lines (summary.txt and stdout).
std::string knitmap_summary(const KnitMap& map);

/// Writes DIR/knitmap.csv (course, needle, l_mm, x_mm, y_mm), DIR/courses.csv and
/// DIR/summary.txt atomically (the directory appears complete or not at all). `option` names the
/// output in a refusal ("--output", or "output directory" for the default name).
void write_knitmap(const KnitMap& map, const KnitMapInput& in, const std::filesystem::path& dir,
                   std::string_view option = "output directory");

namespace detail {
/// The most times the closed polygon `poly` (in the course frame (s, t)) covers a stretch of
/// the course line t = tc wider than `tiny`, by the winding number of its signed crossings;
/// `at` and `width` the middle and width of the widest such stretch (knitmap.cpp; exposed for
/// its test). 1 for a line that crosses a simple polygon.
int largest_cover(const std::vector<Eigen::Vector2d>& poly, double tc, double tiny, double& at,
                  double& width);
}  // namespace detail

}  // namespace knit::macro
