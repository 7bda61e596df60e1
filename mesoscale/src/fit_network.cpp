// Fit of the network family of the energy-based law (knit/material/convex_network.hpp) with
// Ceres' L-BFGS (ceres::GradientProblemSolver). Ceres is included in the fit files only.
//
// Unknowns: phi_j, one vector per loop length l_j of the database (the knots of theta(l)); the
// weights that must stay nonnegative (V, w, w1) are phi^2 (so any phi gives a convex law), the
// others are phi itself. Scaled variables: x = e / sE, t = (S - floor e) / sS (the network is
// fitted in these and converted to mm/MPa units at the end). Objective:
//
//   f = 1/(3 sum w) sum_p w_p |S_W(x_p; theta_j(p)) - t_p|^2
//       + l_coupling / n_theta sum_j |phi_j+1 - phi_j|^2
//       + tube_weight / (3 n) sum_p m_p sum_c max(0, |S_W,c - t_p,c| - tau_p)^2,
//
// the last term only with a tube (EnergyFitOptions::tube > 0; tau_p = tube x the loop length's
// stress range / sS, on the uniaxial states at most tube_uniaxial x |own axial stress| / sS;
// m_p = tube_uniaxial_weight on the uniaxial states, 1 on the others). With the softness prior
// (prior_points > 0) the sums also run over its states (target t = 0, no tube: m_p = 0), and
// both n and sum w count them (the tube fits with the prior in docs/law-experiments.md were
// measured so).
// S_W the stress of the mirror-averaged, normalized law (S(0) = 0). With the exponential outer
// function (option outer "exp", session 15) the law is built from exp(N) instead of N:
// S_W = 1/2 (g'(N(x)) S_N(x) + M g'(N(Mx)) S_N(Mx)) - g'(N(0)) S_N0, and the gradient adds
// g''(N) (g . S_N) dN/dtheta (network_value_gradient) to g'(N) d(g . S_N)/dtheta. The gradient is
// exact (network_stress_gradient, reverse mode by hand, checked against finite differences in
// tests/common/test_material_convex_network.cpp); each objective evaluation costs about three
// network passes per point. The initial phi is drawn from a seeded normal distribution (same for
// every knot, so the knots start coupled), with positive first-layer biases so that the smoothed
// ReLUs start in their curved or linear part.
//
// Threads (EnergyFitOptions::threads, session 18): each loop length's points go to one thread,
// in their order, and write only that knot's gradient block; the objective's terms are stored
// per point and summed afterwards in the serial order. So every thread count gives the same
// floating-point operations in the same order: the fitted law is the same to the last bit.
#include <ceres/ceres.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <random>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include "fit_energy_data.hpp"
#include "knit/material/convex_network.hpp"

namespace knit::meso::fit::detail {

namespace {

using material::NetworkShape;

/// Runs `item(i)` for i = 0 .. count - 1 on up to `threads` threads (this one included), each
/// thread taking the next item in turn. A thread that cannot be created leaves its items to the
/// others; what an item computes does not depend on which thread runs it.
template <class Item>
void for_each_on_threads(int count, int threads, const Item& item) {
  std::atomic<int> next{0};
  const auto work = [&] {
    for (int i = next++; i < count; i = next++) item(i);
  };
  std::vector<std::thread> pool;
  try {
    for (int t = 1; t < std::min(threads, count); ++t) pool.emplace_back(work);
  } catch (const std::system_error&) {
    // No more threads to be had: the ones started (and this one) do every item.
  }
  work();
  for (std::thread& t : pool) t.join();
}

/// theta of all n knots from phi (squares where nonnegative).
void phi_to_theta(const NetworkShape& sh, int n, const double* phi, double* theta) {
  const int P = sh.size();
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < P; ++k) {
      const double v = phi[j * P + k];
      theta[j * P + k] = sh.nonnegative(k) ? v * v : v;
    }
}

class NetworkObjective : public ceres::FirstOrderFunction {
 public:
  NetworkObjective(NetworkShape shape, int knots, std::vector<Eigen::Vector3d> x,
                   std::vector<Eigen::Vector3d> t, std::vector<double> w, std::vector<int> knot,
                   double coupling, std::vector<double> tube, std::vector<double> tube_scale,
                   double tube_weight, int threads)
      : sh_(shape),
        n_(knots),
        x_(std::move(x)),
        t_(std::move(t)),
        w_(std::move(w)),
        knot_(std::move(knot)),
        coupling_(coupling),
        tube_(std::move(tube)),
        tube_scale_(std::move(tube_scale)),
        tube_weight_(tube_weight / (3.0 * static_cast<double>(x_.size()))),
        theta_(static_cast<std::size_t>(knots * shape.size())),
        gtheta_(theta_.size()),
        terms_(4 * x_.size()),
        points_of_knot_(static_cast<std::size_t>(knots)),
        threads_(std::max(1, std::min(threads, knots))) {
    double sum = 0.0;
    for (double v : w_) sum += v;
    scale_ = 1.0 / (3.0 * sum);
    for (std::size_t p = 0; p < x_.size(); ++p)
      points_of_knot_[static_cast<std::size_t>(knot_[p])].push_back(p);
  }
  int NumParameters() const override { return n_ * sh_.size(); }

