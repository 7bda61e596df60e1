// knit-macro run CASE.json [--output DIR] [--max-output-size SIZE]
//   Runs a macroscale shell case (docs/case-format.md); writes DIR (default: the case file's
//   name without extension, in the current directory). Exit codes: 0 completed, 1 a load step
//   failed or the material failed to evaluate somewhere ("completed with N failed material
//   evaluations; results are not trustworthy"; the outputs are written), 2 bad input (nothing
//   is written): this includes an output DIR that cannot be written or is not ours to replace,
//   an output in use by another run, and an estimated output size above SIZE (default 2G;
//   docs/io.md "Output targets").
// Example:
//   knit-macro run cases/verification/scordelis_lo.json --output out/scordelis_lo
#include <filesystem>
#include <iostream>
#include <memory>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/output_target.hpp"
#include "knit/macro/run.hpp"

// A named namespace per command: the cmd_*.cpp files share one unity translation unit
// (docs/build.md), and each defines its own Options, run and reg.
namespace knit::macro::cmd_run {
namespace {

struct Options {
  std::string case_file, output, max_output_size;
};

knit::cli::SubcommandRegistrar reg(
    "run", "Run a shell case (JSON): Newton load stepping, CSV/VTU/HDF5 outputs",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("case", o->case_file, "case file (JSON)")->required();
      sub.add_option(
          "-o,--output,--out", o->output,
          "output directory (default: the case file's name without its extension, in the "
          "current directory)");
      sub.add_option("--max-output-size", o->max_output_size,
                     "refuse a run whose estimated output is larger (default 2G; 0: no cap)");
      return [o]() -> int {
        knit::macro::RunOptions ro;
        ro.output_dir = o->output.empty() ? std::filesystem::path(o->case_file).stem()
                                          : std::filesystem::path(o->output);
        knit::io::check_output_target(ro.output_dir, knit::io::OutputKind::kDirectory,
                                      o->output.empty() ? "output directory" : "--output");
        if (o->output.empty()) knit::io::check_default_output_input(ro.output_dir, o->case_file);
        if (!o->max_output_size.empty())
          ro.max_output_bytes = knit::io::parse_size(o->max_output_size, "--max-output-size");
        const knit::macro::Case c = knit::macro::load_case(o->case_file);
        ro.progress = &std::cout;
        ro.warnings = &std::cerr;
        const auto r = knit::macro::run_case(c, ro);
        if (!r.succeeded()) {
          std::cerr << "knit-macro run: " << o->case_file << ": "
                    << knit::macro::run_failure_message(r)
                    << (r.wrote_outputs ? "; outputs in " + ro.output_dir.string() : "")
                    << (!r.wrote_outputs || !r.replaced_earlier ? ""
                        : r.earlier_kept_in.empty()
                            ? " (they replace the earlier outputs there: a stopped run keeps its "
                              "converged steps)"
                            : " (they replace the earlier outputs there, a stopped run keeps its "
                              "converged steps; the completed earlier output is kept in " +
                                  r.earlier_kept_in.string() + ")")
                    << "\n";
          return knit::kExitFailure;
        }
        std::cout << "wrote " << ro.output_dir.string() << "\n";
        return knit::kExitOk;
      };
    });

}  // namespace
}  // namespace knit::macro::cmd_run
