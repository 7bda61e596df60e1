// A system of geometrically exact Simo-Reissner rods discretized by isogeometric collocation
// (paper Sect. 2.1.2, eq. 6; Weeger, Yeung & Dunn 2017, CMAME 321, "Isogeometric collocation
// methods for Cosserat rods and rod structures", mixed variant).
//
// Fields of one rod, all on the same B-spline/NURBS basis N_a(xi), a = 0..n-1, xi in [lo, hi]:
//   r(xi) = sum N_a r_a       centerline (3)
//   q(xi) = sum N_a q_a       orientation, a 4-D spline of quaternions, R = R(q/|q|) (4)
//   n(xi) = sum N_a n_a       spatial internal force  (3)    } mixed formulation: the stress
//   m(xi) = sum N_a m_a       spatial internal moment (3)    } resultants are own fields
// Arc length derivative (.)' = (1/|r0_xi|) d/dxi with the reference (undeformed) metric.
// Strains (material): Gamma = R^T r' - Gamma0,  K = 2 vec(conj(q) q')/|q|^2 - K0, where the
// reference values Gamma0, K0 are taken from (r0, q0) so that the reference state is stress free.
//
// Equations at every collocation point xi_j (the Greville abscissae, j = 0..n-1), 13 rows:
//   rows 0-2   force balance    n' + nbar = 0                    (paper eq. 6a)
//   rows 3-5   moment balance   m' + r' x n + mbar = 0           (paper eq. 6b; the paper's
//                                                                  "n x r'" is a sign typo)
//   rows 6-8   constitutive     R^T r' - Gamma0 - C_Gamma^{-1} R^T n = 0
//   rows 9-11  constitutive     K(q) - K0 - C_K^{-1} R^T m = 0
//   row  12    gauge            |q|^2 - 1 = 0
// At the two end points (j = 0 and j = n-1) the 6 balance rows are REPLACED by the boundary
// conditions (3 position-or-force rows, 3 rotation-or-moment rows); the constitutive and gauge
// rows stay. Why mixed: the pure displacement collocation (n, m eliminated) locks in shear
// for slender rods (d/L ~ 0.01) at coarse discretizations; with n, m as own fields the
// constitutive law is collocated in compliance form and the scheme is locking-free
// (verified in tests/meso/test_rod_verification.cpp).
//
// Global unknown vector x: rod after rod, control point after control point, 13 DOFs each
// (see Field). Global residual rows: rod after rod, collocation point after point, 13 each
// (see Row). Loads and prescribed end values are multiplied by the load factor lambda.
// Units: mm, N, MPa. Distributed loads nbar, mbar are per unit REFERENCE arc length.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "knit/meso/rod/quaternion.hpp"
#include "knit/meso/rod/section.hpp"
#include "knit/spline/bspline_basis.hpp"
#include "knit/spline/curve.hpp"

namespace knit::meso::rod {

/// Degrees of freedom per control point and their offsets.
inline constexpr int kDofsPerPoint = 13;
enum Field : int { kFieldR = 0, kFieldQ = 3, kFieldN = 7, kFieldM = 10 };
/// Equation rows per collocation point and their offsets.
inline constexpr int kRowsPerPoint = 13;
enum Row : int { kRowForce = 0, kRowMoment = 3, kRowStrain = 6, kRowCurvature = 9, kRowGauge = 12 };

enum class End : int { kStart = 0, kEnd = 1 };

/// Boundary condition of one rod end. Standard: the position is either prescribed
/// (r = r0 + lambda u) or loaded by a dead force (lambda F); the rotation is either prescribed
/// (R = exp(lambda theta) R0) or loaded by a dead moment (lambda M). Custom: the 6 balance rows
/// of the end point are left EMPTY (zero) by the system; the caller's ExternalContribution must
/// fill them (e.g. periodicity r_end - r_start = F (w,0,0), equal rotations, force transfer).
struct EndCondition {
  enum class Kind { kStandard, kCustom };
  Kind kind = Kind::kStandard;
  bool fix_position = false;
  bool fix_rotation = false;
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();  ///< u [mm] if fix_position
  Eigen::Vector3d rotation =
      Eigen::Vector3d::Zero();                      ///< rotation vector theta [rad] if fix_rotation
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< dead end force F [N] otherwise
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  ///< dead end moment M [N mm] otherwise

