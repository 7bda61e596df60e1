// Load-time check of the reference surface (see knit/macro/geometry_check.hpp).
#include "knit/macro/geometry_check.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "knit/spline/knot_vector.hpp"
#include "knit/spline/quadrature.hpp"

namespace knit::macro {

namespace {

/// Span ends and the max(p + 1, n) Gauss points of every non-empty knot span, increasing.
std::vector<double> sample_abscissae(const std::vector<double>& U, int p, int n) {
  const spline::QuadratureRule g = spline::gauss_legendre(std::max(p + 1, n));
  std::vector<double> s;
  for (std::size_t i = 0; i + 1 < U.size(); ++i) {
    const double a = U[i], b = U[i + 1];
    if (!(b > a)) continue;
    if (s.empty() || s.back() < a) s.push_back(a);
    for (double x : g.points) s.push_back(0.5 * (a + b) + 0.5 * (b - a) * x);
    s.push_back(b);
  }
  return s;
}

std::string where(const Eigen::Vector2d& t, const std::vector<double>& su,
                  const std::vector<double>& sv) {
  const bool u_end = t(0) == su.front() || t(0) == su.back();
  const bool v_end = t(1) == sv.front() || t(1) == sv.back();
  std::ostringstream os;
  os << "(theta1, theta2) = (" << t(0) << ", " << t(1) << ")"
     << (u_end && v_end   ? ", a corner of the patch"
         : u_end || v_end ? ", on an edge of the patch"
                          : "");
  return os.str();
}

/// The tangents A1, A2 at (u, v), the basis workspace kept (both checks below).
void tangents(const spline::SplineSurface& s, double u, double v, spline::SurfaceBasis& sb,
              Eigen::Vector3d& A1, Eigen::Vector3d& A2) {
  s.basis(u, v, 1, sb);
  const Eigen::MatrixXd& P = s.control_points();
  A1.setZero();
  A2.setZero();
  for (Eigen::Index l = 0; l < sb.index.size(); ++l) {
    A1 += sb.R(1, l) * P.row(sb.index(l)).transpose();
    A2 += sb.R(2, l) * P.row(sb.index(l)).transpose();
  }
}

/// |A1 x A2| at (u, v).
double area_density(const spline::SplineSurface& s, double u, double v, spline::SurfaceBasis& sb) {
  Eigen::Vector3d A1, A2;
  tangents(s, u, v, sb, A1, A2);
  return A1.cross(A2).norm();
}

/// The area of the element [u0, u1] x [v0, v1] by nu x nv Gauss points.
double element_area(const spline::SplineSurface& s, double u0, double u1, double v0, double v1,
                    int nu, int nv, spline::SurfaceBasis& sb) {
  const auto qu = spline::gauss_legendre(nu, u0, u1), qv = spline::gauss_legendre(nv, v0, v1);
  double a = 0.0;
  for (std::size_t j = 0; j < qv.points.size(); ++j)
    for (std::size_t i = 0; i < qu.points.size(); ++i)
      a += qu.weights[i] * qv.weights[j] * area_density(s, qu.points[i], qv.points[j], sb);
  return a;
}

}  // namespace

double patch_size(const spline::SplineSurface& s) {
  const Eigen::MatrixXd& P = s.control_points();
  return (P.colwise().maxCoeff() - P.colwise().minCoeff()).norm();
}

double patch_width(const spline::SplineSurface& s) {
  constexpr int kSegments = 64;
  const auto line_length = [&s](bool along_u) {
    const auto& b = along_u ? s.basis_u() : s.basis_v();
    const auto& o = along_u ? s.basis_v() : s.basis_u();
    const double mid = 0.5 * (o.lo() + o.hi());
    double len = 0.0;
    Eigen::VectorXd prev;
    for (int i = 0; i <= kSegments; ++i) {
      const double t = b.lo() + (b.hi() - b.lo()) * i / kSegments;
      Eigen::VectorXd x = along_u ? s.eval(t, mid) : s.eval(mid, t);
      if (i > 0) len += (x - prev).norm();
      prev = std::move(x);
    }
    return len;
  };
  return std::min(line_length(true), line_length(false));
}

int dense_samples_per_span(const spline::SplineSurface& s) {
  const auto spans = [](const std::vector<double>& U) {
    return std::max<std::size_t>(1, spline::unique_knots(U).size() - 1);
  };
  const double cells = static_cast<double>(spans(s.basis_u().knots())) *
                       static_cast<double>(spans(s.basis_v().knots()));
  return static_cast<int>(std::clamp(std::floor(std::sqrt(kMaxDenseSamples / cells)), 1.0,
                                     static_cast<double>(kDenseSamplesPerSpan)));
}

std::optional<GeometryDefect> find_geometry_defect(const spline::SplineSurface& s,
                                                   int samples_per_span) {
  double scale = patch_size(s);
  if (!(scale > 0)) scale = 1.0;
  const std::vector<double> su =
      sample_abscissae(s.basis_u().knots(), s.basis_u().degree(), samples_per_span);
  const std::vector<double> sv =
      sample_abscissae(s.basis_v().knots(), s.basis_v().degree(), samples_per_span);
  const std::size_t nu = su.size();
  spline::SurfaceBasis sb;
  std::vector<Eigen::Vector3d> prev_row(nu);  // normals of the previous v row
  Eigen::Vector3d left = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < sv.size(); ++j) {
    for (std::size_t i = 0; i < nu; ++i) {
      const Eigen::Vector2d t(su[i], sv[j]);
      Eigen::Vector3d A1, A2;
      tangents(s, t(0), t(1), sb, A1, A2);
      const Eigen::Vector3d a3 = A1.cross(A2);
      const double J = a3.norm();
      if (!(J > 1e-10 * scale * scale) || !(A1.norm() > 1e-12 * scale) ||
          !(A2.norm() > 1e-12 * scale)) {
        std::ostringstream os;
        os << "degenerate geometry: the surface Jacobian |A1 x A2| = " << J << " vanishes at "
           << where(t, su, sv) << " (coincident or collinear control points?)";
        return GeometryDefect{t, J, os.str()};
      }
      const Eigen::Vector3d n = a3 / J;
      const bool fold_u = i > 0 && !(n.dot(left) > 0.0);
      const bool fold_v = j > 0 && !(n.dot(prev_row[i]) > 0.0);
      if (fold_u || fold_v) {
        std::ostringstream os;
        os << "folded geometry: the surface normal flips (turns by more than 90 degrees from "
              "the neighbouring sample in theta"
           << (fold_u ? 1 : 2) << ") at " << where(t, su, sv) << " (control points out of order?)";
        return GeometryDefect{t, J, os.str()};
      }
      left = n;
      prev_row[i] = n;
    }
  }
  return std::nullopt;
}