  void to_theta(const double* phi, double* theta) const { phi_to_theta(sh_, n_, phi, theta); }

  bool Evaluate(const double* phi, double* cost, double* grad) const override {
    const int P = sh_.size();
    const bool outer = sh_.outer != 0;
    to_theta(phi, theta_.data());
    std::fill(gtheta_.begin(), gtheta_.end(), 0.0);
    double f = 0.0;
    // Per knot at e = 0: N0, S_N0 and (outer) g'(N0), g''(N0); S0 the normalization's stress.
    std::vector<Eigen::Vector3d> S0(static_cast<std::size_t>(n_)), G0(static_cast<std::size_t>(n_)),
        SN0(static_cast<std::size_t>(n_));
    std::vector<double> dg0(static_cast<std::size_t>(n_), 1.0), ddg0(static_cast<std::size_t>(n_));
    for (int j = 0; j < n_; ++j) {
      const auto J = static_cast<std::size_t>(j);
      const material::NetworkResponse r0 =
          material::network_evaluate(sh_, theta_.data() + j * P, Eigen::Vector3d::Zero(), false);
      SN0[J] = r0.S;
      if (outer) {
        double g;
        material::network_outer(r0.W, sh_.outer_cap, g, dg0[J], ddg0[J]);
      }
      S0[J] = dg0[J] * Eigen::Vector3d(r0.S(0), r0.S(1), 0.0);
      G0[J].setZero();
    }
    // One knot's points, in their order (see the file comment): terms_ gets each point's
    // addends to f (0 where a term is absent: f + 0 = f exactly), gtheta_ and G0 that knot's
    // blocks only.
    const auto knot_terms = [&](int j) {
      const double* th = theta_.data() + j * P;
      material::NetworkForward fa, fb;  // each pass's activations, once per point
      for (std::size_t p : points_of_knot_[static_cast<std::size_t>(j)]) {
        double* term = terms_.data() + 4 * p;
        const Eigen::Vector3d& x = x_[p];
        const Eigen::Vector3d mx(x(0), x(1), -x(2));
        material::network_forward(sh_, th, x, fa);
        material::network_forward(sh_, th, mx, fb);
        const material::NetworkResponse ra = material::network_evaluate(sh_, th, x, fa, false);
        const material::NetworkResponse rb = material::network_evaluate(sh_, th, mx, fb, false);
        // The outer function's slopes (1 and 0 without it): S_G = g'(N) S_N.
        double ga = 0.0, dga = 1.0, ddga = 0.0, dgb = 1.0, ddgb = 0.0;
        if (outer) {
          material::network_outer(ra.W, sh_.outer_cap, ga, dga, ddga);
          material::network_outer(rb.W, sh_.outer_cap, ga, dgb, ddgb);
        }
        const Eigen::Vector3d sa = dga * ra.S, sb = dgb * rb.S;
        const Eigen::Vector3d s = 0.5 * (sa + Eigen::Vector3d(sb(0), sb(1), -sb(2))) -
                                  S0[static_cast<std::size_t>(j)] - t_[p];
        term[0] = scale_ * w_[p] * s.squaredNorm();
        // The tube: each component's excess over tau_p, squared (C1), unweighted.
        Eigen::Vector3d gt_tube = Eigen::Vector3d::Zero();
        for (int c = 0; c < 3; ++c) term[1 + c] = 0.0;
        if (tube_weight_ > 0.0)
          for (int c = 0; c < 3; ++c) {
            const double ex = std::abs(s(c)) - tube_[p];
            if (ex <= 0.0) continue;
            const double tw = tube_weight_ * tube_scale_[p];
            term[1 + c] = tw * ex * ex;
            gt_tube(c) = 2.0 * tw * ex * (s(c) < 0.0 ? -1.0 : 1.0);
          }
        if (!grad) continue;
        const Eigen::Vector3d g = (2.0 * scale_ * w_[p]) * s + gt_tube;  // d f / d S_W
        const Eigen::Vector3d mg(g(0), g(1), -g(2));
        double* gt = gtheta_.data() + j * P;
        // d(g . g'(N) S_N) = g'(N) d(g . S_N) + g''(N) (g . S_N) dN.
        material::network_stress_gradient(sh_, th, x, fa, 0.5 * dga * g, gt);
        material::network_stress_gradient(sh_, th, mx, fb, 0.5 * dgb * mg, gt);
        if (outer) {
          material::network_value_gradient(sh_, th, x, fa, 0.5 * ddga * g.dot(ra.S), gt);
          material::network_value_gradient(sh_, th, mx, fb, 0.5 * ddgb * mg.dot(rb.S), gt);
        }
        G0[static_cast<std::size_t>(j)] -= Eigen::Vector3d(g(0), g(1), 0.0);
      }
    };
    if (threads_ == 1) {
      for (int j = 0; j < n_; ++j) knot_terms(j);
    } else {
      for_each_on_threads(n_, threads_, knot_terms);  // the same result (the file comment)
    }
    for (double v : terms_) f += v;  // the serial order: point by point, term by term
    if (grad) {
      for (int j = 0; j < n_; ++j) {
        const auto J = static_cast<std::size_t>(j);
        material::network_stress_gradient(sh_, theta_.data() + j * P, Eigen::Vector3d::Zero(),
                                          dg0[J] * G0[J], gtheta_.data() + j * P);
        if (outer)
          material::network_value_gradient(sh_, theta_.data() + j * P, Eigen::Vector3d::Zero(),
                                           ddg0[J] * G0[J].dot(SN0[J]), gtheta_.data() + j * P);
      }
      for (int j = 0; j < n_; ++j)
        for (int k = 0; k < P; ++k) {
          const int i = j * P + k;
          grad[i] = sh_.nonnegative(k) ? 2.0 * phi[i] * gtheta_[static_cast<std::size_t>(i)]
                                       : gtheta_[static_cast<std::size_t>(i)];
        }
    }
    const double c = coupling_ / P;
    for (int j = 0; j + 1 < n_; ++j)
      for (int k = 0; k < P; ++k) {
        const double d = phi[(j + 1) * P + k] - phi[j * P + k];
        f += c * d * d;
        if (grad) {
          grad[(j + 1) * P + k] += 2.0 * c * d;
          grad[j * P + k] -= 2.0 * c * d;
        }
      }
    *cost = f;
    return std::isfinite(f);
  }

