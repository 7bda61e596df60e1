// Point-to-curve contact of yarns at collocation points (Weeger et al.: contact forces applied
// point-wise within the collocation scheme), with friction history and exact linearization.
//
// Slave: a collocation point x_s of the cell's yarn. Master: the yarn of one course (the cell's
// own course or a neighbouring one) as an infinite periodic chain in the unrolled parameter u:
//   x_m(u) = sum_b N_b(u - k) Q_b + k a1 + t,   k = the copy index (u - k in [0,1]),
// a1 = F* (w, 0, 0) the period along the course and t = j F* (0, c, 0) the course shift.
// Closest point: phi(u) = (x_s - x_m(u)) . x_m,u(u) = 0 (Newton, safeguarded, per element).
// Gap g = |x_s - x_m| - d, normal n = (x_s - x_m)/|x_s - x_m| (pointing to the slave).
// Line load on the slave [N/mm]: f = p(g) n + f_T tau,  tau = x_m,u / |x_m,u|;
// moment line load of the friction force acting at the slave surface x_s - (d/2) n:
//   m = -(d/2) n x (f_T tau) = -(d/2) f_T (n x tau).
// The reaction -f acts on the master at u (with the same friction moment m: the master surface
// point is x_m + (d/2) n and (d/2) n x (-f_T tau) = m), see contact_set.hpp.
// Linearization w.r.t. z = [x_s (3), Q_0 .. Q_p (3 each)] with du from d(phi) = 0:
//   du = -(1/phi_u) [x_m,u . dx_s - x_m,u . dx_m|_u + r . dx_m,u|_u],  r = x_s - x_m,
//   phi_u = -|x_m,u|^2 + r . x_m,uu.
#pragma once

#include <Eigen/Core>

#include "knit/meso/contact/law.hpp"
#include "knit/spline/bspline_basis.hpp"

namespace knit::meso::contact {

/// The master yarn of one course as a periodic chain.
struct Chain {
  const spline::BSplineBasis* basis = nullptr;   ///< open basis on [0,1]
  const Eigen::MatrixXd* Q = nullptr;            ///< n x 3 centerline control points
  Eigen::Vector3d a1 = Eigen::Vector3d::Zero();  ///< period along the course
  Eigen::Vector3d t = Eigen::Vector3d::Zero();   ///< course shift
};

/// Chain evaluated at unrolled parameter u in copy k.
struct ChainPoint {
  double u = 0;
  int k = 0;
  int first = 0;  ///< first non-zero basis function (control point index)
  Eigen::Vector3d x, x_u, x_uu;
  Eigen::MatrixXd N;  ///< 3 x (p+1): N, N_u, N_uu of the local functions
};
ChainPoint eval_chain(const Chain& c, double u, int k);

struct Projection {
  bool ok = false;  ///< a stationary point with phi ~ 0 in [lo, hi]
  double u = 0;
  int k = 0;
  int iterations = 0;
  double distance = 0;
};
/// Closest point of x_s on copy k of the chain, searched in [lo, hi] (unrolled, within the copy),
/// starting at u0.
Projection project(const Chain& c, const Eigen::Vector3d& x_s, int k, double lo, double hi,
                   double u0);

/// History of one contact pair.
struct PairHistory {
  double u_anchor = 0;  ///< master parameter at which the slave sticks
  /// Reference gap g_r < 0 of a pair that overlaps in the stress-free reference cell
  /// (contact_set.hpp, "Stress-free reference"); 0 = none. With g_r < 0 the normal line load is
  /// p(g) - p(g_r) for g <= g_r and 0 for g > g_r (the pair is active at g = g_r itself, with
  /// zero force and the stiffness dp/dg(g_r) of the pressing side).
  double g_ref = 0;
};

struct PairResult {
  double u = 0, gap = 0, p = 0, f_T = 0, e = 0;
  bool active = false;  ///< p(g) > 0 (penetration beyond the allowance g0)
  bool slip = false;
  Eigen::Vector3d n = Eigen::Vector3d::Zero(), tau = Eigen::Vector3d::Zero();
  Eigen::Vector3d f = Eigen::Vector3d::Zero();  ///< line load on the slave [N/mm]
  Eigen::Vector3d m = Eigen::Vector3d::Zero();  ///< moment line load on the slave [N mm/mm]
  double u_anchor_new = 0;                      ///< updated history (return mapping)
  double dissipation = 0;  ///< friction work per unit length in this increment, >= 0 [N]
  double energy = 0;       ///< normal penalty energy + elastic stick energy per unit length
  int master_first = 0;
  /// d f / d z and d m / d z, z = [x_s, Q_first .. Q_first+p] (3 + 3(p+1) columns).
  Eigen::MatrixXd df_dz, dm_dz;
  Eigen::RowVectorXd du_dz;  ///< derivative of the closest-point parameter
  Eigen::MatrixXd Nm;        ///< 2 x (p+1): master basis functions and derivatives at u
};

/// Evaluates the pair at the projection `pr` (which must be a converged closest point of x_s on
/// the chain). d = yarn diameter. With want_jac the derivatives are filled.
PairResult evaluate_pair(const Eigen::Vector3d& x_s, const Chain& c, const Projection& pr, double d,
                         const PenaltyLaw& law, const FrictionLaw& fr, const PairHistory& hist,
                         bool want_jac);

}  // namespace knit::meso::contact
