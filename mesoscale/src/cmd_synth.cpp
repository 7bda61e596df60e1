// knit-meso synth: a synthetic material database, the STAND-IN for the mesoscale sweep until
// real homogenized data exist. It evaluates a known orthotropic, stiffening law (not a knit;
// see knit/meso/fit/synthetic.hpp) on the default 13 load paths plus coverage and held-out
// paths (synthetic_coverage_paths: the full circle of biaxial directions, shear with stretch,
// 24 quasi-random held-out states), stores the raw data like the sweep would, fits the paper's
// response surfaces (from the "paper" set) and the energy-based law (unless --no-fit) and
// writes the database.
//
//   knit-meso synth --out synthetic.h5
//   knit-meso synth --out db.h5 --loop-lengths 4.5,5.5,6.5 --steps 20 --fit-options fit.json
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/output_target.hpp"
#include "knit/material/database.hpp"
#include "knit/meso/fit/energy_fit.hpp"
#include "knit/meso/fit/report.hpp"
#include "knit/meso/fit/response_fit.hpp"
#include "knit/meso/fit/synthetic.hpp"

namespace {
struct SynthCli {
  std::string out, fit_options, energy_options;
  std::vector<double> loop_lengths = {4.5, 5.0, 5.5, 6.0, 6.5};
  int steps = 20;
  bool no_fit = false, no_coverage = false;
};
}  // namespace

static knit::cli::SubcommandRegistrar reg_synth(
    "synth",
    "Write a SYNTHETIC material database (a stand-in for the mesoscale sweep: a known "
    "orthotropic stiffening law on the default load paths, not a knit: in tension about 8 "
    "times softer than a swept database), fitted unless --no-fit",
    [](CLI::App& sub) {
      auto o = std::make_shared<SynthCli>();
      sub.add_option("-o,--output,--out", o->out, "output database (.h5)")->required();
      // The defaults in the help (session 39's walkthrough: neither was stated).
      sub.add_option("--loop-lengths", o->loop_lengths,
                     "loop lengths in mm (increasing; default 4.5,5,5.5,6,6.5)")
          ->delimiter(',')
          ->check(knit::cli::number(0, 50, knit::cli::Ends::kOpenLow));
      sub.add_option("--steps", o->steps, "load steps per path (default 20)")
          ->check(knit::cli::integer(4, 1000));
      auto* fo = sub.add_option("--fit-options", o->fit_options, "fit options (JSON file)");
      auto* eo = sub.add_option("--energy-options", o->energy_options,
                                "energy-law fit options (JSON file)");
      // Options of a fit that --no-fit skips were ignored unread, even a missing file (session
      // 24): now the parser refuses the combination.
      sub.add_flag("--no-fit", o->no_fit, "store the raw data only")->excludes(fo)->excludes(eo);
      sub.add_flag("--no-coverage", o->no_coverage,
                   "only the 13 paper paths (no coverage or held-out paths)");
      return [o]() -> int {
        using namespace knit::meso::fit;
        knit::io::check_output_target(o->out, knit::io::OutputKind::kFile, "--out",
                                      knit::material::kDatabaseFormatName);
        knit::material::refuse_replacing_swept_database(o->out, "--out");
        const knit::io::OutputLock lock(o->out);
        SyntheticOptions so;
        so.loop_lengths = o->loop_lengths;
        // As the sweep's (sweep_input.cpp): at least 0.001 mm apart (session 38's red team:
        // synth took 4.5 and 4.5001, which the sweep refuses).
        for (std::size_t k = 0; k < so.loop_lengths.size(); ++k)
          if (!(so.loop_lengths[k] > 0.0) ||
              (k > 0 && !(so.loop_lengths[k] >= so.loop_lengths[k - 1] + 1e-3 - 1e-9)))
            throw knit::InputError("", "--loop-lengths",
                                   "must be positive and increase by at least 0.001 mm");
        so.paths = knit::material::default_load_paths(o->steps);
        if (!o->no_coverage)
          for (const auto& p : synthetic_coverage_paths(std::max(4, o->steps / 2)))
            so.paths.push_back(p);
        // Both options files are read and checked before the database is built (the review of
        // session 44: a missing --energy-options file was refused after the build and the
        // paper fit). The synthetic law is exactly a sum of ridge functions of the default
        // directions (knit/meso/fit/synthetic.hpp), so the stand-in fits the ridge family
        // unless the options say otherwise (the network's fit costs seconds for nothing here).
        const FitOptions fo = o->fit_options.empty()
                                  ? FitOptions{}
                                  : FitOptions::from_json(knit::meso::fit::read_text_file(
                                                              o->fit_options, "--fit-options"),
                                                          o->fit_options);
        EnergyFitOptions eo;
        eo.family = "ridge";
        if (!o->energy_options.empty()) {
          const std::string text = read_text_file(o->energy_options, "--energy-options");
          eo = EnergyFitOptions::from_json(text, o->energy_options);
          EnergyFitOptions::refuse_other_family_keys(text, o->energy_options);
        }
        auto db = synthetic_database(so);
        // The stand-in's stiffness k = (4.5 / l)^2 overflows for a tiny l: its stresses were
        // written as inf and NaN with exit 0 (session 21, --loop-lengths 1e-300), and beyond
        // what the reader takes (session 38, --loop-lengths 0.0001: 1.4e9 MPa, exit 0).
        if (const auto bad = knit::material::first_unstorable_step(db))
          throw knit::InputError("", "--loop-lengths",
                                 "the stand-in law's stress cannot be stored (" + *bad +
                                     "): its stiffness (4.5 / l)^2 MPa is too large; give loop "
                                     "lengths of a knit (a few mm)");
        if (!o->no_fit)
          knit::meso::fit::refuse_unfittable_options(db, fo, o->fit_options, eo, o->energy_options);
        int rc = knit::kExitOk;
        std::string first_failure;
        if (!o->no_fit) {
          const auto fits = fit_paper_law(db, fo);
          std::cout << "knit-meso synth: fitted " << fits.size() << " loop lengths\n";
          knit::meso::fit::print_fit_summaries(std::cout, db, fits);
          if (const std::string w = knit::meso::fit::paper_fit_warning(db.loop_lengths(), fits);
              !w.empty())
            std::cerr << "knit-meso synth: " << w << "\n";
          first_failure = knit::meso::fit::first_fit_failure(db, fits);
          if (!first_failure.empty()) rc = knit::kExitFailure;
          const auto es = fit_energy_database(db, eo);
          std::cout << energy_fit_report(es);
          if (!es.ok()) {
            rc = knit::kExitFailure;
            if (first_failure.empty()) first_failure = "the energy law: " + es.reason;
          }
        }
        // A fit that failed writes nothing, as knit-meso fit (session 41's red team: synth
        // replaced a good database by one whose loop length held raw data only, exit 1).
        if (rc != knit::kExitOk) {
          const char* state = knit::io::unwritten_output_state(o->out);
          std::cout << "database NOT written: a fit failed; " << o->out << state << "\n";
          std::cout.flush();
          std::cerr << "knit-meso synth: error: " << first_failure << "; " << o->out << state
                    << " (the fit's report is on stdout; --no-fit writes the raw data alone)\n";
          return rc;
        }
        knit::material::write_database(o->out, db);
        std::cout << "wrote " << o->out << " (synthetic stand-in, generator = \"synth\")\n";
        return rc;
      };
    });
