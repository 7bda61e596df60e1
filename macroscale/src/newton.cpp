#include "knit/macro/newton.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>

#include "knit/macro/fold_guard.hpp"

namespace knit::macro {

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// CPU seconds of the process (all threads): the cost of a phase on a loaded machine.
double cpu_now() {
  return double(std::clock()) / CLOCKS_PER_SEC;
}

/// The residual at one iterate.
struct State {
  Eigen::VectorXd r;      ///< reduced residual Z^T f_int - lambda Z^T f_ext
  double norm = 0.0;      ///< ||r||
  double ref = 0.0;       ///< reference force of the convergence test
  double Pi = 0.0;        ///< total potential (hyperelastic materials)
  double Pi_scale = 0.0;  ///< |Psi| + |lambda f_ext . u|: the round-off scale of Pi
};

enum class Eval { kOk, kDegenerate, kNonFinite };

struct StepOutcome {
  bool converged = false;
  bool work_cap = false;
  int iterations = 0;
  double residual = 0.0;
  double reference = 0.0;  ///< the reference force of the last convergence test
  /// Converged by the absolute part of the tolerance alone (residual > tolerance x reference).
  bool by_absolute = false;
  int negative_pivots = -2;  ///< -2: no factorization in this step
  int determinant_sign = 0;  ///< of that factorization; 0: none in this step
  std::string why;
};

}  // namespace

bool at_round_off_floor(double r, double ref, double du_rel, double r2, const SolverOptions& opt) {
  if (!(r <= 1e3 * (opt.tolerance * ref + opt.absolute_tolerance) + 1e-9 * ref)) return false;
  if (du_rel <= opt.displacement_tolerance) return true;
  return r >= 0.99 * r2 && du_rel <= 100.0 * opt.displacement_tolerance;
}

EnergyLineSearch energy_line_search(const std::function<std::optional<double>(double)>& Pi,
                                    double Pi0, double g0, double Pi_scale) {
  constexpr double kArmijo = 1e-4;  // sufficient decrease
  constexpr int kMaxBacktracks = 10;
  EnergyLineSearch ls;
  std::optional<double> P = Pi(1.0);
  ls.evaluations = 1;
  for (int k = 0; k < kMaxBacktracks && g0 < 0.0; ++k) {
    if (P && *P <= Pi0 + kArmijo * ls.alpha * g0 + 1e-12 * Pi_scale) break;
    double a = 0.5 * ls.alpha;
    if (P) {
      const double q = *P - Pi0 - g0 * ls.alpha;  // curvature term of the quadratic
      if (q > 0.0)
        a = std::clamp(-g0 * ls.alpha * ls.alpha / (2.0 * q), 0.1 * ls.alpha, 0.5 * ls.alpha);
    }
    ls.alpha = a;
    P = Pi(a);
    ++ls.evaluations;
  }
  ls.valid = P.has_value();
  ls.Pi = P ? *P : 0.0;
  return ls;
}

std::string stability_summary(const RunReport& r) {
  std::ostringstream o;
  if (r.converged_steps == 0) {
    o << "not available (no converged step)";
  } else if (r.max_negative_pivots < 0) {
    // The LU path: no inertia, only the sign of det K (an odd number of negative real
    // eigenvalues when negative; a pair of them, or a complex pair, leaves it positive).
    o << "unsymmetric tangent (LU factorization: no inertia, only the sign of det K): ";
    if (r.first_negative_determinant_step < 0 && r.unknown_determinant_steps == 0)
      o << "det K > 0 at every converged step (no odd number of negative real eigenvalues; an "
           "even number would not show)";
    else if (r.first_negative_determinant_step < 0)
      o << "det K > 0 at every converged step where it is known (unknown at "
        << r.unknown_determinant_steps << " of " << r.converged_steps
        << ": a singular tangent there); an even number of negative real eigenvalues would not "
           "show";
    else
      o << "det K < 0 from step " << r.first_negative_determinant_step << " (load factor "
        << r.first_negative_determinant_lambda << "), at " << r.negative_determinant_steps << " of "
        << r.converged_steps
        << " converged steps: an odd number of negative real eigenvalues of the reduced tangent "
           "(loss of stability: a limit or bifurcation point was passed)";
  } else if (r.first_unstable_step < 0) {
    o << "the tangent was positive definite at every converged step (0 negative pivots)";
  } else {
    o << "unstable from step " << r.first_unstable_step << " (load factor "
      << r.first_unstable_lambda << "): up to " << r.max_negative_pivots
      << " negative pivots of the reduced tangent (loss of stability: a limit or bifurcation "
         "point was passed)";
  }
  return o.str();
}

