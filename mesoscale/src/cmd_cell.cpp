// knit-meso cell --loop-length L [--out DIR] [--diameter D] [--gamma-over-w G] [--config CELL.json]
//   Writes (atomically, like every output directory) the single-jersey unit-cell geometry for a
//   look before simulating (paper Sect. 2.1.2): DIR/cell.vtp   the four B-spline curves of eq. 5
//   sampled as polylines with a radius array, plus
//                  the 8 periodic neighbours (cell array "image" > 0);
//   DIR/cell.json  w, c, h, measured l, minimum clearance between yarns, crossing order.
//   --config reads the yarn diameter and the loop shape from a cell parameter file
//   (schemas/cell.schema.json, the same object as a sweep's inline "cell"); --diameter and
//   --gamma-over-w given on the command line override it.
//   Every option is range-checked before any work (exit 2, the message names the option).
// Example: knit-meso cell --loop-length 4.5 --out cell45
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "knit/core/cli.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/meso/cell/geometry.hpp"
#include "knit/meso/cell/output.hpp"
#include "knit/meso/homog/cell_config.hpp"

// A named namespace per command: the cmd_*.cpp files share one unity translation unit
// (docs/build.md), and each defines its own Options, run and reg.
namespace knit::meso::cmd_cell {
namespace {

struct Options {
  double loop_length = 0;
  std::string out = "cell";
  double d = 0.38;
  double gamma_over_w = knit::meso::cell::GeometryOptions{}.gamma_over_w;
  int samples = 60;
  std::string config;
  bool d_given = false, gamma_given = false;  ///< flags override --config
};

// The ranges of the options (docs/unit-cell.md): the loop length as in the sweep schema, the
// yarn diameter and the loop bulge as in the cell schema.
constexpr double kMaxLoopLength = 50.0;  // mm

int run(const Options& o) {
  using namespace knit::meso::cell;
  // The parser's validators already refused non-finite and out-of-range values; these
  // re-checks keep run() safe on its own.
  if (!(o.loop_length > 0 && o.loop_length <= kMaxLoopLength))
    throw knit::InputError("", "--loop-length",
                           "must be in (0, 50] mm, got " + std::to_string(o.loop_length));
  GeometryOptions go;
  // The contact allowance the cell would be solved with (the sweep's and path's): a yarn no
  // thicker than it is refused, as CellOptions::validate refuses it there (session 44's red
  // team: --diameter 1e-300 wrote a cell whose yarns' centrelines were 1e-16 mm apart, exit 0).
  double allowance = knit::meso::homog::CellOptions{}.contact.penalty.g0;
  if (!o.config.empty()) {  // yarn diameter and loop shape from the cell parameters
    const auto co = knit::meso::homog::read_cell_options(o.config);
    go.d = co.section.d;
    go.gamma_over_w = co.geometry.gamma_over_w;
    allowance = co.contact.penalty.g0;
  }
  if (o.d_given || o.config.empty()) go.d = o.d;
  if (o.gamma_given || o.config.empty()) go.gamma_over_w = o.gamma_over_w;
  if (!(go.d > 0 && std::isfinite(go.d)))
    throw knit::InputError("", "--diameter", "must be a finite number > 0");
  if (std::isfinite(allowance) && !(go.d > allowance)) {
    std::ostringstream m;
    m << "must be larger than the contact allowance " << allowance << " mm"
      << (o.config.empty() ? " (its default)" : " (/contact/allowance of " + o.config + ")")
      << ", got " << go.d
      << " mm: the yarns' centrelines lie about one diameter apart, and within the allowance "
         "they would pass through each other without force";
    if (o.d_given || o.config.empty()) throw knit::InputError("", "--diameter", m.str());
    throw knit::InputError(o.config, "/yarn/d", m.str());
  }
  if (!(go.gamma_over_w >= 0 && go.gamma_over_w <= 1))
    throw knit::InputError("", "--gamma-over-w", "must be in [0, 1]");
  knit::io::check_output_target(o.out, knit::io::OutputKind::kDirectory, "--out");
  const CellGeometry g = [&] {
    try {
      CellGeometry built = make_cell_geometry(o.loop_length, go);
      if (const auto bad = interlock_defect(built.shape, built.dim.c)) throw GeometryError(*bad);
      return built;
    } catch (const GeometryError& e) {  // a loop that cannot be built or does not interlock
      // Named where the culprit was given: the config file's field, the flag, or the loop
      // length (session 29: a config's /yarn/d = 1.5 mm was reported at --loop-length).
      const std::string msg = loop_length_message(o.loop_length, go.d, e);
      const bool from_file = !o.config.empty();
      switch (
          geometry_blame(o.loop_length, go, o.d_given || from_file, o.gamma_given || from_file)) {
        case GeometryBlame::kDiameter:
          if (o.d_given) throw knit::InputError("", "--diameter", msg);
          throw knit::InputError(o.config, "/yarn/d", msg);
        case GeometryBlame::kGamma:
          if (o.gamma_given) throw knit::InputError("", "--gamma-over-w", msg);
          throw knit::InputError(o.config, "/loop/gamma_over_w", msg);
        case GeometryBlame::kLoopLength:
          break;
      }
      throw knit::InputError("", "--loop-length", msg);
    }
  }();
  knit::io::AtomicDirectory dir(o.out, knit::io::AtomicDirectory::OnAbandon::Remove, "--out",
                                o.config);

  std::vector<Polyline> lines;
  int image = 0;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      const Eigen::Vector3d t(i * g.dim.w, j * g.dim.c, 0);
      const int img = (i == 0 && j == 0) ? 0 : ++image;
      for (std::size_t k = 0; k < g.pieces.size(); ++k) {
        Polyline pl;
        pl.piece = int(k);
        pl.image = img;
        for (int q = 0; q <= o.samples; ++q)
          pl.points.push_back(g.pieces[k].eval(double(q) / o.samples).head<3>() + t);
        lines.push_back(std::move(pl));
      }
    }
  write_polylines_vtp((dir / "cell.vtp").string(), lines, 0.5 * go.d);

