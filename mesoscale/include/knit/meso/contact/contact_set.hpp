// Frictional self-contact of a periodic yarn with its periodic images, as collocated line loads
// (paper Sect. 2.1.2; Weeger et al.: contact forces as point loads within collocation).
//
// Two-pass, point-to-curve: the slaves are Gauss points xi_g (`slave_points_per_element` per
// element) of the cell's yarn;
// the masters are the yarn's courses j_c as periodic chains (contact/pair.hpp), shifted by
// j_c F*(0, c): every course and copy along it whose box can reach the yarn's (session 57's red
// team: with courses -1, 0, +1 alone, the courses +-2 went through the yarn unopposed under wale
// compression and large shear; 4.5 mm, the paper's 40 deg shear path: S12 1.59 MPa for 2.60). For
// the own course (j_c = 0) the part of the yarn within `self_exclusion` of xi_j in the loop
// parameter is not a contact partner. The mirror pair (the image's point against the cell's yarn)
// is the same contact seen from the other side. Each pass applies half the load: +f/2 at the slave
// point and the reaction -f/2 at the master's closest point u, which by periodicity is the material
// point u - k of the cell's own yarn. So action equals reaction exactly and the net contact force
// on the course vanishes (a plain two-pass point-to-curve law does not balance: the normals from
// the two sides of curved yarns differ, which left a net force as large as the yarn force). Broad
// phase: the copies (course j, copy k along it; |j|, |k| <= kMaxCopy) whose whole-yarn box (the
// control polygon's, convex-hull property), inflated, meets the yarn's; on them the boxes of the
// elements, inflated by d + margin; the closest point is searched on every candidate element and
// kept if it is a true stationary point. A state in which a copy at |j| or |k| = kMaxCopy could
// touch the yarn is refused by the guard (guard_refusal). Collocated line load (choice): the
// contact line load f(xi) evaluated at the Gauss points is projected on the collocation rows,
// nbar_j = (1/W_j) sum_g w_g |r0_xi| N_j(xi_g) f(xi_g) with the tributary lengths W_j = int N_j ds.
// By the partition of unity sum_j W_j nbar_j = int f ds, so the total contact force is integrated,
// not sampled at the few collocation points (sampling them made the net force on the course, which
// must vanish, as large as the yarn force). The same for the friction moment. The end points'
// balance rows carry the periodicity: loads on them are dropped (the seam is the head top, free of
// contact). Stress-free reference (issue 11; choice, ContactOptions::reference): the closed-form
// loops start with overlaps of up to 0.16 mm, so with the plain law the unloaded cell carries
// contact forces and a residual stress. With Reference::kInitialOverlap, capture_reference()
// records at the reference state every overlapping pair (slave point, course, master parameter u_r,
// gap g_r < 0); its line load is then p(g) - p(g_r) while g <= g_r and 0 when it opens (g > g_r):
// the reference overlap is the stress-free flattening of the yarn sections, so the unloaded
// cell is in equilibrium with zero force in every pair and zero stress. The stiffness of a
// pressed pair is the plain law's dp/dg at the same geometric gap. A found pair takes the
// reference of its (slave point, course) with the nearest u_r within `match_tol`; u_r follows
// the pair at every commit (sliding). A pair that opens keeps its reference (its last u_r), so
// re-closing is elastic and history-free: force 0 until g returns below g_r. Pairs found only
// later (no reference within match_tol) use the plain law p(g) (p = 0 at g >= 0: no jump).
// Reference::kNone: the plain law everywhere (the old behaviour; the cell then equilibrates
// with a residual stress, see homog/periodic_cell.hpp).
// History: per (slave point, course) the list of sticking anchors of the last converged state;
// a pair found in an iteration takes the nearest anchor within `match_tol` in u, else it starts
// sticking where it is found (kept for the rest of the increment). commit() accepts the
// return-mapped anchors and the dissipation of the increment.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "knit/meso/contact/law.hpp"
#include "knit/meso/contact/pair.hpp"
#include "knit/meso/rod/rod_system.hpp"

