// The sub-step schedule of one cell step (PeriodicCell::solve): the load fraction lam goes
// from 0 to 1 in sub-steps; a failed sub-step halves the next, two converged ones in a row
// double it back up to the full step.
#pragma once

#include <algorithm>

namespace knit::meso::homog {

struct SubstepLimits {
  int max_cutbacks = 6;       ///< halvings allowed in a row (the next failure ends the step)
  int max_substeps = 500;     ///< sub-steps (converged or not) of the step
  double min_substep = 1e-6;  ///< a sub-step below this fraction of the step ends it
};

struct SubstepOutcome {
  enum class Stop { kDone, kCutbacks, kMinSubstep, kMaxSubsteps };
  Stop stop = Stop::kDone;
  double lam = 0;  ///< load fraction of the last converged sub-step
  int substeps = 0, cutbacks = 0;
};

/// Marches lam from 0 to 1: `attempt(next)` solves the sub-step to the load fraction `next`
/// (from the last converged one) and says whether it converged; the same sub-step is never
/// tried twice in a row. Why the growth: before
/// session 58 a halved sub-step never grew again, so one hard stretch left the rest of the
/// step at the smallest sub-step reached (a held-out twin path at 6.5 mm ran > 16 min in one
/// step). Why the cap: a stretch that keeps failing every third sub-step would still crawl.
/// A limit point (sub-steps shrinking towards a fraction the cell cannot pass; each success
/// resets the count of halvings in a row) ends at min_substep (session 12).
template <class Attempt>
SubstepOutcome march_substeps(const SubstepLimits& lim, Attempt&& attempt) {
  SubstepOutcome out;
  double inc = 1.0;
  int halvings = 0, successes = 0;
  while (out.lam < 1 - 1e-14) {
    if (out.substeps >= lim.max_substeps) {
      out.stop = SubstepOutcome::Stop::kMaxSubsteps;
      return out;
    }
    ++out.substeps;
    const double next = std::min(1.0, out.lam + inc);
    if (attempt(next)) {
      out.lam = next;
      halvings = 0;
      if (++successes >= 2) {
        inc = std::min(1.0, 2.0 * inc);
        successes = 0;
      }
    } else {
      successes = 0;
      ++out.cutbacks;
      if (++halvings > lim.max_cutbacks) {
        out.stop = SubstepOutcome::Stop::kCutbacks;
        return out;
      }
      // Half the sub-step just tried (as the rod's solve_path does), not half of `inc`: a
      // grown `inc` can reach past 1, where `next` was clipped, and half of it past 1 again
      // would retry the same failed sub-step (session 58's review).
      inc = 0.5 * (next - out.lam);
      if (inc < lim.min_substep) {
        out.stop = SubstepOutcome::Stop::kMinSubstep;
        return out;
      }
    }
  }
  return out;
}

}  // namespace knit::meso::homog