RunReport solve_load_steps(const ShellModel& model, const DofMap& dofs, const Eigen::VectorXd& fext,
                           const SolverOptions& opt, const StepCallback& on_step) {
  RunReport report;
  SolverStats& stats = report.stats;
  const bool hyper = model.material().hyperelastic();
  const int n = dofs.num_free();
  const bool sparse = opt.linear_solver == LinearSolver::kSparse ||
                      (opt.linear_solver == LinearSolver::kAuto && n > opt.dense_limit);
  const auto t_setup = Clock::now();
  ReducedTangent K(model, dofs, hyper && opt.symmetric, sparse, opt.supernodal, opt.multifrontal);
  stats.setup = since(t_setup);
  stats.unknowns = n;
  stats.stored_entries = K.stored_entries();
  stats.sparse = sparse;
  stats.symmetric = K.symmetric();
  stats.supernodal = K.supernodal();
  stats.multifrontal = K.multifrontal();
  stats.ordering = K.ordering();
  // Every return: whether CHOLMOD failed where it was wanted (SolverStats).
  const auto done = [&]() -> RunReport& {
    stats.supernodal_failure = K.supernodal_failure();
    stats.fallback_factorizations = K.fallback_factorizations();
    stats.multifrontal_factorizations = K.multifrontal_factorizations();
    stats.multifrontal_failure = K.multifrontal_failure();
    return report;
  };
  stats.threads = model.assembly_threads();
  // Progress of long runs (SolverOptions::progress): the setup, then slow iterations.
  auto last_line = Clock::now();
  std::string last_method;  // of the last factorization, for the progress lines
  int last_negative_pivots = -1;
  if (opt.progress && stats.setup > opt.progress_after) {
    std::ostringstream s;
    s.precision(3);
    s << "setup: " << n << " unknowns, "
      << (!sparse            ? "dense"
          : stats.supernodal ? "supernodal Cholesky (ordering " + stats.ordering + ")"
          : stats.symmetric  ? "sparse LDLT"
                             : "sparse LU")
      << ", " << stats.setup << " s";
    if (!K.supernodal_failure().empty())
      s << " (the supernodal Cholesky failed in " << K.supernodal_failure() << ")";
    opt.progress(s.str());
    last_line = Clock::now();
  }

  const int nsteps = std::max(1, opt.steps);
  const long work_cap = opt.max_total_iterations > 0
                            ? opt.max_total_iterations
                            : 20L * nsteps * std::max(1, opt.max_iterations);
  const double h_nom = 1.0 / nsteps;
  const Eigen::VectorXd fext_red = dofs.reduce(fext);
  const double fext_norm = fext.norm();
  Eigen::VectorXd ufree = Eigen::VectorXd::Zero(n);
  double lambda = 0.0, h = h_nom, lambda_prev = 0.0;
  Eigen::VectorXd ufree_prev = ufree;
  int cutbacks = 0, step = 0, last_negative = -1, last_sign = 0;
  ShellModel::Evaluation ev, trial;

  // The state (residual, reference force, potential) at u = expand(uf, lam) from an evaluation
  // there.
  auto state_from = [&](const ShellModel::Evaluation& E, const Eigen::VectorXd& u, double lam,
                        State& s) {
    if (!E.ok) return Eval::kDegenerate;
    s.r = dofs.reduce(E.fint) - lam * fext_red;
    double react = 0.0;
    for (int d = 0; d < dofs.num_dofs(); ++d)
      if (dofs.constrained(d)) react += E.fint(d) * E.fint(d);
    s.ref = std::max(std::abs(lam) * fext_norm, std::sqrt(react));
    s.norm = s.r.norm();
    if (hyper) {
      const double wext = lam * fext.dot(u);
      s.Pi = E.energy - wext;
      s.Pi_scale = std::abs(E.energy) + std::abs(wext);
    }
    if (!std::isfinite(s.norm) || !std::isfinite(s.ref) || (hyper && !std::isfinite(s.Pi)))
      return Eval::kNonFinite;
    return Eval::kOk;
  };
  // Where `trial` and `ev` were last evaluated (empty: not valid), so that an evaluation at the
  // same displacement is reused (bitwise the same result: f_int does not depend on whether the
  // tangent was computed, nor on the number of threads).
  Eigen::VectorXd trial_u, ev_u;
  // Residual (and potential) at (uf, lam).
  auto residual = [&](const Eigen::VectorXd& uf, double lam, State& s) {
    const auto t0 = Clock::now();
    const double c0 = cpu_now();
    ++stats.evaluations;
    trial_u = dofs.expand(uf, lam);
    model.evaluate(trial_u, false, trial, /*keep_points=*/true);
    stats.residuals += since(t0);
    stats.residuals_cpu += cpu_now() - c0;
    return state_from(trial, trial_u, lam, s);
  };
  // Tangent (with the residual) at (uf, lam), timed as assembly. At the point of the last
  // residual-only evaluation (the accepted trial point of a Newton step: usually) the tangent
  // is completed from that evaluation's point states (ShellModel::tangent_from; bitwise the
  // same): no second pass through the kinematics and the material.
  auto tangent = [&](const Eigen::VectorXd& uf, double lam) {
    const auto t0 = Clock::now();
    const double c0 = cpu_now();
    ev_u = dofs.expand(uf, lam);
    // The element tangents go straight into K (ReducedTangent::begin_assembly).
    K.begin_assembly(model);
    if (trial.has_points && trial_u.size() > 0 && trial_u == ev_u) {
      model.tangent_from(trial, ev, &K);
      ++stats.tangents_reused;
    } else {
      model.evaluate(ev_u, true, ev, false, &K);
    }
    if (ev.ok) K.end_assembly();
    stats.assembly += since(t0);
    stats.assembly_cpu += cpu_now() - c0;
    return ev.ok;
  };
  auto why_not = [](Eval e, const State& s) {
    if (e == Eval::kDegenerate)
      return std::string("the configuration degenerated (zero Jacobian or non-finite strains)");
    std::ostringstream o;
    o << "non-finite residual (||r|| = " << s.norm << ", reference force " << s.ref
      << "): the loads or the state overflow";
    return o.str();
  };

  // Whether anything loads the patch: forces, or prescribed displacements (a zero-load case
  // converges at the undeformed state by right).
  // (The largest entry, not the 2-norm, whose square underflows to 0 below about 1e-154:
  // session 29.)
  const bool loaded =
      fext_red.lpNorm<Eigen::Infinity>() > 0.0 ||
      dofs.expand(Eigen::VectorXd::Zero(ufree.size()), 1.0).lpNorm<Eigen::Infinity>() > 0.0;
  // Newton iterations at load factor lam from uf.
  auto newton = [&](double lam, Eigen::VectorXd& uf, bool energy_search) {
    StepOutcome o;
    State cur, next;
    // The first iterate with its tangent: a step rarely converges at its predictor, and when it
    // does the symmetric path factorizes this tangent anyway (for the inertia); this saves the
    // residual-only evaluation at the start of every step.
    tangent(uf, lam);
    Eval st = state_from(ev, ev_u, lam, cur);
    bool have_tangent = ev.ok;
    // The residuals of the two previous iterates (the round-off floor's test below).
    double r1 = std::numeric_limits<double>::infinity(), r2 = r1;
    for (int it = 0;; ++it) {
      if (st != Eval::kOk) {
        o.why = why_not(st, cur);
        return o;
      }
      o.residual = cur.norm;
      o.reference = cur.ref;
      o.iterations = it;
      if (opt.progress && it > 0 && since(last_line) > opt.progress_after) {
        std::ostringstream s;
        s.precision(4);
        s << "  load factor " << lam << ", iteration " << it << ": residual " << cur.norm
          << " (reference " << cur.ref << "), last factorization " << last_method;
        if (last_negative_pivots > 0)
          s << " (indefinite: " << last_negative_pivots << " negative pivots)";
        s << ", " << std::setprecision(3) << since(last_line) << " s since the last line";
        opt.progress(s.str());
        last_line = Clock::now();
      }
      // Unloaded, the undeformed state is the answer by right, whatever round-off its internal
      // forces carry (session 49's red team: the Sze cantilever with zero load chased 1.5e-10 N
      // through 25 iterations and 8 cut-backs to "no convergence").
      if (cur.norm <= opt.tolerance * cur.ref + opt.absolute_tolerance ||
          (!loaded && it == 0 && uf.lpNorm<Eigen::Infinity>() == 0.0)) {
        o.converged = true;
        // Not the unloaded rule's step, whose residual may lie beyond both (the review of
        // session 56: a case with no load was told its loads were too small, 523 % off).
        o.by_absolute = cur.norm > opt.tolerance * cur.ref &&
                        cur.norm <= opt.tolerance * cur.ref + opt.absolute_tolerance;
        return o;
      }
      if (it >= opt.max_iterations) {
        std::ostringstream s;
        s << "no convergence in " << opt.max_iterations << " iterations (residual " << cur.norm
          << ")";
        o.why = s.str();
        return o;
      }
      if (stats.iterations >= work_cap) {
        o.work_cap = true;
        std::ostringstream s;
        s << "the cap on the total work was reached: " << stats.iterations << " Newton iterations";
        // The case file cannot set the cap (session 48's red team: the message named
        // max_total_iterations, which a case refuses as an unknown key): say what sets it.
        if (opt.max_total_iterations > 0)
          s << " (max_total_iterations " << work_cap << ")";
        else
          s << " (the cap is 20 x /solver/steps x /solver/max_iterations = 20 x " << nsteps << " x "
            << std::max(1, opt.max_iterations) << " = " << work_cap
            << "; the cut-backs spent it: raise /solver/steps, so that each step asks less, or "
               "/solver/max_iterations)";
        o.why = s.str();
        return o;
      }
      ++stats.iterations;
      if (!have_tangent && !tangent(uf, lam)) {
        o.why = why_not(Eval::kDegenerate, cur);
        return o;
      }
      have_tangent = false;
      const auto t0 = Clock::now();
      const double c0 = cpu_now();
      const Factorization f = K.factorize();
      Eigen::VectorXd du;
      if (f.ok) du = K.solve(-cur.r);
      stats.solve += since(t0);
      stats.solve_cpu += cpu_now() - c0;
      if (!f.ok) {
        o.why = f.why;
        return o;
      }
      o.negative_pivots = f.negative_pivots;
      o.determinant_sign = f.determinant_sign;
      last_method = f.method, last_negative_pivots = f.negative_pivots;
      if (!du.allFinite()) {
        o.why = "the linear solve produced non-finite values";
        return o;
      }
      // A correction at round-off level: the residual sits at its floor, the solution is
      // converged (at_round_off_floor; its stalled form since session 12: s323_hypar_tension's
      // residual stuck at 4.15e-8 N for 13 iterations with |du| = 5.6e-7 mm, 3e-8 of |u|, failed
      // the step at max_iterations, and its cut-back's first iterations diverged to |u| ~ 1e5
      // mm, 2.6 % of the case's material evaluations far outside the data box).
      if (it > 0 &&
          at_round_off_floor(cur.norm, cur.ref, du.norm() / std::max(uf.norm(), 1e-300), r2, opt)) {
        uf += du;
        o.converged = true;
        o.iterations = it + 1;
        return o;
      }
      double alpha = 1.0;
      const double g0 = du.dot(cur.r);  // dPi/dalpha at alpha = 0
      Eval st1 = residual(uf + du, lam, next);
      if (hyper && !energy_search) {
        // Plain Newton: the full step, halved only while it degenerates the geometry.
        for (int k = 0; k < 10 && st1 != Eval::kOk; ++k) {
          alpha *= 0.5;
          st1 = residual(uf + alpha * du, lam, next);
        }
      } else if (hyper) {
        // Energy line search, only when the full step does not decrease Pi (or degenerates).
        const EnergyLineSearch ls = energy_line_search(
            [&](double a) {
              if (a != 1.0) st1 = residual(uf + a * du, lam, next);
              return st1 == Eval::kOk ? std::optional<double>(next.Pi) : std::nullopt;
            },
            cur.Pi, g0, cur.Pi_scale);
        alpha = ls.alpha;
      } else if (opt.line_search) {
        if (st1 == Eval::kOk) {
          const double g1 = du.dot(next.r);
          if (next.norm > cur.norm && std::abs(g1) > 0.5 * std::abs(g0) && g0 < 0.0) {
            // Secant iterations on g(alpha) = du . r(u + alpha du) between 0 and 1.
            double a0 = 0.0, ga0 = g0, a1 = 1.0, ga1 = g1;
            State s1 = next, s2;
            for (int k = 0; k < 6 && std::abs(ga1) > 0.5 * std::abs(g0); ++k) {
              double a2 = a1 - ga1 * (a1 - a0) / (ga1 - ga0);
              if (!std::isfinite(a2)) break;
              a2 = std::clamp(a2, 0.05, 1.0);
              if (residual(uf + a2 * du, lam, s2) != Eval::kOk) break;
              a0 = a1, ga0 = ga1, a1 = a2, ga1 = du.dot(s2.r);
              s1 = s2;
            }
            alpha = a1;
            next = s1;
          }
        } else {
          alpha = 0.5;  // the full step degenerated the geometry: take half of it
          st1 = residual(uf + alpha * du, lam, next);
        }
      }
      uf += alpha * du;
      r2 = r1;
      r1 = cur.norm;
      cur = next;
      st = st1;
    }
  };

  auto stop = [&](StopReason reason, const std::string& what, double lam1, const std::string& why) {
    std::ostringstream s;
    s << "load step to lambda = " << lam1 << " failed " << what << ": " << why << "; " << step
      << " converged steps kept, last lambda = " << lambda;
    report.status = RunStatus::kNotConverged;
    report.reason = reason;
    report.message = s.str();
  };

  // No converged state may fold over itself (fold_guard.hpp). The first check point whose
  // normal at the converged u turned by 90 degrees or more, or -1; -2 if the configuration
  // degenerated. The quadrature points' normals come from `trial`'s point states, evaluated
  // there if they are not.
  FoldGuard folds(model);
  auto flipped_point = [&](const Eigen::VectorXd& u) {
    if (!(trial.has_points && trial_u.size() > 0 && trial_u == u)) {
      trial_u = u;
      model.evaluate(trial_u, false, trial, /*keep_points=*/true);
      if (!trial.ok) return -2;
    }
    return folds.check(u, trial.points);
  };
  while (lambda < 1.0 - 1e-12) {
    const double next_nominal = std::min(1.0, h_nom * std::floor(lambda / h_nom + 1.0 + 1e-9));
    // A step that reaches the next nominal load factor up to round-off ends on it (session 42's
    // red team: 0.9 + 0.1 = 0.9999999999999999 was the last step's load factor, and the run's
    // applied strain 0.14999999999999997 where the case asks for 0.15).
    const double lam1 =
        lambda + h >= next_nominal - 1e-12 ? next_nominal : std::min(lambda + h, next_nominal);
    const auto t0 = Clock::now();
    // Secant predictor: extrapolate the last converged increment.
    Eigen::VectorXd uf = ufree;
    if (step > 0 && lambda > lambda_prev)
      uf += ((lam1 - lambda) / (lambda - lambda_prev)) * (ufree - ufree_prev);
    // Hyperelastic: plain Newton first (the energy search slowed the Sze cantilever from 60 to
    // 82 iterations by cutting overshooting steps that Newton recovers from), then the step
    // again with the energy line search (line_search_first: the other way round), then
    // without the predictor; otherwise the predictor, then without it.
    const Eigen::VectorXd uf0 = uf;
    const bool search = hyper && opt.line_search;
    const bool search_first = search && opt.line_search_first;
    StepOutcome o = newton(lam1, uf, search_first);
    if (!o.converged && !o.work_cap && search) {  // the other of the two
      uf = uf0;
      o = newton(lam1, uf, !search_first);
    }
    if (!o.converged && !o.work_cap && step > 0) {  // retry without the predictor
      uf = ufree;
      o = newton(lam1, uf, search);
    }
    if (o.converged && step == 0 && o.iterations == 0 && o.residual > 0.0 && loaded &&
        ufree.size() > 0 && ufree.squaredNorm() == 0.0) {
      std::ostringstream s;
      s << "load step to lambda = " << lam1
        << " converged at the undeformed state with no iteration: its out-of-balance force "
        << o.residual << " is already within the tolerance (tolerance " << opt.tolerance
        << " x reference force " << o.reference << " + absolute_tolerance "
        << opt.absolute_tolerance << "; forces "
        << (opt.force_unit.rfind("in ", 0) == 0 ? "" : "in ") << opt.force_unit << "), ";
      // Which part of the tolerance hides the step (session 36's red team: a pressure of 1e10
      // MPa on a patch held in z, carried by the supports alone, was reported as loads too
      // small to see).
      if (opt.tolerance * o.reference > opt.absolute_tolerance)
        s << "so the rest of the loading is lost beside the reference force (the larger of the "
             "applied loads and the support reactions, here far beyond what deforms the patch: "
             "a load carried by the supports alone, say); check the loads' size and "
             "directions, or lower /solver/tolerance";
      else
        s << "so the loads are too small for the solver to see them; lower "
             "/solver/absolute_tolerance well below the load";
      s << "; 0 converged steps kept";
      report.status = RunStatus::kNotConverged;
      report.reason = StopReason::kLoadBelowTolerance;
      report.message = s.str();
      return done();
    }
    if (o.converged) {
      if (const int q = flipped_point(dofs.expand(uf, lam1)); q != -1) {
        o.converged = false;
        o.why = q == -2 ? "the configuration degenerated (zero Jacobian or non-finite strains)"
                        : folds.describe(q);
      }
    }
    if (o.converged) {
      folds.accept();
      if (o.determinant_sign == 0 && o.negative_pivots == -2) {
        // No factorization in this step (converged at once): the inertia (the LU: the sign of
        // the determinant) at this state (its tangent is assembled already when the step's
        // first evaluation was here).
        if (ev_u.size() == 0 || ev_u != dofs.expand(uf, lam1)) tangent(uf, lam1);
        const Factorization f = K.factorize();
        o.negative_pivots = f.ok ? f.negative_pivots : last_negative;
        // A singular tangent at the converged state (a limit point): the sign is not known
        // there, and not the last step's (session 43's review).
        o.determinant_sign = f.ok ? f.determinant_sign : 0;
      }
      if (o.negative_pivots != -2) last_negative = o.negative_pivots;
      last_sign = o.determinant_sign;
      lambda_prev = lambda;
      ufree_prev = ufree;
      lambda = lam1;
      ufree = uf;
      ++step;
      StepResult sr;
      sr.step = step;
      sr.lambda = lambda;
      sr.iterations = o.iterations;
      sr.residual = o.residual;
      sr.negative_pivots = last_negative;
      sr.determinant_sign = last_sign;
      sr.u = dofs.expand(ufree, lambda);
      // The internal forces at the converged state: usually evaluated there already.
      if (trial_u.size() > 0 && trial_u == sr.u && trial.ok)
        sr.fint = trial.fint;
      else if (ev_u.size() > 0 && ev_u == sr.u && ev.ok)
        sr.fint = ev.fint;
      else {
        model.evaluate(sr.u, false, trial);
        trial_u = sr.u;
        sr.fint = trial.fint;
      }
      sr.seconds = since(t0);
      // A step the absolute tolerance let through out of balance by more than
      // kLooseRelativeResidual of the reference force (session 56's red team: a patch loaded by
      // 2e-9 N converged to within 1e-10 N, 0.6-1 % off, steps accepted with 0 iterations).
      // Not where the reference force itself lies within the absolute tolerance (loads at
      // round-off: a patch moving as a rigid body, warned of as such in run.cpp).
      if (o.by_absolute && o.reference > opt.absolute_tolerance &&
          o.residual > kLooseRelativeResidual * o.reference) {
        const double rel = o.residual / std::max(o.reference, 1e-300);
        if (report.loose_steps++ == 0 || rel > report.loosest_relative_residual) {
          report.loosest_relative_residual = rel;
          report.loosest_lambda = lambda;
          report.loosest_reference = o.reference;
        }
      }
      report.converged_steps = step;
      report.last_lambda = lambda;
      report.max_negative_pivots = std::max(report.max_negative_pivots, last_negative);
      if (last_negative > 0 && report.first_unstable_step < 0) {
        report.first_unstable_step = step;
        report.first_unstable_lambda = lambda;
      }
      if (last_sign == 0) ++report.unknown_determinant_steps;
      if (last_sign < 0) {
        ++report.negative_determinant_steps;
        if (report.first_negative_determinant_step < 0) {
          report.first_negative_determinant_step = step;
          report.first_negative_determinant_lambda = lambda;
        }
      }
      if (on_step) on_step(sr);
      last_line = Clock::now();  // the step's own line
      if (std::abs(lambda - next_nominal) < 1e-12) {
        cutbacks = 0;
        h = h_nom;
      } else {
        h = std::min(2.0 * h, h_nom);
      }
      continue;
    }
    if (o.work_cap) {
      stop(StopReason::kWorkCap, "at the work cap", lam1, o.why);
      return done();
    }
    if (++cutbacks > opt.max_cutbacks) {
      std::ostringstream s;
      s << "after " << opt.max_cutbacks << " cut-backs of the increment (last increment "
        << (lam1 - lambda) << ")";
      stop(StopReason::kCutbacks, s.str(), lam1, o.why);
      return done();
    }
    if (0.5 * (lam1 - lambda) < opt.min_increment) {
      std::ostringstream s;
      s << "with the increment at its floor (" << (lam1 - lambda)
        << "; halving it would pass min_increment = " << opt.min_increment << ")";
      stop(StopReason::kIncrementFloor, s.str(), lam1, o.why);
      return done();
    }
    // Half the increment that failed, not half of h: after a doubling, lam1 may have been
    // clipped at the nominal level, and h / 2 then retried the same increment from the same
    // state (session 31: 0.5 -> 1 failed twice, one cut-back and 36 iterations spent on it).
    h = 0.5 * (lam1 - lambda);
  }
  return done();
}

}  // namespace knit::macro
