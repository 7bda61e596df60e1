// The knitting map's layout (knit/macro/knitmap.hpp; rules in docs/design.md).
#include "knit/macro/knitmap.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "knit/core/errors.hpp"
#include "knit/macro/knit_material.hpp"
#include "knit/material/database.hpp"

namespace knit::macro {

CellTable::CellTable(const material::Database& db, const std::string& db_file) {
  for (std::size_t k = 0; k < db.entries.size(); ++k) {
    const auto& e = db.entries[k];
    const std::string g = "/loop_" + std::to_string(k);
    auto check = [&](double v, const char* what, const char* attr) {
      if (v >= kMinCellSize && v <= kMaxCellSize) return;  // NaN: refused
      std::ostringstream os;
      os << "the knitting map needs a " << what << " (cell parameter) in [" << kMinCellSize << ", "
         << kMaxCellSize << "] mm at l = " << e.loop_length << " mm, got " << v;
      throw InputError(db_file, g + "/" + attr, os.str());
    };
    check(e.cell.wale_width, "wale width", "wale_width");
    check(e.cell.course_height, "course height", "course_height");
    l_.push_back(e.loop_length);
    w_.push_back(e.cell.wale_width);
    c_.push_back(e.cell.course_height);
  }
  if (l_.empty()) throw InputError(db_file, "/loop_lengths", "the database has no loop length");
}

double CellTable::min_wale_width() const {
  return *std::min_element(w_.begin(), w_.end());
}
double CellTable::min_course_height() const {
  return *std::min_element(c_.begin(), c_.end());
}
double CellTable::max_wale_width() const {
  return *std::max_element(w_.begin(), w_.end());
}
double CellTable::max_course_height() const {
  return *std::max_element(c_.begin(), c_.end());
}

double CellTable::interpolate(const std::vector<double>& y, double l) const {
  if (l_.size() == 1 || l <= l_.front()) return y.front();
  if (l >= l_.back()) return y.back();
  const auto it = std::upper_bound(l_.begin(), l_.end(), l);
  const std::size_t k = static_cast<std::size_t>(it - l_.begin());
  const double s = (l - l_[k - 1]) / (l_[k] - l_[k - 1]);
  return (1 - s) * y[k - 1] + s * y[k];
}

namespace {

constexpr double kPi = std::numbers::pi;

/// An angle in degrees as printed: within 1e-9 deg of 0 it is 0 (session 42's red team:
/// 4.599205532e-16 and -6.9e-15 of round-off for courses along x).
double angle(double deg) {
  return std::abs(deg) < 1e-9 ? 0.0 : deg;
}

/// The planar patch seen in the course frame: (s, t) = (p . d1, p . d2) for p = (x, y).
class PlanarPatch {
 public:
  PlanarPatch(const spline::SplineSurface& g, const KnitMaterial& m) : g_(g), m_(m) {}

  Eigen::Vector2d xy(const Eigen::Vector2d& th) const {
    const Eigen::VectorXd p = g_.eval(th.x(), th.y());
    return {p(0), p(1)};
  }
  /// Course direction angle phi = angle(e1) + alpha (alpha about the normal).
  double course_angle(const Eigen::Vector2d& th) const {
    const Eigen::MatrixXd d = g_.derivatives(th.x(), th.y(), 1);
    const double cross = d(1, 0) * d(2, 1) - d(1, 1) * d(2, 0);
    const double sign = cross >= 0 ? 1.0 : -1.0;
    return std::atan2(d(1, 1), d(1, 0)) + sign * m_.knitting_angle(th);
  }
  /// The parametric point of the plane point p (Newton, clamped to the domain, warm-started
  /// from the previous call). Points just outside the patch give the nearest boundary point.
  Eigen::Vector2d invert(const Eigen::Vector2d& p) {
    const auto& bu = g_.basis_u();
    const auto& bv = g_.basis_v();
    Eigen::Vector2d th =
        guess_valid_ ? guess_
                     : Eigen::Vector2d(0.5 * (bu.lo() + bu.hi()), 0.5 * (bv.lo() + bv.hi()));
    for (int it = 0; it < 50; ++it) {
      const Eigen::MatrixXd d = g_.derivatives(th.x(), th.y(), 1);
      const Eigen::Vector2d r(d(0, 0) - p.x(), d(0, 1) - p.y());
      Eigen::Matrix2d J;
      J << d(1, 0), d(2, 0), d(1, 1), d(2, 1);
      const Eigen::Vector2d step = J.partialPivLu().solve(r);
      th -= step;
      th.x() = std::clamp(th.x(), bu.lo(), bu.hi());
      th.y() = std::clamp(th.y(), bv.lo(), bv.hi());
      if (step.norm() < 1e-13 * (1 + th.norm())) break;
    }
    guess_ = th;
    guess_valid_ = true;
    return th;
  }
  double stitch_value(const Eigen::Vector2d& th) const { return m_.stitch_value(th); }

