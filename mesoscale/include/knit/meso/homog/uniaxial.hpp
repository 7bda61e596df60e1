// Uniaxial stress on the unit cell (issue 11): one normal stretch of F* prescribed, the other
// found so that its normal stress vanishes -- a mixed macroscopic condition
//   F* = diag(l_a, l_b) (axis 0: l_a = F11 prescribed, l_b = F22 unknown; axis 1 swapped),
//   S_bb(F*) = 0   (paper eq. 9, S = F^-1 P, here S_bb = P_bb / l_b for diagonal F*).
// Choice (docs/unit-cell.md, "Uniaxial stress"): a safeguarded secant iteration on l_b per
// step (Illinois regula falsi once a sign change brackets the root), each trial a full cell
// solve from the last converged state of the path (snapshot/restore, so rejected trials leave
// no friction history behind). The first trial is extrapolated from the previous steps, the
// second uses the last step's secant slope; this needs 2-4 cell solves per step. Simpler than
// an extra unknown in the rod's Newton system, and the lateral equation is one scalar.
#pragma once

#include "knit/meso/homog/periodic_cell.hpp"

namespace knit::meso::homog {

struct UniaxialOptions {
  /// Converged when |S_lateral| <= tol [MPa] (0.002 % of the cell's stress range of ~6 MPa).
  double tol = 1e-4;
  int max_solves = 16;       ///< cell solves per step
  double max_change = 0.08;  ///< largest change of the lateral stretch per trial
};

/// State carried between the steps of one uniaxial path.
struct UniaxialState {
  double l_prev = 1.0, l_prev2 = 1.0;  ///< lateral stretch of the last two converged steps
  double a_prev = 1.0, a_prev2 = 1.0;  ///< their prescribed stretches
  int steps = 0;                       ///< converged steps so far
  double slope = 0.0;                  ///< dS_lat/dl_b of the last step (secant), 0 = unknown
};

struct UniaxialStep {
  StepResult step;  ///< the accepted solve (converged = lateral condition met too)
  int solves = 0;
  double lateral_stress = 0;  ///< S_bb of the accepted state [MPa]
};

/// Solves one step: stretch `l_a` along `axis`, lateral stretch found. The cell must hold the
/// last converged state; on success it holds the new one and `st` is updated; on failure the
/// cell is restored to the state before the step.
UniaxialStep solve_uniaxial_step(PeriodicCell& cell, int axis, double l_a, UniaxialState& st,
                                 const UniaxialOptions& opt = {});

}  // namespace knit::meso::homog
