// Uniaxial stress on the unit cell: see knit/meso/homog/uniaxial.hpp.
#include "knit/meso/homog/uniaxial.hpp"

#include <algorithm>
#include <cmath>

namespace knit::meso::homog {

namespace {
/// Slope dS_lat/dl_b assumed when nothing better is known [MPa]: the order of the cell's
/// lateral stiffness at small strain; only the second trial of the first step uses it.
constexpr double kDefaultSlope = 5.0;
/// Retries of a trial whose cell solve fails, each halfway back to the last good value.
constexpr int kTrialRetries = 3;

struct Trial {
  double l = 1, f = 0;
  bool ok = false;
};
}  // namespace

UniaxialStep solve_uniaxial_step(PeriodicCell& cell, int axis, double la, UniaxialState& st,
                                 const UniaxialOptions& opt) {
  const int b = 1 - axis;
  const PeriodicCell::Snapshot snap = cell.snapshot();
  UniaxialStep out;
  auto eval = [&](double l) {
    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    F(axis, axis) = la;
    F(b, b) = l;
    cell.restore(snap);
    out.step = cell.solve(F);
    ++out.solves;
    Trial t;
    t.l = l;
    t.ok = out.step.converged && std::isfinite(out.step.S(b, b));
    t.f = t.ok ? out.step.S(b, b) : 0.0;
    return t;
  };
  // A trial whose solve fails is moved halfway back to `good` (a value known to be solvable).
  auto eval_safe = [&](double l, double good) {
    Trial t = eval(l);
    for (int r = 0; r < kTrialRetries && !t.ok && out.solves < opt.max_solves; ++r) {
      l = 0.5 * (l + good);
      t = eval(l);
    }
    return t;
  };
  auto fail = [&](const std::string& why) {
    cell.restore(snap);
    out.step.converged = false;
    out.step.message =
        "uniaxial: " + why + (out.step.message.empty() ? "" : "; " + out.step.message);
    return out;
  };
  auto accept = [&](const Trial& t, double slope) {
    st.l_prev2 = st.l_prev;
    st.a_prev2 = st.a_prev;
    st.l_prev = t.l;
    st.a_prev = la;
    ++st.steps;
    if (slope > 0 && std::isfinite(slope)) st.slope = slope;
    out.lateral_stress = t.f;
    out.step.converged = true;
    return out;
  };
  auto clamp = [&](double l, double from) {
    return std::clamp(l, from - opt.max_change, from + opt.max_change);
  };

  // First trial: linear extrapolation in the prescribed stretch from the last two states.
  double l0 = st.l_prev;
  if (st.steps >= 1 && std::abs(st.a_prev - st.a_prev2) > 1e-14)
    l0 = st.l_prev + (st.l_prev - st.l_prev2) * (la - st.a_prev) / (st.a_prev - st.a_prev2);
  Trial A = eval_safe(clamp(l0, st.l_prev), st.l_prev);
  if (!A.ok)
    return fail("the cell did not converge near the lateral stretch " + std::to_string(l0));
  if (std::abs(A.f) <= opt.tol) return accept(A, st.slope);
  const double k0 = st.slope > 0 ? st.slope : kDefaultSlope;
  Trial B = eval_safe(clamp(A.l - A.f / k0, A.l), A.l);
  if (!B.ok) return fail("the cell did not converge in the lateral iteration");
  bool bracket = A.f * B.f < 0;
  while (true) {
    const double slope = (B.f - A.f) / (B.l - A.l);
    if (std::abs(B.f) <= opt.tol) return accept(B, slope);
    if (out.solves >= opt.max_solves)
      return fail("lateral stress " + std::to_string(B.f) + " MPa after " +
                  std::to_string(out.solves) + " cell solves");
    double l;
    if (bracket) {
      l = (A.l * B.f - B.l * A.f) / (B.f - A.f);  // regula falsi inside [A, B]
    } else {
      const double k = slope > 0 && std::isfinite(slope) ? slope : 2.0 * k0;
      l = clamp(B.l - B.f / k, B.l);
    }
    const Trial C = eval_safe(l, B.l);
    if (!C.ok) return fail("the cell did not converge in the lateral iteration");
    if (bracket) {
      if (C.f * B.f < 0) {
        A = B;
      } else {
        A.f *= 0.5;  // Illinois: the retained end point's value is halved
      }
      B = C;
    } else {
      A = B;
      B = C;
      bracket = A.f * B.f < 0;
    }
  }
}

}  // namespace knit::meso::homog
