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
  /// "coverage": an extra path that only the energy-based law uses;
  /// "holdout": a check of the law, never fitted.
  std::string set = "paper";
};

/// The strain box the database covers (material frame, Green-Lagrange, tensor E12); the
/// evidence for its default is in docs/unit-cell.md ("Strain box"): the paper's cases visit
/// E11 in [-0.32, 0.40], E22 in [-0.15, 0.50], |E12| <= 0.39.
struct StrainBox {
  double E11_min = -0.35, E11_max = 0.45;
  double E22_min = -0.30, E22_max = 0.55;
  double E12_max = 0.40;  ///< |E12| <= E12_max
  /// Smallest extent of each side from 0 that a sweep input may give (0.1 % strain): below it
  /// the coverage paths carry stresses at the level of the cell's round-off.
  static constexpr double kMinExtent = 1e-3;
  bool contains(double E11, double E22, double E12) const;
};

/// The coverage paths (set "coverage") that the energy-based law needs beyond the paper's fan
/// (issue 11), all inside `box`:
///   * 2 uniaxial-stress paths (axis 0 = course, 1 = wale) to the box's tensile edge;
///   * `directions` proportional biaxial paths whose end strains (E11, E22) lie on the box edge
///     in the directions theta_k = 2 pi k / directions (k = 0.., the full circle incl. biaxial
///     compression and the anticlastic quadrants);
///   * gradient paths F = I + t H, H = [[e1, sin g], [0, e2]] for the (e1, e2) of `stretch`
///     (shear combined with stretch; (e1, e2) = uniaxial-like states too), g = `gamma`;
///   * `fill_count` gradient paths of `fill_steps` steps to quasi-random strain states of the
///     whole box (E12 of both signs): the R3 sequence (fill_point), a different low-discrepancy
///     sequence than the held-out paths' Halton points, so no fill path ends on a held-out state.
///     They sample shear combined with stretch and compression throughout the box, where the
///     rays above leave gaps (issue 11, docs/law-experiments.md "Denser sampling, measured
///     (session 5)"). States whose area ratio J = det F is below `fill_min_J` (0.5) are skipped:
///     there the cell locks up (one fill state at J = 0.19 reached S = 114 MPa, 5x the stress
///     range of every other state, just before its path diverged); the held-out states all have
///     J >= 0.56.
///   * `rays` gradient paths of `ray_steps` steps along rays of the whole 3-D box (issue 11,
///     docs/law-experiments.md "The compressed-and-sheared corner"): the ray directions are the
///     `rays` points of a Fibonacci lattice on the half-sphere E12 > 0 in box-normalized strain
///     (each axis scaled by the box's extent on that side of 0, so the box is the cube [-1, 1]^3),
///     each ray from E = 0 out to the box's surface; a ray whose end has J = det F < `fill_min_J`
///     is shortened to J = fill_min_J. The full circle of biaxial directions above is the E12 = 0
///     section of this sphere; the rays add every mix of stretch, compression and shear out to the
///     box's faces, edges and corners (the fill paths sample the interior).
///     The law is even in E12, so one half-sphere suffices.
struct CoverageOptions {
  StrainBox box;
  int directions = 16;  ///< biaxial directions on the full circle (22.5 deg)
  int biaxial_steps = 10, uniaxial_steps = 10, gradient_steps = 10;
  double gamma = 0.6981317007977318;  ///< 40 deg, end shear angle of the gradient paths
  /// (e1, e2) of the gradient paths (displacement gradients F11 - 1, F22 - 1).
  std::vector<Eigen::Vector2d> stretch = {{0.0, 0.0},   {0.2, 0.0},  {0.0, 0.25}, {0.25, -0.12},
                                          {-0.12, 0.3}, {0.15, 0.2}, {-0.1, -0.1}};
  int fill_count = 0, fill_steps = 6;  ///< quasi-random fill paths (0 = none)
  double fill_min_J = 0.5;             ///< skip fill states with det F below this
  int rays = 0, ray_steps = 8;         ///< rays of the 3-D box (0 = none)
  /// Also the course/wale mirror image of every shear-with-stretch path: H' = P H P with P the
  /// axis swap, [[e2, 0], [sin g, e1]] (lower triangular, so the shear's F12^2 / 2 goes to E11
  /// instead of E22, and shear with E22 compressed is reached).
  bool gradient_swapped = false;
};
std::vector<LoadPath> coverage_load_paths(const CoverageOptions& opt);

