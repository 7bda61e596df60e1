// JSON reader of the unit-cell parameters: see knit/meso/homog/cell_config.hpp.
#include "knit/meso/homog/cell_config.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/io/json_input.hpp"

namespace knit::meso::homog {

namespace {

using nlohmann::json;

struct Reader {
  std::string file;
  std::string prefix;  ///< pointer of the cell object inside its document
  [[noreturn]] void fail(const std::string& ptr, const std::string& msg) const {
    throw InputError(file, prefix + ptr, msg);
  }
  void object(const json& j, const std::string& ptr, const std::set<std::string>& allowed) const {
    if (!j.is_object()) fail(ptr, "must be an object");
    if (auto u = io::find_unknown_key(j, ptr, {allowed.begin(), allowed.end()}))
      fail(ptr, "unknown key \"" + u->key + "\"" + u->note);
  }
  // Reads j[key] into v if present; checks lo < v (strict) or lo <= v and v <= hi.
  void num(const json& j, const std::string& ptr, const char* key, double& v, double lo, double hi,
           bool strict_lo, bool strict_hi = false) const {
    if (!j.contains(key)) return;
    const json& x = j[key];
    const std::string p = ptr + "/" + key;
    if (!x.is_number()) fail(p, "must be a number");
    const double d = x.get<double>();
    if ((strict_lo ? !(d > lo) : !(d >= lo)) || (strict_hi ? !(d < hi) : !(d <= hi))) {
      std::ostringstream m;
      m.precision(12);  // 0.49999995 printed as 0.5 beside "<= 0.5" (session 25)
      m << "must be " << (strict_lo ? "> " : ">= ") << lo;
      if (hi < 1e299)
        m << (strict_hi ? " and < " : " and <= ") << hi;
      else
        m << " and finite (below 1e300)";
      m << ", got " << d;
      fail(p, m.str());
    }
    v = d;
  }
  void integer(const json& j, const std::string& ptr, const char* key, int& v, int lo,
               int hi) const {
    if (!j.contains(key)) return;
    const json& x = j[key];
    const std::string p = ptr + "/" + key;
    if (!io::json_is_integer(x)) fail(p, "must be an integer");
    // Range before narrowing: get<int>() of 4294967297 gave 1 (issue 14).
    const long long i = io::json_integer_saturated(x);
    if (i < lo) fail(p, "must be >= " + std::to_string(lo) + ", got " + std::to_string(i));
    if (i > hi) fail(p, "must be <= " + std::to_string(hi) + ", got " + x.dump());
    v = static_cast<int>(i);
  }
};

}  // namespace

namespace {

// One range check of CellOptions::validate(): finite and within [lo, hi] (lo excluded if
// lo_open). Ranges as in schemas/cell.schema.json.
struct RangeCheck {
  const char* pointer;
  double value, lo, hi;
  bool lo_open, hi_open;
};

std::optional<CellOptionError> check_ranges(std::initializer_list<RangeCheck> checks) {
  for (const RangeCheck& c : checks) {
    const double v = c.value;
    const bool ok = std::isfinite(v) && (c.lo_open ? v > c.lo : v >= c.lo) &&
                    (c.hi_open ? v < c.hi : v <= c.hi);
    if (ok) continue;
    std::ostringstream m;
    m << "must be a finite number ";
    if (std::isinf(c.hi))
      m << (c.lo_open ? "> " : ">= ") << c.lo;
    else
      m << "in " << (c.lo_open ? "(" : "[") << c.lo << ", " << c.hi << (c.hi_open ? ")" : "]");
    m << ", got " << v;
    return CellOptionError{c.pointer, m.str()};
  }
  return std::nullopt;
}

}  // namespace

std::optional<CellOptionError> CellOptions::validate() const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const auto& p = contact.penalty;
  const auto& f = contact.friction;
  // Two fields together (session 21, found by fuzzing: an allowance of 123456789 mm ran with
  // exit 0): an allowance of a whole yarn diameter lets two yarns pass through each other
  // without force, so the cell has no contact at all.
  if (std::isfinite(p.g0) && std::isfinite(section.d) && section.d > 0 && p.g0 >= section.d) {
    std::ostringstream m;
    // The default allowance with a thin yarn: named at the yarn the user set (session 38's red
    // team: "/contact/allowance ... got 0.14" for a file without that key).
    if (p.g0 == contact::PenaltyLaw{}.g0) {
      m << "must be larger than the contact allowance /contact/allowance = " << p.g0
        << " mm (its default when the file does not set it), got " << section.d
        << " (give /contact/allowance below the diameter with a thinner yarn)";
      return CellOptionError{"/yarn/d", m.str()};
    }
    m << "must be smaller than the yarn diameter /yarn/d = " << section.d << " mm, got " << p.g0
      << " (an allowance of a whole diameter lets yarns pass through each other without force)";
    return CellOptionError{"/contact/allowance", m.str()};
  }
  // The onset widths likewise (session 54: /contact/delta 1e300 made the normal law's onset
  // k x^2 / (2 delta) vanish and ran a cell without contact, exit 0; soft_delta 1e300 took the
  // soft branch away): an onset as wide as the yarn is no onset.
  for (const auto& [pointer, value] :
       {std::pair{"/contact/delta", p.delta}, std::pair{"/contact/soft_delta", p.delta_0}}) {
    if (std::isfinite(value) && std::isfinite(section.d) && section.d > 0 && value >= section.d) {
      std::ostringstream m;
      m << "must be smaller than the yarn diameter /yarn/d = " << section.d << " mm, got " << value
        << " (an onset of a whole diameter leaves the yarns next to no contact force)";
      return CellOptionError{pointer, m.str()};
    }
  }
  return check_ranges({
      // A yarn's Young's modulus in MPa (polymer fibres 1e2-1e5; steel 2e5): session 52's red
      // team gave 1e-308, and the cell ended with "residual is not finite", naming no field.
      {"/yarn/E", section.E, 1e-3, 1e8, false, false},
      {"/yarn/nu", section.nu, -1, 0.5, true, true},
      {"/yarn/d", section.d, 0, inf, true, false},
      {"/loop/gamma_over_w", geometry.gamma_over_w, 0, 1, false, false},
      {"/analysis/elements", double(elements), 4, kMaxElements, false, false},
      {"/analysis/degree", double(degree), 2, kMaxDegree, false, false},
      {"/analysis/slave_points_per_element", double(contact.slave_points_per_element), 1,
       kMaxSlavePoints, false, false},
      {"/contact/penalty", p.k_N, kMinPenalty, kMaxPenalty, false, false},
      {"/contact/allowance", p.g0, 0, inf, false, false},
      {"/contact/delta", p.delta, 0, inf, true, false},
      {"/contact/soft_penalty", p.k_0, 0, kMaxSoftPenalty, false, false},
      {"/contact/soft_delta", p.delta_0, 0, inf, true, false},
      {"/contact/mu", f.mu, 0, inf, false, false},
      {"/contact/stick_penalty", f.k_T, kMinStickPenalty, kMaxStickPenalty, false, false},
      {"/contact/margin", contact.margin, 0, inf, false, false},
      {"/contact/self_exclusion", contact.self_exclusion, 0, 1, true, false},
      {"/contact/max_overlap", contact.max_overlap, 0, 1, true, false},
      {"/solver/tolerance", newton.tol, 0, 0.01, true, false},  // 1 accepted the first iterate
      {"/solver/max_iterations", double(newton.max_iterations), 1, kMaxIterations, false, false},
      {"/solver/equilibration_steps", double(equilibration_steps), 1, kMaxIterations, false, false},
      {"/solver/max_cutbacks", double(max_cutbacks), 0, kMaxCutbacks, false, false},
      {"/solver/max_substeps", double(max_substeps), 1, kMaxSubsteps, false, false},
  });
}

