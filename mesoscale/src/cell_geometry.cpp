// Single-jersey unit-cell geometry: see knit/meso/cell/geometry.hpp.
#include "knit/meso/cell/geometry.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "knit/spline/knot_vector.hpp"
#include "knit/spline/quadrature.hpp"

namespace knit::meso::cell {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kStitchDensity = 18.27;  // l^2/(w c), notes.md
// Parts of the same yarn closer than this in the loop parameter are neighbours along the yarn,
// not a contact (a quarter loop: head to leg).
constexpr double kSelfExclusion = 0.3;
}  // namespace

CellDimensions cell_dimensions(double l) {
  if (!(l > 0) || !std::isfinite(l))
    throw std::invalid_argument("loop length must be positive, got " + std::to_string(l));
  CellDimensions d;
  d.loop_length = l;
  if (std::abs(l - 4.5) < 1e-12) {
    d.w = 1.26;
    d.c = 0.88;
  } else if (std::abs(l - 6.5) < 1e-12) {
    d.w = 1.41;
    d.c = 1.64;
  } else {
    d.w = 1.26 + (l - 4.5) * (1.41 - 1.26) / 2.0;
    d.c = l * l / (kStitchDensity * d.w);
  }
  return d;
}

std::string loop_length_range_warning(double l) {
  if (l >= kPublishedLoopLengthMin - 1e-12 && l <= kPublishedLoopLengthMax + 1e-12) return {};
  std::ostringstream os;
  os << "warning: loop length " << l << " mm lies outside the cells with published wale width "
     << "and course height (" << kPublishedLoopLengthMin << " and " << kPublishedLoopLengthMax
     << " mm; docs/unit-cell.md): w and c are extrapolated (w = " << cell_dimensions(l).w
     << " mm, c = " << cell_dimensions(l).c
     << " mm), and the cell has not been compared with any knit there";
  return os.str();
}

Eigen::Vector3d LoopShape::point(double s, int k) const {
  const double a = 2 * kPi * s, b = 4 * kPi * s;
  switch (k) {
    case 0:
      return {w * s + gamma * std::sin(b), 0.5 * h * std::cos(a), 0.5 * d * std::cos(b)};
    case 1:
      return {w + gamma * 4 * kPi * std::cos(b), -0.5 * h * 2 * kPi * std::sin(a),
              -0.5 * d * 4 * kPi * std::sin(b)};
    case 2:
      return {-gamma * 16 * kPi * kPi * std::sin(b), -0.5 * h * 4 * kPi * kPi * std::cos(a),
              -0.5 * d * 16 * kPi * kPi * std::cos(b)};
    default:
      throw std::invalid_argument("LoopShape::point: derivative order must be 0..2");
  }
}

double LoopShape::length() const {
  const auto q = spline::gauss_legendre(20);
  double L = 0;
  const int segs = 32;
  for (int e = 0; e < segs; ++e) {
    const double a = double(e) / segs, b = double(e + 1) / segs;
    for (std::size_t i = 0; i < q.points.size(); ++i) {
      const double s = 0.5 * (a + b) + 0.5 * (b - a) * q.points[i];
      L += 0.5 * (b - a) * q.weights[i] * point(s, 1).norm();
    }
  }
  return L;
}

double spline_length(const spline::SplineCurve& curve, int npts) {
  const auto q = spline::gauss_legendre_on_spans(npts, curve.knots());
  double L = 0;
  for (std::size_t i = 0; i < q.points.size(); ++i)
    L += q.weights[i] * curve.derivatives(q.points[i], 1).row(1).norm();
  return L;
}