 private:
  const spline::SplineSurface& g_;
  const KnitMaterial& m_;
  Eigen::Vector2d guess_ = Eigen::Vector2d::Zero();
  bool guess_valid_ = false;
};

void check_planar(const Case& c) {
  const Eigen::MatrixXd& P = c.input_surface.control_points();
  const double size = (P.colwise().maxCoeff() - P.colwise().minCoeff()).norm();
  for (Eigen::Index a = 0; a < P.rows(); ++a)
    if (std::abs(P(a, 2) - P(0, 2)) > 1e-9 * (1 + size)) {
      std::ostringstream os;
      os << "the knitting map needs a planar patch in a plane z = const (z = " << P(a, 2)
         << " here, " << P(0, 2)
         << " at control point 0); curved shells are not flattened (docs/design.md)";
      throw InputError(c.file, "/geometry/control_points/" + std::to_string(a), os.str());
    }
}

/// The boundary polygon of the patch in (s, t).
std::vector<Eigen::Vector2d> boundary(const PlanarPatch& patch, const spline::SplineSurface& g,
                                      const Eigen::Matrix2d& R, int n) {
  const auto& bu = g.basis_u();
  const auto& bv = g.basis_v();
  std::vector<Eigen::Vector2d> poly;
  auto edge = [&](Eigen::Vector2d a, Eigen::Vector2d b) {
    for (int i = 0; i < n; ++i) poly.push_back(R * patch.xy(a + (b - a) * (double(i) / n)));
  };
  edge({bu.lo(), bv.lo()}, {bu.hi(), bv.lo()});
  edge({bu.hi(), bv.lo()}, {bu.hi(), bv.hi()});
  edge({bu.hi(), bv.hi()}, {bu.lo(), bv.hi()});
  edge({bu.lo(), bv.hi()}, {bu.lo(), bv.lo()});
  return poly;
}

/// The crossings (s values) of the line t = tc with the closed polygon, sorted.
std::vector<double> crossings(const std::vector<Eigen::Vector2d>& poly, double tc) {
  std::vector<double> s;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[(i + 1) % poly.size()];
    if ((a.y() - tc) * (b.y() - tc) > 0 || a.y() == b.y()) continue;
    if (b.y() == tc) continue;  // counted once, as the start of the next segment
    s.push_back(a.x() + (b.x() - a.x()) * (tc - a.y()) / (b.y() - a.y()));
  }
  std::sort(s.begin(), s.end());
  return s;
}

/// The stitches of one course: centre s (after the centring of rule 4), loop length l, the
/// point p where l was taken (before the centring; the centre but for a stitch on a jump) and
/// whether the stitch lies on a jump (see centre_of); `shift` is the centring's move.
struct Laid {
  std::vector<double> s, l, p;
  std::vector<char> jump;
  double shift = 0.0;
};

/// The most fixed-point steps of rules 3 and 4 before the bracketing (centre_of).
constexpr int kFixedPointSteps = 30;

/// Where an item of the layout that begins at e lies: a stitch along its course (rule 4, F the
/// wale width w(l)) or a course across the courses (rule 3, F the mean course height c(l) of
/// its stitches). Its centre p solves p = e + F(p)/2: the item is as wide (tall) as the cell
/// size at its own centre, so neighbours lie the mean of their sizes apart.
struct Centre {
  double p = 0.0;     ///< where F (and l) is taken
  double size = 0.0;  ///< F(p)
  bool valid = true;  ///< false: no item can lie at p (size_at gave nullopt; size = the guess)
  bool jump = false;  ///< no fixed point: F jumps down across it (see centre_of)
};

/// Solves p = e + F(p)/2 (rules 3, 4); `size_at(p)` is F(p), or nullopt where no item can lie
/// (past the chord's end, a course line outside the patch or holding no stitch), and F lies
/// in [size_min, size_max]. First the fixed-point iteration p <- e + F(p)/2 from the previous
/// item's size (what every map did until session 54, unchanged where it converges). Where F
/// drops across the jump of a discontinuous l field (l falling in the laying direction) no p
/// solves it: with the size before the jump the centre lies past it, with the size after it
/// before it, and the iteration swung between the two for its 30 steps and kept a pair that
/// broke the rules (session 54's red team: a stitch w(6.5) = 1.41 mm wide with l = 4.5, and a
/// course centred 0.38 mm into its neighbour). Then the residual r(p) = e + F(p)/2 - p, >= 0
/// at e + size_min/2 and <= 0 at e + size_max/2, is bisected to the resolution of the
/// doubles: a root of r (a fixed point, also of a steep continuous field where the iteration
/// diverges) is taken; otherwise r changes sign at a jump J of F, and CHOICE: the item takes
/// the field on the jump's start side (p just before J, by the round-off tolerance: its l,
/// its size), so its centre
/// e + F/2 lies past J by less than half the jump of F. Every printed l and size pair then
/// keeps rules 3 and 4 (the size is F at the l printed, neighbours the mean of their sizes
/// apart), and only the field at such an item's centre differs from its l (docs/design.md,
/// rule 7).
/// The round-off within which centre_of takes r(p) = e + F(p)/2 - p as 0 for an item that
/// begins at e, F at most size_max. The layout's check (make_knitmap) accepts a centre this far
/// from where its l was taken, with e bounded by the centre's |c| + size_max (the review of
/// session 54: a check stricter than the solver's acceptance could fail a valid map).
double fixed_point_tolerance(double e, double size_max) {
  return 1e-9 * size_max + 16 * std::numeric_limits<double>::epsilon() * (std::abs(e) + size_max);
}

template <class SizeAt>
Centre centre_of(double e, double size0, double size_min, double size_max, SizeAt&& size_at) {
  double size = size0;
  // The bracket [lo, hi] of the root or jump: r(lo) > 0 (the centre lies beyond lo), r(hi) <= 0.
  bool have_lo = false, have_hi = false, hi_valid = true;
  double lo = 0.0, hi = 0.0, f_lo = 0.0, f_hi = 0.0;
  for (int it = 0; it < kFixedPointSteps; ++it) {
    const double p = e + 0.5 * size;
    const std::optional<double> f = size_at(p);
    if (!f) return {p, size, false, false};
    if (std::abs(*f - size) <= 1e-13 * size) return {p, *f, true, false};
    if (*f > size) {  // r(p) = (F(p) - size)/2 > 0
      if (!have_lo || p > lo) std::tie(have_lo, lo, f_lo) = std::tuple(true, p, *f);
    } else if (!have_hi || p < hi) {
      std::tie(have_hi, hi, f_hi) = std::tuple(true, p, *f);
    }
    size = *f;
  }
  auto r = [e](double p, double f) { return e + 0.5 * f - p; };
  if (!have_lo || (have_hi && lo >= hi)) {
    lo = e + 0.5 * size_min;
    const std::optional<double> f = size_at(lo);
    if (!f) return {lo, size_min, false, false};
    f_lo = *f;
  }
  if (!have_hi) {
    hi = e + 0.5 * size_max;
    const std::optional<double> f = size_at(hi);
    hi_valid = f.has_value();
    f_hi = f.value_or(size_max);
  }
  for (int it = 0; it < 200; ++it) {  // about 50 halvings from 0.1 mm to the doubles' spacing
    const double mid = lo + 0.5 * (hi - lo);
    if (!(mid > lo && mid < hi)) break;
    const std::optional<double> f = size_at(mid);
    if (f && r(mid, *f) > 0) {
      lo = mid;
      f_lo = *f;
    } else {
      hi = mid;
      hi_valid = f.has_value();
      f_hi = f.value_or(f_hi);
    }
  }
  // A root: r within round-off (of the sizes, and of the coordinates' doubles far out).
  const double tol = fixed_point_tolerance(e, size_max);
  if (hi_valid && std::abs(r(hi, f_hi)) <= tol) return {hi, f_hi, true, false};
  if (std::abs(r(lo, f_lo)) <= tol) return {lo, f_lo, true, false};
  if (!hi_valid) return {hi, f_lo, false, false};  // the item would reach past where none lies
  // The start side, `tol` before the bisected jump: at lo itself, a double or so from J, the
  // field taken again (the point's inversion warm-starts from the last) may be the other side's.
  return {lo - tol, f_lo, true, true};
}

}  // namespace