  static EndCondition clamped() {
    EndCondition c;
    c.fix_position = c.fix_rotation = true;
    return c;
  }
  static EndCondition free() { return {}; }
  static EndCondition custom() {
    EndCondition c;
    c.kind = Kind::kCustom;
    return c;
  }
};

/// Definition of one rod.
struct RodSpec {
  std::string name;
  spline::BSplineBasis basis;  ///< shared by r, q, n, m (clamped knot vector)
  Eigen::VectorXd weights;     ///< NURBS weights (n) or empty for B-splines
  Eigen::MatrixXd r0;          ///< n x 3 control points of the reference centerline [mm]
  /// n x 4 control points of the reference quaternion spline, or empty: then the system builds
  /// a rotation-minimizing (parallel transported) frame with d3 = tangent, starting from d1_hint
  /// projected on the normal plane at xi = lo, and interpolates it at the Greville points.
  Eigen::MatrixXd q0;
  Eigen::Vector3d d1_hint = Eigen::Vector3d::UnitZ();
  Section section;
  EndCondition start = EndCondition::clamped();
  EndCondition end = EndCondition::free();
  Eigen::Vector3d line_force = Eigen::Vector3d::Zero();   ///< dead nbar [N/mm], times lambda
  Eigen::Vector3d line_moment = Eigen::Vector3d::Zero();  ///< dead mbar [N mm/mm], times lambda
};

/// One collocation point (precomputed, read-only).
struct CollocationPoint {
  double xi = 0.0;   ///< parameter (Greville abscissa)
  double jac = 1.0;  ///< reference metric |r0_xi|: ds = jac dxi
  int first = 0;     ///< first of the p+1 control points whose basis functions are non-zero
  int row = 0;       ///< global index of its first equation row (13 consecutive rows)
  Eigen::Vector3d gamma0 = Eigen::Vector3d::Zero();  ///< reference R0^T r0' (material)
  Eigen::Vector3d kappa0 = Eigen::Vector3d::Zero();  ///< reference curvature K0 (material)
};

/// Non-zero basis functions at a parameter: N(k, i) = d^k N_{first+i} / dxi^k.
struct PointBasis {
  int first = 0;
  Eigen::MatrixXd N;
};

/// All fields of one rod at a parameter, for a given state x.
struct PointState {
  double xi = 0.0;
  Eigen::Vector3d r, r_xi, r_xixi;  ///< centerline and its parametric derivatives
  Quat<double> q, q_xi;             ///< quaternion spline (not normalized) and derivative
  Eigen::Matrix3d R;                ///< rotation R(q/|q|); columns are the directors d1, d2, d3
  Eigen::Vector3d n, m;             ///< spatial internal force [N] and moment [N mm]
  double jac = 1.0;                 ///< reference metric |r0_xi|
};

class RodSystem;

/// Caller-supplied terms: contact line loads on balance rows, custom end equations, penalty
/// terms. add() ADDS to the residual and appends Jacobian triplets d(residual)/d(x) with global
/// row/column indices (duplicates are summed). It is called at every Newton iteration.
/// Sign convention: a distributed load nbar (per unit reference length) at collocation point j
/// of rod k enters as  residual[sys.row(k, j, kRowForce) + i] += nbar_i  (same for mbar).
class ExternalContribution {
 public:
  virtual ~ExternalContribution() = default;
  virtual void add(const RodSystem& sys, const Eigen::VectorXd& x, double lambda,
                   Eigen::VectorXd& residual, std::vector<Eigen::Triplet<double>>& jac) = 0;
};

class RodSystem {
 public:
  /// Adds a rod; validates shapes and section data (throws std::invalid_argument with a
  /// message naming the problem). Returns the rod index.
  int add_rod(RodSpec spec);