spline::SplineCurve interpolate_greville(int p, int n,
                                         const std::function<Eigen::Vector3d(double)>& f) {
  if (p < 1 || n < p + 1) throw std::invalid_argument("interpolate_greville: need n >= p+1 >= 2");
  spline::BSplineBasis basis(p, spline::uniform_knots(p, n - p, 0.0, 1.0));
  const auto g = basis.greville();
  Eigen::MatrixXd A(n, n), rhs(n, 3);
  for (int i = 0; i < n; ++i) {
    A.row(i) = basis.eval_all(g[i]).transpose();
    rhs.row(i) = f(g[i]).transpose();
  }
  Eigen::MatrixXd P = A.partialPivLu().solve(rhs);
  return spline::SplineCurve(basis, P);
}

namespace {

// Secant iteration on h so that length(h) = l. `build` returns the spline length for h.
template <class Build>
double solve_h(double l, double h0, double rtol, Build&& build, int* iters) {
  double h1 = h0, L1 = build(h1) - l;
  double h2 = h0 * 1.05, L2 = build(h2) - l;
  int it = 0;
  for (; it < 60 && std::abs(L2) > rtol * l; ++it) {
    if (L2 == L1) break;
    const double h3 = h2 - L2 * (h2 - h1) / (L2 - L1);
    h1 = h2;
    L1 = L2;
    h2 = h3 > 0 ? h3 : 0.5 * h1;
    L2 = build(h2) - l;
  }
  // Written so that a NaN residual (a yarn diameter of 1e308 mm overflows the shape) fails too:
  // before, it passed this test and the cell was written with a measured length of NaN, exit 0.
  if (!(std::abs(L2) <= 1e3 * rtol * l))
    throw GeometryError("cell geometry: could not match the loop length (residual " +
                        std::to_string(L2) + " mm); is the loop too short for w and d?");
  if (iters) *iters = it;
  return h2;
}

LoopShape base_shape(const CellDimensions& dim, const GeometryOptions& opt) {
  LoopShape s;
  s.w = dim.w;
  s.d = opt.d;
  s.gamma = opt.gamma_over_w * dim.w;
  // Initial h: the closed form's length is roughly 2 h + 2 (w/2 + pi*gamma) ...
  s.h = std::max(0.2, 0.5 * (dim.loop_length - dim.w - 2 * kPi * s.gamma));
  return s;
}

void check(const GeometryOptions& o) {
  if (!(o.d > 0)) throw std::invalid_argument("yarn diameter must be positive");
  if (o.pieces < 1) throw std::invalid_argument("pieces must be >= 1");
  if (o.degree < 1 || o.ctrl_per_piece < o.degree + 1)
    throw std::invalid_argument("need ctrl_per_piece >= degree + 1 >= 2");
}

}  // namespace

CellGeometry make_cell_geometry(double l, const GeometryOptions& opt) {
  check(opt);
  CellGeometry g;
  g.dim = cell_dimensions(l);
  g.shape = base_shape(g.dim, opt);
  const int np = opt.pieces;
  auto build = [&](double h) {
    LoopShape s = g.shape;
    s.h = h;
    g.pieces.clear();
    double L = 0;
    for (int k = 0; k < np; ++k) {
      const double a = double(k) / np, b = double(k + 1) / np;
      g.pieces.push_back(interpolate_greville(
          opt.degree, opt.ctrl_per_piece, [&](double xi) { return s.point(a + (b - a) * xi); }));
      L += spline_length(g.pieces.back());
    }
    return L;
  };
  g.shape.h = solve_h(l, g.shape.h, opt.length_rtol, build, &g.h_iterations);
  g.measured_length = build(g.shape.h);
  return g;
}

AnalysisCurve analysis_curve(const CellDimensions& dim, int elements, int p,
                             const GeometryOptions& opt) {
  check(opt);
  if (elements < 1) throw std::invalid_argument("analysis curve: elements must be >= 1");
  AnalysisCurve a;
  a.shape = base_shape(dim, opt);
  const int n = elements + p;
  auto build = [&](double h) {
    LoopShape s = a.shape;
    s.h = h;
    a.curve = interpolate_greville(p, n, [&](double t) { return s.point(t); });
    return spline_length(a.curve);
  };
  a.shape.h = solve_h(dim.loop_length, a.shape.h, opt.length_rtol, build, nullptr);
  a.length = build(a.shape.h);
  return a;
}

