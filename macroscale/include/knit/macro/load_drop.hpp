// Load drops of a displacement-controlled run (session 37): the reaction's magnitude falling
// between converged steps while the applied displacement grows. In a tensile test the load of
// a fabric does not fall; a drop there is a snap of the material law (issue 11 found the
// paper's law dropping from 17.1 to 5.7 N in a wale-wise test) or a lost stability, and the
// user should hear of it in the run, not only in the reproduction's report (scripts/report.py
// judges the paper's tensile cases with the same threshold, TOL_MONOTONE = 1e-6).
#pragma once

#include <string>
#include <vector>

#include "knit/macro/case.hpp"
#include "knit/macro/run.hpp"

namespace knit::macro {

/// Relative threshold of a load drop: s (F_k - F_k+1) > kLoadDropTolerance x max_j |F_j|, s the
/// sign of the load of largest magnitude (the direction the test pulls it; a reaction at the
/// held edge is negative), and
/// more than the Newton solve's absolute residual tolerance (Case::solver.absolute_tolerance,
/// N): a reaction is not known more closely than that (session 38's red team: a reaction of a
/// free edge "fell" from -1.8e-15 to 4.4e-16 N, 75 % of its largest).
inline constexpr double kLoadDropTolerance = 1e-6;

/// The drops of one reaction: how many, and the largest (the steps on either side of it).
struct LoadDrop {
  std::string reaction;                        ///< the name in output.reactions
  int count = 0;                               ///< consecutive-step decrements above the threshold
  double largest = 0.0;                        ///< s (F_from - F_to) of the largest (N)
  double max_load = 0.0;                       ///< max_j |F_j| over the run (N)
  double direction = 0.0;                      ///< s: the sign of the load of largest magnitude
  int from_step = 0, to_step = 0;              ///< of the largest drop
  int first_from_step = 0, first_to_step = 0;  ///< of the first drop (count > 1)
  double from_load = 0.0, to_load = 0.0;       ///< F at those steps (N)
  double from_strain = 0.0, to_strain = 0.0;   ///< the applied strain at those steps
};

/// The load drops of a run's rows: only for a case with output.applied_displacement, and only
/// for the reactions in the applied displacement's component (the load along the pull; the
/// lateral reactions of a tensile test may well fall). Rows in run order; the applied
/// displacement grows with the load factor. Empty when there is none.
std::vector<LoadDrop> find_load_drops(const Case& c, const std::vector<StepRow>& rows,
                                      double tolerance = kLoadDropTolerance);

/// One line (no "warning: " prefix): "load drop: reaction 'jaw_force' falls from 17.1 to 5.74 N
/// between step 12 (strain 0.2) and step 13 (strain 0.21) while the applied displacement grows
/// ...".
/// `force`: the force unit's label (the case's /units; unit_labels(c.units).of("N")).
std::string load_drop_message(const LoadDrop& d, double tolerance = kLoadDropTolerance,
                              const std::string& force = "N");

}  // namespace knit::macro