  int num_rods() const { return static_cast<int>(rods_.size()); }
  const RodSpec& spec(int rod) const { return rods_[rod].spec; }
  int num_control_points(int rod) const { return rods_[rod].spec.basis.size(); }
  int num_dofs() const { return ndofs_; }
  /// Global DOF of component c of field f at control point a of a rod.
  int dof(int rod, int a, Field f, int c = 0) const {
    return rods_[rod].offset + kDofsPerPoint * a + f + c;
  }
  /// Global row of component c of equation group g at collocation point j of a rod.
  int row(int rod, int j, Row g, int c = 0) const {
    return rods_[rod].offset + kRowsPerPoint * j + g + c;
  }
  /// Index of the collocation point at an end (0 or n-1).
  int end_point(int rod, End e) const { return e == End::kStart ? 0 : num_control_points(rod) - 1; }
  const std::vector<CollocationPoint>& collocation_points(int rod) const {
    return rods_[rod].points;
  }
  /// Reference arc length of a rod [mm] (Gauss quadrature of |r0_xi|).
  double reference_length(int rod) const { return rods_[rod].length; }

  /// Reference state: r = r0, q = q0, n = m = 0.
  Eigen::VectorXd initial_state() const;

  // ---- evaluation (any parameter, any state) ------------------------------------------------
  /// Non-zero (rational) basis functions and derivatives 0..nder at xi.
  PointBasis basis(int rod, double xi, int nder) const;
  /// Allocation-free variant: N must be (nder+1) x (p+1); returns the first control point.
  int basis(int rod, double xi, int nder, Eigen::Ref<Eigen::MatrixXd> N) const {
    return rods_[rod].geo.basis_derivatives(xi, nder, N);
  }
  /// Row k = d^k r / dxi^k, k = 0..nder.
  Eigen::MatrixXd position_derivatives(int rod, double xi, const Eigen::VectorXd& x,
                                       int nder) const;
  Eigen::Vector3d position(int rod, double xi, const Eigen::VectorXd& x) const;
  PointState state(int rod, double xi, const Eigen::VectorXd& x) const;
  /// Reference centerline r0 at xi.
  Eigen::Vector3d reference_position(int rod, double xi) const;
  /// The smallest axial stretch d3 . r' / |r0'| over every rod's collocation points (1 in the
  /// reference state; <= 0 where the centerline has been pushed through zero length, which no
  /// rod state describes: session 50's red team, a rod shortened by three times its length
  /// "completed" at a strain of -3), with the rod and the parameter where it lies.
  struct AxialStretch {
    double value = 1.0;
    int rod = 0;
    double xi = 0.0;
  };
  AxialStretch min_axial_stretch(const Eigen::VectorXd& x) const;

  // ---- assembly ----------------------------------------------------------------------------
  /// Residual of the built-in equations (custom end rows are zero).
  void residual(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& F) const;
  /// Residual and Jacobian triplets (appended) of the built-in equations. F is resized.
  void assemble(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& F,
                std::vector<Eigen::Triplet<double>>& jac) const;

  /// Row weights that make the residual dimensionless for the convergence test (force rows
  /// L/EA, moment rows 1/EA, curvature rows L, end position rows 1/L, end moment rows
  /// 1/(EA L)); custom rows default to 1 and may be changed by the caller.
  const Eigen::VectorXd& row_scales() const { return row_scale_; }
  void set_row_scale(int row, double s) { row_scale_(row) = s; }

 private:
  struct RodData {
    RodSpec spec;
    spline::SplineCurve geo;  // reference centerline (carries the rational basis)
    int offset = 0;           // first DOF == first row
    double length = 0.0;
    Eigen::Vector3d r_start, r_end;  // reference end positions (no allocation in assembly)
    std::vector<CollocationPoint> points;
    Eigen::MatrixXd Nc;  // collocation basis: rows 2j, 2j+1 = N, N_xi at point j ((2n) x (p+1))
  };
  void update_scales(int rod);
  void assemble_impl(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& F,
                     std::vector<Eigen::Triplet<double>>& jac, bool want_jac) const;
  std::vector<RodData> rods_;
  int ndofs_ = 0;
  Eigen::VectorXd row_scale_;
};

}  // namespace knit::meso::rod