namespace knit::meso::contact {

struct ContactOptions {
  enum class Reference { kNone, kInitialOverlap };
  Reference reference = Reference::kInitialOverlap;  ///< see "Stress-free reference" above
  PenaltyLaw penalty;
  FrictionLaw friction;
  double d = 0.38;              ///< yarn diameter [mm]
  double margin = 0.05;         ///< broad-phase inflation beyond d [mm]
  double self_exclusion = 0.3;  ///< loop-parameter distance below which the own yarn is skipped
  double match_tol = 0.08;      ///< history matching tolerance in u
  int slave_points_per_element = 4;  ///< Gauss points per element that act as slaves
  /// Pass-through guard (below): a converged state with a pair overlapping by more than
  /// max_overlap d is refused as well (choice, /contact/max_overlap, 1 = off): the centerlines
  /// are then within (1 - max_overlap) d of each other, one step short of passing through.
  /// 4.5 mm, wale stretch F22 = 1.8 in one step converged at an overlap of 0.93 d with S =
  /// (8.7, 10.2) MPa for (17.8, 17.2) in 40 steps, whose deepest overlap is 0.66 d. A softer
  /// contact law sinks deeper in equilibrium (k_N = 250 MPa: 0.775 d on the paper's (0.4, 0.4)
  /// path at 4.5 mm) and needs a larger bound.
  double max_overlap = 0.8;
};

/// One active contact of the current state (for output and homogenization).
struct ActivePair {
  int point = 0;   ///< slave (Gauss) point
  double xi = 0;   ///< its parameter
  int course = 0;  ///< the master's course j (|j| <= ContactSet::kMaxCopy)
  int k = 0;       ///< the master's copy along the course (its period F* (w, 0, 0))
  double u = 0, gap = 0, p = 0, f_T = 0;
  bool slip = false;
  Eigen::Vector3d f = Eigen::Vector3d::Zero();  ///< line load on the slave [N/mm]
  double weight = 0;  ///< quadrature weight of the slave point (w_g |r0_xi|) [mm]
};

class ContactSet : public rod::ExternalContribution {
 public:
  ContactSet(const rod::RodSystem& sys, int rod, const ContactOptions& opt);

  /// Periods: a1 = F*(w,0,0), a2 = F*(0,c,0).
  void set_periods(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2) {
    a1_ = a1;
    a2_ = a2;
  }
  /// Scales the penalty (0..1) for the equilibration ramp.
  void set_penalty_scale(double s) { scale_ = s; }

  void add(const rod::RodSystem& sys, const Eigen::VectorXd& x, double lambda,
           Eigen::VectorXd& residual, std::vector<Eigen::Triplet<double>>& jac) override;

  /// Evaluates the contacts at x without touching the residual (for output).
  std::vector<ActivePair> active_pairs(const rod::RodSystem& sys, const Eigen::VectorXd& x);
  /// Stored contact energy (penalty + elastic stick) [N mm], each contact counted once.
  double energy(const rod::RodSystem& sys, const Eigen::VectorXd& x);
  /// Records the overlapping pairs of the state x as the stress-free reference (see above).
  /// Returns their number.
  int capture_reference(const rod::RodSystem& sys, const Eigen::VectorXd& x);
  int num_reference_pairs() const;
  /// Accepts the state x as converged: histories and dissipation are updated.
  void commit(const rod::RodSystem& sys, const Eigen::VectorXd& x);
  /// Pass-through guard (session 28). The gap |x_s - x_m| - d has no sign, so a slave point
  /// that crosses its master's centerline within one increment sees the pair open again on
  /// the other side, and Newton converges to yarns that went through each other (4.5 mm, course
  /// stretch F11 = 1.8 in one step: S = (-1.2, -3.8) MPa for (8.7, 15.4) in 40 steps, exit 0).
  /// commit() records, for every pair within kWatchRadius d + margin of each other, the side of
  /// the master on which the slave point lies: n = (x_s - x_m(u)) / |x_s - x_m(u)| at the
  /// master's material point (copy k, parameter u). A converged state in which
  /// (x_s - x_m(u)) . n < 0 for one of them has the slave point on the other side of the same
  /// material point: a pass-through. Sliding moves the slave along the master and turns n, so a
  /// large step can be refused that is none; it is then cut back, and the smaller steps pass.
  /// (A sliding-invariant side, the sign of r . (t_s x t_m) of crossing strands, was tried and
  /// rejected: where the loop wraps around a leg, the slave points along the wrap cross the
  /// tangent plane, and 4.5 mm shear to 50 degrees stopped at a limit point in 40 steps.)
  /// Pairs farther apart at the last commit are not watched (a step that moves a yarn through
  /// another from farther away is not caught).
  static constexpr double kWatchRadius = 2.0;  ///< in yarn diameters (choice)
  /// The farthest course and copy along a course searched (a lattice compressed or sheared so
  /// far that one of them could touch the yarn is refused: guard_refusal).
  static constexpr int kMaxCopy = 6;
  struct Side {
    int point = 0, course = 0, k = 0;
    double u = 0;
    Eigen::Vector3d n = Eigen::Vector3d::Zero();  ///< r/|r| at the commit
  };
  struct PassThrough {
    int point = 0, course = 0;
    double xi = 0, u = 0;  ///< slave parameter; master parameter (unrolled)
    double depth = 0;      ///< -(x_s - x_m(u)) . n [mm], > 0: how far beyond the master
  };
  /// The deepest pass-through of the converged state x against the last commit, or nullopt.
  std::optional<PassThrough> pass_through(const rod::RodSystem& sys,
                                          const Eigen::VectorXd& x) const;
  /// Why the converged state x is refused by the guard (a pass-through, a pair overlapping
  /// more than ContactOptions::max_overlap d, or a copy beyond kMaxCopy within reach), or an
  /// empty string.
  std::string guard_refusal(const rod::RodSystem& sys, const Eigen::VectorXd& x);
  int num_watched_pairs() const { return static_cast<int>(sides_.size()); }

