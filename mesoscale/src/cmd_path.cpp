// knit-meso path --loop-length L (--biaxial EPS11 EPS22 | --shear GAMMA_DEG |
//                --uniaxial AXIS E) [--steps N]
//                [--out DIR] [--elements NE] [--penalty K_N] [--allowance G0] [--delta D]
//                [--mu MU] [--stick K_T] [--no-vtp] [--config CELL.json]
//   Runs one macroscopic deformation path on the single-jersey unit cell (paper Sect. 2.1.2,
//   eqs. 7-9): equilibrates the initial geometry (step 0: residual stress), then N steps.
//   --biaxial gives the strains of F* = diag(1+eps11, 1+eps22); --shear the shear angle gamma in
//   DEGREES of F* = [[1, sin g], [0, cos g]]; --uniaxial the axis (0 = course, 1 = wale) and the
//   end Green-Lagrange strain E along it under uniaxial stress (the other normal stress zero,
//   homog/uniaxial.hpp: the sweep's uniaxial kind, F_aa = 1 + t (sqrt(1 + 2E) - 1)).
//   Every option is checked for finiteness and range before any work (exit 2, the message names
//   the option and the allowed range); a value is never silently replaced by its default.
//   Writes (atomically: built in DIR.partial-<pid>, DIR replaced at the end) DIR/path.csv (F*, P*,
//   E, S and solver figures per step), DIR/yarn_NNNN.vtp (deformed cell yarn and its 8 periodic
//   neighbours, radius array) and DIR/yarn.pvd; prints the time per step and the Newton iterations.
// Example: knit-meso path --loop-length 4.5 --biaxial 0.3 0 --steps 20 --out path45
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/output_target.hpp"
#include "knit/meso/cell/geometry.hpp"
#include "knit/meso/cell/output.hpp"
#include "knit/meso/homog/cell_config.hpp"
#include "knit/meso/homog/path.hpp"

// A named namespace per command: the cmd_*.cpp files share one unity translation unit
// (docs/build.md), and each defines its own Options, run and reg.
namespace knit::meso::cmd_path {
namespace {

/// Whether the path.csv of an earlier output ends at lambda = 1 (its path completed): the
/// second column of its last data row; false when it cannot be read.
bool path_csv_completed(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string line, last;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (std::exchange(header, false)) continue;
    last = line;
  }
  const auto a = last.find(','), b = last.find(',', a == std::string::npos ? a : a + 1);
  if (a == std::string::npos || b == std::string::npos) return false;
  try {
    return std::stod(last.substr(a + 1, b - a - 1)) == 1.0;
  } catch (const std::exception&) {
    return false;
  }
}

struct Options {
  double loop_length = 0;
  std::vector<double> biaxial;
  std::vector<double> uniaxial;  ///< AXIS E
  double shear = std::nan("");
  int steps = 20;
  std::string out = "path";
  // Overrides of the cell parameters: applied only when given, never replaced by defaults.
  std::optional<int> elements;
  std::optional<double> k_N, g0, delta, mu, k_T;
  // Parser targets of the overrides (copied into the optionals when the flag was given).
  int elements_arg = 0;
  double k_N_arg = 0, g0_arg = 0, delta_arg = 0, mu_arg = 0, k_T_arg = 0;
  bool no_vtp = false;
  std::string config;
  std::string max_output_size;  ///< --max-output-size ("" = the default cap)
};

/// The default cap of --max-output-size, as knit-meso rod's and knit-macro run's: 2 GB.
constexpr std::uint64_t kDefaultMaxOutputBytes = 2'000'000'000;

void write_step_vtp(knit::meso::homog::PeriodicCell& cell, const std::string& file) {
  using knit::meso::cell::Polyline;
  std::vector<Polyline> lines;
  int img = 0;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      Polyline pl;
      pl.image = (i == 0 && j == 0) ? 0 : ++img;
      pl.points = cell.centerline(120, i, j);
      lines.push_back(std::move(pl));
    }
  knit::meso::cell::write_polylines_vtp(file, lines, 0.5 * cell.system().spec(0).section.d);
}

