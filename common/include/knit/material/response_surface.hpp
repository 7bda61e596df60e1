// The B-spline response-surface material law of one loop length (paper eqs. 16-18).
//
//   (S1, S2)(xi) = sum_ij N_ij(xi) (S1, S2)_ij,   (E1, E2)(xi) = sum_ij N_ij(xi) (E1, E2)_ij  (17)
//   S12 = S12(E12) as a B-spline curve (u) -> (E12(u), S12(u)) (16) C = dS/dE = [dS/dxi][dE/dxi]^-1
//   for the tensile block, C33 = dS12/(2 dE12)                 (18)
//
// The E-surface and the S-surface share one parameter domain xi = (xi1, xi2) in [0, 1]^2:
// xi1 runs across the fan of biaxial load paths (ordered by angle), xi2 is the step fraction.
// The law is implicit: for a given (E1, E2) the E-surface is inverted with Newton.
//
// Degenerate edge. Every path starts at E = 0, so the edge xi2 = 0 of the E-surface collapses
// to the origin and dE/dxi1 = 0 there. We write dE/dxi1 = xi2 * G(xi) (G = (dE/dxi1)/xi2 for
// |xi2| > tau, G = d2E/dxi1dxi2 at |xi2| <= tau) and solve for (xi2*dxi1, dxi2): a Newton step
// in "polar" form, regular on the collapsed edge. The tangent uses the same scaling,
// C = [S_1/xi2, S_2][E_1/xi2, E_2]^-1, whose limit at xi2 -> 0 is the direction-dependent
// initial stiffness. At E = 0 exactly the direction is undefined: C0 is the least-squares
// stiffness over the edge, C0 * dE/dxi2(xi1, 0) ~ dS/dxi2(xi1, 0).
//
// Initial guess (no warm start needed, thread-safe): a table of the fan's edge directions
// phi(xi1) = atan2(E2, E1)(xi1, 1) and radii gives xi1 by bisection in angle and xi2 from
// the radius; Newton then needs 2-4 steps.
//
// Extrapolation (documented choice). Along the fan (xi1 in [0, 1]) the paths continue beyond
// their last step with the end tangent, and slightly outside the fan xi1 continues by the
// tensor-product first-order Taylor expansion about the nearest point of the square,
//   V(xi) = V(c) + V_1 d1 + V_2 d2 + V_12 d1 d2,  c = clamp(xi), d = xi - c,
// a C1 continuation of both surfaces, inverted with xi2 >= 0 only ("the fan chart", S_f).
// Farther from the fan the law becomes a linear, soft compression law S_c = K_c E (K_c: the
// symmetric part of the fan's initial stiffness C0, eigenvalues floored, times a factor
// <= 1; symmetric positive definite). One extension for every direction, blended in the
// angle of the strain: with beta = the angle of (E11, E22) beyond the fan's angular range
// [lo, hi] (every path at every step, initial and end tangents included) and
// w = smoothstep((beta - beta0) / (beta1 - beta0)) (C1 in the angle),
//   S = (1 - w) S_f(E) + w K_c E,   C = (1 - w) C_f + w K_c + (K_c E - S_f) (dw/dE)^T,
// so S is continuous (C1 away from the origin) in every direction and C is its exact
// derivative. The former rule (two branches, xi2 >= 0 and xi2 <= 0, switched at +-90 degrees
// from the fan's bisector) let S jump between directions 2.5 degrees apart at any strain, and
// its compression branch (the initial tangent of the paths continued linearly) was stiffer
// than the cell and indefinite in many directions. beta0, beta1 and the factor are in
// ExtensionOptions (the band is narrowed so the two sides never overlap).
// The shear curve is odd, S12(-E12) = -S12(E12), and continued linearly beyond its last point.
// Every evaluation reports whether it extrapolated (the caller counts and reports them).
// A non-finite strain is never evaluated: the result is flagged kInversionFailed |
// kNonFiniteStrain with non-finite S and C, so that the caller fails the step.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "knit/spline/bspline_basis.hpp"

namespace knit::material {

/// The control data of one loop length's law (what the database stores per loop length).
struct ResponseSurfaceData {
  int degree1 = 3, degree2 = 3;        ///< degrees in xi1 (path fan) and xi2 (step fraction)
  std::vector<double> knots1, knots2;  ///< clamped knot vectors on [0, 1]
  /// Control points, one row each, index a = i + n1*j (xi1 fastest), columns (E1, E2) and
  /// (S1, S2) with E = Green-Lagrange strain, S = 2nd Piola-Kirchhoff stress (MPa).
  Eigen::MatrixXd E_ctrl, S_ctrl;
  int shear_degree = 3;
  std::vector<double> shear_knots;     ///< clamped, on [0, 1]
  Eigen::VectorXd E12_ctrl, S12_ctrl;  ///< tensor shear strain E12 and S12 (MPa)

