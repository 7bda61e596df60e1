// Case input of the knit material (the "knit" branch of the material factory):
//
//   "material": {
//     "type": "knit",
//     "database": "db.h5",                        // relative to the case file's directory
//     "stitch_value": 5.5 | {field},              // l(theta1, theta2), mm
//     "knitting_angle": 0.0 | {field} | {"align_with": [vx, vy, vz], "degrees": [pu, pv],
//                                         "knots_u": [...], "knots_v": [...]},
//     "law": "energy" | "paper",   // default: "energy" when the database has it, else "paper"
//     "uniaxial_tolerance": 0.25   // energy law: warn where its own uniaxial response departs
//                                  // from the cell's by more than this (KnitMaterial::warning())
//   }
//   {field} = {"degrees": [pu, pv], "knots_u": [...], "knots_v": [...], "values": [...],
//              "unit": "rad" | "deg" (knitting angle only)}
// Control values run with the u index fastest; repeated knots give discontinuous grading.
// A field's domain must equal the patch's parameter domain. A stitch value outside the
// database's loop lengths is an error naming the field and the range.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/json_input.hpp"
#include "knit/macro/geometry_check.hpp"
#include "knit/macro/knit_material.hpp"
#include "knit/macro/material_factory.hpp"
#include "knit/material/database.hpp"
#include "knit/material/response_surface.hpp"
#include "knit/spline/basis.hpp"