namespace detail {

/// The most times the patch covers a stretch of the line t = tc wider than `tiny` (the
/// boundary's winding number there, summed over its signed crossings), and the middle and width
/// of the widest such stretch. An edge crosses when its ends lie on either side of the line,
/// one at or below it and one above (the half-open rule: a vertex on the line counts as below,
/// so a vertex that only touches the line adds no crossing or two; the review of session 52: a
/// notch's tip on the line added one stray crossing, and two such tips read as covered twice).
int largest_cover(const std::vector<Eigen::Vector2d>& poly, double tc, double tiny, double& at,
                  double& width) {
  std::vector<std::pair<double, int>> x;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[(i + 1) % poly.size()];
    if ((a.y() <= tc) == (b.y() <= tc)) continue;
    x.emplace_back(a.x() + (b.x() - a.x()) * (tc - a.y()) / (b.y() - a.y()),
                   b.y() > a.y() ? 1 : -1);
  }
  std::sort(x.begin(), x.end());
  int w = 0, most = 1;
  for (std::size_t i = 0; i + 1 < x.size(); ++i) {
    w += x[i].second;
    const double dx = x[i + 1].first - x[i].first;
    if (dx > tiny && (std::abs(w) > most || (std::abs(w) == most && most > 1 && dx > width))) {
      most = std::abs(w);
      at = 0.5 * (x[i].first + x[i + 1].first);
      width = dx;
    }
  }
  return most;
}

}  // namespace detail

