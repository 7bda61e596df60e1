// Newton-Raphson with SparseLU and load stepping with cut-back (see solver.hpp).
#include "knit/meso/rod/solver.hpp"

#include "knit/meso/rod/triplet_assembler.hpp"

#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace knit::meso::rod {

namespace {

// The symbolic analysis (column ordering, elimination tree) depends on the sparsity pattern
// only; it is reused across Newton iterations and load steps while the pattern is unchanged
// (contact may change it: then it is redone). The matrix is assembled with a reused pattern
// (TripletAssembler). One workspace per thread.
struct LinearWorkspace {
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
  TripletAssembler assembler;
  std::vector<Eigen::Triplet<double>> trip;
  std::vector<int> outer, inner;
  bool analyzed = false;

  bool same_pattern(const Eigen::SparseMatrix<double>& J) const {
    if (!analyzed || static_cast<Eigen::Index>(outer.size()) != J.outerSize() + 1 ||
        static_cast<Eigen::Index>(inner.size()) != J.nonZeros())
      return false;
    return std::equal(outer.begin(), outer.end(), J.outerIndexPtr()) &&
           std::equal(inner.begin(), inner.end(), J.innerIndexPtr());
  }
  void analyze(const Eigen::SparseMatrix<double>& J) {
    lu.analyzePattern(J);
    outer.assign(J.outerIndexPtr(), J.outerIndexPtr() + J.outerSize() + 1);
    inner.assign(J.innerIndexPtr(), J.innerIndexPtr() + J.nonZeros());
    analyzed = true;
  }
};

double scaled_norm(const RodSystem& sys, const Eigen::VectorXd& F) {
  const double v = F.cwiseProduct(sys.row_scales()).cwiseAbs().maxCoeff();
  return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
}

}  // namespace

void assemble_all(const RodSystem& sys, const Eigen::VectorXd& x, double lambda,
                  const std::vector<ExternalContribution*>& extra, Eigen::VectorXd& F,
                  Eigen::SparseMatrix<double>& J) {
  std::vector<Eigen::Triplet<double>> trip;
  sys.assemble(x, lambda, F, trip);
  for (ExternalContribution* c : extra) c->add(sys, x, lambda, F, trip);
  J.resize(sys.num_dofs(), sys.num_dofs());
  J.setFromTriplets(trip.begin(), trip.end());
}

NewtonReport solve_newton(const RodSystem& sys, Eigen::VectorXd& x, double lambda,
                          const std::vector<ExternalContribution*>& extra,
                          const NewtonOptions& opt) {
  NewtonReport rep;
  const int N = sys.num_dofs();
  Eigen::VectorXd F(N);
  thread_local LinearWorkspace ws;
  // The list keeps its capacity from call to call (the cell's lists reach 250,000 triplets).
  std::vector<Eigen::Triplet<double>>& trip = ws.trip;
  auto& lu = ws.lu;
  trip.reserve(static_cast<size_t>(N) * 40);
  for (int it = 0;; ++it) {
    trip.clear();
    sys.assemble(x, lambda, F, trip);
    for (ExternalContribution* c : extra) c->add(sys, x, lambda, F, trip);
    const double res = scaled_norm(sys, F);
    rep.history.push_back(res);
    rep.residual_final = res;
    if (it == 0) rep.residual_initial = res;
    rep.iterations = it;
    if (!std::isfinite(res)) {
      rep.message = "residual is not finite";
      return rep;
    }
    if (res <= opt.tol) {
      rep.converged = true;
      rep.message = "converged";
      return rep;
    }
    if (it > 0 && res > opt.divergence_factor * std::max(rep.residual_initial, opt.tol)) {
      rep.message = "diverged";
      return rep;
    }
    if (it >= opt.max_iterations) {
      rep.message = "maximum number of iterations reached";
      return rep;
    }
    const Eigen::SparseMatrix<double>& J = ws.assembler.build(trip, N);
    // An unchanged pattern is the one analysed last (the assembler says so without comparing).
    if ((ws.assembler.pattern_changed() || !ws.analyzed) && !ws.same_pattern(J)) ws.analyze(J);
    lu.factorize(J);
    if (lu.info() != Eigen::Success) {
      rep.message = "singular Jacobian";
      return rep;
    }
    const Eigen::VectorXd dx = lu.solve(F);
    if (lu.info() != Eigen::Success || !dx.allFinite()) {
      rep.message = "linear solve failed";
      return rep;
    }
    x -= dx;
  }
}

std::string to_string(PathStop s) {
  switch (s) {
    case PathStop::kCompleted:
      return "completed";
    case PathStop::kStartState:
      return "start state did not converge";
    case PathStop::kCutbacks:
      return "cut-back limit";
    case PathStop::kStepFloor:
      return "step floor";
    case PathStop::kWorkCap:
      return "work cap";
    case PathStop::kBadOptions:
      return "bad options";
  }
  return "?";
}

long PathOptions::work_cap() const {
  if (max_total_iterations > 0) return max_total_iterations;
  return kWorkFactor * std::max(1, steps) * std::max(1, newton.max_iterations);
}

