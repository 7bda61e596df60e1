// Quaternion kinematics of the rod cross-section (singularity-free rotation parameterization).
//
// A quaternion is stored as q = (q0, q1, q2, q3) = (scalar, vector) in an Eigen::Matrix<T,4,1>.
// The rotation of a NON-normalized quaternion is defined as that of q/|q| (Weeger, Yeung & Dunn
// 2017, CMAME 321, Sect. 3; the scale of q is a gauge freedom fixed by |q|^2 = 1 at the
// collocation points):
//   R(q) = I + 2/|q|^2 ( q0 [v]x + [v]x^2 ),  v = (q1, q2, q3)
// Material (convected) curvature from a quaternion field q(s) (body angular velocity):
//   K = axial(R^T R') = 2 vec(conj(q) * q') / |q|^2
// which is invariant under q -> c(s) q for any scalar field c(s) > 0.
// Functions are templates so that Eigen::AutoDiffScalar can differentiate them.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace knit::meso::rod {

template <class T>
using Quat = Eigen::Matrix<T, 4, 1>;
template <class T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <class T>
using Mat3 = Eigen::Matrix<T, 3, 3>;

/// Hamilton product a * b.
template <class T>
Quat<T> qmul(const Quat<T>& a, const Quat<T>& b) {
  Quat<T> c;
  c(0) = a(0) * b(0) - a(1) * b(1) - a(2) * b(2) - a(3) * b(3);
  c(1) = a(0) * b(1) + a(1) * b(0) + a(2) * b(3) - a(3) * b(2);
  c(2) = a(0) * b(2) - a(1) * b(3) + a(2) * b(0) + a(3) * b(1);
  c(3) = a(0) * b(3) + a(1) * b(2) - a(2) * b(1) + a(3) * b(0);
  return c;
}

template <class T>
Quat<T> qconj(const Quat<T>& a) {
  return Quat<T>(a(0), -a(1), -a(2), -a(3));
}

/// Left multiplication matrix: a * b = qleft(a) b.
template <class T>
Eigen::Matrix<T, 4, 4> qleft(const Quat<T>& a) {
  Eigen::Matrix<T, 4, 4> L;
  L << a(0), -a(1), -a(2), -a(3), a(1), a(0), -a(3), a(2), a(2), a(3), a(0), -a(1), a(3), -a(2),
      a(1), a(0);
  return L;
}

/// Right multiplication matrix: a * b = qright(b) a.
template <class T>
Eigen::Matrix<T, 4, 4> qright(const Quat<T>& b) {
  Eigen::Matrix<T, 4, 4> R;
  R << b(0), -b(1), -b(2), -b(3), b(1), b(0), b(3), -b(2), b(2), -b(3), b(0), b(1), b(3), b(2),
      -b(1), b(0);
  return R;
}

/// R(q) of the normalized quaternion q/|q| (q need not be unit).
template <class T>
Mat3<T> rotation(const Quat<T>& q) {
  const T s = T(2) / q.squaredNorm();
  const T w = q(0), x = q(1), y = q(2), z = q(3);
  Mat3<T> R;
  R(0, 0) = T(1) - s * (y * y + z * z);
  R(0, 1) = s * (x * y - w * z);
  R(0, 2) = s * (x * z + w * y);
  R(1, 0) = s * (x * y + w * z);
  R(1, 1) = T(1) - s * (x * x + z * z);
  R(1, 2) = s * (y * z - w * x);
  R(2, 0) = s * (x * z - w * y);
  R(2, 1) = s * (y * z + w * x);
  R(2, 2) = T(1) - s * (x * x + y * y);
  return R;
}

/// Material curvature K = 2 vec(conj(q) q_s) / |q|^2 for q and its derivative q_s (per unit
/// of the same parameter as q_s).
template <class T>
Vec3<T> material_curvature(const Quat<T>& q, const Quat<T>& q_s) {
  const Quat<T> c = qmul(qconj(q), q_s);
  return (T(2) / q.squaredNorm()) * c.template tail<3>();
}

/// Unit quaternion of the rotation vector theta (exponential map), q = (cos|θ|/2, sin(|θ|/2)
/// θ/|θ|).
Quat<double> quat_from_rotation_vector(const Eigen::Vector3d& theta);
/// Unit quaternion of a rotation matrix (Shepperd's method; sign with q0 >= 0 or the largest
/// component positive).
Quat<double> quat_from_matrix(const Eigen::Matrix3d& R);
/// Rotation vector of the unit quaternion q (log map), |θ| <= pi after choosing the sign.
Eigen::Vector3d rotation_vector(const Quat<double>& q);

}  // namespace knit::meso::rod