const char* loop_part(double s) {
  s -= std::floor(s);
  if (s < 0.125 || s > 0.875) return "head";
  if (std::abs(s - 0.5) < 0.125) return "foot";
  return "leg";
}

namespace {

// Newton on (s1, s2) for P(a(s1)) = P(b(s2)) + t in the x-y projection.
bool refine_crossing(const LoopShape& sh, const Eigen::Vector2d& t, double& s1, double& s2) {
  for (int it = 0; it < 30; ++it) {
    const Eigen::Vector3d a = sh.point(s1), b = sh.point(s2);
    const Eigen::Vector2d r = a.head<2>() - b.head<2>() - t;
    if (r.norm() < 1e-14) return true;
    Eigen::Matrix2d J;
    J.col(0) = sh.point(s1, 1).head<2>();
    J.col(1) = -sh.point(s2, 1).head<2>();
    const Eigen::Vector2d ds = J.partialPivLu().solve(-r);
    s1 += ds(0);
    s2 += ds(1);
  }
  return (sh.point(s1).head<2>() - sh.point(s2).head<2>() - t).norm() < 1e-10;
}

}  // namespace

std::optional<std::string> interlock_defect(const LoopShape& shape, double c) {
  const std::size_t n = crossings_with_next_course(shape, c, kInterlockChords).size();
  if (n == static_cast<std::size_t>(kStitchCrossings)) return std::nullopt;
  std::ostringstream m;
  m << "the loop does not interlock with the next course like a single-jersey stitch: its "
       "centreline crosses the next course's at "
    << n << " points in projection, not " << kStitchCrossings
    << " (the loop shape, set by the loop length, gamma/w and the yarn diameter, is outside the "
       "range where the closed-form loop is a knit)";
  return m.str();
}

std::vector<Crossing> crossings_with_next_course(const LoopShape& sh, double c, int samples) {
  // Self loop over s in [0,1); neighbours: the loop shifted by (i w, c) for i = -2..2, each over
  // its own s in [0,1). Segment-segment intersection of dense polylines, then Newton.
  const int N = std::max(8, samples);
  std::vector<Eigen::Vector2d> P(N + 1);
  for (int k = 0; k <= N; ++k) P[k] = sh.point(double(k) / N).head<2>();
  std::vector<Crossing> out;
  for (int i = -2; i <= 2; ++i) {
    const Eigen::Vector2d t(i * sh.w, c);
    for (int a = 0; a < N; ++a) {
      const Eigen::Vector2d p0 = P[a], p1 = P[a + 1];
      for (int b = 0; b < N; ++b) {
        const Eigen::Vector2d q0 = P[b] + t, q1 = P[b + 1] + t;
        const Eigen::Vector2d r = p1 - p0, sdir = q1 - q0;
        const double den = r.x() * sdir.y() - r.y() * sdir.x();
        if (std::abs(den) < 1e-15) continue;
        const Eigen::Vector2d qp = q0 - p0;
        const double ta = (qp.x() * sdir.y() - qp.y() * sdir.x()) / den;
        const double tb = (qp.x() * r.y() - qp.y() * r.x()) / den;
        if (ta < 0 || ta >= 1 || tb < 0 || tb >= 1) continue;
        double s1 = (a + ta) / N, s2 = (b + tb) / N;
        refine_crossing(sh, t, s1, s2);
        Crossing x;
        x.s_self = s1 - std::floor(s1);
        x.s_other = s2 - std::floor(s2);
        x.shift_i = i;
        x.shift_j = 1;
        x.dz = sh.point(s1).z() - sh.point(s2).z();
        x.part_self = loop_part(s1);
        x.part_other = loop_part(s2);
        out.push_back(x);
      }
    }
  }
  return out;
}