/// `count` held-out paths (set "holdout"): gradient paths F = I + t H from 0 to the strain
/// states E_k of the Halton sequence (bases 2, 3, 5; points 1..count) mapped onto `box`
/// (E12 over [-E12_max, E12_max]); H upper triangular, so F(1) = [[a, b], [0, d]] with
/// a = sqrt(1 + 2 E11), b = 2 E12 / a, d = sqrt(1 + 2 E22 - b^2) gives E(F(1)) = E_k exactly.
/// States with 1 + 2 E22 - b^2 <= 0.01 are skipped (the next Halton point is taken).
std::vector<LoadPath> holdout_load_paths(const StrainBox& box, int count, int steps);

/// The end deformation gradient of an upper-triangular F with E(F) = E (see above); throws
/// std::invalid_argument where none exists.
Eigen::Matrix2d upper_gradient_for(double E11, double E22, double E12);

/// Direction k (0 <= k < n) of a Fibonacci lattice on the half-sphere d(2) > 0 (unit vector):
/// d(2) = (k + 1/2) / n, azimuth 2 pi k / phi^2 with phi the golden ratio (the points spread
/// evenly in area; Gonzalez 2010, "Measurement of areas on a sphere using Fibonacci and
/// latitude-longitude lattices").
Eigen::Vector3d half_sphere_direction(int k, int n);

/// The end strain (E11, E22, E12) of the ray from 0 along `d` in box-normalized strain
/// (see CoverageOptions::rays) out to the surface of `box`, shortened along the ray to
/// J = det F = min_J where the surface lies beyond it (J^2 = (1 + 2 E11)(1 + 2 E22) - 4 E12^2).
Eigen::Vector3d box_ray_end(const StrainBox& box, const Eigen::Vector3d& d, double min_J);

/// Point i (i >= 1) of the Halton sequence in base b (radical inverse), in [0, 1).
double halton(int i, int base);

/// Point i (i >= 1) of the R3 additive recurrence in [0, 1)^3: frac(1/2 + i (1/g, 1/g^2, 1/g^3))
/// with g = 1.2207440846... the plastic number (g^4 = g + 1), the three-dimensional analogue of
/// the golden-ratio sequence (M. Roberts, "The unreasonable effectiveness of quasirandom
/// sequences", 2018).
Eigen::Vector3d fill_point(int i);

/// The paper's fan: the largest and the smallest end strain of the biaxial paths (the sweep
/// input's `load_paths/e_max` and `e_min` when absent).
inline constexpr double kDefaultFanEMax = 0.40;
inline constexpr double kDefaultFanEMin = -0.15;

/// The 13 default paths (12 biaxial + 1 shear), `steps` increments each.
std::vector<LoadPath> default_load_paths(int steps = 20, double e_max = kDefaultFanEMax,
                                         double e_min = kDefaultFanEMin,
                                         double gamma_max = 0.6981317007977318 /*40 deg*/);

/// Macroscopic deformation gradient F* (2x2) of path `path` at step fraction t in [0, 1].
///   biaxial:  diag(1 + t (l1 - 1), 1 + t (l2 - 1)), l_i = sqrt(1 + 2 E_ii(target))
///   shear:    [[1, sin(t gamma)], [0, cos(t gamma)]]
///   uniaxial: the prescribed stretch 1 + t (l - 1) along `axis`, the other one 1 -- the start
///             value of the unknown lateral stretch that the runner finds (S_lateral = 0)
///   gradient: I + t H
Eigen::Matrix2d deformation_gradient(const LoadPath& path, double t);

/// Green-Lagrange strain E = (F^T F - I)/2 (paper eq. 9) as a 2x2 tensor.
Eigen::Matrix2d green_lagrange(const Eigen::Matrix2d& F);

/// 2nd Piola-Kirchhoff stress S = F^-1 P (paper eq. 9), symmetrized (the homogenized P* of a
/// converged cell makes F^-1 P symmetric up to the solver tolerance).
Eigen::Matrix2d second_piola_kirchhoff(const Eigen::Matrix2d& F, const Eigen::Matrix2d& P);

/// First Piola-Kirchhoff stress from S: P = F S.
Eigen::Matrix2d first_piola_kirchhoff(const Eigen::Matrix2d& F, const Eigen::Matrix2d& S);

/// Name of a path kind in files ("biaxial", "shear", "uniaxial", "gradient").
std::string to_string(PathKind k);
/// Inverse of to_string(PathKind); throws std::invalid_argument for an unknown name.
PathKind path_kind_from_string(const std::string& name);
/// The set names ("paper", "coverage", "holdout"); true if `set` is one of them.
bool is_valid_path_set(const std::string& set);

}  // namespace knit::material