CellOptions read_cell_options(const std::string& file, CellOptions o) {
  // A sweep input given for a cell file (session 54: `path --config cases/sweep/default.json`
  // said only 'unknown key "cell"'): its cell parameters are its /cell object.
  if (const json whole = io::read_json_file(file);
      whole.is_object() && whole.contains("cell") && whole.contains("loop_lengths"))
    throw InputError(file, "/cell",
                     "this is a sweep input (knit-meso sweep), not a cell parameter file: its cell "
                     "parameters are this /cell object; write that object to a file of its own "
                     "for --config (schemas/cell.schema.json)");
  // Schema first (schemas/cell.schema.json, embedded): types, ranges, unknown keys with
  // "did you mean", and line numbers from the file's text.
  const json j = io::load_and_validate(file, "cell");
  return cell_options_from_json(j, file, "", o);
}

CellOptions cell_options_from_json(const json& j, const std::string& file,
                                   const std::string& pointer, CellOptions o) {
  Reader R{file, pointer};
  if (const auto errors = io::JsonSchema::embedded("cell").errors(j); !errors.empty())
    R.fail(errors.front().pointer, errors.front().message);
  // The reader keeps its own checks so that it is safe on its own.
  R.object(j, "", {"$schema", "description", "yarn", "loop", "analysis", "contact", "solver"});
  constexpr double inf = 1e300;
  if (j.contains("yarn")) {
    const json& y = j["yarn"];
    R.object(y, "/yarn", {"E", "nu", "d"});
    R.num(y, "/yarn", "E", o.section.E, 1e-3, 1e8, false);  // MPa (session 52)
    // (-1, 0.5) as schemas/cell.schema.json says (the bound was 0.4999999, which refused
    // 0.49999995 that the schema allows; session 25).
    R.num(y, "/yarn", "nu", o.section.nu, -1, 0.5, true, true);
    R.num(y, "/yarn", "d", o.section.d, 0, inf, true);
  }
  if (j.contains("loop")) {
    const json& l = j["loop"];
    R.object(l, "/loop", {"gamma_over_w"});
    R.num(l, "/loop", "gamma_over_w", o.geometry.gamma_over_w, 0, 1, false);
  }
  if (j.contains("analysis")) {
    const json& a = j["analysis"];
    R.object(a, "/analysis", {"elements", "degree", "slave_points_per_element"});
    R.integer(a, "/analysis", "elements", o.elements, 4, CellOptions::kMaxElements);
    R.integer(a, "/analysis", "degree", o.degree, 2, CellOptions::kMaxDegree);
    R.integer(a, "/analysis", "slave_points_per_element", o.contact.slave_points_per_element, 1,
              CellOptions::kMaxSlavePoints);
  }
  if (j.contains("contact")) {
    const json& c = j["contact"];
    R.object(c, "/contact",
             {"penalty", "allowance", "delta", "soft_penalty", "soft_delta", "mu", "stick_penalty",
              "margin", "self_exclusion", "reference", "max_overlap"});
    if (c.contains("reference")) {
      const json& r = c["reference"];
      if (!r.is_string() || (r != "initial_overlap" && r != "none"))
        R.fail("/contact/reference", "must be \"initial_overlap\" or \"none\"");
      o.contact.reference = r == "none" ? contact::ContactOptions::Reference::kNone
                                        : contact::ContactOptions::Reference::kInitialOverlap;
    }
    R.num(c, "/contact", "penalty", o.contact.penalty.k_N, CellOptions::kMinPenalty,
          CellOptions::kMaxPenalty, false);
    R.num(c, "/contact", "allowance", o.contact.penalty.g0, 0, inf, false);
    R.num(c, "/contact", "delta", o.contact.penalty.delta, 0, inf, true);
    R.num(c, "/contact", "soft_penalty", o.contact.penalty.k_0, 0, CellOptions::kMaxSoftPenalty,
          false);
    R.num(c, "/contact", "soft_delta", o.contact.penalty.delta_0, 0, inf, true);
    R.num(c, "/contact", "mu", o.contact.friction.mu, 0, inf, false);
    R.num(c, "/contact", "stick_penalty", o.contact.friction.k_T, CellOptions::kMinStickPenalty,
          CellOptions::kMaxStickPenalty, false);
    R.num(c, "/contact", "margin", o.contact.margin, 0, inf, false);
    R.num(c, "/contact", "self_exclusion", o.contact.self_exclusion, 0, 1, true);
    R.num(c, "/contact", "max_overlap", o.contact.max_overlap, 0, 1, true);
  }
  if (j.contains("solver")) {
    const json& s = j["solver"];
    R.object(
        s, "/solver",
        {"tolerance", "max_iterations", "equilibration_steps", "max_cutbacks", "max_substeps"});
    R.num(s, "/solver", "tolerance", o.newton.tol, 0, 0.01, true);
    R.integer(s, "/solver", "max_iterations", o.newton.max_iterations, 1,
              CellOptions::kMaxIterations);
    R.integer(s, "/solver", "equilibration_steps", o.equilibration_steps, 1,
              CellOptions::kMaxIterations);
    R.integer(s, "/solver", "max_cutbacks", o.max_cutbacks, 0, CellOptions::kMaxCutbacks);
    R.integer(s, "/solver", "max_substeps", o.max_substeps, 1, CellOptions::kMaxSubsteps);
  }
  if (const auto bad = o.validate()) R.fail(bad->pointer, bad->message);
  return o;
}

}  // namespace knit::meso::homog