  int n1() const { return static_cast<int>(knots1.size()) - degree1 - 1; }
  int n2() const { return static_cast<int>(knots2.size()) - degree2 - 1; }
};

/// Checks sizes, knots and finiteness; throws std::invalid_argument naming what is wrong.
void validate(const ResponseSurfaceData& d);

/// Extrapolation flags of one evaluation (bit set).
enum ExtrapolationFlag : std::uint8_t {
  kInside = 0,
  kBeyondPaths = 1,       ///< xi2 > 1: larger strain than the last load step
  kOutsideFan = 2,        ///< xi1 outside [0, 1]: direction outside the fan of paths
  kCompression = 4,       ///< the soft compression law contributes (blending weight w > 0)
  kBeyondShear = 8,       ///< |E12| beyond the shear data
  kInversionFailed = 16,  ///< Newton did not converge, or the strain is not finite
  kNonFiniteStrain = 32   ///< the strain had a NaN/inf component: S and C are NaN
};

/// The extension beyond the fan of paths (documented choice, see the header comment).
struct ExtensionOptions {
  /// Angles (degrees) beyond the fan's angular range where the blend into the compression
  /// law starts (w = 0 up to here) and ends (w = 1 from here); 0 <= begin < end. Both are
  /// scaled down together when the two bands would overlap on the far side of the fan.
  /// Default 0 and 30 (chosen on the paper cases with the swept database, see
  /// docs/database.md: wider bands and a softer K_c made some of them stop early).
  double blend_begin_deg = 0.0, blend_end_deg = 30.0;
  /// K_c = compression_scale * SPD part of sym(C0); (0, 1]: never stiffer than the fan's
  /// initial stiffness.
  double compression_scale = 1.0;
  /// Eigenvalue floor of the SPD part, relative to the largest eigenvalue of sym(C0).
  double compression_floor = 0.05;
  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

struct ResponseEvaluation {
  Eigen::Vector3d S = Eigen::Vector3d::Zero();  ///< (S11, S22, S12)
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();  ///< dS/d(E11, E22, 2E12), eq. (18)
  /// Parameters of the fan chart (meaningful while the blending weight is below 1).
  Eigen::Vector2d xi = Eigen::Vector2d::Zero();
  double blend = 0.0;  ///< weight w of the compression law (0: the fan chart only)
  std::uint8_t flags = kInside;
  int iterations = 0;
};

/// The evaluator of one law. Immutable after construction; evaluate() is thread-safe.
class ResponseSurface {
 public:
  ResponseSurface() = default;
  /// Validates the data and precomputes the initial-guess table and C0.
  explicit ResponseSurface(ResponseSurfaceData data, ExtensionOptions extension = {});

  const ResponseSurfaceData& data() const { return data_; }

  /// S and C at E = (E11, E22, 2E12) in the material (course/wale) frame.
  ResponseEvaluation evaluate(const Eigen::Vector3d& E) const;

  /// The two surfaces at xi (with the extension outside [0, 1]^2): rows E1, E2, S1, S2.
  Eigen::Vector4d point(const Eigen::Vector2d& xi) const;
  /// The shear curve at parameter u in [0, 1]: (E12, S12).
  Eigen::Vector2d shear_point(double u) const;

  /// Initial stiffness used at E = 0 (tensile 2x2 block from the edge, C33 from the curve).
  const Eigen::Matrix3d& C0() const { return C0_; }

  /// The compression stiffness K_c (symmetric positive definite, tensile 2x2 block).
  const Eigen::Matrix2d& compression_stiffness() const { return Kc_; }
  /// The fan's angular range [lo, hi] (radians, unwrapped; every path, every step, initial
  /// and end tangents) and the blending band actually used (radians beyond the range).
  double range_lo() const { return lo_; }
  double range_hi() const { return hi_; }
  double blend_begin() const { return beta0_; }
  double blend_end() const { return beta1_; }

  /// Fan angles atan2(E2, E1) of the first and last path at xi2 = 1 (radians).
  double fan_begin() const { return phi_.front(); }
  double fan_end() const { return phi_.back(); }

  /// Newton tolerances: |E(xi) - E| <= kTolAbs + kTolRel |E|.
  static constexpr double kTolAbs = 1e-13, kTolRel = 1e-11;
  static constexpr int kMaxIterations = 40;
  static constexpr int kMaxBacktracking = 30;

 private:
  /// Surface values V and derivatives V_1, V_2, V_12 (columns) at xi, extension included.
  void eval4(const Eigen::Vector2d& xi, Eigen::Matrix4d& V) const;
  /// The fan chart (xi2 >= 0, xi1 continued beyond the edges): S_f, C_f and flags at Et,
  /// whose angle psi is unwrapped around the fan's range.
  struct FanSolution {
    Eigen::Vector2d S = Eigen::Vector2d::Zero(), xi = Eigen::Vector2d::Zero();
    Eigen::Matrix2d C = Eigen::Matrix2d::Zero();
    std::uint8_t flags = kInside;
    int iterations = 0;
  };
  FanSolution solve_fan(const Eigen::Vector2d& Et, double psi) const;
  Eigen::Vector2d initial_guess(double rE, double psi) const;
  void shear(double E12, double& S12, double& dS12_dE12, std::uint8_t& flags) const;

  ResponseSurfaceData data_;
  spline::BSplineBasis b1_, b2_, bs_;
  /// Interleaved control points (E1, E2, S1, S2), a = i + n1*j.
  std::vector<Eigen::Vector4d> P_;
  std::vector<double> table_xi_, phi_, radius_;  ///< initial-guess table along xi1 at xi2 = 1
  std::vector<double> slope1_;  ///< radial growth of the end tangent (guess beyond xi2 = 1)
  Eigen::Matrix3d C0_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix2d Kc_ = Eigen::Matrix2d::Zero();
  double lo_ = 0.0, hi_ = 0.0, beta0_ = 0.0, beta1_ = 0.0;
  double E12_max_ = 0.0;
  bool shear_linear_ = false;
};

}  // namespace knit::material