int run(const Options& o) {
  using namespace knit::meso::homog;
  if (!(o.loop_length > 0)) throw knit::InputError("", "--loop-length", "must be positive");
  const bool bi = !o.biaxial.empty(), sh = !std::isnan(o.shear), un = !o.uniaxial.empty();
  if (int(bi) + int(sh) + int(un) != 1)
    throw knit::InputError("", "--biaxial, --shear, --uniaxial",
                           "give exactly one of them (the load path)");
  if (bi && o.biaxial.size() != 2) throw knit::InputError("", "--biaxial", "needs EPS11 EPS22");
  if (o.steps < 1) throw knit::InputError("", "--steps", "must be >= 1");
  knit::io::check_output_target(o.out, knit::io::OutputKind::kDirectory, "--out");
  CellOptions co = o.config.empty() ? CellOptions{} : read_cell_options(o.config);
  if (o.elements) co.elements = *o.elements;
  if (o.k_N) co.contact.penalty.k_N = *o.k_N;
  if (o.g0) co.contact.penalty.g0 = *o.g0;
  if (o.delta) co.contact.penalty.delta = *o.delta;
  if (o.mu) co.contact.friction.mu = *o.mu;
  if (o.k_T) co.contact.friction.k_T = *o.k_T;
  // The same checks as the cell parameter file (CellOptions::validate names the field): a flag
  // the parser let through is still refused here, never replaced by a default.
  if (const auto bad = co.validate()) {
    // A value a flag set is named by its flag (session 41's red team: "<input>:
    // /contact/allowance" for --allowance without a --config file).
    const std::pair<const char*, bool> flags[] = {{"/analysis/elements", o.elements.has_value()},
                                                  {"/contact/penalty", o.k_N.has_value()},
                                                  {"/contact/allowance", o.g0.has_value()},
                                                  {"/contact/delta", o.delta.has_value()},
                                                  {"/contact/mu", o.mu.has_value()},
                                                  {"/contact/stick_penalty", o.k_T.has_value()}};
    const char* names[] = {"--elements", "--penalty", "--allowance", "--delta", "--mu", "--stick"};
    for (std::size_t i = 0; i < std::size(flags); ++i)
      if (flags[i].second && bad->pointer == flags[i].first)
        throw knit::InputError("", names[i], bad->message);
    throw knit::InputError(o.config.empty() ? "" : o.config, bad->pointer,
                           bad->message + " (command-line flags override the file)");
  }
  PathSpec p;
  p.steps = o.steps;
  if (bi) {
    p.kind = PathSpec::Kind::kBiaxial;
    p.eps11 = o.biaxial[0];
    p.eps22 = o.biaxial[1];
    if (!(1 + p.eps11 > 0 && 1 + p.eps22 > 0))
      throw knit::InputError("", "--biaxial", "strains must be > -1");
  } else if (un) {
    if (o.uniaxial.size() != 2) throw knit::InputError("", "--uniaxial", "needs AXIS E");
    p.kind = PathSpec::Kind::kUniaxial;
    if (!(o.uniaxial[0] == 0 || o.uniaxial[0] == 1))
      throw knit::InputError("", "--uniaxial", "AXIS must be 0 (course) or 1 (wale)");
    p.axis = static_cast<int>(o.uniaxial[0]);
    if (!(o.uniaxial[1] > -0.5 && o.uniaxial[1] <= 10))
      throw knit::InputError("", "--uniaxial", "E must be in (-0.5, 10]");
    p.stretch = std::sqrt(1 + 2 * o.uniaxial[1]);
  } else {
    p.kind = PathSpec::Kind::kShear;
    p.gamma = o.shear * M_PI / 180.0;
    if (!(std::abs(o.shear) < 80))
      throw knit::InputError("", "--shear", "|gamma| must be < 80 deg");
  }
  // A loop too short for its yarn is bad input (exit 2, as in `knit-meso cell`), not a failed
  // computation: before, exit 1 with a message that named no option.
  const auto cell_ptr = [&] {
    try {
      return std::make_unique<PeriodicCell>(o.loop_length, co);
    } catch (const knit::meso::cell::GeometryError& e) {
      namespace kc = knit::meso::cell;
      const std::string msg = kc::loop_length_message(o.loop_length, co.section.d, e);
      // The config file's field when its value alone fails (session 29: /yarn/d = 1.5 mm and
      // /loop/gamma_over_w = 0 were reported at --loop-length).
      if (!o.config.empty()) {
        kc::GeometryOptions go = co.geometry;
        go.d = co.section.d;
        switch (kc::geometry_blame(o.loop_length, go, true, true)) {
          case kc::GeometryBlame::kDiameter:
            throw knit::InputError(o.config, "/yarn/d", msg);
          case kc::GeometryBlame::kGamma:
            throw knit::InputError(o.config, "/loop/gamma_over_w", msg);
          case kc::GeometryBlame::kLoopLength:
            break;
        }
      }
      throw knit::InputError("", "--loop-length", msg);
    }
  }();
  PeriodicCell& cell = *cell_ptr;
  // What the run cannot vouch for, before it starts (session 42's metamorphic red team: 8
  // elements gave an equibiaxial S11 52 % above 64 elements', 4 elements 130 %, and 12 mm
  // loops ran, each with exit 0 and no word).
  if (const std::string w = knit::meso::cell::loop_length_range_warning(o.loop_length); !w.empty())
    std::fprintf(stderr, "knit-meso path: %s\n", w.c_str());
  if (co.elements < CellOptions{}.elements)
    std::fprintf(stderr,
                 "knit-meso path: warning: %d analysis-curve elements, fewer than the default "
                 "%d: the stresses are not mesh-converged (docs/unit-cell.md, \"Convergence "
                 "study\": at 16 elements S is 5-20 %% above 64 elements', at 8 up to 52 %%)\n",
                 co.elements, CellOptions{}.elements);
  knit::io::AtomicDirectory dir(o.out, knit::io::AtomicDirectory::OnAbandon::Remove, "--out",
                                o.config);
  // An earlier output written before its marker said whether it completed (session 49) is
  // judged from its path.csv: a path output holds at least one converged step, and the path
  // completed when its last row is at lambda = 1 (session 50; before, such outputs were
  // replaced by a stopped rerun).
  dir.judge_earlier_by_files(
      [](const std::filesystem::path& out) { return path_csv_completed(out / "path.csv"); });
  // The outputs' size, estimated before the run from one VTP of the reference state (session
  // 41's red team: --steps 100000 started writing about 5.9 GB without a word; knit-meso rod
  // and knit-macro run have the same cap).
  const std::uint64_t cap = o.max_output_size.empty()
                                ? kDefaultMaxOutputBytes
                                : knit::io::parse_size(o.max_output_size, "--max-output-size");
  if (cap > 0) {
    std::uint64_t per_step = 200;  // a CSV row
    if (!o.no_vtp) {
      const std::string probe = (dir / "yarn_probe.vtp").string();
      write_step_vtp(cell, probe);
      per_step += std::filesystem::file_size(probe);
      std::filesystem::remove(probe);
    }
    const std::uint64_t est = per_step * (static_cast<std::uint64_t>(p.steps) + 1);
    if (est > cap)
      throw knit::InputError(
          "", "--steps",
          "the estimated output size " + knit::io::format_bytes(est) + " (" +
              std::to_string(p.steps + 1) + " steps of " + knit::io::format_bytes(per_step) +
              ") exceeds the cap of " + knit::io::format_bytes(cap) +
              ": use fewer --steps, --no-vtp, or raise the cap with --max-output-size");
  }
  std::string csv = csv_header();
  std::vector<std::pair<double, std::string>> pvd;
  const PathResult res = run_path(cell, p, [&](int k, const StepResult& r) {
    csv += csv_row(k, double(k) / p.steps, r);
    std::printf(
        "step %2d  E11=%+.4f E22=%+.4f E12=%+.4f  S11=%+.4f S22=%+.4f S12=%+.4f MPa  "
        "newton=%d  %.3f s\n",
        k, r.E(0, 0), r.E(1, 1), r.E(0, 1), r.S(0, 0), r.S(1, 1), r.S(0, 1), r.iterations,
        r.seconds);
    if (!o.no_vtp) {
      char name[64];
      std::snprintf(name, sizeof name, "yarn_%04d.vtp", k);
      write_step_vtp(cell, (dir / name).string());
      pvd.emplace_back(double(k), name);
    }
  });
  const int n = static_cast<int>(res.steps.size()) - 1;
  // A path with no converged load step writes nothing and leaves an earlier output in place,
  // as knit-macro run does (session 40's data-safety red team: `--biaxial 9 9` replaced a
  // complete earlier path by its reference state alone).
  if (!res.completed && n <= 0) {
    std::fprintf(stderr,
                 "knit-meso path: %s; no load step converged: nothing written; the earlier "
                 "outputs in %s, if any, are left as they were\n",
                 res.message.c_str(), o.out.c_str());
    return knit::kExitFailure;
  }
  knit::meso::cell::write_text_atomic((dir / "path.csv").string(), csv);
  if (!o.no_vtp) knit::meso::cell::write_pvd((dir / "yarn.pvd").string(), pvd);
  dir.set_completed(res.completed);  // a stopped run keeps a completed earlier output beside
  dir.commit();                      // a run that stopped early keeps its converged steps (exit 1)
  std::printf(
      "%s: %d steps in %.3f s (%.4f s/step, %.1f Newton iterations/step), "
      "equilibration %.3f s -> %s/path.csv\n",
      res.message.c_str(), n, res.seconds, n > 0 ? res.seconds / n : 0.0,
      n > 0 ? double(res.iterations) / n : 0.0, res.equilibration_seconds, o.out.c_str());
  if (res.completed) return knit::kExitOk;
  // Said on stderr too, as the other commands do (before: on stdout only, stderr empty).
  const std::string kept = dir.replaced_kept_in().empty() ? std::string()
                                                          : ", the completed earlier output in " +
                                                                dir.replaced_kept_in().string();
  std::fprintf(stderr, "knit-meso path: %s; the %d converged step(s) are kept in %s%s\n",
               res.message.c_str(), n, o.out.c_str(), kept.c_str());
  return knit::kExitFailure;
}

