// knit-meso rod CASE.json [-o OUTDIR]: one rod problem (issue #5; paper Sect. 2.1.2, eq. 6).
//   knit-meso rod cases/rod/rollup.json -o out/rollup
//   knit-meso rod cases/rod/elastica.json            (outputs in ./elastica.out)
// Exit codes: 0 converged to lambda = 1, 1 the load path stopped early (outputs hold the
// converged steps), 2 bad input (nothing written).
#include <filesystem>
#include <iostream>
#include <memory>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/output_target.hpp"
#include "knit/meso/rod/rod_case.hpp"

// A named namespace per command: the cmd_*.cpp files share one unity translation unit
// (docs/build.md), and each defines its own Options, run and reg.
namespace knit::meso::cmd_rod {
namespace {

struct Options {
  std::string file;
  std::string outdir;
  std::string max_output_size;
  bool quiet = false;
};

knit::cli::SubcommandRegistrar reg(
    "rod", "Solve one geometrically exact rod problem (isogeometric collocation) from a JSON case",
    [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      sub.add_option("case", o->file, "case file (schema: schemas/rod.schema.json)")->required();
      sub.add_option("-o,--output,--out", o->outdir,
                     "output directory (default: <case stem>.out in the working directory)");
      sub.add_flag("-q,--quiet", o->quiet, "no progress lines");
      sub.add_option("--max-output-size", o->max_output_size,
                     "refuse the case before the run if its outputs are estimated above this "
                     "size (default 2GB; e.g. 500MB, 10GB; 0 = no cap)");
      return [o]() -> int {
        namespace rod = knit::meso::rod;
        const std::filesystem::path out =
            o->outdir.empty()
                ? std::filesystem::path(std::filesystem::path(o->file).stem().string() + ".out")
                : std::filesystem::path(o->outdir);
        knit::io::check_output_target(out, knit::io::OutputKind::kDirectory,
                                      o->outdir.empty() ? "output directory" : "--output");
        const std::uint64_t cap =
            o->max_output_size.empty()
                ? rod::kDefaultMaxOutputBytes
                : knit::io::parse_size(o->max_output_size, "--max-output-size");
        const rod::RodCase c =
            rod::load_rod_case(o->file);  // InputError -> exit 2, nothing written
        rod::check_output_size(c, cap);
        const rod::CasePathReport rep = rod::run_rod_case(c, out, o->quiet ? nullptr : &std::cout);
        if (!rep.written) {
          // (session 41's review: "no load increment converged" where sub-increments had)
          std::cerr << "knit-meso rod: " << rep.message
                    << "; no load step completed (lambda reached " << rep.lambda_reached
                    << "): nothing written; the earlier outputs in " << out.string()
                    << ", if any, are left as they were\n";
          return knit::kExitFailure;
        }
        std::cout << "rod: " << rep.message << "; lambda = " << rep.lambda_reached << ", "
                  << rep.increments << " increments, " << rep.cutbacks << " cut-backs, "
                  << rep.total_iterations << " Newton iterations; outputs in " << out.string()
                  << "\n";
        if (rep.resolution) {
          const rod::ResolutionCheck& rc = *rep.resolution;
          if (!rc.checked || rc.difference > rod::kResolutionTolerance)
            std::cerr << "knit-meso rod: warning: " << rc.describe() << " (tolerance "
                      << 100 * rod::kResolutionTolerance << " %)"
                      << (rc.checked
                              ? "; the mesh is too coarse for this case: raise the elements or the "
                                "degree of the rods' curves (or their \"refine\")"
                              : "")
                      << "\n";
          else
            std::cout << "resolution: " << rc.describe() << "\n";
        }
        if (rep.completed) return knit::kExitOk;
        // Said on stderr too, as knit-meso path says it (session 49's red team: stdout only,
        // and printed under -q).
        std::cerr << "knit-meso rod: " << rep.message << " (lambda reached " << rep.lambda_reached
                  << "); the converged steps are kept in " << out.string()
                  << (rep.earlier_kept_in.empty()
                          ? ""
                          : ", the completed earlier output in " + rep.earlier_kept_in.string())
                  << "\n";
        return knit::kExitFailure;
      };
    });

}  // namespace
}  // namespace knit::meso::cmd_rod
