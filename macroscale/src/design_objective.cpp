// The design objective as residuals with their Jacobian (knit/macro/design_problem.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <sstream>

#include "knit/macro/design_problem.hpp"
#include "knit/macro/design_sensitivity.hpp"

namespace knit::macro {

namespace {

/// Accumulates residuals and their Jacobian rows (over the variables).
struct Residuals {
  std::vector<double> r;
  std::vector<Eigen::RowVectorXd> rows;
  void add(double value, Eigen::RowVectorXd row) {
    r.push_back(value);
    rows.push_back(std::move(row));
  }
};

/// Chains d/d(control values) to d/d(variables): a variable moves all its control values.
Eigen::RowVectorXd to_variables(const DesignProblem& d, const Eigen::RowVectorXd& dcv) {
  Eigen::RowVectorXd out = Eigen::RowVectorXd::Zero(static_cast<Eigen::Index>(d.variables.size()));
  if (dcv.size() == 0) return out;
  Eigen::Index c = 0;
  for (std::size_t v = 0; v < d.variables.size(); ++v)
    for (std::size_t i = 0; i < d.variables[v].indices.size(); ++i, ++c)
      out(static_cast<Eigen::Index>(v)) += dcv(c);
  return out;
}

/// Sample points of a strain term: a uniform grid over its region.
std::vector<Eigen::Vector2d> samples(const DesignObjective& o) {
  std::vector<Eigen::Vector2d> t;
  auto at = [](const Eigen::Vector2d& r, int n, int i) {
    return n == 1 ? 0.5 * (r(0) + r(1)) : r(0) + (r(1) - r(0)) * i / (n - 1);
  };
  for (int j = 0; j < o.samples_v; ++j)
    for (int i = 0; i < o.samples_u; ++i)
      t.emplace_back(at(o.u_range, o.samples_u, i), at(o.v_range, o.samples_v, j));
  return t;
}

/// Second differences of the designed fields' control values along u and v, over their
/// Greville abscissae (smoothness_weights), so that a linear grading is free.
void smoothness(const DesignProblem& d, const std::vector<double>& x, Residuals& res) {
  const double s = std::sqrt(d.smoothness);
  const auto nv = static_cast<Eigen::Index>(d.variables.size());
  for (const DesignFieldGrid& g : d.fields) {
    std::vector<double> v = g.values;
    std::vector<int> owner(v.size(), -1);  // the variable of each control value
    for (std::size_t k = 0; k < d.variables.size(); ++k)
      if (d.variables[k].field == g.field)
        for (int i : d.variables[k].indices) {
          v[static_cast<std::size_t>(i)] = x[k];
          owner[static_cast<std::size_t>(i)] = static_cast<int>(k);
        }
    auto term = [&](int a, int b, int c, const std::vector<double>& gr, int i) {
      const auto at = [&](int k) { return gr[static_cast<std::size_t>(k)]; };
      const auto n = static_cast<int>(gr.size());
      const auto w =
          smoothness_weights(at(i - 1), at(i), at(i + 1), (gr.back() - gr.front()) / double(n - 1));
      if (!w) return;  // a jump the knots put in: the field's own, not penalized
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(nv);
      const int idx[3] = {a, b, c};
      double r = 0.0;
      for (int k = 0; k < 3; ++k) {
        r += (*w)[static_cast<std::size_t>(k)] * v[static_cast<std::size_t>(idx[k])];
        if (owner[static_cast<std::size_t>(idx[k])] >= 0)
          row(owner[static_cast<std::size_t>(idx[k])]) += s * (*w)[static_cast<std::size_t>(k)];
      }
      if (row.cwiseAbs().maxCoeff() > 0.0) res.add(s * r, row);
    };
    for (int j = 0; j < g.nv; ++j)
      for (int i = 1; i + 1 < g.nu; ++i)
        term(j * g.nu + i - 1, j * g.nu + i, j * g.nu + i + 1, g.greville_u, i);
    for (int i = 0; i < g.nu; ++i)
      for (int j = 1; j + 1 < g.nv; ++j)
        term((j - 1) * g.nu + i, j * g.nu + i, (j + 1) * g.nu + i, g.greville_v, j);
  }
}

}  // namespace

std::optional<std::array<double, 3>> smoothness_weights(double ga, double gb, double gc, double h) {
  const double h1 = gb - ga, h2 = gc - gb;
  // Abscissae closer than 1e-9 of the mean spacing: a repeated knot, i.e. a jump.
  if (!(h1 > 1e-9 * h && h2 > 1e-9 * h)) return std::nullopt;
  // The divided second difference 2 [(v_c - v_b) / h2 - (v_b - v_a) / h1] / (h1 + h2), times
  // h^2: exact for quadratics, 0 for linear values, (1, -2, 1) at uniform spacing h.
  const double k = 2.0 * h * h / (h1 + h2);
  return std::array<double, 3>{k / h1, -k / h1 - k / h2, k / h2};
}

DesignEvaluation evaluate_design(const DesignProblem& d, const std::vector<double>& x,
                                 bool with_gradient) {
  DesignEvaluation out;
  const auto vars = d.expanded();
  std::vector<double> values;
  for (std::size_t k = 0; k < d.variables.size(); ++k)
    for (std::size_t i = 0; i < d.variables[k].indices.size(); ++i) values.push_back(x.at(k));
  const std::string text = case_text_with_design(d.c.text, d.case_file, vars, values);
  // The load factors of every objective: lambda = eps L / Delta_1.
  const double delta1 = d.c.output.applied ? d.c.output.applied->value : 0.0;
  auto lambda_of = [&](double eps) { return eps * d.c.output.applied->gauge_length / delta1; };
  std::vector<double> levels;
  for (const auto& o : d.objectives)
    for (double e : o.at_strain)
      if (std::find(levels.begin(), levels.end(), lambda_of(e)) == levels.end())
        levels.push_back(lambda_of(e));
  const DesignSolve s(text, d.case_file, vars, levels, with_gradient);
  out.forward_seconds = s.forward_seconds();
  out.gradient_seconds = s.sensitivity_seconds();
  if (s.status() != RunStatus::kCompleted) {
    out.status = s.status();
    out.message = s.message();
    return out;
  }
  Residuals res;
  out.reached.resize(d.objectives.size());
  for (std::size_t oi = 0; oi < d.objectives.size(); ++oi) {
    const DesignObjective& o = d.objectives[oi];
    const std::size_t first = res.r.size();
    const double w = std::sqrt(o.weight);
    if (o.kind == DesignObjective::Kind::kReactionLinearity) {
      const ReactionOutput& ro = d.c.output.reactions[static_cast<std::size_t>(o.reaction)];
      const double eK = o.at_strain.back();
      const Sensitive end = s.reaction(s.level(lambda_of(eK)), ro);
      for (std::size_t k = 0; k + 1 < o.at_strain.size(); ++k) {
        const Sensitive q = s.reaction(s.level(lambda_of(o.at_strain[k])), ro);
        const double t = o.at_strain[k] / eK;
        res.add(w * (q.value - t * end.value), w * to_variables(d, q.d - t * end.d));
      }
    }
    for (std::size_t k = 0; k < o.at_strain.size(); ++k) {
      if (o.kind == DesignObjective::Kind::kReactionLinearity) break;
      const int L = s.level(lambda_of(o.at_strain[k]));
      switch (o.kind) {
        case DesignObjective::Kind::kReaction: {
          const Sensitive q =
              s.reaction(L, d.c.output.reactions[static_cast<std::size_t>(o.reaction)]);
          res.add(w * (q.value - o.target[k]), w * to_variables(d, q.d));
          out.reached[oi].push_back(q.value);
          break;
        }
        case DesignObjective::Kind::kDisplacement: {
          const Sensitive q = s.displacement(
              L, d.c.output.points[static_cast<std::size_t>(o.point)].at, o.component);
          res.add(w * (q.value - o.target[k]), w * to_variables(d, q.d));
          out.reached[oi].push_back(q.value);
          break;
        }
        case DesignObjective::Kind::kStrainVariance:
        case DesignObjective::Kind::kTargetStrain: {
          const auto pts = samples(o);
          const double n = static_cast<double>(pts.size()), wn = std::sqrt(o.weight / n);
          std::vector<double> E;
          std::vector<Eigen::RowVectorXd> dE;
          for (const auto& t : pts) {
            const Sensitive q = s.strain(L, t, o.component);
            E.push_back(q.value);
            dE.push_back(to_variables(d, q.d));
          }
          double ref = o.kind == DesignObjective::Kind::kTargetStrain ? o.target[k] : 0.0;
          Eigen::RowVectorXd dref = Eigen::RowVectorXd::Zero(dE[0].size());
          if (o.kind == DesignObjective::Kind::kStrainVariance) {
            for (std::size_t i = 0; i < E.size(); ++i) {
              ref += E[i] / n;
              dref += dE[i] / n;
            }
          }
          for (std::size_t i = 0; i < E.size(); ++i)
            res.add(wn * (E[i] - ref), wn * (dE[i] - dref));
          // What summary.txt reports (session 40's walkthrough: the region means had to be
          // worked out from results.h5): the mean over the samples, or their spread.
          double mean = 0.0, spread = 0.0;
          for (double e : E) mean += e / n;
          for (double e : E) spread += (e - mean) * (e - mean) / n;
          out.reached[oi].push_back(
              o.kind == DesignObjective::Kind::kTargetStrain ? mean : std::sqrt(spread));
          break;
        }
        case DesignObjective::Kind::kReactionLinearity:
          break;
      }
    }
    double term = 0.0;
    for (std::size_t i = first; i < res.r.size(); ++i) term += res.r[i] * res.r[i];
    out.terms.emplace_back(o.name, term);
  }
  if (d.smoothness > 0.0) {
    const std::size_t first = res.r.size();
    smoothness(d, x, res);
    double term = 0.0;
    for (std::size_t i = first; i < res.r.size(); ++i) term += res.r[i] * res.r[i];
    out.terms.emplace_back("smoothness", term);
  }
  const auto m = static_cast<Eigen::Index>(res.r.size());
  const auto n = static_cast<Eigen::Index>(d.variables.size());
  out.residuals = Eigen::Map<const Eigen::VectorXd>(res.r.data(), m);
  out.J = out.residuals.squaredNorm();
  if (with_gradient) {
    out.jacobian.resize(m, n);
    for (Eigen::Index i = 0; i < m; ++i)
      out.jacobian.row(i) = res.rows[static_cast<std::size_t>(i)];
    out.gradient = 2.0 * out.jacobian.transpose() * out.residuals;
  }
  for (double r : res.r)
    if (!std::isfinite(r)) {
      out.status = RunStatus::kNotConverged;
      out.message = "a residual is not finite";
    }
  return out;
}

std::vector<std::string> final_run_step_notes(const DesignProblem& d) {
  std::vector<std::string> notes;
  if (!d.c.output.applied || d.c.output.applied->value == 0.0) return notes;
  const double L = d.c.output.applied->gauge_length, delta = d.c.output.applied->value;
  const int steps = std::max(1, d.c.solver.steps), every = std::max(1, d.c.output.every);
  const double per_step = delta / L / steps;  // strain of one nominal step, with its sign
  std::vector<double> seen;
  for (const auto& o : d.objectives)
    for (double e : o.at_strain) {
      if (std::find(seen.begin(), seen.end(), e) != seen.end()) continue;
      seen.push_back(e);
      const double k = e * L / delta * steps;  // the step index at this strain
      const double nearest = std::round(k);
      std::ostringstream s;
      s.precision(6);
      if (std::abs(k - nearest) > 1e-9 * std::max(1.0, std::abs(k))) {
        const double below = std::floor(k) * per_step, above = std::ceil(k) * per_step;
        s << "the final run (run/) has no step at strain " << e << " of " << o.name << ": its "
          << steps << " steps lie every " << per_step << " of strain (nearest " << below << " and "
          << above << "); what the design reached there was solved at " << e << " itself";
        const double lambda = e * L / delta;  // the smallest step count with a step there
        for (int q = 1; q <= 1000; ++q)
          if (std::abs(lambda * q - std::round(lambda * q)) <= 1e-9 * q) {
            s << "; a step count (/solver/steps of the case) that is a multiple of " << q
              << " has one";
            break;
          }
        notes.push_back(s.str());
      } else if (static_cast<long>(nearest) % every != 0 && static_cast<long>(nearest) != steps) {
        // Counted in nominal steps: a cut-back adds converged sub-steps and moves the count of
        // /output/every (the session's review), so the note says which count it assumes.
        s << "the final run (run/) writes its fields only every " << every
          << " converged steps and at the last (/output/every): strain " << e << " of " << o.name
          << " is its nominal step " << static_cast<long>(nearest)
          << ", which gets none unless a cut-back shifted the count; its row is in "
             "run/load_strain.csv";
        notes.push_back(s.str());
      }
    }
  return notes;
}

}  // namespace knit::macro