  /// Everything commit() changes (friction anchors, references, dissipation, sides): trial
  /// solves (the uniaxial path's lateral iteration) save and restore it.
  struct State {
    std::vector<std::vector<double>> history;
    std::vector<std::vector<Eigen::Vector2d>> reference;
    double dissipation = 0, last_dissipation = 0;
    std::vector<Side> sides;
  };
  State save() const { return {history_, reference_, dissipation_, last_dissipation_, sides_}; }
  void restore(const State& s) {
    history_ = s.history;
    reference_ = s.reference;
    dissipation_ = s.dissipation;
    last_dissipation_ = s.last_dissipation;
    sides_ = s.sides;
    reset_increment();
  }
  /// Drops the pending (in-increment) pairs, e.g. after a failed increment.
  void reset_increment() { pending_.assign(pending_.size(), {}); }

  double dissipation() const { return dissipation_; }  ///< cumulative friction work [N mm]
  double last_increment_dissipation() const { return last_dissipation_; }
  const std::vector<double>& tributary() const { return W_; }
  int num_slave_points() const { return static_cast<int>(xi_.size()); }

 private:
  struct Found {
    int point, course;
    Projection pr;
  };
  /// Pairs within `inflate` of each other (d + margin for the contact loads).
  std::vector<Found> search(const Eigen::MatrixXd& Q, double inflate) const;
  /// The copies (course j, copy k along it) whose whole-yarn box, inflated by `inflate`, meets
  /// the yarn's, |j|, |k| <= kMaxCopy; `edge` is set when one of them has |j| or |k| = kMaxCopy.
  std::vector<Eigen::Vector2i> copies(const Eigen::MatrixXd& Q, double inflate, bool& edge) const;
  /// The slot of (slave point, course) in history_, pending_ and reference_.
  static int slot(int point, int course) { return (2 * kMaxCopy + 1) * point + course + kMaxCopy; }
  /// search(Q) at the current periods, remembered for the last (Q, a1, a2): a converged state
  /// is searched by the Newton's last residual, commit() (twice) and homogenization
  /// (active_pairs()); the search is a pure function of them, so the result is reused.
  const std::vector<Found>& found(const Eigen::MatrixXd& Q);
  Chain chain(const Eigen::MatrixXd& Q, int course) const;
  double anchor_for(const Found& f);
  /// sides_ of the state x (see Side).
  void record_sides(const rod::RodSystem& sys, const Eigen::VectorXd& x);
  /// x_s - x_m(u) of slave point `point` and copy k of course `course` in the state Q.
  Eigen::Vector3d separation(const Eigen::MatrixXd& Q, int point, int course, int k,
                             double u) const;
  /// The reference (u_r, g_r) matched by f, or nullptr.
  Eigen::Vector2d* reference_for(const Found& f);
  Eigen::MatrixXd positions(const rod::RodSystem& sys, const Eigen::VectorXd& x) const;
  template <class Visit>
  void visit(const rod::RodSystem& sys, const Eigen::VectorXd& x, bool want_jac, Visit&& v);

  int rod_ = 0;
  ContactOptions opt_;
  spline::BSplineBasis basis_;
  std::vector<double> xi_;      // slave (Gauss) points
  std::vector<int> first_;      // first basis function at each slave point
  Eigen::MatrixXd Nc_;          // ns x (p+1) basis values at the slave points
  std::vector<double> weight_;  // quadrature weights w_g |r0_xi| [mm]
  std::vector<double> W_;       // tributary lengths of the collocation points
  Eigen::Vector3d a1_ = Eigen::Vector3d::Zero(), a2_ = Eigen::Vector3d::Zero();
  double scale_ = 1.0;
  // history_[slot(slave, course)]: anchors of the last converged state; pending_: new in step
  std::vector<std::vector<double>> history_, pending_;
  // reference_[slot(slave, course)]: (u_r, g_r) of the stress-free reference pairs
  std::vector<std::vector<Eigen::Vector2d>> reference_;
  double dissipation_ = 0, last_dissipation_ = 0;
  std::vector<Side> sides_;  // of the last committed state (pass-through guard)
  struct SearchCache {
    bool valid = false;
    Eigen::MatrixXd Q;
    Eigen::Vector3d a1, a2;
    std::vector<Found> found;
  } search_cache_;
};

}  // namespace knit::meso::contact
