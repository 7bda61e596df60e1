#include <numbers>

#include "knit/meso/rod/quaternion.hpp"
#include "knit/meso/rod/section.hpp"

namespace knit::meso::rod {

double Section::A() const {
  return std::numbers::pi * d * d / 4.0;
}
double Section::I() const {
  return std::numbers::pi * d * d * d * d / 64.0;
}
double Section::J() const {
  return 2.0 * I();
}
Eigen::Vector3d Section::C_Gamma() const {
  const double GAs = G() * shear_factor() * A();
  return {GAs, GAs, E * A()};
}
Eigen::Vector3d Section::C_K() const {
  return {E * I(), E * I(), G() * J()};
}

Quat<double> quat_from_rotation_vector(const Eigen::Vector3d& theta) {
  const double a = theta.norm();
  if (a < 1e-12) {
    Quat<double> q(1.0, 0.5 * theta(0), 0.5 * theta(1), 0.5 * theta(2));
    return q.normalized();
  }
  const double s = std::sin(0.5 * a) / a;
  return {std::cos(0.5 * a), s * theta(0), s * theta(1), s * theta(2)};
}

Quat<double> quat_from_matrix(const Eigen::Matrix3d& R) {
  // Shepperd (1978): pick the largest of the four squared components for stability.
  const double tr = R.trace();
  Eigen::Vector4d c(1.0 + tr, 1.0 + 2 * R(0, 0) - tr, 1.0 + 2 * R(1, 1) - tr,
                    1.0 + 2 * R(2, 2) - tr);
  int k;
  c.maxCoeff(&k);
  Quat<double> q;
  const double s = 2.0 * std::sqrt(c(k));  // = 4 |q_k|
  switch (k) {
    case 0:
      q << 0.25 * s, (R(2, 1) - R(1, 2)) / s, (R(0, 2) - R(2, 0)) / s, (R(1, 0) - R(0, 1)) / s;
      break;
    case 1:
      q << (R(2, 1) - R(1, 2)) / s, 0.25 * s, (R(0, 1) + R(1, 0)) / s, (R(0, 2) + R(2, 0)) / s;
      break;
    case 2:
      q << (R(0, 2) - R(2, 0)) / s, (R(0, 1) + R(1, 0)) / s, 0.25 * s, (R(1, 2) + R(2, 1)) / s;
      break;
    default:
      q << (R(1, 0) - R(0, 1)) / s, (R(0, 2) + R(2, 0)) / s, (R(1, 2) + R(2, 1)) / s, 0.25 * s;
  }
  if (q(0) < 0.0) q = -q;
  return q.normalized();
}

Eigen::Vector3d rotation_vector(const Quat<double>& qin) {
  Quat<double> q = qin.normalized();
  if (q(0) < 0.0) q = -q;
  const double sv = q.tail<3>().norm();
  if (sv < 1e-14) return 2.0 * q.tail<3>();
  const double a = 2.0 * std::atan2(sv, q(0));
  return (a / sv) * q.tail<3>();
}

}  // namespace knit::meso::rod
