// knit-macro design DESIGN.json [--check] [--output DIR]
//   Inverse design of the l and alpha fields (issue 13, docs/design.md): reads and checks the
//   design file (schemas/design.schema.json) and prints the problem; with --check that is all.
//   Otherwise optimizes (the design file's `optimizer`: bounded Levenberg-Marquardt in Ceres by
//   default) and writes DIR (default: the design file's name without extension) atomically:
//   history.csv (iteration, J, gradient norm, seconds, the variables), summary.txt (status,
//   objective terms before and after, evaluations, time), case.json (the best design; runs as
//   is with `knit-macro run`) and run/ (that run's usual outputs).
//   A status line "status: converged | infeasible target | target not met | iteration limit |
//   failed" (the two misses with a "message:" line saying why).
//   Exit codes: 0 converged, infeasible target or target not met (the best design inside the
//   bounds is written; the status line says which), 1 iteration limit or a failed solve (the best
//   design so far is written; nothing if the first solve fails), 2 bad input (nothing is written).
// Example:
//   knit-macro design cases/design/uniform_load.json --output out/design/uniform_load
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/output_target.hpp"
#include "knit/io/provenance.hpp"
#include "knit/macro/design_problem.hpp"
#include "knit/macro/run.hpp"
#include "results_writer.hpp"