  const Clearance cl = minimum_clearance(g.shape, g.dim.c);
  nlohmann::json j;
  // (session 44's red team: the file carried no units)
  j["units"] = "mm (every length and distance of this file; the curves' counts are numbers)";
  j["loop_length"] = g.dim.loop_length;
  j["w"] = g.dim.w;
  j["c"] = g.dim.c;
  j["yarn_diameter"] = g.shape.d;
  j["loop_height_h"] = g.shape.h;
  j["gamma"] = g.shape.gamma;
  j["measured_length"] = g.measured_length;
  j["curves"] = {{"count", g.pieces.size()}, {"degree", 4}, {"control_points", 12}};
  j["min_centerline_distance"] = cl.min_distance;
  j["min_clearance"] = cl.clearance;
  j["min_clearance_note"] = "centerline distance minus d; negative = initial overlap";
  j["min_clearance_at"] = {
      {"s_self", cl.s_self}, {"s_other", cl.s_other}, {"shift", {cl.shift_i, cl.shift_j}}};
  nlohmann::json xs = nlohmann::json::array();
  for (const auto& x : crossings_with_next_course(g.shape, g.dim.c))
    xs.push_back({{"s_self", x.s_self},
                  {"part_self", x.part_self},
                  {"s_next_course", x.s_other},
                  {"part_next_course", x.part_other},
                  {"dz", x.dz},
                  {"in_front", x.dz > 0 ? "self" : "next course"}});
  j["crossings_with_next_course"] = xs;
  write_text_atomic((dir / "cell.json").string(), j.dump(2) + "\n");
  dir.commit();
  // (session 42's metamorphic red team: loop lengths up to 50 mm were accepted without a word)
  if (const std::string w = loop_length_range_warning(g.dim.loop_length); !w.empty())
    std::cerr << "knit-meso cell: " << w << "\n";
  std::cout << "cell l=" << g.dim.loop_length << " mm: w=" << g.dim.w << " c=" << g.dim.c
            << " h=" << g.shape.h << " measured l=" << g.measured_length
            << " min clearance=" << cl.clearance << " mm -> " << o.out << "/cell.{vtp,json}\n";
  return knit::kExitOk;
}

knit::cli::SubcommandRegistrar reg(
    "cell", "Write the single-jersey unit-cell geometry (VTP + JSON)", [](CLI::App& sub) {
      auto o = std::make_shared<Options>();
      using knit::cli::Ends;
      const double inf = std::numeric_limits<double>::infinity();
      sub.add_option("--loop-length", o->loop_length, "loop length l (mm)")
          ->required()
          ->check(knit::cli::number(0, kMaxLoopLength, Ends::kOpenLow));
      sub.add_option("-o,--output,--out", o->out, "output directory");
      auto* d = sub.add_option("--diameter", o->d, "yarn diameter d (mm)")
                    ->check(knit::cli::number(0, inf, Ends::kOpenLow));
      auto* g = sub.add_option("--gamma-over-w", o->gamma_over_w, "loop bulge gamma / w")
                    ->check(knit::cli::number(0, 1));
      sub.add_option("--config", o->config,
                     "JSON cell parameters (schemas/cell.schema.json): yarn d and loop shape; "
                     "flags override it");
      return [o, d, g]() {
        o->d_given = d->count() > 0;
        o->gamma_given = g->count() > 0;
        return run(*o);
      };
    });

}  // namespace
}  // namespace knit::meso::cmd_cell
