#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "knit/material/load_paths.hpp"

namespace knit::material {

namespace {
/// Stretch 1 + eps giving Green-Lagrange strain E: E = ((1+eps)^2 - 1)/2.
double stretch_from_green(double E) {
  if (E <= -0.5)
    throw std::invalid_argument("load path: Green-Lagrange strain <= -0.5 is not reachable");
  return std::sqrt(1.0 + 2.0 * E);
}
}  // namespace

std::vector<LoadPath> default_load_paths(int steps, double e_max, double e_min, double gamma_max) {
  if (steps < 1) throw std::invalid_argument("load paths: steps must be >= 1");
  if (!(e_max > 0.0) || !(e_min < e_max))
    throw std::invalid_argument("load paths: need e_min < e_max and e_max > 0");
  std::vector<LoadPath> paths;
  const int n = 12;
  const double leg = e_max - e_min;  // length of each leg of the polyline
  for (int i = 0; i < n; ++i) {
    const double s = 2.0 * leg * static_cast<double>(i) / (n - 1);  // arc length from the start
    LoadPath p;
    p.steps = steps;
    if (s <= leg)
      p.target = {e_max, e_min + s};
    else
      p.target = {e_max - (s - leg), e_max};
    paths.push_back(p);
  }
  LoadPath shear;
  shear.kind = PathKind::kShear;
  shear.target = {gamma_max, 0.0};
  shear.steps = steps;
  paths.push_back(shear);
  return paths;
}

Eigen::Matrix2d deformation_gradient(const LoadPath& path, double t) {
  Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
  switch (path.kind) {
    case PathKind::kBiaxial: {
      const double l1 = stretch_from_green(path.target(0)), l2 = stretch_from_green(path.target(1));
      F(0, 0) = 1.0 + t * (l1 - 1.0);
      F(1, 1) = 1.0 + t * (l2 - 1.0);
      break;
    }
    case PathKind::kShear: {
      const double g = t * path.target(0);
      F(0, 1) = std::sin(g);
      F(1, 1) = std::cos(g);
      break;
    }
    case PathKind::kUniaxial: {
      if (path.axis != 0 && path.axis != 1)
        throw std::invalid_argument("load path: uniaxial axis must be 0 (course) or 1 (wale)");
      const int a = path.axis;
      F(a, a) = 1.0 + t * (stretch_from_green(path.target(0)) - 1.0);
      break;
    }
    case PathKind::kGradient:
      F += t * path.H;
      break;
  }
  return F;
}

bool StrainBox::contains(double E11, double E22, double E12) const {
  return E11 >= E11_min && E11 <= E11_max && E22 >= E22_min && E22 <= E22_max &&
         std::abs(E12) <= E12_max;
}

double halton(int i, int base) {
  double f = 1.0, r = 0.0;
  for (int n = i; n > 0; n /= base) {
    f /= base;
    r += f * (n % base);
  }
  return r;
}

Eigen::Matrix2d upper_gradient_for(double E11, double E22, double E12) {
  const double a = stretch_from_green(E11);
  const double b = 2.0 * E12 / a;
  const double d2 = 1.0 + 2.0 * E22 - b * b;
  if (!(d2 > 0.0))
    throw std::invalid_argument(
        "load path: no upper-triangular F for this strain (1 + 2 E22 <= b^2)");
  Eigen::Matrix2d F;
  F << a, b, 0.0, std::sqrt(d2);
  return F;
}

namespace {
/// Gradient paths from 0 to the strain states point(i) (i = 1, 2, ..., in [0, 1)^3) mapped
/// onto `b` (E12 over [-E12_max, E12_max]); states without an upper-triangular F with some
/// margin (1 + 2 E11 <= 0.01 or 1 + 2 E22 - b^2 <= 0.01), and those whose area ratio
/// J = det F is below `min_J`, are skipped.
template <class Point>
std::vector<LoadPath> paths_to_points(const StrainBox& b, int count, int steps,
                                      const std::string& set, double min_J, Point point) {
  std::vector<LoadPath> paths;
  for (int i = 1; static_cast<int>(paths.size()) < count && i < 100000; ++i) {
    const Eigen::Vector3d u = point(i);
    const double E11 = b.E11_min + u(0) * (b.E11_max - b.E11_min);
    const double E22 = b.E22_min + u(1) * (b.E22_max - b.E22_min);
    const double E12 = (2.0 * u(2) - 1.0) * b.E12_max;
    const double a2 = 1.0 + 2.0 * E11, bb = 4.0 * E12 * E12 / a2;
    if (!(a2 > 0.01) || !(1.0 + 2.0 * E22 - bb > 0.01)) continue;
    const Eigen::Matrix2d F = upper_gradient_for(E11, E22, E12);
    if (F.determinant() < min_J) continue;
    LoadPath p;
    p.kind = PathKind::kGradient;
    p.H = F - Eigen::Matrix2d::Identity();
    p.steps = steps;
    p.set = set;
    paths.push_back(p);
  }
  return paths;
}
}  // namespace

Eigen::Vector3d fill_point(int i) {
  constexpr double g = 1.22074408460575947536;  // plastic number: g^4 = g + 1
  const Eigen::Vector3d a(1.0 / g, 1.0 / (g * g), 1.0 / (g * g * g));
  Eigen::Vector3d u;
  for (int k = 0; k < 3; ++k) {
    const double x = 0.5 + static_cast<double>(i) * a(k);
    u(k) = x - std::floor(x);
  }
  return u;
}

Eigen::Vector3d half_sphere_direction(int k, int n) {
  if (n < 1 || k < 0 || k >= n)
    throw std::invalid_argument("half_sphere_direction: need 0 <= k < n");
  constexpr double kPi = 3.14159265358979323846;
  constexpr double kPhi = 1.61803398874989484820;
  const double z = (k + 0.5) / n;
  const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double az = 2.0 * kPi * static_cast<double>(k) / (kPhi * kPhi);
  return {rho * std::cos(az), rho * std::sin(az), z};
}

Eigen::Vector3d box_ray_end(const StrainBox& b, const Eigen::Vector3d& d, double min_J) {
  // Box-normalized strain u: E_i = u_i * (the box's extent on u_i's side of 0).
  const auto to_strain = [&](const Eigen::Vector3d& u) {
    return Eigen::Vector3d(u(0) * (u(0) >= 0 ? b.E11_max : -b.E11_min),
                           u(1) * (u(1) >= 0 ? b.E22_max : -b.E22_min), u(2) * b.E12_max);
  };
  const double m = d.cwiseAbs().maxCoeff();
  if (!(m > 0.0)) throw std::invalid_argument("box_ray_end: zero direction");
  const auto J2 = [](const Eigen::Vector3d& E) {
    return (1.0 + 2.0 * E(0)) * (1.0 + 2.0 * E(1)) - 4.0 * E(2) * E(2);
  };
  const double target = min_J * min_J;
  const Eigen::Vector3d end = to_strain(d / m);  // on the cube's surface
  if (J2(end) >= target) return end;
  // J^2 = 1 > target at s = 0: bisect s in [0, 1] for the first crossing J^2 = target (J^2 is
  // quadratic in s on each side's linear map, so bisection from the start finds it).
  double lo = 0.0, hi = 1.0;
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (lo + hi);
    (J2(to_strain(mid * d / m)) >= target ? lo : hi) = mid;
  }
  return to_strain(lo * d / m);
}

