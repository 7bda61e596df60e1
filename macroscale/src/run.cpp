#include "knit/macro/run.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/macro/geometry_check.hpp"
#include "knit/macro/load_drop.hpp"
#include "knit/macro/output_units.hpp"
#include "results_writer.hpp"

namespace knit::macro {

std::string gauge_length_warning(const Case& c) {
  if (!c.output.applied || !c.output.applied->at_edge) return {};
  const AppliedDisplacement& a = *c.output.applied;
  const auto i = static_cast<std::size_t>(a.component);
  const Edge opposite = a.edge == Edge::kU0   ? Edge::kU1
                        : a.edge == Edge::kU1 ? Edge::kU0
                        : a.edge == Edge::kV0 ? Edge::kV1
                                              : Edge::kV0;
  bool held = false, moving = false;
  for (const BoundaryCondition& bc : c.bcs)
    if (bc.target == BoundaryCondition::Target::kEdge && bc.edge == opposite) {
      held = held || bc.fix[i] || bc.prescribe[i].has_value();
      moving = moving || (!bc.fix[i] && bc.prescribe[i].has_value() && *bc.prescribe[i] != 0.0);
    }
  if (!held) return {};
  const std::string length = unit_labels(c.units).of("mm");
  if (moving)  // (the review of session 53: two jaws pulled apart read half their strain)
    return "/output/applied_displacement: the opposite edge " + edge_name(opposite) +
           " is prescribed a displacement along " + "xyz"[i] +
           " too: the curve's strain is this edge's displacement over the gauge length and "
           "leaves the other jaw's out (two jaws pulled apart by equal amounts read half the "
           "strain between them); hold the opposite edge, or read the strain accordingly";
  // Each edge's control points: their mean, and their spread along the component.
  const Eigen::MatrixXd& P = c.surface.control_points();
  const int nu = c.surface.size_u(), nv = c.surface.size_v();
  double spread = 0.0;
  const auto mean = [&](Edge e) {
    const std::vector<int> row = edge_row(nu, nv, e, 0);
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(P.cols());
    double lo = P(row.front(), static_cast<Eigen::Index>(i)), hi = lo;
    for (int k : row) {
      sum += P.row(k).transpose();
      lo = std::min(lo, P(k, static_cast<Eigen::Index>(i)));
      hi = std::max(hi, P(k, static_cast<Eigen::Index>(i)));
    }
    spread = std::max(spread, hi - lo);
    return Eigen::VectorXd(sum / static_cast<double>(row.size()));
  };
  const Eigen::VectorXd delta = mean(a.edge) - mean(opposite);
  const double d = std::abs(delta(static_cast<Eigen::Index>(i)));
  // Judged only where the component separates the edges (at least half their offset lies
  // along it: a load along the edges, a shear, is not) and both edges are straight across it
  // (their control points spread along it by at most the tolerance of d: a curved edge's mean
  // depends on the refinement and the weights). The review of session 53: a top edge offset
  // by 2 mm and pulled along itself was told to take 2 mm as its gauge length.
  if (!(d > 0.0) || d < 0.5 * delta.norm() || spread > kGaugeJawTolerance * d ||
      std::abs(a.gauge_length - d) <= kGaugeJawTolerance * d)
    return {};
  std::ostringstream s;
  s.precision(6);
  s << "/output/applied_displacement/gauge_length: " << a.gauge_length << " " << length
    << ", but the loaded edge " << edge_name(a.edge) << " lies " << d << " " << length
    << " from the held edge " << edge_name(opposite) << " along "
    << "xyz"[i] << " (more than " << 100 * kGaugeJawTolerance
    << " % apart): the curve's strain is the applied displacement over the gauge length, here "
    << d / a.gauge_length << " times the strain between the jaws; give " << d
    << " if the jaws hold these edges";
  return s.str();
}

Problem setup_problem(const Case& c) {
  Problem p;
  ShellOptions so;
  so.integration = c.integration;
  so.threads = c.threads;
  so.extra_quadrature_points = c.extra_quadrature_points;
  try {
    p.model = std::make_unique<ShellModel>(c.surface, c.thickness, c.material, so);
  } catch (const DegenerateGeometryError& e) {
    throw InputError(c.file, "/geometry/control_points", e.what());
  }
  const ShellModel& m = *p.model;
  const int nu = c.surface.size_u(), nv = c.surface.size_v();
  Constraints con(m.num_dofs());
  // Which entry held each DOF, and how: a conflict names both entries and the control point's
  // place (session 39's walkthrough: "DOF 168 (control point 56, component x) is prescribed
  // twice" named neither the other entry nor a point the user can see).
  struct Holder {
    int bc = -1;
    double value = 0.0;
    const char* how = "";
  };
  std::vector<Holder> holder(static_cast<std::size_t>(m.num_dofs()));
  const std::string length = unit_labels(c.units).of("mm");  // the case's length symbol
  const auto where = [&](int dof) {
    std::ostringstream s;
    s.precision(6);
    const auto X = c.surface.control_points().row(dof / 3);
    s << "component "
      << "xyz"[dof % 3] << " of control point " << dof / 3 << " of the analysis "
      << "net, at (" << X(0) << ", " << X(1) << ", " << X(2) << ") " << length;
    return s.str();
  };
  for (std::size_t bi = 0; bi < c.bcs.size(); ++bi) {
    const BoundaryCondition& bc = c.bcs[bi];
    const auto hold = [&](int dof, double value, const char* how) {
      const Holder& h = holder[static_cast<std::size_t>(dof)];
      if (h.bc >= 0 && values_conflict(h.value, value)) {
        const auto what = [&](const char* verb, double v) {
          std::ostringstream w;
          w << verb;
          if (std::string(verb).find("symmetry") == std::string::npos)
            w << " (" << v << " " << length << ")";
          return w.str();
        };
        std::ostringstream s;
        s << where(dof) << ", is " << what(how, value) << " here and " << what(h.how, h.value)
          << (h.bc == static_cast<int>(bi) ? std::string(" by the same entry")
                                           : " by " + c.bcs[static_cast<std::size_t>(h.bc)].pointer)
          << ": a displacement takes one value; change one of the two";
        throw InputError(c.file, bc.pointer, s.str());
      }
      con.prescribe(dof, value);
      holder[static_cast<std::size_t>(dof)] = {static_cast<int>(bi), value, how};
    };
    try {
      std::vector<int> row0, row1;
      switch (bc.target) {
        case BoundaryCondition::Target::kEdge:
          row0 = edge_row(nu, nv, bc.edge, 0);
          row1 = edge_row(nu, nv, bc.edge, 1);
          break;
        case BoundaryCondition::Target::kCorner:
          row0 = corner_region(c.surface, bc.corner, bc.radius);
          break;
        case BoundaryCondition::Target::kAll:
          for (int a = 0; a < m.num_control_points(); ++a) row0.push_back(a);
          break;
      }
      for (int a : row0)
        for (int i = 0; i < 3; ++i) {
          if (bc.fix[i]) hold(3 * a + i, 0.0, "fixed");
          if (bc.prescribe[i]) hold(3 * a + i, *bc.prescribe[i], "prescribed");
        }
      if (bc.clamp)  // zero rotation: the second row moves with the edge row
        for (size_t k = 0; k < row0.size(); ++k)
          for (int i = 0; i < 3; ++i) con.tie(3 * row1[k] + i, 3 * row0[k] + i);
      if (bc.symmetry >=
          0) {  // u_s = 0 on the edge, the cross-edge slope stays normal to the plane
        if (const std::string why =
                symmetry_plane_problem(c.surface, row0, row1, bc.symmetry, length);
            !why.empty())
          throw InputError(c.file, bc.pointer + "/symmetry", why);
        for (size_t k = 0; k < row0.size(); ++k)
          for (int i = 0; i < 3; ++i) {
            if (i == bc.symmetry)
              hold(3 * row0[k] + i, 0.0, "held at 0 by the symmetry plane");
            else
              con.tie(3 * row1[k] + i, 3 * row0[k] + i);
          }
      }
    } catch (const ConstraintConflict& e) {
      throw InputError(c.file, bc.pointer, e.what());
    }
  }
  try {
    p.dofs = DofMap(con);
  } catch (const ConstraintConflict& e) {
    // Both members of the tied group, each with its place and the entry that holds it.
    const auto held = [&](int dof) {
      const Holder& h = holder[static_cast<std::size_t>(dof)];
      return where(dof) + (h.bc >= 0 ? ", " + std::string(h.how) + " by " +
                                           c.bcs[static_cast<std::size_t>(h.bc)].pointer
                                     : std::string());
    };
    throw InputError(c.file, "/boundary_conditions",
                     std::string(e.what()) + " (" + held(e.dof()) +
                         (e.other() >= 0 ? "; the other: " + held(e.other()) : std::string()) +
                         "; a clamp or symmetry condition ties the edge's second row to its "
                         "first)");
  }
  if (const auto mode = p.dofs.unconstrained_rigid_mode(c.surface.control_points()))
    throw InputError(c.file, "/boundary_conditions",
                     "missing support: the boundary conditions do not prevent a rigid-body " +
                         *mode + " (the tangent stiffness would be singular); add supports");
  p.fext = Eigen::VectorXd::Zero(m.num_dofs());
  for (std::size_t k = 0; k < c.loads.size(); ++k) {
    const Load& l = c.loads[k];
    Eigen::VectorXd f;
    switch (l.kind) {
      case Load::Kind::kPoint:
        f = m.point_force(l.at, l.value);
        break;
      case Load::Kind::kEdge:
        f = m.edge_force(l.edge, l.value);
        break;
      case Load::Kind::kArea:
        f = m.area_force(l.value);
        break;
    }
    // A load whose every nonzero entry sits on a fixed or prescribed DOF goes into the
    // supports, not into the patch (session 39's walkthrough: an edge load on the held edge ran
    // with exit 0, and the held edge's reaction then "dropped", which the load-drop warning
    // blamed on the material law).
    double total = 0.0, held = 0.0;
    for (Eigen::Index i = 0; i < f.size(); ++i) {
      total += std::abs(f(i));
      if (p.dofs.constrained(static_cast<int>(i))) held += std::abs(f(i));
    }
    if (total > 0.0 && held >= total * (1.0 - 1e-12))
      p.warnings.push_back("/loads/" + std::to_string(k) +
                           ": the load acts on held degrees of freedom only (fixed or prescribed "
                           "in the components it loads): the supports take it and the patch "
                           "does not feel it; load another edge, or free those components");
    p.fext += f;
  }
  if (std::string w = gauge_length_warning(c); !w.empty()) p.warnings.push_back(std::move(w));
  // One row of a clamped edge leaves out the support force its second row carries (session 46's
  // walkthrough: 5.72 N against 14.78 N for a clamped jaw, exit 0). Without "rows" a clamped
  // edge's reaction takes both (case_loader); an explicit 1 is named here.
  for (std::size_t k = 0; k < c.output.reactions.size(); ++k) {
    const ReactionOutput& ro = c.output.reactions[k];
    if (ro.at_edge && ro.rows == 1 && edge_is_clamped(c.bcs, ro.edge))
      p.warnings.push_back("/output/reactions/" + std::to_string(k) +
                           "/rows: 1 row of a clamped edge: its second row of control points, "
                           "tied to the first, carries part of the support force, which this "
                           "reaction leaves out (it can read less than half of it); give 2, or "
                           "leave rows out (a clamped edge's default)");
  }
  return p;
}

std::vector<int> reaction_points(const ShellModel& m, const ReactionOutput& r) {
  if (!r.at_edge) return corner_region(m.surface(), r.corner, r.radius);
  const int nu = m.surface().size_u(), nv = m.surface().size_v();
  std::vector<int> points;
  for (int row = 0; row < r.rows; ++row)
    for (int a : edge_row(nu, nv, r.edge, row)) points.push_back(a);
  return points;
}

double sum_over(const Eigen::VectorXd& f, const std::vector<int>& points, int component) {
  double sum = 0.0;
  for (int a : points) sum += f(3 * a + component);
  return sum;
}

std::string material_failure_message(const RunReport& report, long n) {
  if (n <= 0) return {};
  return std::string(report.status == RunStatus::kCompleted ? "completed" : "stopped") + " with " +
         std::to_string(n) + " failed material evaluation" + (n == 1 ? "" : "s") +
         "; results are not trustworthy";
}

std::string solver_fallback_message(const SolverStats& stats) {
  std::string m;
  // Who made the factorizations CHOLMOD refused: MUMPS; the SimplicialLDLT without MUMPS; both
  // when MUMPS failed after it had made some (the counts do not split them: session 38 credited
  // them all to the SimplicialLDLT).
  const bool mumps = stats.multifrontal && stats.multifrontal_failure.empty();
  const bool both = stats.multifrontal && !stats.multifrontal_failure.empty() &&
                    stats.multifrontal_factorizations > 0;
  if (!stats.supernodal_failure.empty())
    m = "the supernodal Cholesky (CHOLMOD) failed in " + stats.supernodal_failure + "; " +
        std::to_string(stats.fallback_factorizations) + " factorization" +
        (stats.fallback_factorizations == 1 ? " was" : "s were") + " made by " +
        (mumps  ? "MUMPS's multifrontal LDLT instead (the same results; "
         : both ? "MUMPS's multifrontal LDLT and, once it had failed, by Eigen's SimplicialLDLT "
                  "instead (the same results, the latter single-threaded and much slower on "
                  "large patches; "
                : "Eigen's SimplicialLDLT instead (the same results, single-threaded and much "
                  "slower on large patches; ") +
        std::to_string(stats.unknowns) + " unknowns)";
  if (!stats.multifrontal_failure.empty())
    m += std::string(m.empty() ? "" : "; ") + "the multifrontal LDLT (MUMPS) failed in " +
         stats.multifrontal_failure +
         "; the indefinite tangents from there on were factorized by Eigen's SimplicialLDLT "
         "(the same results, single-threaded and much slower on large patches; " +
         std::to_string(stats.unknowns) + " unknowns)";
  return m;
}

std::vector<std::string> run_warning_lines(const RunResult& r) {
  std::vector<std::string> out = r.input_warnings;
  out.insert(out.end(), r.load_drops.begin(), r.load_drops.end());
  if (!r.solver_warning.empty()) out.push_back(r.solver_warning);
  // The material's warning comes as lines of its own, each with "warning: ".
  std::istringstream mw(r.material_warning);
  for (std::string line; std::getline(mw, line);)
    if (!line.empty()) out.push_back(line.rfind("warning: ", 0) == 0 ? line.substr(9) : line);
  return out;
}

std::string run_failure_message(const RunResult& r) {
  std::string m;
  const auto add = [&m](const std::string& part) {
    if (part.empty()) return;
    m += (m.empty() ? "" : "; ") + part;
  };
  if (r.report.status != RunStatus::kCompleted) add(r.report.message);
  // What to change when Newton gave up (session 39's walkthrough: the paper's law stopped a
  // run at 1.6 % strain with "no convergence in 25 iterations" and no hint).
  if (r.report.reason == StopReason::kCutbacks || r.report.reason == StopReason::kIncrementFloor)
    add("to get further: more Newton iterations per step (/solver/max_iterations), more load "
        "steps (/solver/steps) or cut-backs (/solver/max_cutbacks); "
        "a material law evaluated far outside its data also stops Newton (summary.txt's "
        "\"material report\" counts the extrapolated evaluations: the paper's law extrapolates "
        "beyond its 13 load paths, the default energy law holds over the whole strain box)");
  // The LU path (a material without strain energy: the paper's law): more steps do not pass a
  // limit point of the law itself (session 43's walkthrough: an off-axis fabric stopped at
  // 0.4 % strain, and at 1.6 % with 200 steps and 50 iterations).
  if ((r.report.reason == StopReason::kCutbacks ||
       r.report.reason == StopReason::kIncrementFloor) &&
      r.report.converged_steps > 0 && r.report.max_negative_pivots < 0) {
    std::ostringstream o;
    o << "the tangent is unsymmetric (a material without strain energy, such as the paper's "
         "law: /material/law), and such a law can stop Newton where no smaller step helps";
    if (r.report.first_negative_determinant_step > 0)
      o << " (det K < 0 from step " << r.report.first_negative_determinant_step << ")";
    o << "; the energy law (/material/law \"energy\", when the database has one) has a strain "
         "energy and a symmetric tangent";
    add(o.str());
  }
  add(material_failure_message(r.report, r.failed_material_evaluations));
  add(r.output_failure);
  if (m.empty() && !r.succeeded()) m = "the run did not complete";
  return m;
}

namespace {

/// A warning when steps converged on /solver/absolute_tolerance alone, out of balance by more
/// than kLooseRelativeResidual of the reference force (RunReport::loose_steps; session 56's red
/// team: a patch loaded by 2e-9 N ran 0.6-1 % off the exact jaw force, steps accepted with no
/// iteration, exit 0 and no word). Empty when there is none.
std::string loose_convergence_warning(const Case& c, const RunReport& r) {
  if (r.loose_steps == 0) return {};
  std::string unit = unit_labels(c.units).of("N");
  if (unit.rfind("in ", 0) != 0) unit = "in " + unit;
  std::ostringstream o;
  o.precision(3);
  o << r.loose_steps << " of " << r.converged_steps
    << " converged steps were accepted by /solver/absolute_tolerance ("
    << c.solver.absolute_tolerance << ") alone, out of balance by up to "
    << 100.0 * r.loosest_relative_residual << " % of the reference force " << r.loosest_reference
    << " (load factor " << r.loosest_lambda << "; forces " << unit
    << "): the loads are too small for that tolerance; set /solver/absolute_tolerance well below "
       "them (e.g. "
    << c.solver.tolerance * r.loosest_reference << ", /solver/tolerance times that force)";
  return o.str();
}

/// A warning when the applied displacement moved the patch without straining it (session 43's
/// walkthrough: a tensile test without the support opposite the moving jaw translated as a rigid
/// body, with a jaw force of 1e-14 N, strain 0.2 in the CSV and exit 0): the largest membrane
/// strain and curvature change times half the thickness on a 9 x 9 grid of the last converged
/// state, against 1e-8 of the applied strain. Empty when the case applies no displacement or
/// the patch is strained.
std::string unstrained_warning(const Case& c, const ShellModel& m, const RunResult& res) {
  if (!c.output.applied || res.rows.empty() || res.u.size() == 0) return {};
  const double applied = res.rows.back().strain;
  if (!(std::abs(applied) > 1e-9)) return {};
  constexpr int kGrid = 9;
  double largest = 0.0;
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      const ShellSample s =
          m.sample(res.u, Eigen::Vector2d(double(i) / (kGrid - 1), double(j) / (kGrid - 1)));
      largest = std::max(
          {largest, s.E.cwiseAbs().maxCoeff(), 0.5 * c.thickness * s.kappa.cwiseAbs().maxCoeff()});
    }
  if (largest > 1e-8 * std::abs(applied)) return {};
  std::ostringstream o;
  o.precision(3);
  o << "the patch is not strained (largest strain " << largest << " on a " << kGrid << " x "
    << kGrid << " grid of the last converged step) although the applied displacement reached "
    << res.rows.back().applied << " " << unit_labels(c.units).of("mm") << " (strain " << applied
    << "): it moved as a rigid body, and the reactions are round-off. Is the edge opposite the "
       "moving one held (/boundary_conditions)?";
  return o.str();
}

}  // namespace

