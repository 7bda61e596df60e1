// Voigt notation of plane (2x2) strain, stress and tangent, and their rotation between the local
// Cartesian frame (e1, e2) of the shell and the principal material frame (ê1, ê2) at angle alpha.
//
// Reference: the paper, Sect. 2.2.1 (eqs. 20-22) and Appendix A (eqs. A.1-A.13).
//   ê_i = Q(alpha) e_i, Q = [[c, -s], [s, c]]                                     (A.1, A.2)
//   tensors: Ê = Qᵀ E Q,  Ŝ = Qᵀ S Q                                             (A.3)
//   Voigt:   E = (E11, E22, 2 E12),  S = (S11, S22, S12),  C = dS/dE (3x3)        (A.9)
//            Ê = T_E E,  Ŝ = T_S S,  T_S = T (eq. 20)                               (A.10)
//            T_E^{-1} = T_Sᵀ,  T_S^{-1} = T_Eᵀ,  hence T_E = T^{-ᵀ} and T_S T_Eᵀ = I  (A.11)
//   strain to the material frame:      Ê = T^{-ᵀ} E                                 (21, A.13)
//   stress and tangent back:           S = T^{-1} Ŝ,  C = T^{-1} Ĉ T^{-ᵀ}             (22, A.13)
// with c = cos(alpha), s = sin(alpha). The strain-stress work is frame-invariant: Eᵀ S = Êᵀ Ŝ.
//
// All functions are pure, fixed-size and allocation-free (meant for quadrature loops). Where
// the same angle is used many times, build T once (T_S / T_E) and use the matrix overloads.
#pragma once

#include <Eigen/Core>

namespace knit::mech {

using Vector3d = Eigen::Vector3d;
using Matrix3d = Eigen::Matrix3d;
using Matrix2d = Eigen::Matrix2d;

/// Q(alpha) of eq. (A.2): the 2-D rotation taking e_i to ê_i.
Matrix2d rotation(double alpha);

/// T_S(alpha) = T(alpha), eq. (20) / (A.10): Ŝ = T_S S for stresses (S11, S22, S12).
Matrix3d T_S(double alpha);
/// T_E(alpha), eq. (A.10): Ê = T_E E for strains (E11, E22, 2E12). T_E = T_S^{-ᵀ}.
Matrix3d T_E(double alpha);
/// T_S^{-1} = T_Eᵀ, eq. (A.11) (= T_S(-alpha)).
Matrix3d T_S_inv(double alpha);
/// T_E^{-1} = T_Sᵀ, eq. (A.11) (= T_E(-alpha)).
Matrix3d T_E_inv(double alpha);

/// Ê = T^{-ᵀ} E = T_E E (eq. 21): strain from the local Cartesian to the material frame.
Vector3d strain_to_material(const Vector3d& E, double alpha);
/// E = T_E^{-1} Ê = Tᵀ Ê: strain from the material frame back to the local Cartesian frame.
Vector3d strain_from_material(const Vector3d& E_hat, double alpha);
/// Ŝ = T S: stress from the local Cartesian to the material frame.
Vector3d stress_to_material(const Vector3d& S, double alpha);
/// S = T^{-1} Ŝ (eq. 22): stress from the material frame back to the local Cartesian frame.
Vector3d stress_from_material(const Vector3d& S_hat, double alpha);
/// C = T^{-1} Ĉ T^{-ᵀ} (eq. 22 / A.12): tangent dS/dE in the local Cartesian frame.
Matrix3d tangent_from_material(const Matrix3d& C_hat, double alpha);
/// Ĉ = T C Tᵀ: the inverse of tangent_from_material.
Matrix3d tangent_to_material(const Matrix3d& C, double alpha);

/// The same transformations with T = T_S(alpha) precomputed (T_inv = T_S_inv(alpha)).
inline Vector3d strain_to_material_T(const Vector3d& E, const Matrix3d& T_inv) {
  return T_inv.transpose() * E;
}
inline Vector3d stress_from_material_T(const Vector3d& S_hat, const Matrix3d& T_inv) {
  return T_inv * S_hat;
}
inline Matrix3d tangent_from_material_T(const Matrix3d& C_hat, const Matrix3d& T_inv) {
  return T_inv * C_hat * T_inv.transpose();
}

/// Symmetric 2x2 strain tensor -> Voigt (E11, E22, 2 E12) (the symmetric part is used).
Vector3d strain_to_voigt(const Matrix2d& E);
/// Voigt (E11, E22, 2 E12) -> symmetric 2x2 strain tensor.
Matrix2d strain_from_voigt(const Vector3d& E);
/// Symmetric 2x2 stress tensor -> Voigt (S11, S22, S12) (the symmetric part is used).
Vector3d stress_to_voigt(const Matrix2d& S);
/// Voigt (S11, S22, S12) -> symmetric 2x2 stress tensor.
Matrix2d stress_from_voigt(const Vector3d& S);

}  // namespace knit::mech
