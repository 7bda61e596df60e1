// Voigt rotations of paper Appendix A: identities (A.11), agreement with the tensor rotation
// Qᵀ E Q (A.3), inverse rotations, work invariance, and the tangent (22) against finite
// differences of the composed stress map.
#include <Eigen/LU>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "knit/mechanics/voigt.hpp"

using namespace knit::mech;

namespace {

Matrix2d random_symmetric(std::mt19937& gen) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  Matrix2d A;
  A << d(gen), d(gen), 0.0, d(gen);
  A(1, 0) = A(0, 1);
  return A;
}

const double kAngles[] = {0.0, 0.3, -1.1, 0.5 * M_PI, 2.7, -3.0, 0.25 * M_PI};

// A nonlinear, anisotropic material law in the material frame and its exact tangent.
Vector3d S_hat_of(const Vector3d& E) {
  return {2.0 * E(0) + 0.7 * E(1) + 3.0 * E(0) * E(0) + std::sinh(E(2)) * 0.2,
          0.7 * E(0) + 1.5 * E(1) + 0.5 * E(1) * E(2),
          0.4 * E(2) + 0.8 * E(2) * E(2) * E(2) + 0.3 * E(0) * E(1)};
}
Matrix3d C_hat_of(const Vector3d& E) {
  Matrix3d C;
  C << 2.0 + 6.0 * E(0), 0.7, 0.2 * std::cosh(E(2)),  //
      0.7, 1.5 + 0.5 * E(2), 0.5 * E(1),              //
      0.3 * E(1), 0.3 * E(0), 0.4 + 2.4 * E(2) * E(2);
  return C;
}

}  // namespace

TEST_CASE("Voigt transformation matrices satisfy eq. (A.11)", "[unit][voigt]") {
  const Matrix3d I = Matrix3d::Identity();
  for (double a : kAngles) {
    CHECK((T_S(a) * T_E(a).transpose() - I).norm() < 1e-14);
    CHECK((T_S(a) * T_S_inv(a) - I).norm() < 1e-14);
    CHECK((T_E(a) * T_E_inv(a) - I).norm() < 1e-14);
    CHECK((T_S_inv(a) - T_S(-a)).norm() < 1e-14);
    CHECK((T_E_inv(a) - T_E(-a)).norm() < 1e-14);
    // T_E = T^{-T}: the strain matrix of eq. (21).
    CHECK((T_E(a) - T_S(a).inverse().transpose()).norm() < 1e-13);
  }
  CHECK((T_S(0.0) - I).norm() == 0.0);
}

TEST_CASE("Voigt rotation equals the tensor rotation Q^T A Q", "[unit][voigt]") {
  std::mt19937 gen(42);
  std::uniform_real_distribution<double> da(-M_PI, M_PI);
  for (int trial = 0; trial < 50; ++trial) {
    const double a = da(gen);
    const Matrix2d Q = rotation(a);
    CHECK((Q.transpose() * Q - Matrix2d::Identity()).norm() < 1e-15);
    const Matrix2d E = random_symmetric(gen), S = random_symmetric(gen);
    const Matrix2d E_hat = Q.transpose() * E * Q, S_hat = Q.transpose() * S * Q;  // eq. (A.3)
    CHECK((strain_to_material(strain_to_voigt(E), a) - strain_to_voigt(E_hat)).norm() < 1e-14);
    CHECK((stress_to_material(stress_to_voigt(S), a) - stress_to_voigt(S_hat)).norm() < 1e-14);
    // Back: eq. (A.4).
    CHECK((strain_from_material(strain_to_voigt(E_hat), a) - strain_to_voigt(E)).norm() < 1e-14);
    CHECK((stress_from_material(stress_to_voigt(S_hat), a) - stress_to_voigt(S)).norm() < 1e-14);
    // Work conjugacy: E : S = Eᵀ S in Voigt notation, in both frames.
    const double w = (E.array() * S.array()).sum();
    CHECK(strain_to_voigt(E).dot(stress_to_voigt(S)) == Approx(w).epsilon(1e-13).margin(1e-15));
    CHECK(
        strain_to_material(strain_to_voigt(E), a).dot(stress_to_material(stress_to_voigt(S), a)) ==
        Approx(w).epsilon(1e-13).margin(1e-15));
  }
}