double reference_area(const spline::SplineSurface& surface, int points_per_span) {
  const int nu = points_per_span > 0 ? points_per_span : surface.basis_u().degree() + 1;
  const int nv = points_per_span > 0 ? points_per_span : surface.basis_v().degree() + 1;
  const auto bu = spline::unique_knots(surface.basis_u().knots());
  const auto bv = spline::unique_knots(surface.basis_v().knots());
  spline::SurfaceBasis sb;
  double area = 0.0;
  for (std::size_t j = 0; j + 1 < bv.size(); ++j)
    for (std::size_t i = 0; i + 1 < bu.size(); ++i)
      area += element_area(surface, bu[i], bu[i + 1], bv[j], bv[j + 1], nu, nv, sb);
  return area;
}

std::optional<AreaQuadratureDefect> area_quadrature_defect(const spline::SplineSurface& surface) {
  const int pu = surface.basis_u().degree(), pv = surface.basis_v().degree();
  const auto bu = spline::unique_knots(surface.basis_u().knots());
  const auto bv = spline::unique_knots(surface.basis_v().knots());
  spline::SurfaceBasis sb;
  for (std::size_t j = 0; j + 1 < bv.size(); ++j)
    for (std::size_t i = 0; i + 1 < bu.size(); ++i) {
      const double a =
          element_area(surface, bu[i], bu[i + 1], bv[j], bv[j + 1], pu + 1, pv + 1, sb);
      const double exact = element_area(surface, bu[i], bu[i + 1], bv[j], bv[j + 1],
                                        pu + 1 + kAreaExtraPoints, pv + 1 + kAreaExtraPoints, sb);
      const double err = std::abs(a - exact) / exact;
      if (!(err <= kMaxAreaQuadratureError))
        return AreaQuadratureDefect{Eigen::Vector2d(bu[i], bv[j]),
                                    Eigen::Vector2d(bu[i + 1], bv[j + 1]), err};
    }
  return std::nullopt;
}

std::string symmetry_plane_problem(const spline::SplineSurface& surface,
                                   const std::vector<int>& row0, const std::vector<int>& row1,
                                   int component, const std::string& length_unit) {
  const Eigen::MatrixXd& P = surface.control_points();
  const char* axis = component == 0 ? "x" : component == 1 ? "y" : "z";
  std::ostringstream m;
  m.precision(6);
  double lo = P(row0.front(), component), hi = lo;
  for (int a : row0) {
    lo = std::min(lo, P(a, component));
    hi = std::max(hi, P(a, component));
  }
  if (hi - lo > kSymmetryPlaneTolerance * patch_size(surface)) {
    m << "the edge does not lie in a plane of normal " << axis << ": its control points' " << axis
      << " run from " << lo << " to " << hi << " " << length_unit << " (a symmetry plane of normal "
      << axis << " needs " << axis
      << " constant along the edge; check the edge and the plane's normal)";
    return m.str();
  }
  for (std::size_t k = 0; k < row0.size() && k < row1.size(); ++k) {
    const Eigen::Vector3d d = (P.row(row1[k]) - P.row(row0[k])).transpose();
    Eigen::Vector3d along = d;
    along(component) = 0.0;
    if (along.norm() > kSymmetryAngleTolerance * d.norm()) {
      m << "the control net does not leave the plane of normal " << axis
        << " along that normal: at the edge's control point " << k + 1 << " of " << row0.size()
        << " the next row is offset by (" << d(0) << ", " << d(1) << ", " << d(2) << ") "
        << length_unit << ", not along " << axis
        << " (the condition ties control points, so the net's second row must lie on the "
           "plane's normal; check the edge and the plane's normal)";
      return m.str();
    }
  }
  return "";
}

}  // namespace knit::macro