 private:
  NetworkShape sh_;
  int n_;
  std::vector<Eigen::Vector3d> x_, t_;
  std::vector<double> w_;
  std::vector<int> knot_;
  double coupling_;
  std::vector<double> tube_;        // tau per point, scaled stress units
  std::vector<double> tube_scale_;  // the tube penalty's weight per point, x tube_weight
  double tube_weight_;
  double scale_ = 1.0;
  mutable std::vector<double> theta_, gtheta_;
  mutable std::vector<double> terms_;                     // 4 addends to f per point
  std::vector<std::vector<std::size_t>> points_of_knot_;  // each knot's points, in order
  int threads_;
};

/// Initial phi of one knot (see the file comment).
std::vector<double> initial_phi(const NetworkShape& sh, int seed) {
  std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<double> phi(static_cast<std::size_t>(sh.size()));
  auto at = [&](int k) -> double& { return phi[static_cast<std::size_t>(k)]; };
  for (int k = 0; k < 3 * sh.h1; ++k) at(sh.a0() + k) = n01(rng);
  for (int k = 0; k < sh.h1; ++k) at(sh.b0() + k) = 0.5 + 0.5 * n01(rng);
  for (int k = 0; k < sh.h1; ++k) at(sh.w1() + k) = 0.5 + 0.1 * n01(rng);
  for (int k = 0; k < sh.h2 * sh.h1; ++k) at(sh.V() + k) = 0.45 + 0.1 * n01(rng);
  for (int k = 0; k < 3 * sh.h2; ++k) at(sh.a1() + k) = n01(rng);
  for (int k = 0; k < sh.h2; ++k) at(sh.b1() + k) = 0.5 * n01(rng);
  for (int k = 0; k < sh.h2; ++k) at(sh.w() + k) = 0.55 + 0.1 * n01(rng);
  for (int k = 0; k < 9; ++k) at(sh.L() + k) = (k % 4 == 0) ? 0.3 : 0.0;
  // With the exponential outer function the output weights start 16 times smaller (phi / 4),
  // so that exp(N) starts near the data's scale: from the draw above, with seed 2, L-BFGS
  // stopped after 3 iterations on the default database (docs/database.md).
  if (sh.outer != 0) {
    for (int k = 0; k < sh.h1; ++k) at(sh.w1() + k) *= 0.25;
    for (int k = 0; k < sh.h2; ++k) at(sh.w() + k) *= 0.25;
    for (int k = 0; k < 9; ++k) at(sh.L() + k) *= 0.25;
  }
  return phi;
}

/// One line of progress every `every` seconds of L-BFGS (EnergyFitOptions::progress): the
/// iteration, the objective and the time so far; `what` is put before "L-BFGS" (which start).
class ProgressLines : public ceres::IterationCallback {
 public:
  ProgressLines(std::FILE* out, int iterations, double every, std::string what = {})
      : out_(out),
        iterations_(iterations),
        every_(every),
        what_(std::move(what)),
        start_(std::chrono::steady_clock::now()),
        last_(start_) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    const auto now = std::chrono::steady_clock::now();
    if (out_ && std::chrono::duration<double>(now - last_).count() >= every_) {
      last_ = now;
      std::fprintf(
          out_, "energy fit: %sL-BFGS iteration %d of %d (%.0f %%), objective %.6g, %.0f s\n",
          what_.c_str(), s.iteration, iterations_, 100.0 * s.iteration / std::max(1, iterations_),
          s.cost, std::chrono::duration<double>(now - start_).count());
      std::fflush(out_);
    }
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::FILE* out_;
  int iterations_;
  double every_;
  std::string what_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace

std::string fit_network(material::EnergyLawData& law, const std::vector<double>& loop_lengths,
                        const std::vector<Point>& pts, const std::vector<double>& weight, double sS,
                        double sE, const EnergyFitOptions& o, int& iterations,
                        double& objective_value, int& best_seed) {
  NetworkShape sh;
  sh.h1 = o.hidden1;
  sh.h2 = o.hidden2;
  sh.stiff1 = o.stiff1;
  sh.stiff2 = o.stiff2;
  sh.outer = o.outer == "exp" ? 1 : 0;
  if (const std::string why = sh.validate(); !why.empty()) return "invalid options: " + why;
  const int n = static_cast<int>(loop_lengths.size()), P = sh.size();
  std::vector<Eigen::Vector3d> x, t;
  std::vector<int> knot;
  for (const Point& p : pts) {
    x.push_back(p.e / sE);
    t.push_back((p.S - law.floor * p.e) / sS);
    knot.push_back(static_cast<int>(p.loop));
  }
  // Each knot's stress range (stress_ranges: the diagnostics' range), scaled; the tube's
  // half-width tau_p is `tube` times it.
  std::vector<double> range = stress_ranges(pts, static_cast<std::size_t>(n));
  for (double& r : range) r /= sS;
  std::vector<double> tube_of_point, tube_scale;
  for (const Point& p : pts) {
    double tau = o.tube * range[p.loop];
    if (p.axis >= 0 && o.tube_uniaxial >= 0.0)
      tau = std::min(tau, o.tube_uniaxial * std::abs(p.S(p.axis)) / sS);
    tube_of_point.push_back(tau);
    tube_scale.push_back(p.axis >= 0 ? o.tube_uniaxial_weight : 1.0);
  }
  // The softness prior: per knot, prior_points states of a Kronecker sequence (additive
  // recurrence with the generalized golden ratio of dimension 3) in the box of that knot's fit
  // data, target S_W = 0 (S = floor e), prior_weight x the mean data weight, outside the tube.
  std::vector<double> w = weight;
  if (o.prior_points > 0 && o.prior_weight > 0.0) {
    double mean_w = 0.0;
    for (double v : weight) mean_w += v;
    mean_w /= static_cast<double>(std::max<std::size_t>(1, weight.size()));
    const double g = 1.2207440846057596;  // x^4 = x + 1
    const Eigen::Vector3d alpha(1.0 / g, 1.0 / (g * g), 1.0 / (g * g * g));
    for (int j = 0; j < n; ++j) {
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
      for (std::size_t p = 0; p < pts.size(); ++p)
        if (knot[p] == j) {
          lo = lo.cwiseMin(x[p]);
          hi = hi.cwiseMax(x[p]);
        }
      if (!(lo.array() <= hi.array()).all()) continue;
      for (int k = 1; k <= o.prior_points; ++k) {
        Eigen::Vector3d u = (0.5 + k * alpha.array()).matrix();
        for (int c = 0; c < 3; ++c) u(c) -= std::floor(u(c));
        x.push_back(lo + u.cwiseProduct(hi - lo));
        t.push_back(Eigen::Vector3d::Zero());
        knot.push_back(j);
        w.push_back(o.prior_weight * mean_w);
        tube_of_point.push_back(1e300);
        tube_scale.push_back(0.0);
      }
    }
  }
  const int threads = o.threads > 0
                          ? o.threads
                          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  ceres::GradientProblemSolver::Options so;
  so.line_search_direction_type = ceres::LBFGS;
  so.max_lbfgs_rank = 50;
  so.max_num_iterations = o.network_iterations;
  so.function_tolerance = 1e-14;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-14;
  so.logging_type = ceres::SILENT;

  // Multi-start (EnergyFitOptions::starts, session 57): L-BFGS from the draws of seeds seed,
  // seed + 1, ..., seed + starts - 1, the one with the smallest final objective kept (ties: the
  // smaller seed). The objective is non-convex and its end point chaotic (docs/law-experiments.md,
  // "The end point is chaotic"), so a single start decides the law's largest error by chance;
  // the choice looks at the fit data's objective only, never at the held-out states. One start
  // spreads its loop lengths over the threads; several run side by side, one thread each or more
  // when there are more threads than starts (each with its own objective and scratch). Either way a
  // start's floating-point operations are the same for every thread count (the file comment), so
  // the kept law is too.
  struct Start {
    std::vector<double> phi;
    double cost = 0.0;
    int iterations = 0;
    std::string error;
  };
  std::vector<Start> starts(static_cast<std::size_t>(o.starts));
  const auto start_clock = std::chrono::steady_clock::now();
  std::mutex report_mutex;
  auto run_start = [&](int s, int start_threads, bool lines) {
    Start& r = starts[static_cast<std::size_t>(s)];
    const int seed = o.seed + s;
    try {
      auto* objective =
          new NetworkObjective(sh, n, x, t, w, knot, o.l_coupling, tube_of_point, tube_scale,
                               o.tube > 0.0 ? o.tube_weight : 0.0, start_threads);
      ceres::GradientProblem problem(objective);  // takes ownership
      ceres::GradientProblemSolver::Options start_options = so;
      ProgressLines progress(o.progress, o.network_iterations, o.progress_seconds,
                             o.starts > 1 ? "start " + std::to_string(s + 1) + " of " +
                                                std::to_string(o.starts) +
                                                " (the others beside "
                                                "it), "
                                          : std::string());
      if (o.progress && lines) start_options.callbacks.push_back(&progress);
      const std::vector<double> phi0 = initial_phi(sh, seed);
      r.phi.assign(static_cast<std::size_t>(n * P), 0.0);
      for (int j = 0; j < n; ++j) std::copy(phi0.begin(), phi0.end(), r.phi.begin() + j * P);
      ceres::GradientProblemSolver::Summary summary;
      ceres::Solve(start_options, problem, r.phi.data(), &summary);
      r.iterations = static_cast<int>(summary.iterations.size());
      r.cost = summary.final_cost;
      if (!summary.IsSolutionUsable() || !std::isfinite(summary.final_cost))
        r.error = "Ceres (L-BFGS): " + summary.message;
    } catch (const std::exception& e) {
      r.error = e.what();
    }
    if (o.progress && o.starts > 1) {
      const std::lock_guard<std::mutex> lock(report_mutex);
      std::fprintf(
          o.progress, "energy fit: start %d of %d (seed %d) %s %.9g, %.0f s\n", s + 1, o.starts,
          seed, r.error.empty() ? "ended at objective" : "failed:", r.error.empty() ? r.cost : 0.0,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_clock).count());
      std::fflush(o.progress);
    }
  };
  if (o.starts == 1) {
    run_start(0, threads, true);
  } else {
    // As many starts side by side as there are threads; more threads than starts go to the
    // starts' loop lengths.
    const int workers = std::min(threads, o.starts), per_start = std::max(1, threads / workers);
    // Start 0 (the first taken) reports its L-BFGS progress as a single start does.
    for_each_on_threads(o.starts, workers, [&](int s) { run_start(s, per_start, s == 0); });
  }
  int kept = -1;
  for (int s = 0; s < o.starts; ++s) {
    const Start& r = starts[static_cast<std::size_t>(s)];
    iterations += r.iterations;
    if (!r.error.empty())
      return o.starts == 1 ? r.error
                           : "start " + std::to_string(s + 1) + " of " + std::to_string(o.starts) +
                                 " (seed " + std::to_string(o.seed + s) + "): " + r.error;
    if (kept < 0 || r.cost < starts[static_cast<std::size_t>(kept)].cost) kept = s;
  }
  std::vector<double> phi = std::move(starts[static_cast<std::size_t>(kept)].phi);
  objective_value = starts[static_cast<std::size_t>(kept)].cost;
  best_seed = o.seed + kept;