Clearance minimum_clearance(const LoopShape& sh, double c) {
  const int N = 400;
  std::vector<Eigen::Vector3d> P(N);
  for (int k = 0; k < N; ++k) P[k] = sh.point(double(k) / N);
  Clearance best;
  best.min_distance = 1e300;
  // Courses and copies up to two periods away (session 57: the contact search takes every one
  // within reach; the courses +-2 lie 0.469 mm from the yarn at 4.5 mm, a thicker yarn reaches
  // them).
  for (int j = -2; j <= 2; ++j)
    for (int i = -2; i <= 2; ++i) {
      const Eigen::Vector3d t(i * sh.w, j * c, 0);
      for (int a = 0; a < N; ++a)
        for (int b = 0; b < N; ++b) {
          // Same course (j = 0): the images are the same yarn continued (point(s + i) =
          // point(s) + i w); only parameter-distant parts of it count.
          if (j == 0 && std::abs(double(a - b) / N - i) < kSelfExclusion) continue;
          const double dd = (P[a] - P[b] - t).norm();
          if (dd < best.min_distance) {
            best.min_distance = dd;
            best.s_self = double(a) / N;
            best.s_other = double(b) / N;
            best.shift_i = i;
            best.shift_j = j;
          }
        }
    }
  // Newton refinement of the distance minimum on the two parameters.
  const Eigen::Vector3d t(best.shift_i * sh.w, best.shift_j * c, 0);
  double s1 = best.s_self, s2 = best.s_other;
  for (int it = 0; it < 30; ++it) {
    const Eigen::Vector3d r = sh.point(s1) - sh.point(s2) - t;
    const Eigen::Vector3d a1 = sh.point(s1, 1), b1 = sh.point(s2, 1);
    const Eigen::Vector3d a2 = sh.point(s1, 2), b2 = sh.point(s2, 2);
    Eigen::Vector2d g(r.dot(a1), -r.dot(b1));
    Eigen::Matrix2d H;
    H << a1.dot(a1) + r.dot(a2), -a1.dot(b1), -a1.dot(b1), b1.dot(b1) - r.dot(b2);
    const Eigen::Vector2d ds = H.ldlt().solve(-g);
    s1 += ds(0);
    s2 += ds(1);
    if (ds.norm() < 1e-14) break;
  }
  const double dd = (sh.point(s1) - sh.point(s2) - t).norm();
  if (dd < best.min_distance) {
    best.min_distance = dd;
    best.s_self = s1 - std::floor(s1);
    best.s_other = s2 - std::floor(s2);
  }
  best.clearance = best.min_distance - sh.d;
  return best;
}

GeometryBlame geometry_blame(double loop_length, const GeometryOptions& failing, bool d_chosen,
                             bool gamma_chosen) {
  auto builds = [loop_length](const GeometryOptions& go) {
    try {
      const CellGeometry g = make_cell_geometry(loop_length, go);
      return !interlock_defect(g.shape, g.dim.c).has_value();
    } catch (const std::exception&) {
      return false;
    }
  };
  const GeometryOptions def;
  if (d_chosen && failing.d != def.d) {
    GeometryOptions go = failing;
    go.d = def.d;
    if (builds(go)) return GeometryBlame::kDiameter;
  }
  if (gamma_chosen && failing.gamma_over_w != def.gamma_over_w) {
    GeometryOptions go = failing;
    go.gamma_over_w = def.gamma_over_w;
    if (builds(go)) return GeometryBlame::kGamma;
  }
  return GeometryBlame::kLoopLength;
}

std::string loop_length_message(double loop_length, double d, const GeometryError& e) {
  std::ostringstream msg;  // (std::to_string printed 1e308 with 309 digits)
  msg << "no cell geometry for " << loop_length << " mm with yarn diameter " << d
      << " mm: " << e.what();
  return msg.str();
}

}  // namespace knit::meso::cell
