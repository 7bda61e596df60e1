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
// Extrapolation (documented choice). Outside [0, 1]^2 both surfaces are continued by their
// tensor-product first-order Taylor expansion about the nearest point of the square,
//   V(xi) = V(c) + V_1 d1 + V_2 d2 + V_12 d1 d2,  c = clamp(xi), d = xi - c,
// a C1 continuation, so S stays continuous and C stays the exact derivative. xi2 > 1 extends
// the paths beyond their last step with the end tangent; xi1 outside [0, 1] rotates beyond
// the outermost paths; xi2 < 0 (strain directions opposite to the fan: biaxial compression)
// gives the linear law with the initial tangent of the paths. The guess takes xi2 >= 0 on the
// half-plane of directions around the fan and xi2 <= 0 on the opposite one. The shear curve
// is odd, S12(-E12) = -S12(E12), and continued linearly beyond its last point.
// Every evaluation reports whether it extrapolated (the caller counts and reports them).
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
  kBeyondPaths = 1,      ///< xi2 > 1: larger strain than the last load step
  kOutsideFan = 2,       ///< xi1 outside [0, 1]: direction outside the fan of paths
  kCompression = 4,      ///< xi2 < 0: direction opposite to the fan
  kBeyondShear = 8,      ///< |E12| beyond the shear data
  kInversionFailed = 16  ///< Newton did not converge; S and C from the last iterate
};

struct ResponseEvaluation {
  Eigen::Vector3d S = Eigen::Vector3d::Zero();  ///< (S11, S22, S12)
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();  ///< dS/d(E11, E22, 2E12), eq. (18)
  Eigen::Vector2d xi = Eigen::Vector2d::Zero();
  std::uint8_t flags = kInside;
  int iterations = 0;
};

/// The evaluator of one law. Immutable after construction; evaluate() is thread-safe.
class ResponseSurface {
 public:
  ResponseSurface() = default;
  /// Validates the data and precomputes the initial-guess table and C0.
  explicit ResponseSurface(ResponseSurfaceData data);

  const ResponseSurfaceData& data() const { return data_; }

  /// S and C at E = (E11, E22, 2E12) in the material (course/wale) frame.
  ResponseEvaluation evaluate(const Eigen::Vector3d& E) const;

  /// The two surfaces at xi (with the extension outside [0, 1]^2): rows E1, E2, S1, S2.
  Eigen::Vector4d point(const Eigen::Vector2d& xi) const;
  /// The shear curve at parameter u in [0, 1]: (E12, S12).
  Eigen::Vector2d shear_point(double u) const;

  /// Initial stiffness used at E = 0 (tensile 2x2 block from the edge, C33 from the curve).
  const Eigen::Matrix3d& C0() const { return C0_; }

  /// Fan angles atan2(E2, E1) of the first and last path at xi2 = 1 (radians).
  double fan_begin() const { return phi_.front(); }
  double fan_end() const { return phi_.back(); }

  /// Newton tolerances: |E(xi) - E| <= kTolAbs + kTolRel |E|.
  static constexpr double kTolAbs = 1e-13, kTolRel = 1e-11;
  static constexpr int kMaxIterations = 40;

 private:
  /// Surface values V and derivatives V_1, V_2, V_12 (columns) at xi, extension included.
  void eval4(const Eigen::Vector2d& xi, Eigen::Matrix4d& V) const;
  Eigen::Vector2d initial_guess(const Eigen::Vector2d& E) const;
  void shear(double E12, double& S12, double& dS12_dE12, std::uint8_t& flags) const;

  ResponseSurfaceData data_;
  spline::BSplineBasis b1_, b2_, bs_;
  /// Interleaved control points (E1, E2, S1, S2), a = i + n1*j.
  std::vector<Eigen::Vector4d> P_;
  std::vector<double> table_xi_, phi_, radius_;  ///< initial-guess table along xi1 at xi2 = 1
  Eigen::Matrix3d C0_ = Eigen::Matrix3d::Zero();
  double E12_max_ = 0.0;
  bool shear_linear_ = false;
};

}  // namespace knit::material
