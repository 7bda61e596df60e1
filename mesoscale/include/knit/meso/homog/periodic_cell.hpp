// The single-jersey unit cell under a prescribed macroscopic deformation gradient, and its
// homogenized stresses (paper Sect. 2.1.2, eqs. 6-9).
//
// One yarn (the cell's loop, an open quartic B-spline over s in [0,1]: analysis_curve()) is a
// mixed Simo-Reissner collocation rod (knit/meso/rod). Its two end points are the same material
// point of the infinite course, so the 12 balance rows of the end collocation points are replaced
// by (PeriodicRows):
//   start, force rows    r(1) - r(0) - a1 = 0,        a1 = F*(w, 0, 0)   (periodic position;
//                                                      z periodic: free out-of-plane contraction
//                                                      of the fabric, no z constraint otherwise)
//   start, moment rows   vec( conj(q(0) q0(0)^-1) (q(1) q0(1)^-1) ) = 0  (equal rotation
//                                                      increments: R(1) R0(1)^T = R(0) R0(0)^T)
//   end, force rows      r(0) - r0(0) = 0             (rigid-body translation removed: the seam
//                                                      point, the head top, is held)
//   end, moment rows     m(1) - m(0) = 0              (moment continuity)
// Force continuity n(1) = n(0) is then not imposed: n(1) - n(0) = -(net contact load), zero in
// the continuum (the course is in equilibrium) and a discretization error here; it is reported
// as the "imbalance" and n1 = (n(0) + n(1))/2.
// In-plane F* (eq. 7, biaxial or pure shear) enters through a1 and the course shift
// a2 = F*(0, c, 0) of the contact images (contact/contact_set.hpp).
//
// Homogenization (eq. 8-9): n1 = force through the face x = const (the yarn's end force);
// n2 = force on the cell's course from the course above (two-pass average
// n2 = 1/2 [sum_{j, course +1} W_j f_j - sum_{j, course -1} W_j f_j], W_j tributary lengths);
// P* = [n1/A1, n2/A2] (2x2 in-plane), A1 = c t, A2 = w t, t = 2 d; E = (F^T F - I)/2, S = F^-1 P.
//
// Reference state (issue 11, choice; CellOptions::contact.reference, docs/unit-cell.md
// "Stress-free reference"): by default the contact pairs that overlap in the closed-form loop
// are measured from their initial overlap (contact/contact_set.hpp), so the unloaded cell is in
// equilibrium with zero contact force, zero yarn force and zero homogenized stress by
// construction; equilibrate() then returns the initial state at once. With
// contact.reference = kNone (the old behaviour) the penalty is ramped from 0 to k_N in
// `equilibration_steps` increments at F* = I (friction active), the initial overlaps push the
// yarns apart gradually, and the P* that remains is the residual stress reported at step 0.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "knit/meso/cell/geometry.hpp"
#include "knit/meso/contact/contact_set.hpp"
#include "knit/meso/rod/rod_system.hpp"
#include "knit/meso/rod/solver.hpp"

namespace knit::meso::homog {

/// A cell parameter outside its range: the JSON pointer of the field in the cell parameter
/// file (schemas/cell.schema.json, e.g. "/contact/penalty") and what is wrong.
struct CellOptionError {
  std::string pointer;
  std::string message;
};

struct CellOptions {
  int elements = 32;  ///< analysis curve elements (convergence study: docs/unit-cell.md)
  int degree = 4;
  rod::Section section;  ///< yarn: d = 0.38, E = 800, nu = 0.3
  cell::GeometryOptions geometry;
  contact::ContactOptions contact;
  /// Newton settings; tolerance 1e-8 on the row-scaled residual (contact makes 1e-10 needlessly
  /// strict: the stresses are converged to ~1e-9 MPa at 1e-8).
  rod::NewtonOptions newton = [] {
    rod::NewtonOptions n;
    n.tol = 1e-8;
    return n;
  }();
  int equilibration_steps = 4;
  int max_cutbacks = 6;
  /// Sub-steps (converged or not) of one step before the step ends as not converged
  /// (PeriodicCell::solve; /solver/max_substeps). A failed sub-step halves the next, two
  /// converged ones in a row double it up to the full step.
  int max_substeps = 500;

  /// Upper bounds of the integer fields (schemas/cell.schema.json "maximum"; session 21: a
  /// value of 123456789 ended in std::bad_alloc or ran for minutes). Far above what the
  /// convergence studies use (docs/unit-cell.md: elements 16-128, degree 3-5).
  static constexpr int kMaxElements = 1024;
  static constexpr int kMaxDegree = 8;
  static constexpr int kMaxSlavePoints = 16;
  static constexpr int kMaxIterations = 1000;   ///< max_iterations and equilibration_steps
  static constexpr int kMaxCutbacks = 30;       ///< 2^-30 of a step
  static constexpr int kMaxSubsteps = 1000000;  ///< max_substeps

  /// Range of the normal contact penalty k_N (MPa; schemas/cell.schema.json "penalty",
  /// `knit-meso path --penalty`): a factor 10 beyond the range calibrated in docs/unit-cell.md
  /// ("Ranges and sources": 250-4000 MPa, default 1000) on either side. A penalty is no
  /// material value; below this the yarns sink into each other (at 250 MPa already 0.775 d on
  /// the (0.4, 0.4) path at 4.5 mm), and 1e-300 ran a cell without contact with exit 0 (session
  /// 53's red team); above it the penalty is 50 times the yarn's modulus and only
  /// stiffens the Newton iteration.
  static constexpr double kMinPenalty = 25.0;
  static constexpr double kMaxPenalty = 4.0e4;

