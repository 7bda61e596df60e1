#include <Eigen/Dense>
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
  if (path.kind == PathKind::kBiaxial) {
    const double l1 = stretch_from_green(path.target(0)), l2 = stretch_from_green(path.target(1));
    F(0, 0) = 1.0 + t * (l1 - 1.0);
    F(1, 1) = 1.0 + t * (l2 - 1.0);
  } else {
    const double g = t * path.target(0);
    F(0, 1) = std::sin(g);
    F(1, 1) = std::cos(g);
  }
  return F;
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
  return k == PathKind::kShear ? "shear" : "biaxial";
}

}  // namespace knit::material