KnitMap make_knitmap(const Case& c, const CellTable& cells, const KnitMapOptions& opt) {
  const auto* mat = dynamic_cast<const KnitMaterial*>(c.material.get());
  if (!mat)
    throw InputError(c.file, "/material/type",
                     "the knitting map needs the knit material (type \"knit\"), not \"" +
                         c.material->name() + "\"");
  check_planar(c);
  PlanarPatch patch(c.surface, *mat);
  KnitMap map;

  // The course direction: its mean over the patch (as a line, modulo pi) and its spread.
  const auto& bu = c.surface.basis_u();
  const auto& bv = c.surface.basis_v();
  const int ns = 21;
  std::vector<double> phis;
  double C = 0, S = 0;
  for (int j = 0; j < ns; ++j)
    for (int i = 0; i < ns; ++i) {
      const Eigen::Vector2d th(bu.lo() + (bu.hi() - bu.lo()) * i / (ns - 1.0),
                               bv.lo() + (bv.hi() - bv.lo()) * j / (ns - 1.0));
      const double phi = patch.course_angle(th);
      phis.push_back(phi);
      C += std::cos(2 * phi);
      S += std::sin(2 * phi);
    }
  const double phi0 = 0.5 * std::atan2(S, C);
  double spread = 0;
  for (double phi : phis) {
    const double d = std::remainder(phi - phi0, kPi);
    spread = std::max(spread, std::abs(d));
  }
  map.course_direction_deg = phi0 * 180 / kPi;
  map.angle_spread_deg = spread * 180 / kPi;
  if (map.angle_spread_deg > opt.angle_tolerance_deg) {
    std::ostringstream os;
    os.precision(4);
    os << "the course direction varies by up to " << map.angle_spread_deg << " deg from its mean "
       << angle(map.course_direction_deg)
       << " deg over the patch; a flat-knitting machine knits straight courses, so the map "
          "needs a course direction constant within "
       << opt.angle_tolerance_deg << " deg (--angle-tolerance)";
    throw InputError(c.file, "/material/knitting_angle", os.str());
  }

  const Eigen::Vector2d d1(std::cos(phi0), std::sin(phi0)), d2(-std::sin(phi0), std::cos(phi0));
  Eigen::Matrix2d R;  // (x, y) -> (s, t)
  R.row(0) = d1.transpose();
  R.row(1) = d2.transpose();
  const auto poly = boundary(patch, c.surface, R, std::max(4, opt.boundary_samples));
  double s_min = 1e300, s_max = -1e300, t_min = 1e300, t_max = -1e300;
  for (const auto& q : poly) {
    s_min = std::min(s_min, q.x());
    s_max = std::max(s_max, q.x());
    t_min = std::min(t_min, q.y());
    t_max = std::max(t_max, q.y());
  }
  const double s_mid = 0.5 * (s_min + s_max);
  // A patch that overlaps itself in the plane (an annulus swept past 360 deg; session 51's red
  // team) covers some points twice, and a map would knit them twice. Its course lines were
  // refused for crossing the boundary four times, "not convex", which names the wrong fix.
  // Course lines at every half of the smallest course height, at most boundary_samples of them.
  {
    const int lines =
        static_cast<int>(std::clamp(std::ceil(2.0 * (t_max - t_min) / cells.min_course_height()),
                                    1.0, static_cast<double>(std::max(4, opt.boundary_samples))));
    int most = 1;
    double widest = 0.0;
    Eigen::Vector2d where(0.0, 0.0);
    for (int k = 0; k < lines; ++k) {
      const double tc = t_min + (t_max - t_min) * (k + 0.5) / lines;
      double at = 0.0, width = 0.0;
      const int cover = detail::largest_cover(poly, tc, 1e-9 * (s_max - s_min), at, width);
      if (cover > most || (cover == most && cover > 1 && width > widest)) {
        most = cover;
        widest = width;
        where = R.transpose() * Eigen::Vector2d(at, tc);
      }
    }
    if (most > 1) {
      std::ostringstream os;
      os.precision(4);
      os << "the patch overlaps itself in the plane: it covers the point x = " << where.x()
         << ", y = " << where.y() << " mm " << most
         << " times (its boundary winds around it), and a map would knit the stitches there "
            "more than once; a knitting map needs a patch that covers each point once (split it "
            "into cases that do not overlap)";
      throw InputError(c.file, "/geometry", os.str());
    }
  }
  {
    const double estimate = std::ceil((s_max - s_min) / cells.min_wale_width()) *
                            std::ceil((t_max - t_min) / cells.min_course_height());
    if (!(estimate <= opt.max_stitches)) {
      std::ostringstream os;
      os.precision(3);
      os << "the patch (" << s_max - s_min << " x " << t_max - t_min
         << " mm along and across the courses) would hold up to " << estimate
         << " stitches (smallest wale width " << cells.min_wale_width() << " mm, course height "
         << cells.min_course_height() << " mm), more than the " << opt.max_stitches
         << " a map may have (--max-stitches); check the geometry's units (mm)";
      throw InputError(c.file, "/geometry/control_points", os.str());
    }
  }

  auto l_at = [&](double s, double t) {
    return patch.stitch_value(patch.invert(R.transpose() * Eigen::Vector2d(s, t)));
  };
  // Stitches of the chord [s0, s1] at t: side by side, each w(l) wide at its centre (rule 4,
  // centre_of). l_at is evaluated once per point: the last point's l is kept for the stitch.
  auto lay = [&](double s0, double s1, double t) {
    Laid out;
    double s = s0, w = cells.wale_width(l_at(std::min(s0 + 1e-9, s1), t));
    double last_p = 0.0, last_l = 0.0;
    auto w_at = [&](double p) -> std::optional<double> {
      if (!(p < s1)) return std::nullopt;
      last_p = p;
      last_l = l_at(p, t);
      return cells.wale_width(last_l);
    };
    for (;;) {
      const Centre at = centre_of(s, w, cells.min_wale_width(), cells.max_wale_width(), w_at);
      if (!at.valid) break;
      const double l = at.p == last_p ? last_l : l_at(at.p, t);
      w = cells.wale_width(l);  // the width printed with this l, exactly
      if (!(s + 0.5 * w < s1)) break;
      out.s.push_back(s + 0.5 * w);
      out.l.push_back(l);
      out.p.push_back(at.p);
      out.jump.push_back(at.jump);
      s += w;
    }
    // Centre the stitches on the chord (their total width differs from it by less than one
    // stitch); each keeps the l it was laid with.
    out.shift = 0.5 * (s1 - s);
    for (double& x : out.s) x += out.shift;
    return out;
  };

  struct Row {
    KnitCourse course;
    Laid laid;
    double r = 0;
    double chord = 0;   ///< the patch's width along the course line (mm)
    double line = 0;    ///< the line t = const its stitches were laid on (centre_of)
    bool jump = false;  ///< the course lies on a jump of its height (centre_of)
  };
  std::vector<Row> rows;
  double t = t_min;
  double height = cells.course_height(l_at(s_mid, t_min + 1e-9 * (t_max - t_min)));
  bool nonconvex_warned = false;
  // Course lines whose chord holds no stitch: at the start and the end of the patch (a taper
  // narrower than one stitch) they are left out with a warning; between courses that hold
  // stitches the fabric would fall apart into pieces, which no machine knits as one map
  // (session 26: the first such line ended the map, and an hourglass's upper half was
  // silently missing, exit 0).
  int empty_start = 0, empty_pending = 0;
  double first_gap = 0.0;
  long empty_lines = 0;
  enum class Line { kStitches, kOutside, kEmpty };
  // The course on the line t = tc: its stitches (rule 4), or the line outside the patch (the
  // map ends) or holding no stitch. The last line laid is kept (centre_of asks for it first).
  Row line_row;
  Line line_status = Line::kOutside;
  double line_tc = std::numeric_limits<double>::quiet_NaN();
  auto course_line = [&](double tc) -> Line {
    if (tc == line_tc) return line_status;
    line_tc = tc;
    line_row = Row();
    line_status = Line::kOutside;
    if (!(tc < t_max)) return line_status;
    const auto cr = crossings(poly, tc);
    if (cr.size() < 2) return line_status;
    if (cr.size() > 2) {
      // A course line that leaves the patch and comes back (a non-convex patch, an arch):
      // its course would lay stitches across the gap, outside the fabric (session 42's red
      // team: 727 of an arch's 1,098 stitches, exit 0 with a warning). A gap narrower than
      // half a stitch (a shallow notch, a boundary's round-off) is knitted over; a wider one
      // is refused, as the pieces between courses are (rule 3).
      // The pairs (cr[2k], cr[2k+1]) are inside; with an odd count (the line through a
      // boundary vertex that is a local extremum, counted once) they are not pairs, and the
      // chord is taken whole (the review of session 42: the fabric beside such a vertex was
      // taken for a gap).
      double gap = 0.0, gap_at = 0.0;
      for (std::size_t i = 1; cr.size() % 2 == 0 && i + 1 < cr.size(); i += 2)
        if (cr[i + 1] - cr[i] > gap) {
          gap = cr[i + 1] - cr[i];
          gap_at = 0.5 * (cr[i] + cr[i + 1]);
        }
      if (gap > 0.5 * cells.min_wale_width()) {
        const Eigen::Vector2d x = R.transpose() * Eigen::Vector2d(gap_at, tc);
        std::ostringstream os;
        os.precision(4);
        os << "a course line " << tc - t_min
           << " mm into the patch (across the courses) crosses its boundary " << cr.size()
           << " times: the patch is not convex along its courses, and the course would be "
              "laid across a gap of "
           << gap << " mm outside the fabric (at x = " << x.x() << ", y = " << x.y()
           << " mm), wider than half a stitch (" << 0.5 * cells.min_wale_width()
           << " mm); a map knits each course as one piece of yarn: map the pieces as "
              "separate cases, or turn the courses (the knitting angle) so that they cross "
              "the patch once";
        throw InputError(c.file, "/geometry", os.str());
      }
      if (gap > 0.0 && !nonconvex_warned) {
        std::ostringstream os;
        os.precision(3);
        os << "a course line crosses the patch boundary " << cr.size()
           << " times (a non-convex patch): its gap of up to " << gap
           << " mm, less than half a stitch, is knitted over";
        map.warnings.push_back(os.str());
        nonconvex_warned = true;
      }
    }
    line_row.laid = lay(cr.front(), cr.back(), tc);
    line_row.chord = cr.back() - cr.front();
    line_row.line = tc;
    line_status = line_row.laid.l.empty() ? Line::kEmpty : Line::kStitches;
    return line_status;
  };
  // The course height of the line tc: the mean c(l) of its stitches (rule 3).
  auto height_at = [&](double tc) -> std::optional<double> {
    if (course_line(tc) != Line::kStitches) return std::nullopt;
    double sum = 0;
    for (double l : line_row.laid.l) sum += cells.course_height(l);
    return sum / double(line_row.laid.l.size());
  };
  for (;;) {
    const Centre at =
        centre_of(t, height, cells.min_course_height(), cells.max_course_height(), height_at);
    const Line status = course_line(at.p);
    if (status == Line::kOutside) break;
    if (status == Line::kEmpty) {
      height = at.size;
      if (rows.empty()) {
        ++empty_start;
      } else if (empty_pending++ == 0) {
        first_gap = at.p - t_min;
      }
      t += height;
      if (++empty_lines > 1000000)
        throw InputError(c.file, "/geometry", "more than 10^6 course lines hold no stitch");
      continue;
    }
    Row row = line_row;
    row.jump = at.jump;
    // The height printed with these stitches, exactly (at.size within round-off).
    height = *height_at(at.p);
    row.course.t = t + 0.5 * height - t_min;
    if (empty_pending > 0) {
      char where[96];
      std::snprintf(where, sizeof where, "%.4g mm", first_gap);
      throw InputError(c.file, "/geometry",
                       "the patch is narrower than one stitch across " +
                           std::to_string(empty_pending) + " course line(s) " + where +
                           " into it (across the courses), between courses that hold stitches: "
                           "the fabric would fall apart into pieces there; widen the patch or "
                           "map the pieces as separate cases");
    }
    row.course.height = height;
    row.course.stitches = static_cast<int>(row.laid.l.size());
    double wsum = 0;
    for (std::size_t i = 0; i < row.laid.l.size(); ++i) {
      wsum += cells.wale_width(row.laid.l[i]);
      row.course.height_mismatch =
          std::max(row.course.height_mismatch,
                   std::abs(cells.course_height(row.laid.l[i]) - height) / height);
    }
    const double wmean = wsum / row.course.stitches;
    const double smid_k = 0.5 * (row.laid.s.front() + row.laid.s.back());
    row.r = (smid_k - s_mid) / wmean - 0.5 * (row.course.stitches - 1);
    rows.push_back(std::move(row));
    t += height;
    if (rows.size() > 1000000)
      throw InputError(c.file, "/material/stitch_value", "more than 10^6 courses");
  }
  if (rows.empty())
    throw InputError(c.file, "/geometry", "the patch holds no course (smaller than one stitch)");
  if (empty_start > 0 || empty_pending > 0)
    map.warnings.push_back(std::to_string(empty_start) + " course line(s) at the start and " +
                           std::to_string(empty_pending) +
                           " at the end of the patch are narrower than one stitch and are "
                           "left out (the patch tapers below one stitch width there)");

  // The layout's rules, verified on what is printed (session 54's red team: unconverged fixed
  // points printed a stitch w(6.5) wide with l = 4.5 and overlapping courses, exit 0). A
  // failure here is a defect of this file, not of the input: it ends the command (exit 1)
  // instead of writing a map that breaks the rules. Tolerances: round-off of the sizes and of
  // the coordinates' doubles (far from the origin they resolve only |s| * 2.2e-16).
  {
    const double eps = std::numeric_limits<double>::epsilon();
    auto fail = [&](int course, int stitch, const std::string& what) {
      std::ostringstream os;
      os.precision(10);
      os << "knitmap: internal error: the layout of " << c.file << " breaks " << what
         << " at course " << course << (stitch > 0 ? ", stitch " + std::to_string(stitch) : "")
         << " (a defect of knit-macro, not of the case: please report it with the case file)";
      throw std::logic_error(os.str());
    };
    long jump_stitches = 0, jump_courses = 0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const Row& row = rows[k];
      const Laid& a = row.laid;
      const int kc = static_cast<int>(k) + 1;
      const double tk = t_min + row.course.t;
      // Rule 3: the course height is the mean c(l) of its stitches, and neighbouring courses
      // lie the mean of their heights apart.
      double sum = 0;
      for (double l : a.l) sum += cells.course_height(l);
      if (!(std::abs(row.course.height - sum / double(a.l.size())) <= 1e-12 * row.course.height))
        fail(kc, 0, "rule 3 (its height is not the mean c(l) of its stitches)");
      if (k > 0) {
        const Row& prev = rows[k - 1];
        const double gap = row.course.t - prev.course.t;
        const double want = 0.5 * (prev.course.height + row.course.height);
        if (!(std::abs(gap - want) <= 1e-9 * want + 16 * eps * std::abs(tk)))
          fail(kc, 0,
               "rule 3 (its centre line is " + std::to_string(gap) +
                   " mm from the previous one, the mean of their heights is " +
                   std::to_string(want) + " mm)");
      }
      // Rule 3's line: the stitches were laid on the course's centre line, or on a jump's
      // start side before it (centre_of).
      const double hk = row.course.height;
      const double hmax = cells.max_course_height();
      if (row.jump ? !(row.line < tk && tk - row.line < 0.5 * hk)
                   : !(std::abs(row.line - tk) <= fixed_point_tolerance(std::abs(tk) + hmax, hmax)))
        fail(kc, 0, "rule 3 (its stitches were not laid on its centre line)");
      jump_courses += row.jump;
      for (std::size_t i = 0; i < a.l.size(); ++i) {
        const int ic = static_cast<int>(i) + 1;
        const double wi = cells.wale_width(a.l[i]);
        // Rule 4: neighbours lie the mean of their widths w(l) apart.
        if (i > 0) {
          const double want = 0.5 * (cells.wale_width(a.l[i - 1]) + wi);
          if (!(std::abs(a.s[i] - a.s[i - 1] - want) <= 1e-9 * want + 16 * eps * std::abs(a.s[i])))
            fail(kc, ic,
                 "rule 4 (its centre is not the mean of the widths w(l) from its neighbour's)");
        }
        // Rule 7: the stitch's l is the field's at its centre as laid (before the centring),
        // or, on a jump, at the jump's start side, less than half its width before the centre.
        const double centre = a.s[i] - a.shift;
        const double wmax = cells.max_wale_width();
        const double tol_s = fixed_point_tolerance(std::abs(centre) + wmax, wmax);
        const bool placed = a.jump[i] ? a.p[i] < centre && centre - a.p[i] < 0.5 * wi
                                      : std::abs(a.p[i] - centre) <= tol_s;
        if (!placed || !(std::abs(l_at(a.p[i], row.line) - a.l[i]) <= 1e-9 * a.l[i]))
          fail(kc, ic, "rule 7 (its loop length is not the field's where it was laid)");
        jump_stitches += a.jump[i];
      }
    }
    if (jump_stitches > 0 || jump_courses > 0) {
      std::ostringstream os;
      if (jump_stitches > 0) os << jump_stitches << " stitch(es)";
      if (jump_stitches > 0 && jump_courses > 0) os << " and ";
      if (jump_courses > 0) os << jump_courses << " course(s)";
      os << " lie on a jump of the stitch-value field where l falls in the laying direction "
            "and no width w(l) (height c(l)) fits the l at the centre: each takes the l just "
            "before the jump, and its centre lies past the jump by less than half its size "
            "(docs/design.md, rule 7)";
      map.warnings.push_back(os.str());
    }
  }

  // The course direction at every stitch (session 46's red team: the 21 x 21 grid above missed
  // a knitting angle that turns between its points, e.g. a band of 1 rad a few stitches wide,
  // and the map said "spread 0", exit 0): each stitch is knitted along phi0, so its own course
  // direction must lie within the tolerance of it too.
  auto check_stitch_direction = [&](const KnitStitch& st) {
    const double d = std::remainder(patch.course_angle(patch.invert(st.position)) - phi0, kPi);
    map.angle_spread_deg = std::max(map.angle_spread_deg, std::abs(d) * 180 / kPi);
    if (map.angle_spread_deg <= opt.angle_tolerance_deg) return;
    std::ostringstream os;
    os.precision(4);
    os << "the course direction at the stitch of course " << st.course << ", needle " << st.needle
       << " (x = " << st.position.x() << ", y = " << st.position.y() << " mm) differs by "
       << std::abs(d) * 180 / kPi << " deg from the map's " << angle(map.course_direction_deg)
       << " deg (the knitting angle turns between the points where it was first checked); a "
          "flat-knitting machine knits straight courses, so the map needs a course direction "
          "constant within "
       << opt.angle_tolerance_deg << " deg (--angle-tolerance)";
    throw InputError(c.file, "/material/knitting_angle", os.str());
  };

  // Round half up with a tolerance: a centred course of an even stitch count has r exactly at
  // a half integer, where round-off must not shift some courses by one needle.
  auto first_of = [](double r) {
    return static_cast<long>(std::floor(r + 0.5 + kNeedleRoundingTolerance));
  };
  long first_min = std::numeric_limits<long>::max();
  for (const auto& row : rows) first_min = std::min(first_min, first_of(row.r));
  map.l_min = 1e300;
  map.l_max = -1e300;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    auto& row = rows[k];
    row.course.index = static_cast<int>(k) + 1;
    row.course.first_needle = static_cast<int>(first_of(row.r) - first_min) + 1;
    map.needles = std::max(map.needles, row.course.first_needle + row.course.stitches - 1);
    map.max_height_mismatch = std::max(map.max_height_mismatch, row.course.height_mismatch);
    for (std::size_t i = 0; i < row.laid.l.size(); ++i) {
      KnitStitch st;
      st.course = row.course.index;
      st.needle = row.course.first_needle + static_cast<int>(i);
      st.l = row.laid.l[i];
      st.position = R.transpose() * Eigen::Vector2d(row.laid.s[i], t_min + row.course.t);
      if (!std::isfinite(st.l) || !st.position.allFinite())
        throw InputError(
            c.file, "/material/stitch_value",
            "a non-finite stitch value or position in course " + std::to_string(st.course));
      check_stitch_direction(st);
      map.yarn_length += st.l;
      map.l_min = std::min(map.l_min, st.l);
      map.l_max = std::max(map.l_max, st.l);
      map.stitches.push_back(st);
    }
    map.courses.push_back(row.course);
  }
  if (map.max_height_mismatch > 0.05) {
    std::ostringstream os;
    os.precision(3);
    os << "the course height c(l) varies by up to " << 100 * map.max_height_mismatch
       << " % along a course; the map knits each course at its mean height (no short rows)";
    map.warnings.push_back(os.str());
  }
  // A patch about one stitch wide or one course tall (session 49's red team: a strip thinner
  // than a course was mapped to one course, exit 0, without a word): the map knits whole
  // stitches and courses, so its fabric may differ from such a patch by most of a stitch. Said
  // when a map of one or two courses (stitches) differs from the patch's extent by more than
  // kNarrowPatchMismatch of it, which a uniform patch two stitches (courses) across or more
  // about never does: the nearest whole count is off by at most half a stitch.
  {
    const double across = t_max - t_min;
    const double tall = rows.back().course.t + 0.5 * rows.back().course.height;
    std::ostringstream os;
    os.precision(3);
    // Only for a map of one or two courses (stitches): a taper's courses left out at one end
    // made a tall patch's 20 courses "about one course tall" (the review of session 50).
    if (rows.size() <= 2 && std::abs(tall - across) > kNarrowPatchMismatch * across) {
      os << "the map's " << rows.size() << " course(s) are " << tall
         << " mm tall where the patch is " << across
         << " mm across the courses: a patch about one course tall is knitted to whole courses "
            "(c = "
         << rows.back().course.height << " mm here)";
      map.warnings.push_back(os.str());
    }
    const Row& wide = *std::max_element(
        rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.chord < b.chord; });
    double width = 0;
    for (double l : wide.laid.l) width += cells.wale_width(l);
    if (wide.laid.l.size() <= 2 &&
        std::abs(width - wide.chord) > kNarrowPatchMismatch * wide.chord) {
      os.str("");
      os << "the widest course's " << wide.laid.l.size() << " stitch(es) are " << width
         << " mm wide where the patch is " << wide.chord
         << " mm wide along it: a patch about one stitch wide is knitted to whole stitches";
      map.warnings.push_back(os.str());
    }
  }
  return map;
}

std::string knitmap_summary(const KnitMap& map) {
  std::ostringstream os;
  os.precision(10);
  os << "stitches: " << map.stitches.size() << "\n"
     << "yarn_length_mm: " << map.yarn_length << "\n"
     << "needles: " << map.needles << "\n"
     << "courses: " << map.courses.size() << "\n"
     << "loop_length_min_mm: " << map.l_min << "\n"
     << "loop_length_max_mm: " << map.l_max << "\n"
     << "course_direction_deg: " << angle(map.course_direction_deg) << "\n"
     << "course_direction_spread_deg: " << angle(map.angle_spread_deg) << "\n"
     << "max_course_height_mismatch: " << map.max_height_mismatch << "\n";
  for (const auto& w : map.warnings) os << "warning: " << w << "\n";
  return os.str();
}

}  // namespace knit::macro
