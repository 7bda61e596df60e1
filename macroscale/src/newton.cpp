#include "knit/macro/newton.hpp"

#include <Eigen/LU>
#include <Eigen/SparseLU>
#include <chrono>
#include <cmath>
#include <sstream>

namespace knit::macro {

namespace {

struct LinearSolve {
  bool ok = false;
  std::string why;
  Eigen::VectorXd x;
};

/// Solves Z^T K Z x = b from the element tangents.
LinearSolve solve_reduced(const ShellModel& m, const DofMap& dofs, const ShellModel::Evaluation& ev,
                          const Eigen::VectorXd& b, int dense_limit) {
  const int n = dofs.num_free();
  LinearSolve out;
  if (n <= dense_limit) {
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
    for (int e = 0; e < m.num_elements(); ++e) {
      const Eigen::VectorXi& cp = m.element_control_points(e);
      const Eigen::MatrixXd& Ke = ev.Ke[e];
      for (int s = 0; s < Ke.cols(); ++s) {
        const int gs = dofs.free_index(3 * cp(s / 3) + s % 3);
        if (gs < 0) continue;
        for (int r = 0; r < Ke.rows(); ++r) {
          const int gr = dofs.free_index(3 * cp(r / 3) + r % 3);
          if (gr >= 0) K(gr, gs) += Ke(r, s);
        }
      }
    }
    Eigen::PartialPivLU<Eigen::MatrixXd> lu(K);
    const double rc = lu.rcond();
    if (!(rc > 1e-15)) {
      std::ostringstream o;
      o << "singular tangent stiffness (reciprocal condition number " << rc << ")";
      out.why = o.str();
      return out;
    }
    out.x = lu.solve(b);
  } else {
    std::vector<Eigen::Triplet<double>> trip;
    for (int e = 0; e < m.num_elements(); ++e) {
      const Eigen::VectorXi& cp = m.element_control_points(e);
      const Eigen::MatrixXd& Ke = ev.Ke[e];
      for (int s = 0; s < Ke.cols(); ++s) {
        const int gs = dofs.free_index(3 * cp(s / 3) + s % 3);
        if (gs < 0) continue;
        for (int r = 0; r < Ke.rows(); ++r) {
          const int gr = dofs.free_index(3 * cp(r / 3) + r % 3);
          if (gr >= 0) trip.emplace_back(gr, gs, Ke(r, s));
        }
      }
    }
    Eigen::SparseMatrix<double> K(n, n);
    K.setFromTriplets(trip.begin(), trip.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(K);
    if (lu.info() != Eigen::Success) {
      out.why = "singular tangent stiffness (sparse LU failed: " + lu.lastErrorMessage() + ")";
      return out;
    }
    out.x = lu.solve(b);
  }
  if (!out.x.allFinite()) {
    out.why = "the linear solve produced non-finite values";
    return out;
  }
  out.ok = true;
  return out;
}

struct StepOutcome {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;
  std::string why;
};

}  // namespace

RunReport solve_load_steps(const ShellModel& model, const DofMap& dofs, const Eigen::VectorXd& fext,
                           const SolverOptions& opt, const StepCallback& on_step) {
  using clock = std::chrono::steady_clock;
  RunReport report;
  const int nsteps = std::max(1, opt.steps);
  const double h_nom = 1.0 / nsteps;
  Eigen::VectorXd ufree = Eigen::VectorXd::Zero(dofs.num_free());
  const Eigen::VectorXd fext_red = dofs.reduce(fext);
  double lambda = 0.0, h = h_nom, lambda_prev = 0.0;
  Eigen::VectorXd ufree_prev = ufree;
  int cutbacks = 0, step = 0;
  ShellModel::Evaluation ev, trial;

  // Reduced residual and its reference force at (u, lam).
  auto residual = [&](const Eigen::VectorXd& uf, double lam, bool tangent,
                      ShellModel::Evaluation& e, Eigen::VectorXd& r, double& ref) {
    model.evaluate(dofs.expand(uf, lam), tangent, e);
    if (!e.ok) return false;
    r = dofs.reduce(e.fint) - lam * fext_red;
    double react = 0.0;
    for (int d = 0; d < dofs.num_dofs(); ++d)
      if (dofs.constrained(d)) react += e.fint(d) * e.fint(d);
    ref = std::max(std::abs(lam) * fext.norm(), std::sqrt(react));
    return r.allFinite();
  };

  // Newton iterations at load factor lam from uf. The residual of the accepted iterate comes
  // from the line search's trial evaluation, so the tangent is only computed when needed.
  auto newton = [&](double lam, Eigen::VectorXd& uf) {
    StepOutcome o;
    Eigen::VectorXd r, rt;
    double ref = 0.0, reft = 0.0;
    bool have_r = false;
    for (int it = 0;; ++it) {
      if (!have_r && !residual(uf, lam, false, trial, r, ref)) {
        o.why = "the configuration degenerated (zero Jacobian or non-finite strains)";
        return o;
      }
      have_r = false;
      o.residual = r.norm();
      o.iterations = it;
      if (o.residual <= opt.tolerance * ref + opt.absolute_tolerance) {
        o.converged = true;
        return o;
      }
      if (it >= opt.max_iterations) {
        std::ostringstream s;
        s << "no convergence in " << opt.max_iterations << " iterations (residual " << o.residual
          << ")";
        o.why = s.str();
        return o;
      }
      model.evaluate(dofs.expand(uf, lam), true, ev);
      LinearSolve ls = solve_reduced(model, dofs, ev, -r, opt.dense_limit);
      if (!ls.ok) {
        o.why = ls.why;
        return o;
      }
      // A correction at round-off level: the residual sits at its floor (stiff materials
      // make f_int's round-off larger than tolerance * ref), the solution is converged.
      if (it > 0 && ls.x.norm() <= opt.displacement_tolerance * uf.norm() &&
          o.residual <= 1e3 * (opt.tolerance * ref + opt.absolute_tolerance) + 1e-9 * ref) {
        uf += ls.x;
        o.converged = true;
        o.iterations = it + 1;
        return o;
      }
      double alpha = 1.0;
      const double g0 = ls.x.dot(r);
      if (residual(uf + ls.x, lam, false, trial, rt, reft)) {
        have_r = true;
        const double g1 = ls.x.dot(rt);
        if (opt.line_search && rt.norm() > o.residual && std::abs(g1) > 0.5 * std::abs(g0) &&
            g0 < 0.0) {
          // Secant iterations on g(alpha) = du . r(u + alpha du) between 0 and 1.
          double a0 = 0.0, ga0 = g0, a1 = 1.0, ga1 = g1;
          Eigen::VectorXd r1 = rt;
          double ref1 = reft;
          for (int k = 0; k < 6 && std::abs(ga1) > 0.5 * std::abs(g0); ++k) {
            double a2 = a1 - ga1 * (a1 - a0) / (ga1 - ga0);
            if (!std::isfinite(a2)) break;
            a2 = std::clamp(a2, 0.05, 1.0);
            if (!residual(uf + a2 * ls.x, lam, false, trial, rt, reft)) break;
            a0 = a1, ga0 = ga1, a1 = a2, ga1 = ls.x.dot(rt);
            r1 = rt;
            ref1 = reft;
          }
          alpha = a1;
          rt = r1;
          reft = ref1;
        }
        r = rt;
        ref = reft;
      } else if (opt.line_search) {
        alpha = 0.5;  // the full step degenerated the geometry: take half of it
      }
      uf += alpha * ls.x;
    }
  };

  while (lambda < 1.0 - 1e-12) {
    const double next_nominal = std::min(1.0, h_nom * std::floor(lambda / h_nom + 1.0 + 1e-9));
    const double lam1 = std::min(lambda + h, next_nominal);
    const auto t0 = clock::now();
    // Secant predictor: extrapolate the last converged increment.
    Eigen::VectorXd uf = ufree;
    if (step > 0 && lambda > lambda_prev)
      uf += ((lam1 - lambda) / (lambda - lambda_prev)) * (ufree - ufree_prev);
    StepOutcome o = newton(lam1, uf);
    if (!o.converged && step > 0) {  // retry from the last converged state without the predictor
      uf = ufree;
      o = newton(lam1, uf);
    }
    if (o.converged) {
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
      sr.seconds = std::chrono::duration<double>(clock::now() - t0).count();
      sr.u = dofs.expand(ufree, lambda);
      model.evaluate(sr.u, false, trial);
      sr.fint = trial.fint;
      report.converged_steps = step;
      report.last_lambda = lambda;
      if (on_step) on_step(sr);
      if (std::abs(lambda - next_nominal) < 1e-12) {
        cutbacks = 0;
        h = h_nom;
      } else {
        h = std::min(2.0 * h, h_nom);
      }
      continue;
    }
    if (++cutbacks > opt.max_cutbacks) {
      std::ostringstream s;
      s << "load step to lambda = " << lam1 << " failed after " << opt.max_cutbacks
        << " cut-backs of the increment (last "
        << "increment " << (lam1 - lambda) << "): " << o.why << "; " << step
        << " converged steps kept, last lambda = " << lambda;
      report.status = RunStatus::kNotConverged;
      report.message = s.str();
      return report;
    }
    h *= 0.5;
  }
  return report;
}

}  // namespace knit::macro