std::vector<LoadPath> coverage_load_paths(const CoverageOptions& o) {
  if (o.directions < 0 || o.biaxial_steps < 1 || o.uniaxial_steps < 1 || o.gradient_steps < 1 ||
      o.fill_count < 0 || o.fill_steps < 1 || o.rays < 0 || o.ray_steps < 1 ||
      !(o.fill_min_J >= 0.0 && o.fill_min_J < 1.0))
    throw std::invalid_argument(
        "coverage paths: directions, fill_count and rays >= 0, steps >= 1 and 0 <= fill_min_J "
        "< 1 required");
  const StrainBox& b = o.box;
  if (!(b.E11_min < 0 && b.E11_max > 0 && b.E22_min < 0 && b.E22_max > 0 && b.E12_max > 0))
    throw std::invalid_argument("coverage paths: the box must contain E = 0 in its interior");
  std::vector<LoadPath> paths;
  for (int axis = 0; axis < 2; ++axis) {
    LoadPath p;
    p.kind = PathKind::kUniaxial;
    p.axis = axis;
    p.target = {axis == 0 ? b.E11_max : b.E22_max, 0.0};
    p.steps = o.uniaxial_steps;
    p.set = "coverage";
    paths.push_back(p);
  }
  constexpr double kPi = 3.14159265358979323846;
  for (int k = 0; k < o.directions; ++k) {
    const double th = 2.0 * kPi * k / o.directions;
    const double c = std::cos(th), s = std::sin(th);
    // Ray from 0 to the box edge: the largest r with r (c, s) inside.
    double r = 1e300;
    if (c > 1e-12) r = std::min(r, b.E11_max / c);
    if (c < -1e-12) r = std::min(r, b.E11_min / c);
    if (s > 1e-12) r = std::min(r, b.E22_max / s);
    if (s < -1e-12) r = std::min(r, b.E22_min / s);
    LoadPath p;
    p.kind = PathKind::kBiaxial;
    p.target = {std::abs(r * c) < 1e-14 ? 0.0 : r * c, std::abs(r * s) < 1e-14 ? 0.0 : r * s};
    p.steps = o.biaxial_steps;
    p.set = "coverage";
    paths.push_back(p);
  }
  for (const Eigen::Vector2d& e : o.stretch) {
    LoadPath p;
    p.kind = PathKind::kGradient;
    p.H << e(0), std::sin(o.gamma), 0.0, e(1);
    p.steps = o.gradient_steps;
    p.set = "coverage";
    paths.push_back(p);
  }
  if (o.gradient_swapped)
    for (const Eigen::Vector2d& e : o.stretch) {
      LoadPath p;
      p.kind = PathKind::kGradient;
      p.H << e(1), 0.0, std::sin(o.gamma), e(0);
      p.steps = o.gradient_steps;
      p.set = "coverage";
      paths.push_back(p);
    }
  const auto fill =
      paths_to_points(b, o.fill_count, o.fill_steps, "coverage", o.fill_min_J, fill_point);
  paths.insert(paths.end(), fill.begin(), fill.end());
  for (int k = 0; k < o.rays; ++k) {
    const Eigen::Vector3d E = box_ray_end(b, half_sphere_direction(k, o.rays), o.fill_min_J);
    LoadPath p;
    p.kind = PathKind::kGradient;
    p.H = upper_gradient_for(E(0), E(1), E(2)) - Eigen::Matrix2d::Identity();
    p.steps = o.ray_steps;
    p.set = "coverage";
    paths.push_back(p);
  }
  return paths;
}

