// Newton-Raphson with SparseLU and load stepping with cut-back (see solver.hpp).
#include "knit/meso/rod/solver.hpp"

#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>

namespace knit::meso::rod {

namespace {

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
  Eigen::SparseMatrix<double> J(N, N);
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
  bool analyzed = false;
  Eigen::Index nnz_pattern = -1;
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
    J.setFromTriplets(trip.begin(), trip.end());
    J.makeCompressed();
    if (!analyzed || J.nonZeros() != nnz_pattern) {
      lu.analyzePattern(J);
      analyzed = true;
      nnz_pattern = J.nonZeros();
    }
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

PathReport solve_path(const RodSystem& sys, Eigen::VectorXd& x, const PathOptions& opt,
                      const StepCallback& on_step,
                      const std::vector<ExternalContribution*>& extra) {
  PathReport rep;
  double lam = opt.lambda_start;
  rep.lambda_reached = lam;
  // Make sure the start state satisfies the equations (e.g. the quaternion gauge).
  {
    const NewtonReport r0 = solve_newton(sys, x, lam, extra, opt.newton);
    rep.total_iterations += r0.iterations;
    if (!r0.converged) {
      rep.message =
          "start state at lambda = " + std::to_string(lam) + " did not converge: " + r0.message;
      return rep;
    }
  }
  const int steps = std::max(1, opt.steps);
  const double nominal = (opt.lambda_end - opt.lambda_start) / steps;
  double inc = nominal;
  int halvings = 0;
  Eigen::VectorXd x_prev = x;
  for (int s = 1; s <= steps; ++s) {
    const double target = opt.lambda_start + nominal * s;
    while (std::abs(target - lam) > 1e-14 * std::max(1.0, std::abs(target))) {
      double next = lam + inc;
      if ((nominal > 0 && next > target) || (nominal < 0 && next < target) ||
          std::abs(target - next) < 1e-9 * std::abs(nominal))
        next = target;
      x_prev = x;
      const NewtonReport r = solve_newton(sys, x, next, extra, opt.newton);
      rep.total_iterations += r.iterations;
      if (r.converged) {
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
        if (++halvings > opt.max_cutbacks) {
          rep.message = "increment to lambda = " + std::to_string(next) + " failed after " +
                        std::to_string(opt.max_cutbacks) + " cut-backs: " + r.message;
          return rep;
        }
        inc = 0.5 * (next - lam);
      }
    }
    if (on_step) on_step(s, lam, x);
  }
  rep.completed = true;
  rep.message = "completed";
  return rep;
}

}  // namespace knit::meso::rod
