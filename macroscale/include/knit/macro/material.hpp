// The material interface of the shell: plane-stress 2nd Piola-Kirchhoff stress S and tangent
// C = dS/dE at one through-thickness point, in the local Cartesian frame (e1, e2) of the
// reference mid-surface (e1 = å1/|å1|, paper Sect. 2.2.1 step 2).
//
// Voigt notation (paper eq. 16 and A.9): E = (E11, E22, 2E12), S = (S11, S22, S12),
// C (3x3) = dS/dE in that notation (eq. 18 form). Units: S and C in MPa.
//
// The shell integrates through the thickness with 3 Gauss points (paper eq. 14) by calling
// evaluate() at each; a material may also offer an analytic thickness integration (the
// St. Venant-Kirchhoff one does, to check the numerical path).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace knit::macro {

/// Where a material is evaluated: the in-plane parametric point (theta1, theta2) in the
/// shell's parameter domain, the index of that point among the points passed to
/// bind_points() (or -1 for a point that was not bound, e.g. an output sample), and the
/// through-thickness coordinate z (mm).
struct MaterialPoint {
  Eigen::Vector2d theta = Eigen::Vector2d::Zero();
  int point_id = -1;
  double z = 0.0;
};

struct MaterialResponse {
  Eigen::Vector3d S = Eigen::Vector3d::Zero();  ///< (S11, S22, S12) in MPa
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();  ///< dS/dE, MPa
  /// Strain-energy density W(E) per unit reference volume (MPa = N mm/mm^3) with S = dW/dE,
  /// for a hyperelastic law (hyperelastic() true); NaN otherwise.
  double W = std::numeric_limits<double>::quiet_NaN();
};

class Material {
 public:
  virtual ~Material() = default;
  virtual std::string name() const = 0;

  /// Called once before an analysis with the parametric coordinates of all in-plane
  /// quadrature points, so a graded material can precompute per-point data (its design
  /// fields, interpolated response surfaces). point_id in MaterialPoint indexes this list.
  virtual void bind_points(const std::vector<Eigen::Vector2d>& theta) {}

  /// S and C at strain E (Voigt, local Cartesian frame). Must be thread-safe (const):
  /// assembly may run on several threads.
  virtual MaterialResponse evaluate(const Eigen::Vector3d& E, const MaterialPoint& where) const = 0;

  /// True if S derives from a strain energy (MaterialResponse::W is set, C is symmetric for
  /// every E): the shell may then use a symmetric factorization and an energy line search.
  virtual bool hyperelastic() const { return false; }

  /// True if the material provides the analytic thickness integration below.
  virtual bool has_analytic_thickness_integration() const { return false; }
  /// Analytic resultants for a linear material: n = A eps + B kappa, m = B eps + D kappa.
  /// Only called when has_analytic_thickness_integration() is true.
  virtual void thickness_matrices(double thickness, const MaterialPoint& where, Eigen::Matrix3d& A,
                                  Eigen::Matrix3d& B, Eigen::Matrix3d& D) const {}

  /// Extra named scalar fields the material adds to the outputs at a sample point with
  /// mid-surface strain E (local Cartesian Voigt), e.g. the design fields (stitch length,
  /// knitting angle) and the strains in the material (course/wale) frame. Empty by default.
  virtual std::vector<std::pair<std::string, double>> output_fields(
      const Eigen::Vector2d& theta, const Eigen::Vector3d& E) const {
    return {};
  }

  /// How many evaluations so far could not produce a valid response (e.g. a response surface
  /// that could not be inverted). A run with failures must not report plain success.
  virtual long failed_evaluations() const { return 0; }

  /// A human-readable summary for the end of a run (e.g. how often and where a response
  /// surface was extrapolated). Empty by default.
  virtual std::string report() const { return {}; }

  /// Converged-state audit: between begin (returning true if the material counts anything)
  /// and end, evaluations are also counted apart, so that the report can say where the
  /// CONVERGED states lie, not only where Newton's trial iterates went. The run evaluates the
  /// residual once more at each converged step inside the audit (run.cpp).
  virtual bool begin_converged_audit() const { return false; }
  virtual void end_converged_audit() const {}

  /// A warning for the end of a run when the converged states lie largely where the material
  /// has no data (e.g. the knit law's extension beyond its database's strain box): the run
  /// still completes, the warning goes to stderr and summary.txt. Empty by default.
  virtual std::string warning() const { return {}; }

  /// The units a case with this material must be in (its data's, e.g. "mm, N, MPa"), or
  /// empty: any consistent units (the case's `units` is then informational).
  virtual std::string required_units() const { return {}; }

  /// Where the material's data come from, as (name, value) attributes of results.h5 (the
  /// knit material: its database's file and when that file was written), so that results of
  /// another database are told from this one's (session 38's red team: the report judged
  /// results older than the database). Empty by default.
  virtual std::vector<std::pair<std::string, std::string>> data_provenance() const { return {}; }
};

}  // namespace knit::macro