std::string PathOptions::validate() const {
  if (steps < 1) return "steps must be >= 1";
  if (!std::isfinite(lambda_start) || !std::isfinite(lambda_end) || lambda_start == lambda_end)
    return "lambda_start and lambda_end must be finite and differ";
  if (max_cutbacks < 0) return "max_cutbacks must be >= 0";
  if (!(min_increment > 0 && min_increment <= 1))
    return "min_increment must be in (0, 1] (a fraction of the nominal increment)";
  if (max_total_iterations < 0) return "max_total_iterations must be >= 0 (0 = automatic)";
  if (!(newton.tol > 0) || !std::isfinite(newton.tol)) return "tolerance must be > 0";
  if (newton.max_iterations < 1) return "max_iterations must be >= 1";
  return {};
}

PathReport solve_path(const RodSystem& sys, Eigen::VectorXd& x, const PathOptions& opt,
                      const StepCallback& on_step,
                      const std::vector<ExternalContribution*>& extra) {
  PathReport rep;
  double lam = opt.lambda_start;
  rep.lambda_reached = lam;
  auto stop = [&](PathStop why, const std::string& message) {
    rep.stop = why;
    rep.message = to_string(why) + ": " + message;
    return rep;
  };
  if (const std::string why = opt.validate(); !why.empty()) return stop(PathStop::kBadOptions, why);
  const long cap = opt.work_cap();
  // Make sure the start state satisfies the equations (e.g. the quaternion gauge).
  {
    const NewtonReport r0 = solve_newton(sys, x, lam, extra, opt.newton);
    rep.total_iterations += r0.iterations;
    if (!r0.converged)
      return stop(PathStop::kStartState,
                  "lambda = " + std::to_string(lam) + " did not converge: " + r0.message);
  }
  const int steps = opt.steps;
  const double nominal = (opt.lambda_end - opt.lambda_start) / steps;
  const double inc_floor = opt.min_increment * std::abs(nominal);
  double inc = nominal;
  int halvings = 0;
  Eigen::VectorXd x_prev = x, x_last = x;
  bool have_last = false;
  double last_inc = 0.0;
  for (int s = 1; s <= steps; ++s) {
    const double target = opt.lambda_start + nominal * s;
    while (std::abs(target - lam) > 1e-14 * std::max(1.0, std::abs(target))) {
      double next = lam + inc;
      if ((nominal > 0 && next > target) || (nominal < 0 && next < target) ||
          std::abs(target - next) < 1e-9 * std::abs(nominal))
        next = target;
      x_prev = x;
      // Secant predictor from the last converged increment (saves about one iteration).
      if (opt.predictor && have_last && std::abs(last_inc) > 0.0)
        x += ((next - lam) / last_inc) * (x - x_last);
      if (rep.total_iterations >= cap)
        return stop(PathStop::kWorkCap,
                    std::to_string(rep.total_iterations) + " Newton iterations spent (cap " +
                        std::to_string(cap) + ", steps.max_total_iterations) at lambda = " +
                        std::to_string(lam) + " of " + std::to_string(opt.lambda_end));
      NewtonReport r = solve_newton(sys, x, next, extra, opt.newton);
      rep.total_iterations += r.iterations;
      // A converged state whose centerline passed through zero length is no rod state: the
      // increment fails and is cut back (session 50's red team: a rod shortened by three times
      // its length "completed" at an axial strain of -3, exit 0).
      if (r.converged) {
        const RodSystem::AxialStretch a = sys.min_axial_stretch(x);
        if (!(a.value > 0.0)) {
          std::ostringstream o;
          o.precision(4);
          o << "the converged state's axial stretch d3 . r' / |r0'| is " << a.value
            << " (<= 0) on rod " << sys.spec(a.rod).name << " at xi = " << a.xi
            << ": the centerline would pass through zero length there, which no rod state "
               "describes (the loads or the prescribed end positions shorten it by its whole "
               "length)";
          r.converged = false;
          r.message = o.str();
        }
      }
      if (r.converged) {
        x_last = x_prev;
        last_inc = next - lam;
        have_last = true;
        lam = next;
        rep.lambda_reached = lam;
        ++rep.increments;
        rep.steps.push_back({lam, r.iterations, r.residual_final});
        halvings = 0;
        // Grow back towards the nominal increment after an easy step.
        if (r.iterations <= 6) inc = std::abs(inc * 2.0) > std::abs(nominal) ? nominal : inc * 2.0;
      } else {
        x = x_prev;
        ++rep.cutbacks;
        if (++halvings > opt.max_cutbacks)
          return stop(PathStop::kCutbacks, "increment to lambda = " + std::to_string(next) +
                                               " failed after " + std::to_string(opt.max_cutbacks) +
                                               " cut-backs: " + r.message);
        inc = 0.5 * (next - lam);
        if (std::abs(inc) < inc_floor)
          return stop(PathStop::kStepFloor,
                      "the increment from lambda = " + std::to_string(lam) + " would fall to " +
                          std::to_string(std::abs(inc)) + ", below the floor " +
                          std::to_string(inc_floor) +
                          " (steps.min_increment = " + std::to_string(opt.min_increment) +
                          " of the nominal increment); last failure: " + r.message);
      }
    }
    if (on_step) on_step(s, lam, x);
  }
  rep.completed = true;
  rep.stop = PathStop::kCompleted;
  rep.message = to_string(PathStop::kCompleted);
  return rep;
}

}  // namespace knit::meso::rod