RunResult run_case(const Case& c, const RunOptions& opt) {
  if (!opt.output_dir.empty()) check_output_size(c, opt);  // before any work or file
  Problem p = setup_problem(c);
  const ShellModel& m = *p.model;
  std::unique_ptr<ResultsWriter> writer;
  if (!opt.output_dir.empty()) writer = std::make_unique<ResultsWriter>(c, m, opt.output_dir);
  // After the writer took the output (and put back an earlier one a killed run had moved
  // aside): is there an earlier output a run without a converged step must not replace?
  std::error_code ec;
  const bool had_output = writer && std::filesystem::is_directory(opt.output_dir, ec) &&
                          !std::filesystem::is_empty(opt.output_dir, ec);
  // A completed earlier output is not lost to a stopped rerun (session 46's red team: a rerun
  // that stopped after 14 of 20 steps replaced the complete result): it is kept beside it.
  // Completed and trustworthy: no material failure, no non-finite output (the review of session
  // 46: such a run also says "status: completed", exits 1, and would have been kept over the
  // clean result kept before).
  const bool had_completed = had_output && [&] {
    std::ifstream in(opt.output_dir / "summary.txt");
    std::string line;
    std::getline(in, line);
    if (line != "status: completed") return false;
    while (std::getline(in, line))
      if (line.rfind("material failures: ", 0) == 0 || line.rfind("output failure: ", 0) == 0)
        return false;
    return true;
  }();
  RunResult res;
  for (const std::string& w : p.warnings) {
    res.input_warnings.push_back(w);
    if (opt.warnings) *opt.warnings << "warning: " << c.file << ": " << w << std::endl;
  }
  std::vector<std::vector<int>> reaction_sets;  // the control points of each reaction
  for (const ReactionOutput& r : c.output.reactions) reaction_sets.push_back(reaction_points(m, r));
  int outputs = 0;
  Eigen::VectorXd last_written;
  ShellModel::Evaluation audit;
  SolverOptions solver = c.solver;
  if (opt.progress)  // long setups and slow iterations say so (newton.hpp)
    solver.progress = [&opt](const std::string& line) { *opt.progress << line << std::endl; };
  res.report = solve_load_steps(m, p.dofs, p.fext, solver, [&](const StepResult& s) {
    // Where the converged state lies in the material's data (one residual pass per step).
    if (c.material->begin_converged_audit()) {
      m.evaluate(s.u, false, audit);
      c.material->end_converged_audit();
    }
    StepRow row;
    row.step = s.step;
    row.lambda = s.lambda;
    if (c.output.applied) {
      row.applied = s.lambda * c.output.applied->value;
      row.strain = row.applied / c.output.applied->gauge_length;
    }
    for (size_t k = 0; k < c.output.reactions.size(); ++k)
      row.reactions.push_back(support_reaction(s.fint, p.fext, s.lambda, reaction_sets[k],
                                               c.output.reactions[k].component));
    for (const OutputPoint& op : c.output.points) row.points.push_back(m.displacement(s.u, op.at));
    row.iterations = s.iterations;
    row.residual = s.residual;
    row.seconds = s.seconds;
    row.negative_pivots = s.negative_pivots;
    row.determinant_sign = s.determinant_sign;
    res.rows.push_back(row);
    res.u = s.u;
    if (opt.progress) {
      char line[240];
      int len =
          std::snprintf(line, sizeof line,
                        "step %4d  load factor %.6f  iterations %2d  residual %.3e  time %.3f s",
                        s.step, s.lambda, s.iterations, s.residual, s.seconds);
      if (s.negative_pivots > 0 && len > 0 && len < int(sizeof line))
        std::snprintf(line + len, sizeof line - len, "  UNSTABLE: %d negative pivots",
                      s.negative_pivots);
      else if (s.negative_pivots < 0 && s.determinant_sign < 0 && len > 0 && len < int(sizeof line))
        std::snprintf(line + len, sizeof line - len, "  UNSTABLE: det K < 0 (LU)");
      *opt.progress << line << std::endl;
    }
    if (writer) {
      writer->add_row(row);
      if (++outputs % c.output.every == 0 || s.lambda >= 1.0 - 1e-12)
        writer->add_step(s.step, s.lambda, s.u);
      else
        last_written = s.u;
    }
  });
  res.failed_material_evaluations = c.material->failed_evaluations();
  const std::string failure = material_failure_message(res.report, res.failed_material_evaluations);
  if (opt.progress && !failure.empty()) *opt.progress << failure << std::endl;
  const std::string material_report = c.material->report();
  if (opt.progress && !material_report.empty()) *opt.progress << material_report << std::endl;
  res.material_warning = c.material->warning();
  if (opt.warnings && !res.material_warning.empty())
    *opt.warnings << res.material_warning << std::endl;
  res.solver_warning = solver_fallback_message(res.report.stats);
  if (opt.warnings && !res.solver_warning.empty())
    *opt.warnings << "warning: " << res.solver_warning << std::endl;
  for (const LoadDrop& d : find_load_drops(c, res.rows))
    res.load_drops.push_back(
        load_drop_message(d, kLoadDropTolerance, unit_labels(c.units).of("N")));
  if (opt.warnings)
    for (const std::string& w : res.load_drops) *opt.warnings << "warning: " << w << std::endl;
  if (std::string w = loose_convergence_warning(c, res.report); !w.empty()) {
    if (opt.warnings) *opt.warnings << "warning: " << w << std::endl;
    res.input_warnings.push_back(std::move(w));
  }
  if (std::string w = unstrained_warning(c, m, res); !w.empty()) {
    if (opt.warnings) *opt.warnings << "warning: " << w << std::endl;
    res.input_warnings.push_back(std::move(w));
  }
  if (opt.progress &&
      (res.report.first_unstable_step > 0 || res.report.first_negative_determinant_step > 0))
    *opt.progress << "stability: " << stability_summary(res.report) << std::endl;
  // A run in which no load step converged does not replace an earlier output of the same
  // directory with its empty one (session 26, found by a helper's audit: a rerun that failed
  // at the first step cost the earlier results); into a new directory it writes its summary.
  if (writer && res.report.converged_steps == 0 && had_output) {
    writer.reset();  // the partial directory goes; the earlier output stays
    res.output_failure = "no load step converged: nothing written; the earlier outputs in " +
                         opt.output_dir.string() + " are left as they were";
  }
  if (writer) {
    writer->set_material_report(material_report);
    writer->set_material_warning(res.material_warning);
    writer->set_material_failure(failure);
    writer->set_load_drops(res.load_drops);
    writer->set_input_warnings(res.input_warnings);
    writer->set_solver_warning(res.solver_warning);
    // A stopped run still writes its last converged state.
    if (res.report.status != RunStatus::kCompleted && !res.rows.empty() &&
        outputs % c.output.every != 0)
      writer->add_step(res.rows.back().step, res.rows.back().lambda, res.u);
    if (had_completed && !res.succeeded()) writer->keep_replaced_as(".last-completed");
    writer->finish(res.report);
    res.wrote_outputs = true;
    res.replaced_earlier = had_output;
    res.earlier_kept_in = writer->replaced_kept_in();
    res.output_failure = writer->output_failure();
  }
  return res;
}

}  // namespace knit::macro
