// The nonlinear isogeometric Kirchhoff-Love shell on one NURBS patch: internal forces and
// the exact consistent tangent (paper eqs. 10-15; Kiendl et al., CMAME 198 (2009), eqs. 21-27;
// Kiendl et al., CMAME 291 (2015) for the through-thickness integration of general materials).
//
//   f_int,r = int  n : eps_,r + m : kappa_,r  dA
//   K_rs    = int  eps_,r D_mm eps_,s + eps_,r D_mb kappa_,s + kappa_,r D_mb eps_,s
//                  + kappa_,r D_bb kappa_,s + n : eps_,rs + m : kappa_,rs  dA
//
// with covariant resultants (n, m) = T^T (n_cart, m_cart) and tangents T^T (A, B, D) T from the
// section integration (section.hpp). Reference quantities are precomputed at all quadrature
// points ((p+1) Gauss points per direction and element) once; the loops do not allocate.
// DOF r = 3 a + i: component i of the displacement of control point a.
//
// Variations (r = (l, i): control point l, component i; R_l the basis, e_i the unit vector):
//   a_alpha,r = R_l,alpha e_i,   a3~ = a1 x a2,  j = |a3~|,  a3 = a3~ / j
//   a3,r   = (a3~,r - a3 j,r)/j,  a3~,r = R_l,1 e_i x a2 + R_l,2 a1 x e_i,  j,r = a3 . a3~,r
//   a3,rs  = (a3~,rs - a3,s j,r - a3 j,rs - a3,r j,s)/j,   j,rs = a3,s . a3~,r + a3 . a3~,rs
//   a3~,rs = (R_l,1 R_m,2 - R_l,2 R_m,1) e_i x e_j
//   eps_ab,r  = (a_a,r . a_b + a_a . a_b,r)/2,      eps_ab,rs = (a_a,r . a_b,s + a_a,s . a_b,r)/2
//   kap_ab,r  = -(a_a,b,r . a3 + a_a,b . a3,r),     kap_ab,rs = -(a_a,b,r . a3,s + a_a,b,s . a3,r +
//   a_a,b . a3,rs)
// Every term is a bilinear form in Phi = (R_1, R_2, R_11, R_12, R_22) of the two control points,
// so per quadrature point a 15 x 15 matrix H (Phi-index x component) holds the whole tangent:
//   K(3l+i, 3m+j) = sum_q sum_fg Phi_f(l) H_q(3f+i, 3g+j) Phi_g(m)
// which is evaluated per element as one matrix product Phi^T [(H Phi)_ij^T ...] over all its
// quadrature points for the 9 component pairs (i, j) (6 if the material tangent is symmetric).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "knit/macro/element_kernel.hpp"
#include "knit/macro/material.hpp"
#include "knit/macro/patch.hpp"
#include "knit/macro/section.hpp"
#include "knit/macro/shell_kinematics.hpp"
#include "knit/spline/quadrature.hpp"
#include "knit/spline/surface.hpp"

namespace knit::macro {

struct ShellOptions {
  ThicknessIntegration integration = ThicknessIntegration::kGauss3;
  /// Assembly threads (elements are split between them; the result does not depend on the
  /// number). 0: automatic, all hardware threads when the tangent's element work exceeds
  /// kAutoThreadWork, one otherwise.
  int threads = 0;
  int quadrature_points = -1;  ///< per direction and element; -1: p + 1 + extra_quadrature_points
  /// Gauss points beyond p + 1 per direction and element (/solver/extra_quadrature_points of a
  /// case; session 58): p + 1 integrates the area exactly on an undistorted patch but not the
  /// knit law's energy, whose strain varies within an element (a red team of session 57: 4-11 %
  /// on the paper's one- and two-element meshes of the hyperbolic paraboloid).
  int extra_quadrature_points = 0;
  /// Elements with the same basis derivatives at their points share one copy (ShellModel::
  /// distinct_bases()); false: each its own (the reference of the test).
  bool share_bases = true;
};

/// Fields at one sample point of the mid-surface (outputs), all in the local Cartesian frame
/// of the reference configuration.
struct ShellSample {
  Eigen::Vector3d X, x, u;                      ///< reference and current position, displacement
  Eigen::Vector3d E = Eigen::Vector3d::Zero();  ///< membrane strain (E11, E22, 2E12)
  Eigen::Vector3d kappa = Eigen::Vector3d::Zero();  ///< curvature change (k11, k22, 2k12)
  Eigen::Vector3d n = Eigen::Vector3d::Zero();      ///< membrane forces N/mm
  Eigen::Vector3d m = Eigen::Vector3d::Zero();      ///< bending moments N mm/mm
};

/// Receives each element tangent where the kernel leaves it, instead of a copy into
/// ShellModel::Evaluation::Ke (ReducedTangent scatters it into the reduced matrix from there: at
/// p = 4 no 45 KB per element written to memory and read back). Entry (r, s) of element e's
/// tangent (local DOFs r = 3 l + i, s) is kt[map[r + 3 nloc s]]. element() is called on
/// assembly thread `thread` of `threads`, which evaluates the elements
/// ShellModel::element_range(ne, thread, threads) in increasing order.
class ElementTangentSink {
 public:
  virtual ~ElementTangentSink() = default;
  virtual void element(int e, int thread, const double* kt, const int* map) = 0;
};

class ShellModel {
 public:
  /// Throws DegenerateGeometryError if the Jacobian vanishes at a quadrature point.
  ShellModel(spline::SplineSurface surface, double thickness, std::shared_ptr<Material> material,
             ShellOptions options = {});

