// The homogenization load paths shared by the mesoscale sweep and the synthetic database
// generator (paper Sect. 2.1.2, eq. 7; Sect. 3.1.1: "13 load cases with 20 incremental load
// steps each").
//
// The paper does not list its load cases. Choice (design/notes.md, "Load cases"):
//   * 12 proportional biaxial paths F* = diag(1 + eps11, 1 + eps22), eps scaled linearly with
//     the step fraction t = k / n_steps (k = 1..n_steps). Their end points, given in
//     Green-Lagrange strain E = (F^T F - I)/2, lie on the polyline
//     (0.4, -0.15) -> (0.4, 0.4) -> (-0.15, 0.4), equally spaced by arc length, ordered
//     counter-clockwise (increasing angle atan2(E22, E11)). e_max = 0.4 covers the paper's
//     tensile tests (30 % applied strain gives E22 up to ~0.37, Sect. 3.1.2) without
//     extrapolation. This fan is the xi1 direction of
//     the response surface (eq. 17); the step fraction is xi2.
//   * 1 pure-shear path F* = [[1, sin g], [0, cos g]] with g = t * gamma_max, gamma_max = 40 deg;
//     there E11 = E22 = 0 and E12 = sin(g)/2 exactly. It feeds the S12(E12) curve.
// Everything is configurable: build your own std::vector<LoadPath>.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace knit::material {

enum class PathKind { kBiaxial = 0, kShear = 1, kUniaxial = 2, kGradient = 3 };

/// One homogenization load path. Biaxial: end Green-Lagrange strains (E11, E22) at t = 1.
/// Shear: the end shear angle gamma (rad) at t = 1 (target(0); target(1) unused).
/// Uniaxial stress: the Green-Lagrange strain along `axis` (target(0)) is prescribed, the
/// other normal stretch is found at every step so that its stress vanishes.
/// Gradient: F(t) = I + t H (any in-plane displacement gradient, e.g. shear with stretch).
struct LoadPath {
  PathKind kind = PathKind::kBiaxial;
  Eigen::Vector2d target = Eigen::Vector2d::Zero();
  int steps = 20;
  int axis = 0;                                 ///< kUniaxial: 0 = E11 (course), 1 = E22 (wale)
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();  ///< kGradient: end displacement gradient
  /// "paper": one of the paper's 13 paths (the fan of eq. 17 and the shear curve);
  /// "coverage": an extra path that only the energy-based law uses.
  std::string set = "paper";
};

/// The 13 default paths (12 biaxial + 1 shear), `steps` increments each.
std::vector<LoadPath> default_load_paths(int steps = 20, double e_max = 0.40, double e_min = -0.15,
                                         double gamma_max = 0.6981317007977318 /*40 deg*/);

/// Macroscopic deformation gradient F* (2x2) of path `path` at step fraction t in [0, 1].
Eigen::Matrix2d deformation_gradient(const LoadPath& path, double t);

/// Green-Lagrange strain E = (F^T F - I)/2 (paper eq. 9) as a 2x2 tensor.
Eigen::Matrix2d green_lagrange(const Eigen::Matrix2d& F);

/// 2nd Piola-Kirchhoff stress S = F^-1 P (paper eq. 9), symmetrized (the homogenized P* of a
/// converged cell makes F^-1 P symmetric up to the solver tolerance).
Eigen::Matrix2d second_piola_kirchhoff(const Eigen::Matrix2d& F, const Eigen::Matrix2d& P);

/// First Piola-Kirchhoff stress from S: P = F S.
Eigen::Matrix2d first_piola_kirchhoff(const Eigen::Matrix2d& F, const Eigen::Matrix2d& S);

/// Name of a path kind in files ("biaxial" / "shear").
std::string to_string(PathKind k);

}  // namespace knit::material