std::vector<LoadPath> holdout_load_paths(const StrainBox& b, int count, int steps) {
  if (count < 0 || steps < 1)
    throw std::invalid_argument("holdout paths: count >= 0 and steps >= 1 required");
  return paths_to_points(b, count, steps, "holdout", 0.0, [](int i) {
    return Eigen::Vector3d(halton(i, 2), halton(i, 3), halton(i, 5));
  });
}

Eigen::Matrix2d green_lagrange(const Eigen::Matrix2d& F) {
  return 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
}

Eigen::Matrix2d second_piola_kirchhoff(const Eigen::Matrix2d& F, const Eigen::Matrix2d& P) {
  const Eigen::Matrix2d S = F.inverse() * P;
  return 0.5 * (S + S.transpose());
}

Eigen::Matrix2d first_piola_kirchhoff(const Eigen::Matrix2d& F, const Eigen::Matrix2d& S) {
  return F * S;
}

std::string to_string(PathKind k) {
  switch (k) {
    case PathKind::kBiaxial:
      return "biaxial";
    case PathKind::kShear:
      return "shear";
    case PathKind::kUniaxial:
      return "uniaxial";
    case PathKind::kGradient:
      return "gradient";
  }
  return "?";
}

PathKind path_kind_from_string(const std::string& name) {
  for (PathKind k :
       {PathKind::kBiaxial, PathKind::kShear, PathKind::kUniaxial, PathKind::kGradient})
    if (to_string(k) == name) return k;
  throw std::invalid_argument("unknown load path kind '" + name +
                              "' (biaxial, shear, uniaxial, gradient)");
}

bool is_valid_path_set(const std::string& set) {
  return set == "paper" || set == "coverage" || set == "holdout";
}

}  // namespace knit::material
