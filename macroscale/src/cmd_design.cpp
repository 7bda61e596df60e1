// knit-macro design DESIGN.json [--check] [--output DIR]
//   Inverse design of the l and alpha fields (issue 13, docs/design.md): reads and checks the
//   design file (schemas/design.schema.json) and prints the problem; with --check that is all.
//   Otherwise optimizes (projected gradient with the adjoint gradient; reaction terms only this
//   round) and writes DIR (default: the design file's name without extension) atomically:
//   history.csv (iteration, J, gradient norm, seconds, the variables) and case.json (the best
//   design, runs as is with `knit-macro run`).
//   Exit codes: 0 converged, 1 the optimization stopped early (the best design is written),
//   2 bad input (nothing is written).
// Example:
//   knit-macro design cases/design/uniform_load.json --check
#include <filesystem>
#include <iostream>
#include <memory>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/csv.hpp"
#include "knit/macro/design_problem.hpp"

namespace {

struct Options {
  std::string file, output;
  bool check = false;
};

knit::cli::SubcommandRegistrar reg(
    "design", "Inverse design of the stitch-value and knitting-angle fields (--check: validate)",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("design", o->file, "design file (JSON)")->required();
      sub.add_flag("--check", o->check, "read and check the design file, print the problem");
      sub.add_option("--output,-o", o->output, "output directory");
      return [o]() -> int {
        const auto d = knit::macro::load_design(o->file);
        std::cout << "design: " << o->file << "\ncase: " << d.case_file << "\n";
        for (const auto& v : d.variables) {
          std::cout << "variable " << v.name << ": "
                    << (v.field == knit::macro::DesignVariable::Field::kStitchValue
                            ? "stitch_value"
                            : "knitting_angle")
                    << " control values";
          for (int i : v.indices) std::cout << " " << i;
          std::cout << ", initial " << v.initial << ", bounds [" << v.lower << ", " << v.upper
                    << "]\n";
        }
        for (const auto& ob : d.objectives)
          std::cout << "objective " << ob.name << ": weight " << ob.weight << ", "
                    << ob.at_strain.size() << " applied strain(s)\n";
        std::cout << "smoothness weight: " << d.smoothness << "\n";
        if (o->check) return knit::kExitOk;
        const auto r = knit::macro::optimize_design(d);
        if (r.history.empty()) {
          std::cerr << "knit-macro design: " << o->file << ": " << r.message << "\n";
          return knit::kExitFailure;
        }
        const std::filesystem::path dir = o->output.empty() ? std::filesystem::path(o->file).stem()
                                                            : std::filesystem::path(o->output);
        knit::io::AtomicDirectory out(dir);
        std::vector<std::string> header = {"iteration", "J", "gradient_norm", "seconds"};
        for (std::size_t k = 0; k < d.variables.size(); ++k)
          header.push_back(d.variables[k].name.empty() ? "x" + std::to_string(k)
                                                       : d.variables[k].name);
        knit::io::CsvWriter csv(out / "history.csv", header);
        for (const auto& h : r.history) {
          std::vector<knit::io::CsvCell> row = {h.iteration, h.J, h.gradient_norm, h.seconds};
          for (double x : h.x) row.emplace_back(x);
          csv.add_row(row);
        }
        csv.commit();
        knit::io::write_file_atomically(out / "case.json", knit::macro::design_case_text(d, r.x));
        out.commit();
        for (const auto& h : r.history)
          std::cout << "iteration " << h.iteration << ": J = " << h.J << "\n";
        std::cout << "wrote " << dir.string() << "\n";
        if (r.status != knit::macro::RunStatus::kCompleted || !r.message.empty()) {
          std::cerr << "knit-macro design: " << r.message << "\n";
          return knit::kExitFailure;
        }
        return knit::kExitOk;
      };
    });

}  // namespace