namespace knit::macro {

namespace {

/// A patch whose size (its control net's bounding-box diagonal) is below this many times the
/// database's largest loop runs with a warning (session 46): 3 x 6.5 mm, about 15 stitches.
constexpr double kFewLoops = 3.0;
/// The bounds of the law's largest stress at 5 % strain (MPa; the check in make_knit_material).
constexpr double kMinLawStress = 1e-9, kMaxLawStress = 1e9;

std::vector<double> number_array(const nlohmann::json& j, const std::string& p,
                                 const CaseContext& ctx) {
  if (!j.is_array()) throw InputError(ctx.file, p, "must be an array of numbers");
  std::vector<double> v;
  for (std::size_t k = 0; k < j.size(); ++k) {
    if (!j[k].is_number())
      throw InputError(ctx.file, p + "/" + std::to_string(k), "must be a number");
    v.push_back(j[k].get<double>());
  }
  return v;
}

void check_keys(const nlohmann::json& j, const std::string& p, const CaseContext& ctx,
                const std::vector<std::string>& allowed) {
  if (auto u = io::find_unknown_key(j, p, allowed))
    throw InputError(ctx.file, u->pointer, "unknown key" + u->note);
}

struct Basis2 {
  int pu = 0, pv = 0;
  std::vector<double> U, V;
};

Basis2 read_basis(const nlohmann::json& j, const std::string& p, const CaseContext& ctx) {
  Basis2 b;
  for (const char* k : {"degrees", "knots_u", "knots_v"})
    if (!j.contains(k))
      throw InputError(ctx.file, p, std::string("missing required key \"") + k + "\"");
  const auto d = number_array(j.at("degrees"), p + "/degrees", ctx);
  if (d.size() != 2 || d[0] < 0 || d[1] < 0 || d[0] != std::floor(d[0]) || d[1] != std::floor(d[1]))
    throw InputError(ctx.file, p + "/degrees", "must be two non-negative integers");
  // Range before the conversion to int (1e10 overflowed it: undefined behaviour).
  for (int k = 0; k < 2; ++k)
    if (d[k] > spline::kMaxDegree)
      throw InputError(ctx.file, p + "/degrees/" + std::to_string(k),
                       "must be at most " + std::to_string(spline::kMaxDegree) + ", got " +
                           nlohmann::json(d[k]).dump());
  b.pu = static_cast<int>(d[0]);
  b.pv = static_cast<int>(d[1]);
  b.U = number_array(j.at("knots_u"), p + "/knots_u", ctx);
  b.V = number_array(j.at("knots_v"), p + "/knots_v", ctx);
  for (int dir = 0; dir < 2; ++dir) {
    const std::string kp = p + (dir == 0 ? "/knots_u" : "/knots_v");
    try {
      const spline::BSplineBasis basis(dir == 0 ? b.pu : b.pv, dir == 0 ? b.U : b.V);
      const auto& pb = dir == 0 ? ctx.patch->basis_u() : ctx.patch->basis_v();
      if (std::abs(basis.lo() - pb.lo()) > 1e-12 || std::abs(basis.hi() - pb.hi()) > 1e-12)
        throw InputError(ctx.file, kp,
                         "the field's domain [" + io::format_number(basis.lo()) + ", " +
                             io::format_number(basis.hi()) + "] differs from the patch's [" +
                             io::format_number(pb.lo()) + ", " + io::format_number(pb.hi()) +
                             "]");  // (std::to_string wrote a knot of 1e308 with 300 digits)
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      throw InputError(ctx.file, kp, e.what());
    }
  }
  return b;
}

// A knitting angle (rad) within one turn either way: a larger one is the same direction as one
// inside, and 1e308 rad is no direction at all (session 21: accepted with exit 0, its cosine
// rounding noise).
void check_angle(double a, const std::string& p, const CaseContext& ctx, bool deg) {
  constexpr double kTurn = 2.0 * std::numbers::pi;
  if (!(std::abs(a) <= kTurn)) {
    // Printed with as many digits as it takes to differ from the bound printed alike (session
    // 40's red team: 2 pi + 1e-12 read "must lie in [-2 pi, 2 pi] rad, got 6.28319").
    const double shown = deg ? a * 180.0 / std::numbers::pi : a, bound = deg ? 360.0 : kTurn;
    std::string got;
    for (int digits = 6; digits <= 17; ++digits) {
      std::ostringstream v, b;
      v.precision(digits);
      b.precision(digits);
      v << std::abs(shown);
      b << bound;
      got = v.str();
      if (got != b.str()) break;
    }
    if (shown < 0.0) got = "-" + got;
    std::ostringstream m;
    m << "a knitting angle must lie in " << (deg ? "[-360, 360] deg" : "[-2 pi, 2 pi] rad")
      << ", got " << got << " (a larger angle is the same course direction as one inside)";
    // An angle meant in degrees (session 39's walkthrough: "values": [30] with no unit).
    if (!deg && std::abs(a) <= 360.0)
      m << "; if it is in degrees, give the spline field \"unit\": \"deg\" (a constant angle as "
           "{\"degrees\": [0, 0], \"knots_u\": [0, 1], \"knots_v\": [0, 1], \"values\": ["
        << a << "], \"unit\": \"deg\"})";
    throw InputError(ctx.file, p, m.str());
  }
}

spline::SplineSurface read_field(const nlohmann::json& j, const std::string& p,
                                 const CaseContext& ctx, bool angle) {
  const auto& pu = ctx.patch->basis_u();
  const auto& pv = ctx.patch->basis_v();
  double scale = 1.0;
  if (j.is_number()) {
    if (angle) check_angle(j.get<double>(), p, ctx, false);
    return make_scalar_field(
        ScalarFieldSpec::constant(j.get<double>(), pu.lo(), pu.hi(), pv.lo(), pv.hi()));
  }
  if (!j.is_object()) throw InputError(ctx.file, p, "must be a number or a spline field object");
  if (angle && j.contains("align_with")) {
    check_keys(j, p, ctx, {"align_with", "degrees", "knots_u", "knots_v", "description"});
    const auto v = number_array(j.at("align_with"), p + "/align_with", ctx);
    if (v.size() != 3) throw InputError(ctx.file, p + "/align_with", "must have 3 components");
    const Basis2 b = read_basis(j, p, ctx);
    try {
      return align_alpha_field(*ctx.patch, b.pu, b.U, b.pv, b.V, Eigen::Vector3d(v[0], v[1], v[2]));
    } catch (const std::exception& e) {
      throw InputError(ctx.file, p + "/align_with", e.what());
    }
  }
  check_keys(
      j, p, ctx,
      angle ? std::vector<std::string>{"degrees", "knots_u", "knots_v", "values", "unit",
                                       "description"}
            : std::vector<std::string>{"degrees", "knots_u", "knots_v", "values", "description"});
  if (angle && j.contains("unit")) {
    const std::string u = j.at("unit").is_string() ? j.at("unit").get<std::string>() : "";
    if (u == "deg")
      scale = std::numbers::pi / 180.0;
    else if (u != "rad")
      throw InputError(ctx.file, p + "/unit", "must be \"rad\" or \"deg\"");
  }
  const Basis2 b = read_basis(j, p, ctx);
  if (!j.contains("values")) throw InputError(ctx.file, p, "missing required key \"values\"");
  ScalarFieldSpec s;
  s.degree_u = b.pu;
  s.degree_v = b.pv;
  s.knots_u = b.U;
  s.knots_v = b.V;
  s.values = number_array(j.at("values"), p + "/values", ctx);
  for (double& x : s.values) x *= scale;
  if (angle)
    for (std::size_t i = 0; i < s.values.size(); ++i)
      check_angle(s.values[i], p + "/values/" + std::to_string(i), ctx, scale != 1.0);
  try {
    return make_scalar_field(s);
  } catch (const std::exception& e) {
    throw InputError(ctx.file, p + "/values", e.what());
  }
}

}  // namespace

std::unique_ptr<Material> make_knit_material(const nlohmann::json& m, const CaseContext& ctx) {
  const std::string& p = ctx.pointer;
  check_keys(m, p, ctx,
             {"type", "database", "stitch_value", "knitting_angle", "law", "description",
              "uniaxial_tolerance"});
  for (const char* k : {"database", "stitch_value"})
    if (!m.contains(k))
      throw InputError(ctx.file, p, std::string("missing required key \"") + k + "\"");
  if (!m.at("database").is_string())
    throw InputError(ctx.file, p + "/database", "must be a file name");
  // "" resolved to the case's own directory (session 36's red team).
  if (m.at("database").get<std::string>().empty())
    throw InputError(ctx.file, p + "/database", "must not be empty: give the database's file");
  if (!ctx.patch) throw InputError(ctx.file, p, "the knit material needs the patch");
  std::filesystem::path db = m.at("database").get<std::string>();
  const bool relative = db.is_relative();
  if (relative && !ctx.file.empty()) db = std::filesystem::path(ctx.file).parent_path() / db;
  material::Database data;
  try {
    data = material::read_database(db, false);
  } catch (const InputError& e) {
    // A relative path is the case file's (session 47's walkthrough: "out/database.h5: file not
    // found" did not say where it was looked for).
    std::error_code ec;
    std::string hint;
    if (relative && !std::filesystem::exists(db, ec))
      hint = " (a relative database path is taken from the case file's directory: here " +
             std::filesystem::absolute(db, ec).lexically_normal().string() + ")";
    throw InputError(ctx.file, p + "/database", e.what() + hint);
  }
  // The law: "energy" (issue 11) by default when the database has it, else "paper" (eq. 17).
  std::string law = data.energy_law ? "energy" : "paper";
  if (m.contains("law")) {
    law = m.at("law").is_string() ? m.at("law").get<std::string>() : "";
    if (law != "energy" && law != "paper")
      throw InputError(ctx.file, p + "/law", "must be \"energy\" or \"paper\"");
  }
  std::shared_ptr<const material::EnergyLaw> energy;
  if (law == "energy") {
    try {
      energy = std::make_shared<const material::EnergyLaw>(
          material::require_energy_law(data, db.string()));
    } catch (const InputError& e) {
      throw InputError(ctx.file, p + "/law", e.what());
    }
  }
  std::shared_ptr<const material::LoopLengthFamily> family;
  try {
    if (law == "paper") family = std::make_shared<const material::LoopLengthFamily>(data.family());
  } catch (const std::exception& e) {
    throw InputError(ctx.file, p + "/database", db.string() + ": " + e.what());
  }
  // Every stored law must be usable (e.g. an E-surface folded by a damaged file): refused
  // here, naming the database and the HDF5 group, before any work. A loop length without a
  // paper-law surface (a database fitted with the energy law only, session 38's red team: the
  // empty optional was read) has nothing to check; the paper law refuses it in family().
  for (std::size_t k = 0; k < data.entries.size(); ++k) {
    if (!data.entries[k].surface) continue;
    try {
      const material::ResponseSurface check(*data.entries[k].surface);
    } catch (const std::exception& e) {
      throw InputError(ctx.file, p + "/database",
                       db.string() + ": /loop_" + std::to_string(k) + "/fit: " + e.what());
    }
  }
  // The law's stress scale (session 49's red team: control points scaled by 1e-200, or a ridge
  // law of zero coefficients and floor, ran to "completed" with a load of 1e-197 N or 0 and
  // exit 0; scaled by 1e300, the run overflowed and blamed the case): at every loop length of
  // the database the law's largest stress component at 5 % strain along the course, the wale
  // and both must lie in [kMinLawStress, kMaxLawStress] MPa. A fabric at 5 % strain carries at
  // least the stiffness floor's share (0.01 x its secant stiffness) and at most what its yarn
  // (E of order 1e3 MPa) can: the bounds are 1e-9 and 1e9 MPa, ten decades beyond both.
  for (std::size_t k = 0; k < data.entries.size(); ++k) {
    const double l = data.entries[k].loop_length;
    if (!energy && !data.entries[k].surface) continue;
    // The law at this loop length, built once (a paper surface was checked above).
    std::optional<material::EnergyLawAt> at;
    std::optional<material::ResponseSurface> surface;
    if (energy)
      at.emplace(energy->at(l));
    else
      surface.emplace(*data.entries[k].surface);
    double largest = 0.0;
    bool finite = true;
    for (const Eigen::Vector3d& e :
         {Eigen::Vector3d(0.05, 0.0, 0.0), Eigen::Vector3d(0.0, 0.05, 0.0),
          Eigen::Vector3d(0.05, 0.05, 0.0)}) {
      const Eigen::Vector3d S = at ? at->evaluate(e).S : surface->evaluate(e).S;
      finite = finite && S.allFinite();
      if (finite) largest = std::max(largest, S.cwiseAbs().maxCoeff());
    }
    if (finite && largest >= kMinLawStress && largest <= kMaxLawStress) continue;
    std::ostringstream os;
    os << db.string() << ": "
       << (energy ? std::string("/energy_law") : "/loop_" + std::to_string(k) + "/fit")
       << ": at l = " << l << " mm the " << (energy ? "energy" : "paper")
       << " law's stress at 5 % strain ";
    if (!finite)
      os << "is not finite";
    else
      os << "reaches " << largest << " MPa, " << (largest < kMinLawStress ? "below " : "above ")
         << (largest < kMinLawStress ? kMinLawStress : kMaxLawStress);
    os << " MPa: not a fabric's law in MPa (a damaged or rescaled file?); refit it with knit-meso "
          "fit";
    throw InputError(ctx.file, p + "/database", os.str());
  }
  // The database's stresses are per its cell's thickness t = 2d (eq. 8's volume w c t): a
  // shell of another thickness scales every force by the ratio (session 39's walkthrough: a
  // 0.30 mm yarn's database, t = 0.60 mm, under a case copied with 0.76 mm gave 27 % more load
  // with exit 0). Databases without cell parameters (thickness 0) cannot say.
  for (std::size_t k = 0; k < data.entries.size() && ctx.thickness > 0.0; ++k) {
    const double t = data.entries[k].cell.thickness;
    if (t > 0.0 && std::abs(ctx.thickness - t) > 1e-6 * t) {
      std::ostringstream os;
      os << "the shell's thickness " << ctx.thickness << " mm is not the database's cell "
         << "thickness t = 2d = " << t << " mm (" << db.string() << ", /loop_" << k
         << "@thickness), per which its stresses are homogenized: every force would be "
         << ctx.thickness / t << " times the fabric's; set /geometry/thickness to " << t;
      throw InputError(ctx.file, "/geometry/thickness", os.str());
    }
  }
  std::string small_patch;
  {
    // A homogenized fabric spans many stitches: a patch smaller than one loop of the database
    // is a case in other units (a 50 mm patch written in metres ran with exit 0, session 22).
    const double size = patch_size(*ctx.patch);
    const double l_max = energy ? energy->data().l_max : family->max();
    if (!(size >= l_max)) {
      std::ostringstream os;
      os << "the patch (size " << size
         << " mm, the diagonal of its control net's bounding box) is smaller than one loop of "
            "the database ("
         << l_max << " mm, " << db.string()
         << "): a knit case is in mm, N, MPa, and a homogenized fabric spans many stitches";
      throw InputError(ctx.file, "/geometry/control_points", os.str());
    }
    // A few loops only: runs, but is likely a case in cm (session 46's walkthrough: a 60 x 40
    // mm patch written in cm ran as 6 x 4 mm, some 4 stitches by 3 courses, with exit 0).
    if (size < kFewLoops * l_max) {
      std::ostringstream os;
      os.precision(3);
      os << "warning: " << ctx.file << ": /geometry/control_points: the patch is only " << size
         << " mm across (the diagonal of its control net's bounding box), " << size / l_max
         << " times the database's largest loop (" << l_max
         << " mm): a homogenized fabric spans many stitches, and a knit case is in mm (is it "
            "in cm?)";
      small_patch = os.str();
    } else {
      // A strip narrower than one loop (the second review of session 46: a 200 x 10 mm strip
      // written in cm, 20 x 1 mm, has a diagonal above the limit): the patch's width, its
      // shorter parameter line through the middle (until session 47 the bounding box's second
      // extent, which a strip turned 45 deg in its plane escaped: 14.8 mm for 20 x 1 mm).
      const double width = patch_width(*ctx.patch);
      if (width < l_max) {
        std::ostringstream os;
        os.precision(3);
        os << "warning: " << ctx.file << ": /geometry/control_points: the patch is only " << width
           << " mm wide (its shorter parameter line through the middle), less than the "
           << "database's largest loop (" << l_max
           << " mm): a homogenized fabric spans many stitches, and a knit case is in mm (is it "
              "in cm?)";
        small_patch = os.str();
      }
    }
  }
  const auto l = read_field(m.at("stitch_value"), p + "/stitch_value", ctx, false);
  const auto a = m.contains("knitting_angle")
                     ? read_field(m.at("knitting_angle"), p + "/knitting_angle", ctx, true)
                     : read_field(nlohmann::json(0.0), p + "/knitting_angle", ctx, true);
  KnitMaterialSource src;
  src.file = ctx.file;
  src.stitch_pointer = p + "/stitch_value";
  src.angle_pointer = p + "/knitting_angle";
  src.database = db.string();
  // When the database file was written: results.h5 keeps it, and the report refuses results
  // of another database (session 38's red team).
  src.database_date_utc = data.provenance.date_utc;
  src.input_warning = small_patch;
  // An align_with field follows its direction only as far as its basis can (session 51's red
  // team: a constant field on a half-annulus turned the courses up to 90 deg off, exit 0).
  if (m.contains("knitting_angle") && m.at("knitting_angle").is_object() &&
      m.at("knitting_angle").contains("align_with")) {
    const auto& w = m.at("knitting_angle").at("align_with");
    const AlignDeviation d = align_deviation(
        *ctx.patch, a, Eigen::Vector3d(w[0].get<double>(), w[1].get<double>(), w[2].get<double>()));
    if (!(d.radians <= kAlignWarning)) {
      std::ostringstream os;
      os.precision(3);
      os << "warning: " << ctx.file << ": " << p
         << "/knitting_angle: the fitted angle field turns the courses up to "
         << d.radians * 180.0 / std::numbers::pi << " deg off align_with (at (theta1, theta2) = ("
         << d.u << ", " << d.v << "); more than " << kAlignWarning * 180.0 / std::numbers::pi
         << " deg): it interpolates the direction at its Greville points only; give it more "
            "knots (knots_u, knots_v) or a higher degree (degrees)";
      src.input_warning += (src.input_warning.empty() ? "" : "\n") + os.str();
    }
  }
  // A constant angle follows A1 (eq. 19): on a flat patch whose A1 turns, the courses fan out
  // (session 56's red team: NURBS weights 1, 2, 3, 1 on a flat square, 22.6 deg, 23 % more
  // jaw force, no word).
  // Constant: a number, absent, or a field whose values are all one (the review of session 56:
  // the one-value field that design files vary); an align_with field is warned of above.
  const bool align = m.contains("knitting_angle") && m.at("knitting_angle").is_object() &&
                     m.at("knitting_angle").contains("align_with");
  if (!align && a.control_points().maxCoeff() == a.control_points().minCoeff()) {
    const AlignDeviation t = course_turn(*ctx.patch);
    if (t.radians > kAlignWarning) {
      std::ostringstream os;
      os.precision(3);
      os << "warning: " << ctx.file << ": " << p
         << "/knitting_angle: the angle is constant, measured from A1 = dX/dtheta1 (eq. 19), and "
            "A1 turns up to "
         << t.radians * 180.0 / std::numbers::pi
         << " deg across this flat patch (against its direction at the patch's centre; at "
            "(theta1, theta2) = ("
         << t.u << ", " << t.v << "); more than " << kAlignWarning * 180.0 / std::numbers::pi
         << " deg), so the courses fan out with it; for straight courses give "
            "\"knitting_angle\": {\"align_with\": [x, y, z], \"degrees\": ..., \"knots_u\": ..., "
            "\"knots_v\": ...} (docs/case-format.md)";
      src.input_warning += (src.input_warning.empty() ? "" : "\n") + os.str();
    }
  }
  // An old file is read unverified (session 54: knit-meso fit said so, knit-macro said nothing).
  if (!data.checksummed) {
    std::ostringstream os;
    os << "warning: " << db.string() << ": written without checksums (format_version "
       << data.format_version
       << ", before the integrity checks of issue 14), so a change to its law or data cannot be "
          "ruled out; `knit-meso fit` rewrites it with checksums";
    src.input_warning += (src.input_warning.empty() ? "" : "\n") + os.str();
  }
  if (data.sweep_failed_cases > 0) {
    // Session 48's walkthrough: a case ran on a failed sweep's database with exit 0 and no
    // word of the cases that failed.
    std::ostringstream os;
    os << "warning: " << db.string() << ": /sweep/report@failed_cases: the sweep that wrote "
       << "this database failed (" << data.sweep_failed_cases << " case"
       << (data.sweep_failed_cases == 1 ? " did" : "s did")
       << " not converge; knit-meso sweep wrote it for the diagnosis, with exit 1): its laws "
          "lack those cases' states; rerun the sweep (its summary says why they failed)";
    src.input_warning += (src.input_warning.empty() ? "" : "\n") + os.str();
  }
  // A synthetic stand-in is no knit's response (session 50's red team: knit-meso synth wrote
  // over a swept database in place, and a wale-wise case ran on it to 41.3 N for 154.7 N, exit 0,
  // with "synthetic" nowhere in its outputs): said wherever the case's warnings go.
  if (data.generator == "synth" || data.generator.find("synthetic") != std::string::npos) {
    std::ostringstream os;
    os << "warning: " << db.string() << ": /@generator: this database is a synthetic stand-in (\""
       << data.generator
       << "\": knit-meso synth, or a sweep with the synthetic runner), not the unit cell's "
          "response: its laws are closed-form placeholders for tests and demonstrations, and "
          "the results are not a knitted fabric's; for those, write the database with "
          "knit-meso sweep (runner \"cell\", the default)";
    src.input_warning += (src.input_warning.empty() ? "" : "\n") + os.str();
  }
  // The law's own uniaxial response beside the cell's (session 41): warned about after a run
  // where it departs by more than /material/uniaxial_tolerance (KnitMaterial::warning()).
  // Every loop length of the diagnostics, those without a curve too: the knots' neighbours
  // decide which laws a point's l uses (session 41's review: a loop length left out made a
  // 5.2 mm case name the 6 mm law).
  if (energy) {
    const auto& per_loop = data.energy_diagnostics.per_loop;
    const bool any = std::any_of(per_loop.begin(), per_loop.end(), [](const auto& pl) {
      return !pl.uniaxial[0].empty() || !pl.uniaxial[1].empty();
    });
    if (any)
      for (const auto& pl : per_loop) src.uniaxial.emplace_back(pl.loop_length, pl.uniaxial);
  }
  src.uniaxial_tolerance_pointer = p + "/uniaxial_tolerance";
  if (m.contains("uniaxial_tolerance")) {
    // Refused rather than passed over (session 41's review): the paper's law has no curves.
    if (!energy)
      throw InputError(ctx.file, p + "/uniaxial_tolerance",
                       "applies to the energy law only (its uniaxial curves); the case uses the "
                       "paper's law: remove the key, or set " +
                           p + "/law to \"energy\"");
    const auto& v = m.at("uniaxial_tolerance");
    if (!v.is_number() || !(v.get<double>() > 0.0) || !std::isfinite(v.get<double>()))
      throw InputError(ctx.file, p + "/uniaxial_tolerance",
                       "must be a positive number (the largest |law / cell - 1| of the law's "
                       "own uniaxial stress tolerated without a warning; default 0.25)");
    src.uniaxial_tolerance = v.get<double>();
  }
  if (m.at("stitch_value").is_number()) {
    // A constant: name the value itself rather than a control value.
    const double v = m.at("stitch_value").get<double>();
    const double lo = energy ? energy->data().l_min : family->min();
    const double hi = energy ? energy->data().l_max : family->max();
    if (!(v >= lo && v <= hi)) {
      std::ostringstream os;
      os << loop_length_outside(v, lo, hi) << " (" << db.string() << ")";
      throw InputError(ctx.file, p + "/stitch_value", os.str());
    }
  }
  return std::make_unique<KnitMaterial>(family, energy, l, a, src);
}

}  // namespace knit::macro