knit::cli::SubcommandRegistrar reg(
    "path", "Run one macroscopic deformation path on the unit cell (CSV + VTP)", [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      using knit::cli::Ends;
      using knit::cli::number;
      // Ranges: the cell schema's (schemas/cell.schema.json) for the cell parameters; strains
      // of a path in (-1, 10], shear angles in (-80, 80) degrees.
      sub.add_option("--loop-length", o->loop_length, "loop length l (mm)")
          ->required()
          ->check(number(0, 50, Ends::kOpenLow));
      auto* b = sub.add_option("--biaxial", o->biaxial, "EPS11 EPS22 of F* = diag(1+eps)")
                    ->expected(2)
                    ->check(number(-1, 10, Ends::kOpenLow));
      auto* s = sub.add_option("--shear", o->shear, "pure-shear angle gamma (degrees)")
                    ->check(number(-80, 80, Ends::kOpen));
      // The help names the two values (session 44's red team: "FLOAT in (-0.5, 10] x 2" for
      // an AXIS that must be 0 or 1); the validator checks that both are finite numbers, run()
      // AXIS (0 or 1) and E's range, each with its own words (the review of session 44: AXIS
      // 11 was refused with E's range).
      auto* u = sub.add_option("--uniaxial", o->uniaxial,
                               "AXIS E: uniaxial stress along AXIS (0 course, 1 wale) to the "
                               "Green-Lagrange strain E in (-0.5, 10]")
                    ->type_size(2)  // (as expected(2), without " x 2" after the names)
                    ->expected(1)
                    ->type_name("AXIS(0|1) E")
                    ->check(number(-std::numeric_limits<double>::infinity(),
                                   std::numeric_limits<double>::infinity())
                                .description(""));
      b->excludes(s);
      u->excludes(b);
      u->excludes(s);
      sub.add_option("--steps", o->steps, "load steps (default 20)")
          ->check(knit::cli::integer(1, 100000));
      sub.add_option("-o,--output,--out", o->out, "output directory");
      auto* ne =
          sub.add_option("--elements", o->elements_arg, "analysis-curve elements (default 32)")
              ->check(knit::cli::integer(4, knit::meso::homog::CellOptions::kMaxElements));
      // The contact's flags have the bounds of the same keys in --config (finite: below
      // 1e300; session 36's red team: --penalty 1e308 was taken here, refused there).
      const double finite = 1e300;
      // k_N in the cell's physical range (CellOptions::kMinPenalty, kMaxPenalty: 25-40000 MPa;
      // 1e-300 ran a cell without contact, exit 0).
      auto* kn = sub.add_option("--penalty", o->k_N_arg,
                                "normal penalty stiffness k_N (MPa, default 1000)")
                     ->check(number(knit::meso::homog::CellOptions::kMinPenalty,
                                    knit::meso::homog::CellOptions::kMaxPenalty));
      auto* g0 = sub.add_option("--allowance", o->g0_arg, "penetration allowance g0 (mm)")
                     ->check(number(0, finite));
      auto* dl = sub.add_option("--delta", o->delta_arg, "quadratic onset width delta (mm)")
                     ->check(number(0, finite, Ends::kOpenLow));
      auto* mu = sub.add_option("--mu", o->mu_arg, "Coulomb friction coefficient (default 0.15)")
                     ->check(number(0, finite));
      // k_T likewise (kMinStickPenalty, kMaxStickPenalty: 2-40000 MPa; 1e-300 ran a
      // frictionless cell, exit 0).
      auto* kt = sub.add_option("--stick", o->k_T_arg, "stick penalty k_T (MPa, default 20)")
                     ->check(number(knit::meso::homog::CellOptions::kMinStickPenalty,
                                    knit::meso::homog::CellOptions::kMaxStickPenalty));
      sub.add_flag("--no-vtp", o->no_vtp, "skip the per-step VTP files");
      sub.add_option("--max-output-size", o->max_output_size,
                     "refuse the path before the run if its outputs are estimated above this "
                     "size (default 2GB; e.g. 500MB, 10GB; 0 = no cap)");
      sub.add_option("--config", o->config,
                     "JSON cell parameters (schemas/cell.schema.json); flags override it");
      return [o, ne, kn, g0, dl, mu, kt]() {
        if (ne->count()) o->elements = o->elements_arg;
        if (kn->count()) o->k_N = o->k_N_arg;
        if (g0->count()) o->g0 = o->g0_arg;
        if (dl->count()) o->delta = o->delta_arg;
        if (mu->count()) o->mu = o->mu_arg;
        if (kt->count()) o->k_T = o->k_T_arg;
        return run(*o);
      };
    });

}  // namespace
}  // namespace knit::meso::cmd_path
