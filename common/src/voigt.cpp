#include "knit/mechanics/voigt.hpp"

#include <cmath>

namespace knit::mech {

Matrix2d rotation(double alpha) {
  // Eq. (A.2).
  const double c = std::cos(alpha), s = std::sin(alpha);
  Matrix2d Q;
  Q << c, -s, s, c;
  return Q;
}

Matrix3d T_S(double alpha) {
  // Eq. (20) = second matrix of eq. (A.10).
  const double c = std::cos(alpha), s = std::sin(alpha);
  Matrix3d T;
  T << c * c, s * s, 2.0 * c * s,  //
      s * s, c * c, -2.0 * c * s,  //
      -c * s, c * s, c * c - s * s;
  return T;
}

Matrix3d T_E(double alpha) {
  // First matrix of eq. (A.10).
  const double c = std::cos(alpha), s = std::sin(alpha);
  Matrix3d T;
  T << c * c, s * s, c * s,  //
      s * s, c * c, -c * s,  //
      -2.0 * c * s, 2.0 * c * s, c * c - s * s;
  return T;
}

Matrix3d T_S_inv(double alpha) {
  return T_E(alpha).transpose();
}  // eq. (A.11)
Matrix3d T_E_inv(double alpha) {
  return T_S(alpha).transpose();
}  // eq. (A.11)

Vector3d strain_to_material(const Vector3d& E, double alpha) {
  return T_E(alpha) * E;
}
Vector3d strain_from_material(const Vector3d& E_hat, double alpha) {
  return T_S(alpha).transpose() * E_hat;
}
Vector3d stress_to_material(const Vector3d& S, double alpha) {
  return T_S(alpha) * S;
}
Vector3d stress_from_material(const Vector3d& S_hat, double alpha) {
  return T_E(alpha).transpose() * S_hat;
}

Matrix3d tangent_from_material(const Matrix3d& C_hat, double alpha) {
  const Matrix3d Ti = T_S_inv(alpha);
  return Ti * C_hat * Ti.transpose();
}

Matrix3d tangent_to_material(const Matrix3d& C, double alpha) {
  const Matrix3d T = T_S(alpha);
  return T * C * T.transpose();
}

Vector3d strain_to_voigt(const Matrix2d& E) {
  return {E(0, 0), E(1, 1), E(0, 1) + E(1, 0)};
}

Matrix2d strain_from_voigt(const Vector3d& E) {
  Matrix2d M;
  M << E(0), 0.5 * E(2), 0.5 * E(2), E(1);
  return M;
}

Vector3d stress_to_voigt(const Matrix2d& S) {
  return {S(0, 0), S(1, 1), 0.5 * (S(0, 1) + S(1, 0))};
}

Matrix2d stress_from_voigt(const Vector3d& S) {
  Matrix2d M;
  M << S(0), S(2), S(2), S(1);
  return M;
}

}  // namespace knit::mech