TEST_CASE("Voigt tensor conversions round-trip", "[unit][voigt]") {
  std::mt19937 gen(3);
  const Matrix2d E = random_symmetric(gen);
  CHECK((strain_from_voigt(strain_to_voigt(E)) - E).norm() < 1e-15);
  CHECK((stress_from_voigt(stress_to_voigt(E)) - E).norm() < 1e-15);
  const Vector3d v(0.1, -0.2, 0.3);
  CHECK(strain_from_voigt(v)(0, 1) == 0.15);
  CHECK(stress_from_voigt(v)(1, 0) == 0.3);
}

TEST_CASE("rotating by alpha then by -alpha is the identity", "[unit][voigt]") {
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  for (double a : kAngles) {
    const Vector3d E(d(gen), d(gen), d(gen)), S(d(gen), d(gen), d(gen));
    Matrix3d C;
    for (int i = 0; i < 9; ++i) C.data()[i] = d(gen);
    CHECK((strain_to_material(strain_to_material(E, a), -a) - E).norm() < 1e-14);
    CHECK((stress_to_material(stress_to_material(S, a), -a) - S).norm() < 1e-14);
    CHECK((strain_from_material(strain_to_material(E, a), a) - E).norm() < 1e-14);
    CHECK((stress_from_material(stress_to_material(S, a), a) - S).norm() < 1e-14);
    CHECK((tangent_from_material(tangent_to_material(C, a), a) - C).norm() < 1e-13);
    CHECK((tangent_to_material(tangent_to_material(C, a), -a) - C).norm() < 1e-13);
    // Precomputed-matrix overloads agree.
    const Matrix3d Ti = T_S_inv(a);
    CHECK((strain_to_material_T(E, Ti) - strain_to_material(E, a)).norm() < 1e-15);
    CHECK((stress_from_material_T(S, Ti) - stress_from_material(S, a)).norm() < 1e-15);
    CHECK((tangent_from_material_T(C, Ti) - tangent_from_material(C, a)).norm() < 1e-14);
  }
}

TEST_CASE("tangent_from_material is the derivative of the rotated stress map", "[unit][voigt]") {
  // S(E) = T^{-1} Ŝ(T^{-T} E); dS/dE must equal T^{-1} Ĉ T^{-T} (eq. 22).
  std::mt19937 gen(17);
  std::uniform_real_distribution<double> d(-0.4, 0.4);
  for (double a : kAngles) {
    const Vector3d E(d(gen), d(gen), d(gen));
    auto S_of = [&](const Vector3d& e) {
      return stress_from_material(S_hat_of(strain_to_material(e, a)), a);
    };
    const Matrix3d C = tangent_from_material(C_hat_of(strain_to_material(E, a)), a);
    const double h = 1e-6;
    Matrix3d C_fd;
    for (int j = 0; j < 3; ++j) {
      Vector3d ep = E, em = E;
      ep(j) += h;
      em(j) -= h;
      C_fd.col(j) = (S_of(ep) - S_of(em)) / (2.0 * h);
    }
    CHECK((C - C_fd).norm() < 1e-8 * (1.0 + C.norm()));
  }
  // The exact tangent of the local law itself (guards the test's own C_hat).
  const Vector3d E(0.1, -0.2, 0.3);
  Matrix3d fd;
  for (int j = 0; j < 3; ++j) {
    Vector3d ep = E, em = E;
    ep(j) += 1e-6;
    em(j) -= 1e-6;
    fd.col(j) = (S_hat_of(ep) - S_hat_of(em)) / 2e-6;
  }
  CHECK((fd - C_hat_of(E)).norm() < 1e-8);
}
