// knit-meso fit DB.h5: refits the response surfaces of an existing material database from its
// raw data with new options, without re-simulating (paper eq. 17; options in
// knit/meso/fit/response_fit.hpp).
//
//   knit-meso fit db.h5
//   knit-meso fit db.h5 --options fit.json --out refit.h5
#include <iostream>
#include <memory>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/output_target.hpp"
#include "knit/meso/fit/report.hpp"
#include "knit/meso/fit/response_fit.hpp"

static knit::cli::SubcommandRegistrar reg_fit(
    "fit",
    "Refit the response surfaces of an existing material database from its raw data (no "
    "re-simulation)",
    [](CLI::App& sub) {
      struct FitCli {
        std::string db, out, options;
      };
      auto o = std::make_shared<FitCli>();
      sub.add_option("database", o->db, "material database (.h5)")->required();
      sub.add_option("--options", o->options, "fit options (JSON file; defaults otherwise)");
      sub.add_option("-o,--output,--out", o->out, "write here instead of replacing the input");
      return [o]() -> int {
        using namespace knit::meso::fit;
        const std::string target = o->out.empty() ? o->db : o->out;
        knit::io::check_output_target(target, knit::io::OutputKind::kFile,
                                      o->out.empty() ? "database" : "--out");
        const knit::io::OutputLock lock(target);
        auto db = knit::material::read_database(o->db, true);
        const FitOptions fo =
            o->options.empty()
                ? FitOptions{}
                : FitOptions::from_json(knit::meso::fit::read_text_file(o->options), o->options);
        const auto fits = fit_database(db, fo);
        std::cout << "knit-meso fit: " << o->db << " (" << fits.size() << " loop lengths)\n";
        knit::meso::fit::print_fit_summaries(std::cout, db, fits);
        db.provenance = knit::material::current_provenance();
        knit::material::write_database(target, db);
        for (const auto& f : fits)
          if (!f.ok()) return knit::kExitFailure;
        return knit::kExitOk;
      };
    });