  const spline::SplineSurface& surface() const { return surface_; }
  double thickness() const { return t_; }
  const Material& material() const { return *material_; }
  int num_control_points() const { return surface_.size(); }
  int num_dofs() const { return 3 * surface_.size(); }
  int num_elements() const { return static_cast<int>(elements_.size()); }
  int num_quadrature_points() const { return static_cast<int>(points_.size()); }
  /// The current unit normal a3 = a1 x a2 / |a1 x a2| at theta for displacement u, and the
  /// reference normal A3 there (zero vectors where the tangents are parallel).
  std::pair<Eigen::Vector3d, Eigen::Vector3d> normals(const Eigen::VectorXd& u,
                                                      const Eigen::Vector2d& theta) const;
  /// The reference configuration at quadrature point pid (its theta, frame e1, e2, e3 = A3).
  const ReferencePoint& quadrature_point(int pid) const { return points_[pid].ref; }
  /// Control points of element e (the (pu+1)(pv+1) functions non-zero on it).
  const Eigen::VectorXi& element_control_points(int e) const { return elements_[e].cp; }
  /// Whether the element tangents use the sum-factorized kernel (a B-spline surface of degree
  /// 1..5 per direction; element_kernel.hpp).
  bool sum_factorized() const { return factorized_; }
  /// Distinct tables of basis derivatives at the elements' points (ShellOptions::share_bases).
  int distinct_bases() const { return static_cast<int>(phis_.size()); }
  /// n >= 1 threads, 0 automatic (see ShellOptions::threads).
  void set_threads(int n) { opt_.threads = n < 0 ? 0 : n; }
  /// The number of threads evaluate() uses with a tangent.
  int assembly_threads() const;
  /// The elements [first, second) that thread k of n evaluates (of ne elements).
  static std::pair<int, int> element_range(int ne, int k, int n) {
    return {static_cast<int>(long(ne) * k / n), static_cast<int>(long(ne) * (k + 1) / n)};
  }
  /// Element work (quadrature points x local DOFs^2) above which the automatic setting uses
  /// every hardware thread: measured on 2 cores, a tangent evaluation of this size takes
  /// ~2 ms, 20x the cost of starting the threads.
  static constexpr double kAutoThreadWork = 2.0e5;

  /// What a residual evaluation keeps per quadrature point (element_kernel.hpp).
  using PointState = kernel::PointState;

  struct Evaluation {
    Eigen::VectorXd fint;             ///< internal force vector (num_dofs)
    std::vector<Eigen::MatrixXd> Ke;  ///< element tangents (3 nloc square, local DOF 3 l + i)
    /// Total strain energy Psi(u) = sum_q dA_q psi_q (N mm; psi the thickness-integrated W,
    /// section.hpp), dPsi/du = fint; NaN unless the material is hyperelastic().
    double energy = 0.0;
    bool ok = true;                  ///< false if the current configuration degenerated
    Eigen::MatrixXd fe;              ///< workspace: element force vectors (3 nloc x elements)
    Eigen::VectorXd element_energy;  ///< workspace: element energies
    std::vector<PointState> points;  ///< per quadrature point, if kept (keep_points)
    bool has_points = false;         ///< `points` belong to this evaluation
  };
  /// Internal forces and energy at displacement u (num_dofs), with the element tangents if
  /// `tangent`. Element results are summed in element order, so the result is bitwise the
  /// same for any number of threads. The workspaces are per thread and kept (no allocation
  /// after the first call), the assembly threads are a process-wide pool (ThreadPool::shared():
  /// concurrent evaluations of several models take turns on it).
  /// `keep_points` (without `tangent`): also keep the PointStates for tangent_from.
  /// `sink` (with `tangent`): each element tangent goes to the sink, out.Ke is left empty.
  void evaluate(const Eigen::VectorXd& u, bool tangent, Evaluation& out, bool keep_points = false,
                ElementTangentSink* sink = nullptr) const;
  /// The evaluation with tangent at the displacement of `from` (evaluated with keep_points, ok):
  /// the element tangents from its point states, fint, energy and ok copied. Bitwise the same
  /// as evaluate(u, true, out) (the same operations on the same numbers). `sink`: as in evaluate.
  void tangent_from(const Evaluation& from, Evaluation& out,
                    ElementTangentSink* sink = nullptr) const;
  /// Psi(u) alone (NaN unless hyperelastic, or if the configuration degenerated).
  double energy(const Eigen::VectorXd& u) const;