  /// Range of the stick penalty k_T (MPa; schemas/cell.schema.json "stick_penalty", `knit-meso
  /// path --stick`): a factor 10 below the default 20 MPa, up to k_N's bound. The elastic slip
  /// before sliding is mu p / k_T: on a 10 degree shear at 5.5 mm, S22 is 0.0406 MPa at k_T =
  /// 20-2000, 0.0235 at 2 and 0.0158 at 0.2, where mu = 0 gives 0.0156 (session 54); so below
  /// this the regularization, not Coulomb's law, sets the friction, and 1e-300 ran a
  /// frictionless cell with exit 0 (session 53's red team).
  static constexpr double kMinStickPenalty = 2.0;
  static constexpr double kMaxStickPenalty = 4.0e4;

  /// Upper bound of the soft branch's slope k_0 inside the allowance (MPa; "soft_penalty"): a
  /// factor 10 above the default 0.5 MPa. The branch is the "mild" penalty of the initial
  /// penetrations (paper Sect. 2.1.2); on a 10 degree shear at 5.5 mm S22 is 0.041 MPa at
  /// k_0 = 0.5, -0.005 at 5 and -0.019 at 50, and 1e300 ended in "residual is not finite"
  /// naming no field (session 54). 0 (no soft branch) stays allowed.
  static constexpr double kMaxSoftPenalty = 5.0;

  /// Checks every field for finiteness and against the range of schemas/cell.schema.json
  /// (implemented beside the JSON reader, homog_cell_config.cpp); the first bad field, or
  /// nothing. The reader, the command line and PeriodicCell use it, so no value is ever
  /// silently replaced by a default.
  std::optional<CellOptionError> validate() const;
};

/// Green-Lagrange strain (eq. 9).
inline Eigen::Matrix2d green_lagrange(const Eigen::Matrix2d& F) {
  return 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
}
/// Second Piola-Kirchhoff stress S = F^-1 P (eq. 9).
inline Eigen::Matrix2d second_pk(const Eigen::Matrix2d& F, const Eigen::Matrix2d& P) {
  return F.inverse() * P;
}

struct StepResult {
  bool converged = false;
  Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
  Eigen::Matrix2d P = Eigen::Matrix2d::Zero(), E = Eigen::Matrix2d::Zero(),
                  S = Eigen::Matrix2d::Zero();
  Eigen::Vector3d n1 = Eigen::Vector3d::Zero(), n2 = Eigen::Vector3d::Zero();
  int iterations = 0;  ///< Newton iterations (all increments of the step)
  int cutbacks = 0;
  int substeps = 0;       ///< attempted sub-steps (converged or cut back) of the step
  int pass_throughs = 0;  ///< of the cut-backs: converged increments whose yarns went through
                          ///< (or sank max_overlap d into) each other (contact_set.hpp)
  double seconds = 0;
  int active_contacts = 0;
  double min_gap = 0;
  double dissipation = 0;  ///< cumulative friction work [N mm]
  double imbalance = 0;    ///< |n(1) - n(0)| [N]
  std::string message;
};

class PeriodicCell {
 public:
  PeriodicCell(double loop_length, const CellOptions& opt = {});
  ~PeriodicCell();
  PeriodicCell(const PeriodicCell&) = delete;
  PeriodicCell& operator=(const PeriodicCell&) = delete;

  /// Ramps the contact penalty at F* = I (see above). Returns the residual-stress state.
  StepResult equilibrate();
  /// Solves for F* (2x2 in-plane) starting from the last converged state (affine warm start,
  /// halving of the increment on failure). Contact histories are committed on success.
  StepResult solve(const Eigen::Matrix2d& F);

  const cell::CellDimensions& dimensions() const { return dim_; }
  double thickness() const { return 2 * opt_.section.d; }
  const rod::RodSystem& system() const { return sys_; }
  const Eigen::VectorXd& state() const { return x_; }
  contact::ContactSet& contacts() { return *contact_; }
  /// The caller terms of the rod system (periodic rows, contact), for custom assembly.
  std::vector<rod::ExternalContribution*> contributions();
  /// Centerline sampled at `n`+1 points (current state), shifted by F*(i w, j c).
  std::vector<Eigen::Vector3d> centerline(int n, int i = 0, int j = 0) const;
  /// Homogenized quantities of the current state at F (no solve).
  StepResult homogenize(const Eigen::Matrix2d& F);
  /// Full residual and Jacobian at the current state (for checks).
  void residual_and_jacobian(Eigen::VectorXd& R, Eigen::SparseMatrix<double>& J);
  /// The converged state (yarn, F*, contact histories): restore() returns to it, e.g. after a
  /// trial solve of the uniaxial path's lateral iteration (homog/uniaxial.hpp).
  struct Snapshot {
    Eigen::VectorXd x;
    Eigen::Matrix2d F;
    contact::ContactSet::State contact;
  };
  Snapshot snapshot() const { return {x_, F_, contact_->save()}; }
  void restore(const Snapshot& s);
  const Eigen::Matrix2d& F() const { return F_; }
  /// Strain energy of the yarn [N mm] (Gauss quadrature of the compliance form).
  double strain_energy() const;

 private:
  class PeriodicRows;
  bool try_solve(const Eigen::Matrix2d& F, StepResult& res);
  void set_F(const Eigen::Matrix2d& F);

  CellOptions opt_;
  cell::CellDimensions dim_;
  rod::RodSystem sys_;
  std::unique_ptr<contact::ContactSet> contact_;
  std::unique_ptr<PeriodicRows> periodic_;
  Eigen::VectorXd x_;
  Eigen::Matrix2d F_ = Eigen::Matrix2d::Identity();
  Eigen::Vector3d r_fix_;
  bool last_refused_ = false;  ///< try_solve's last state was refused by the pass-through guard
};

}  // namespace knit::meso::homog