// A named namespace per command: the cmd_*.cpp files share one unity translation unit
// (docs/build.md), and each defines its own Options, run and reg.
namespace knit::macro::cmd_design {
namespace {

/// A variable's history.csv column: its name, or x<k>.
std::string column_name(const knit::macro::DesignProblem& d, std::size_t k) {
  return d.variables[k].name.empty() ? "x" + std::to_string(k) : d.variables[k].name;
}

struct Options {
  std::string file, output, max_output_size;
  bool check = false;
};

knit::cli::SubcommandRegistrar reg(
    "design", "Inverse design of the stitch-value and knitting-angle fields (--check: validate)",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      // What a design file holds, in the help (session 40's walkthrough: the objective types
      // were only in docs/design.md).
      sub.add_option("design", o->file,
                     "design file (JSON, schemas/design.schema.json; docs/design.md): a knit case, "
                     "variables (stitch_value or knitting_angle control values with bounds), "
                     "objectives (reaction, displacement, strain_variance, target_strain, "
                     "reaction_linearity; at applied strains) and a smoothness penalty")
          ->required();
      sub.add_flag("--check", o->check, "read and check the design file, print the problem");
      sub.add_option(
          "-o,--output,--out", o->output,
          "output directory (default: the design file's name without its extension, in the "
          "current directory)");
      sub.add_option("--max-output-size", o->max_output_size,
                     "refuse a design whose final run's outputs (run/) are estimated larger "
                     "(default 2G; 0: no cap), as knit-macro run does");
      return [o]() -> int {
        knit::macro::RunOptions ro;
        if (!o->max_output_size.empty())
          ro.max_output_bytes = knit::io::parse_size(o->max_output_size, "--max-output-size");
        auto d = knit::macro::load_design(o->file);
        std::cout << "design: " << o->file << "\ncase: " << d.case_file << "\n";
        for (const auto& v : d.variables) {
          std::cout << "variable " << v.name << ": "
                    << (v.field == knit::macro::DesignVariable::Field::kStitchValue
                            ? "stitch_value"
                            : "knitting_angle")
                    << " control values";
          for (int i : v.indices) std::cout << " " << i;
          std::cout << ", initial " << v.initial << ", bounds [" << v.lower << ", " << v.upper
                    << "] " << v.unit << "\n";
        }
        for (const auto& ob : d.objectives)
          std::cout << "objective " << ob.name << ": weight " << ob.weight << ", "
                    << ob.at_strain.size() << " applied strain(s)\n";
        std::cout << "smoothness weight: " << d.smoothness << "\n";
        const std::filesystem::path dir = o->output.empty() ? std::filesystem::path(o->file).stem()
                                                            : std::filesystem::path(o->output);
        // The output target is checked before the optimization, and by --check (session 24:
        // it was checked only when the results were written, after minutes of optimizing).
        knit::io::check_output_target(dir, knit::io::OutputKind::kDirectory,
                                      o->output.empty() ? "output directory" : "--output");
        if (o->output.empty()) knit::io::check_default_output_input(dir, o->file);
        // The final run's outputs against the cap, before the optimization and by --check
        // (session 42's red team: the final run refused them after the whole optimization,
        // naming DIR/case.json, which was never written, and an option design did not have).
        // The case's output settings are the final run's: the design changes its fields only.
        knit::macro::check_output_size(d.c, ro);
        // The case's input warnings (a reaction over one row of a clamped edge, a load on held
        // degrees of freedom) before the optimization, and with --check: the design optimizes
        // what the case measures (session 47's walkthrough: a reaction objective over one row
        // of a clamped jaw "met" 5 N where the jaw carried 23 N, and nothing was said).
        for (const std::string& w : knit::macro::setup_problem(d.c).warnings)
          std::cerr << "warning: " << d.case_file << ": " << w << "\n";
        if (!d.twin.empty()) {
          std::cout << "twin:";
          for (std::size_t k = 0; k < d.variables.size(); ++k)
            std::cout << " " << column_name(d, k) << " = " << d.twin[k];
          std::cout << " (the reaction and displacement terms' targets come from its run)\n";
        }
        if (o->check) return knit::kExitOk;
        // The output directory (and its lock) before any work (session 40's data-safety red
        // team: taken after the optimization, a second design into the same directory started
        // meanwhile was silently replaced, and a run into it failed the design after all its
        // work). Until commit() only DIR.partial-<pid> exists; a failure removes it.
        knit::io::AtomicDirectory out(dir, knit::io::AtomicDirectory::OnAbandon::Remove,
                                      o->output.empty() ? "output directory" : "--output", o->file);
        // An earlier design written before the marker said whether it completed (session 49):
        // judged from its summary.txt, as design_verdict() judged it (a status other than
        // "iteration limit" and "failed", and a final run that completed).
        out.judge_earlier_by_files([](const std::filesystem::path& earlier) {
          std::ifstream in(earlier / "summary.txt");
          std::string line;
          bool status_ok = false, final_ok = false;
          if (std::getline(in, line))
            status_ok = line.rfind("status: ", 0) == 0 && line != "status: iteration limit" &&
                        line != "status: failed";
          while (std::getline(in, line)) final_ok = final_ok || line == "final run: completed";
          return status_ok && final_ok;
        });
        // The twin's targets: the case solved at the twin's values (not for --check).
        if (const std::string why = knit::macro::set_twin_targets(d); !why.empty()) {
          std::cerr << "knit-macro design: " << o->file << ": " << why << "\n";
          std::cout << "status: failed\n";
          return knit::kExitFailure;
        }
        // Each accepted iteration as it comes (session 42's red team: printed after the
        // optimization, so an interrupted design left not even the header in a log file).
        knit::macro::OptimizeOptions oo;
        oo.on_iteration = [](const knit::macro::DesignIteration& h) {
          std::cout << "iteration " << h.iteration << ": J = " << h.J
                    << ", |dJ/dp| = " << h.gradient_norm << ", " << h.seconds << " s" << std::endl;
        };
        std::cout.flush();
        const auto opt_start = std::chrono::steady_clock::now();
        const auto r = knit::macro::optimize_design(d, oo);
        // summary.txt's `seconds`: the whole optimization's wall time (session 56's walkthrough:
        // it was the last accepted iteration's time, below forward + gradient seconds).
        const double opt_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - opt_start).count();
        using knit::macro::DesignStatus;
        if (r.status == DesignStatus::kFailed && r.evaluations <= 1) {
          std::cerr << "knit-macro design: " << o->file << ": " << r.message << "\n";
          std::cout << "status: failed\n";
          return knit::kExitFailure;
        }
        std::vector<std::string> header = {"iteration", "J", "gradient_norm", "seconds"};
        for (std::size_t k = 0; k < d.variables.size(); ++k) header.push_back(column_name(d, k));
        knit::io::CsvWriter csv(out / "history.csv", header);
        // Provenance and units, as knitmap.csv and load_strain.csv have them (session 42's red
        // team: none here).
        csv.add_comment("provenance: " + knit::io::Provenance::current(o->file).to_json_string());
        {
          std::string units =
              "units: J the sum of the weighted squared residuals (a reaction's in N^2, a "
              "displacement's in mm^2, a strain's dimensionless, each times its weight; "
              "docs/design.md); gradient_norm |dJ/dp| in J per unit of the variables; seconds "
              "s (wall time since the start);";
          for (std::size_t k = 0; k < d.variables.size(); ++k)
            units += " " + column_name(d, k) + " " + d.variables[k].unit;
          csv.add_comment(units);
        }
        for (const auto& h : r.history) {
          std::vector<knit::io::CsvCell> row = {h.iteration, h.J, h.gradient_norm, h.seconds};
          for (double x : h.x) row.emplace_back(x);
          csv.add_row(row);
        }
        csv.commit();
        const std::string case_text = knit::macro::design_case_text(d, r.x);
        knit::io::write_file_atomically(out / "case.json", case_text);
        // The final run's usual outputs. Its case is named by its final path, which exists once
        // the directory is committed (out / "case.json" is in DIR.partial-<pid>: the run's
        // provenance named a directory that no longer exists; session 27). Relative paths in
        // the case resolve alike: both directories have the same parent.
        const auto best = knit::macro::parse_case(case_text, (dir / "case.json").string());
        ro.output_dir = out / "run";
        // The final run's warnings on stderr, as knit-macro run gives them (session 47's
        // walkthrough: only run/summary.txt had them, the material law's departure from its
        // cell included), and in summary.txt below.
        ro.warnings = &std::cerr;
        const auto run = knit::macro::run_case(best, ro);
        std::ostringstream sum;
        sum << "status: " << to_string(r.status) << "\n";
        if (!r.message.empty()) sum << "message: " << r.message << "\n";
        sum << "optimizer: "
            << (d.optimizer.method == knit::macro::DesignOptimizerSpec::Method::kCeres
                    ? "ceres"
                    : "projected_gradient")
            << "\niterations: " << (r.history.empty() ? 0 : r.history.back().iteration)
            << "\nevaluations: " << r.evaluations << "\nseconds: " << opt_seconds
            << "\nseconds_to_last_accepted: "
            << (r.history.empty() ? 0.0 : r.history.back().seconds) << "\nJ_initial: " << r.J0
            << "\nJ_final: " << r.J << "\nforward_seconds: " << r.forward_seconds
            << "\ngradient_seconds: " << r.gradient_seconds << "\ngradients: " << r.gradients;
        // One gradient (forward run + sensitivities) in units of one forward run.
        if (r.forward_seconds > 0.0)
          sum << "\ngradient_cost_in_forward_solves: "
              << (r.forward_seconds + r.gradient_seconds) / r.forward_seconds;
        sum << "\n";
        for (std::size_t k = 0; k < r.terms0.size(); ++k)
          sum << "term " << r.terms0[k].first << ": " << r.terms0[k].second << " -> "
              << (k < r.terms.size() ? r.terms[k].second : r.terms0[k].second) << "\n";
        // What the design reached beside what was asked (session 39's walkthrough: only J was
        // given, and the load had to be read from run/load_strain.csv or worked out from J).
        for (std::size_t k = 0; k < d.objectives.size() && k < r.reached.size(); ++k) {
          const auto& o = d.objectives[k];
          if (r.reached[k].empty()) continue;
          using Kind = knit::macro::DesignObjective::Kind;
          const std::string& comp = o.component_name();
          sum << "reached " << o.name << ":";
          for (double v : r.reached[k]) sum << " " << v;
          // The unit slot (scripts/figures/design.py reads the word before the parenthesis):
          // N, mm, or the strain component (session 40: the strain objectives had no line).
          switch (o.kind) {
            case Kind::kReaction:
              sum << " N (target";
              break;
            case Kind::kDisplacement:
              sum << " mm (target";
              break;
            case Kind::kTargetStrain:
              sum << " " << comp << " (the mean over the region's samples; target";
              break;
            default:
              sum << " " << comp
                  << "_std (the standard deviation over the region's samples; a "
                     "uniform strain has 0";
              break;
          }
          for (double t : o.target) sum << " " << t;
          sum << "; at strain";
          for (double e : o.at_strain) sum << " " << e;
          sum << ")\n";
        }
        for (std::size_t k = 0; k < d.variables.size(); ++k)
          sum << "variable " << header[4 + k] << ": " << d.variables[k].initial << " -> " << r.x[k]
              << " in [" << d.variables[k].lower << ", " << d.variables[k].upper << "] "
              << d.variables[k].unit << "\n";
        // A twin experiment: its targets and how far the design ends from the twin, per
        // variable in % of its bound interval (docs/design.md, "Twin experiments").
        for (std::size_t k = 0; k < d.objectives.size() && !d.twin.empty(); ++k)
          if (d.twin_targets[k]) {
            sum << "twin target " << d.objectives[k].name << ":";
            for (double t : d.objectives[k].target) sum << " " << t;
            sum << "\n";
          }
        for (std::size_t k = 0; k < d.twin.size(); ++k) {
          const auto& v = d.variables[k];
          sum << "twin " << header[4 + k] << ": " << d.twin[k] << " (recovered " << r.x[k]
              << ", off by " << 100.0 * std::abs(r.x[k] - d.twin[k]) / (v.upper - v.lower)
              << " % of the bounds)\n";
        }
        const std::string run_failure = knit::macro::run_failure_message(run);
        sum << "final run: " << (run.succeeded() ? "completed" : run_failure) << "\n";
        for (const std::string& n : knit::macro::final_run_step_notes(d))
          sum << "note: " << n << "\n";
        for (const std::string& w : knit::macro::run_warning_lines(run))
          sum << "warning: final run: " << w << "\n";
        knit::io::write_file_atomically(out / "summary.txt", sum.str());
        const auto verdict = knit::macro::design_verdict(r, run);
        // A design that ends with exit 1 keeps a completed earlier design of DIR beside it
        // (session 49's red team: a rerun stopped at its iteration limit replaced a converged
        // design).
        out.set_completed(verdict.exit_code == knit::kExitOk);
        out.commit();
        std::cout << sum.str() << "wrote " << dir.string() << "\n";
        if (verdict.exit_code != knit::kExitOk)
          std::cerr << "knit-macro design: " << o->file << ": " << verdict.reason << "; outputs in "
                    << dir.string()
                    << (out.replaced_kept_in().empty()
                            ? ""
                            : " (they replace the earlier outputs there; the completed earlier "
                              "design is kept in " +
                                  out.replaced_kept_in().string() + ")")
                    << "\n";
        return verdict.exit_code;
      };
    });

}  // namespace
}  // namespace knit::macro::cmd_design