  // theta in scaled variables -> mm / MPa: N(e) = sS sE N^(e / sE) without an outer function;
  // with it G(e) = sS sE g(N^(e / sE)), so N's output weights keep their values, outer_scale =
  // sS sE, and the cap is set one unit above the largest N over the fit data (the stored law
  // equals the fitted one there; beyond, g continues quadratically).
  std::vector<double> theta(phi.size());
  phi_to_theta(sh, n, phi.data(), theta.data());
  if (sh.outer != 0) {
    double n_max = -1e300;  // over the fit data and e = 0 (the normalization's point)
    for (int j = 0; j < n; ++j)
      n_max = std::max(
          n_max,
          material::network_evaluate(sh, theta.data() + j * P, Eigen::Vector3d::Zero(), false).W);
    for (std::size_t p = 0; p < pts.size(); ++p) {
      const double* th = theta.data() + static_cast<int>(pts[p].loop) * P;
      const Eigen::Vector3d xp = pts[p].e / sE, mp(xp(0), xp(1), -xp(2));
      n_max = std::max({n_max, material::network_evaluate(sh, th, xp, false).W,
                        material::network_evaluate(sh, th, mp, false).W});
    }
    sh.outer_scale = sS * sE;
    sh.outer_cap = std::min(n_max + 1.0, sh.outer_cap);
  }
  law.network.shape = sh;
  law.network.l_knots = loop_lengths;
  law.network.l_interpolation = o.l_interpolation == "energy"
                                    ? material::LInterpolation::kEnergy
                                    : material::LInterpolation::kParameters;
  law.network.l_blend = o.l_blend;
  law.network.theta.resize(n, P);
  const double wscale = sh.outer != 0 ? 1.0 : sS * sE;
  const double lscale = sh.outer != 0 ? 1.0 / sE : std::sqrt(sS / sE);
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < P; ++k) {
      double v = theta[static_cast<std::size_t>(j * P + k)];
      if ((k >= sh.a0() && k < sh.b0()) || (k >= sh.a1() && k < sh.b1())) v /= sE;
      if ((k >= sh.w1() && k < sh.V()) || (k >= sh.w() && k < sh.L())) v *= wscale;
      if (k >= sh.L()) v *= lscale;
      law.network.theta(j, k) = v;
    }
  return {};
}

}  // namespace knit::meso::fit::detail