  /// Output fields at (theta1, theta2) for displacement u.
  ShellSample sample(const Eigen::VectorXd& u, const Eigen::Vector2d& theta) const;
  /// Displacement of the mid-surface at theta.
  Eigen::Vector3d displacement(const Eigen::VectorXd& u, const Eigen::Vector2d& theta) const;

  /// Consistent nodal forces (num_dofs) of dead loads: a point force F (N) at theta, a line
  /// force q (N/mm of reference length) along an edge, an area force q (N/mm^2 of reference area).
  Eigen::VectorXd point_force(const Eigen::Vector2d& theta, const Eigen::Vector3d& F) const;
  Eigen::VectorXd edge_force(Edge edge, const Eigen::Vector3d& q) const;
  Eigen::VectorXd area_force(const Eigen::Vector3d& q) const;

 private:
  struct Element {
    Eigen::VectorXi cp;
    int first_point = 0, num_points = 0;
    /// nloc x (5 num_points): R_1, R_2, R_11, R_12, R_22 at each point (column 5 q + f); only
    /// while the model is built, then shared: phis_[phi].
    Eigen::MatrixXd PhiT;
    int phi = -1;
    /// Tensor-product factors of PhiT (kernel::ElementTangentInput::Au, Bk), if factorized_.
    std::vector<double> Au, Bk;
  };
  struct Point {
    ReferencePoint ref;
    double dA = 0.0;  ///< quadrature weight x Jacobian
  };
  enum class Pass { kResidual, kResidualKeep, kTangent, kTangentFromStates };
  /// Runs evaluate_range over the elements on assembly_threads() threads; false if any range
  /// failed.
  bool run_ranges(const Eigen::VectorXd* u, Pass pass, const Evaluation* from, Evaluation& out,
                  ElementTangentSink* sink) const;
  void factorize_elements(const std::vector<std::pair<double, double>>& su,
                          const std::vector<std::pair<double, double>>& sv,
                          const spline::QuadratureRule& gu, const spline::QuadratureRule& gv);
  /// Workspace of evaluate_range, one per thread (thread_local: kept across calls and models).
  struct Workspace;
  /// The calling thread's workspace, sized (and zeroed) for this model when it does not fit.
  Workspace& workspace() const;
  bool evaluate_range(int thread, int threads, const Eigen::VectorXd* u, Pass pass,
                      const Evaluation* from, Evaluation& out, ElementTangentSink* sink,
                      Workspace& ws) const;
  /// Residual part at one point: the point state, dA psi, and the element force
  /// contributions fe_i(l) += sum_f Phi_f(l) g(3f+i) (Phi: the point's columns of PhiT; xT and
  /// feT: the element's control points and forces, kernel::current_derivatives' layout). False
  /// if the configuration degenerated there.
  bool residual_point(int pid, const double* Phi, const double* xT, PointState& s, double& energy,
                      double* feT) const;
  /// The 15 x 15 matrix H at one point (column-major) from its state; clears `symmetric` if
  /// the section tangent is not.
  void point_matrix(int pid, const PointState& s, double* H, bool& symmetric) const;
  SectionResponse section(const Eigen::Vector3d& Ec, const Eigen::Vector3d& Kc,
                          const Eigen::Vector2d& theta, int point_id) const;

  spline::SplineSurface surface_;
  double t_;
  std::shared_ptr<Material> material_;
  ShellOptions opt_;
  int nloc_ = 0;
  std::vector<Element> elements_;
  std::vector<Point> points_;
  /// 1 x (nloc * num points): the basis functions at every quadrature point (area loads; the
  /// derivatives are in each Element's PhiT)
  Eigen::MatrixXd R_;
  double scale_ = 1.0;
  /// Every element's Phi is the tensor product of its 1D bases (a B-spline surface, checked
  /// numerically) and small enough for the sum-factorized kernel.
  bool factorized_ = false;
  int nqu_ = 0, nqv_ = 0;  ///< quadrature points per direction
  int max_points_ = 0;     ///< quadrature points of the largest element
  /// The distinct PhiT of the elements (share_phis).
  std::vector<Eigen::MatrixXd> phis_;
  void share_phis();
  /// Where entry (r, s) of an element tangent is in the kernel's output KT
  /// (element_tangent_blocks), for the symmetric layout ([1]: 6 component pairs, the diagonal
  /// ones possibly as lower triangles) and the full one ([0]: 9 pairs).
  std::vector<int> kt_map_[2];
};

}  // namespace knit::macro
