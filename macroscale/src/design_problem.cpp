// Design file -> DesignProblem (knit/macro/design_problem.hpp). The specific checks come first
// (they name what is wrong in design terms); the schema is the last word, as in the case
// loader.
#include "knit/macro/design_problem.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/io/input_file.hpp"
#include "knit/io/json_input.hpp"
#include "knit/io/names.hpp"
#include "knit/macro/knit_material.hpp"
#include "knit/material/database.hpp"
#include "knit/spline/bspline_basis.hpp"

namespace knit::macro {

namespace {
/// The component names of an objective kind, in the order of DesignObjective::component.
const std::vector<std::string>& component_names(DesignObjective::Kind kind) {
  static const std::vector<std::string> displacement = {"x", "y", "z"};
  static const std::vector<std::string> strain = {"E11", "E22", "E12"};
  return kind == DesignObjective::Kind::kDisplacement ? displacement : strain;
}
}  // namespace

const std::string& DesignObjective::component_name() const {
  return component_names(kind).at(static_cast<std::size_t>(component));
}

namespace {

using nlohmann::json;

const char* kKinds[] = {"reaction", "displacement", "strain_variance", "target_strain",
                        "reaction_linearity"};

std::string fmt(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

double number(const json& j, const std::string& file, const std::string& p) {
  if (!j.is_number()) throw InputError(file, p, "must be a number");
  return j.get<double>();
}

std::vector<double> numbers(const json& j, const std::string& file, const std::string& p) {
  if (!j.is_array()) throw InputError(file, p, "must be an array of numbers");
  std::vector<double> v;
  for (std::size_t k = 0; k < j.size(); ++k)
    v.push_back(number(j[k], file, p + "/" + std::to_string(k)));
  return v;
}

/// The most strain samples (samples_u x samples_v x applied strains, summed over the strain
/// terms) a design may ask for per evaluation, and the most entries of their sensitivities
/// (those samples x (variables + 1)): each sample keeps a gradient row per variable, about
/// 50-70 bytes an entry (session 46: 250,000 samples took 154 MB with 8 variables and 4.8 GB
/// with 400, 9 s per evaluation).
constexpr double kMaxStrainSamples = 250000;
constexpr double kMaxStrainEntries = 5e6;

/// The most applied strains off the design solve's load steps (over every term, each counted
/// once): each is a solve of the whole case of its own per design evaluation (DesignSolve), so
/// 20 of them cost 21 solves of the case. Session 54's red team: 3000 such strains took 17 s
/// per evaluation on a case that solves in 0.006 s (about 30 min for a design), and `--check`
/// said nothing.
constexpr std::size_t kMaxOffStepStrains = 20;

/// The most design variables: the Jacobian of the residuals (the smoothness rows grow with the
/// variables) is dense, solved by dense QR, and each variable adds a sensitivity solve per load
/// level. Session 54's red team: 2,500 variables took 6.7 s and 643 MB per iteration, 4,900
/// ended in std::bad_alloc under a 2 GB limit. 1,000 is a 30 x 30 field designed value by value.
constexpr std::size_t kMaxDesignVariables = 1000;

/// `loop_lengths`: the case database's loop lengths, read by the first stitch-value variable
/// and kept for the others (session 46's red team: read once per variable, 2,000 variables took
/// 25 s of `--check`).
void read_variable(const json& j, const std::string& p, const json& case_root, const Case& c,
                   const std::string& file, DesignVariableSpec& v,
                   std::optional<std::vector<double>>& loop_lengths) {
  if (!j.is_object()) throw InputError(file, p, "must be an object");
  // An unknown key before a missing one (session 56's walkthrough: "uper" read "missing
  // required key \"upper\"", the misspelt key unnamed), as the case loader does.
  if (auto u = io::find_unknown_key(j, p, {"name", "field", "indices", "lower", "upper"}))
    throw InputError(file, u->pointer, "unknown key" + u->note);
  for (const char* k : {"field", "indices", "lower", "upper"})
    if (!j.contains(k))
      throw InputError(file, p, std::string("missing required key \"") + k + "\"");
  const std::string field = j.at("field").is_string() ? j.at("field").get<std::string>() : "";
  if (field != "stitch_value" && field != "knitting_angle")
    throw InputError(file, p + "/field", "must be \"stitch_value\" or \"knitting_angle\"");
  v.field = field == "stitch_value" ? DesignVariable::Field::kStitchValue
                                    : DesignVariable::Field::kKnittingAngle;
  if (j.contains("name") && j.at("name").is_string()) v.name = j.at("name").get<std::string>();
  // A reference, not `cond ? at(field) : json()`: the conditional's prvalue copied the whole
  // field for every variable (session 46's red team: 10,000 variables took 43 s of --check).
  static const json kNone;
  const json& f =
      case_root.at("material").contains(field) ? case_root.at("material").at(field) : kNone;
  if (!f.is_object() || !f.contains("values") || !f.at("values").is_array())
    throw InputError(file, p + "/field",
                     "the case's /material/" + field +
                         " has no control values (a constant or aligned field cannot be designed; "
                         "write it as a spline field)");
  const json& vals = f.at("values");
  const json& idx = j.at("indices");
  if (!idx.is_array() || idx.empty())
    throw InputError(file, p + "/indices", "must be a non-empty array of control-value indices");
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const std::string ip = p + "/indices/" + std::to_string(k);
    if (!io::json_is_integer(idx[k]) || io::json_integer_saturated(idx[k]) < 0 ||
        io::json_integer_saturated(idx[k]) >= static_cast<long long>(vals.size()))
      throw InputError(file, ip,
                       "must be the index of one of the " + std::to_string(vals.size()) +
                           " control values of the case's /material/" + field);
    v.indices.push_back(static_cast<int>(io::json_integer_saturated(idx[k])));
  }
  v.lower = number(j.at("lower"), file, p + "/lower");
  v.upper = number(j.at("upper"), file, p + "/upper");
  if (!(v.lower < v.upper)) throw InputError(file, p + "/upper", "must exceed lower");
  if (v.field == DesignVariable::Field::kStitchValue) {
    std::filesystem::path db =
        io::resolve_input_path(c.file, case_root.at("material").at("database").get<std::string>());
    if (!loop_lengths) loop_lengths = material::read_database(db, false).loop_lengths();
    const std::vector<double>& ls = *loop_lengths;
    for (const char* b : {"lower", "upper"}) {
      const double x = std::string(b) == "lower" ? v.lower : v.upper;
      if (x < ls.front() || x > ls.back())
        // As many digits as tell x from the ends (session 50's red team: 6.5000000001 was
        // said as "6.5 mm is outside the database's 4.5-6.5 mm").
        throw InputError(file, p + "/" + b,
                         loop_length_outside(x, ls.front(), ls.back()) + " (" + db.string() + ")");
    }
  } else {
    const bool deg = f.contains("unit") && f.at("unit") == "deg";
    v.unit = deg ? "deg" : "rad";
    const double lim = deg ? 180.0 : std::numbers::pi;
    if (v.lower < -lim || v.upper > lim)
      throw InputError(file, p + (v.lower < -lim ? "/lower" : "/upper"),
                       "knitting-angle bounds must lie in [-" + fmt(lim) + ", " + fmt(lim) + "] (" +
                           (deg ? "deg" : "rad") + ", the field's unit)" +
                           // Degrees for a field in rad (session 47's review).
                           (!deg && v.lower >= -180.0 && v.upper <= 180.0
                                ? "; are the bounds in deg? give them in rad, or the field "
                                  "\"unit\": \"deg\""
                                : ""));
  }
  v.initial = number(vals[static_cast<std::size_t>(v.indices[0])], file, "/material/" + field);
  for (int i : v.indices)
    if (vals[static_cast<std::size_t>(i)] != vals[static_cast<std::size_t>(v.indices[0])])
      throw InputError(file, p + "/indices",
                       "tied control values must start equal in the case (" + fmt(v.initial) +
                           " and " + vals[static_cast<std::size_t>(i)].dump() + ")");
  if (v.initial < v.lower || v.initial > v.upper) {
    // An angle and its bounds in different units (session 47's walkthrough: a field in deg at
    // 90 with bounds 1.2 ... 1.9 read only "outside the bounds").
    std::string hint;
    if (v.field == DesignVariable::Field::kKnittingAngle) {
      const double to_rad = std::numbers::pi / 180.0;
      if (v.unit == "deg" && v.initial * to_rad >= v.lower && v.initial * to_rad <= v.upper)
        hint = "; the field is in deg (its \"unit\") and the bounds hold " +
               fmt(v.initial * to_rad) + " rad: are the bounds in rad? give them in deg";
      else if (v.unit == "rad" && v.initial / to_rad >= v.lower && v.initial / to_rad <= v.upper)
        hint = "; the field is in rad and the bounds hold " + fmt(v.initial / to_rad) +
               " deg: are the bounds in deg? give them in rad, or the field \"unit\": \"deg\"";
    }
    throw InputError(file, p,
                     "the case's value " + fmt(v.initial) + " " + v.unit +
                         " is outside the bounds [" + fmt(v.lower) + ", " + fmt(v.upper) + "]" +
                         hint);
  }
}

int find_name(const std::vector<std::string>& names, const json& j, const std::string& file,
              const std::string& p, const std::string& what) {
  const std::string n = j.is_string() ? j.get<std::string>() : "";
  const auto it = std::find(names.begin(), names.end(), n);
  if (it == names.end()) {
    const std::string list = io::join_names(names);
    throw InputError(file, p,
                     "\"" + n + "\" is not among the case's " + what + " (" +
                         (list.empty() ? "none" : list) + ")");
  }
  return static_cast<int>(it - names.begin());
}

void read_objective(const json& j, const std::string& p, const Case& c, const std::string& file,
                    bool twin, DesignObjective& o) {
  if (!j.is_object() || !j.contains("type") || !j.at("type").is_string())
    throw InputError(file, p, "an objective needs a \"type\"");
  const std::string type = j.at("type").get<std::string>();
  const auto k = std::find(std::begin(kKinds), std::end(kKinds), type);
  if (k == std::end(kKinds))
    throw InputError(file, p + "/type",
                     "unknown objective \"" + type +
                         "\" (allowed: reaction, displacement, strain_variance, target_strain, "
                         "reaction_linearity)");
  o.kind = static_cast<DesignObjective::Kind>(k - std::begin(kKinds));
  // The keys of this type only (session 37's red team: a strain_variance "target", a
  // reaction's "component", a displacement's "region" were read by no one, with exit 0; the
  // schema lists the keys of every type together).
  {
    std::vector<std::string> keys = {"type", "name", "weight", "at_strain"};
    using K = DesignObjective::Kind;
    const std::vector<std::string> extra =
        o.kind == K::kReaction            ? std::vector<std::string>{"reaction", "target"}
        : o.kind == K::kReactionLinearity ? std::vector<std::string>{"reaction"}
        : o.kind == K::kDisplacement      ? std::vector<std::string>{"point", "component", "target"}
        : o.kind == K::kStrainVariance
            ? std::vector<std::string>{"component", "region", "samples"}
            : std::vector<std::string>{"component", "region", "samples", "target"};
    keys.insert(keys.end(), extra.begin(), extra.end());
    for (auto it = j.begin(); it != j.end(); ++it)
      if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) {
        const std::string near = io::closest_key(it.key(), keys);
        throw InputError(file, p + "/" + io::json_pointer_escape(it.key()),
                         "not used by a " + type + " term (" +
                             (near.empty() ? "" : "did you mean \"" + near + "\"? ") +
                             "its keys: " + io::join_names(keys) + ")");
      }
  }
  o.name = j.contains("name") && j.at("name").is_string() ? j.at("name").get<std::string>() : type;
  if (j.contains("weight")) o.weight = number(j.at("weight"), file, p + "/weight");
  if (!j.contains("at_strain")) throw InputError(file, p, "missing required key \"at_strain\"");
  if (!c.output.applied)
    throw InputError(file, p + "/at_strain",
                     "the case names no applied displacement (output.applied_displacement)");
  o.at_strain = numbers(j.at("at_strain"), file, p + "/at_strain");
  if (o.at_strain.empty()) throw InputError(file, p + "/at_strain", "needs at least one strain");
  // The design solves the case at the load factors lambda = eps L / Delta_1 of these strains,
  // and the case's loading ends at lambda = 1: a strain of the other sign, 0 or beyond the
  // case's end is refused here, by pointer (123456789 ran to a load of 1e48 N and exit code 0;
  // 0 and -1 failed in the solve, naming no field).
  // Below kMinLoadFraction of the end the load step lies within the solver's tolerance of the
  // unloaded state (session 36's red team: 1e-300 passed --check, then the solve failed with
  // exit 1 naming neither file nor field; 1e-8 of a 20 % case still solves, 1e-10 does not).
  const double end = c.output.applied->value / c.output.applied->gauge_length;
  constexpr double kMinLoadFraction = 1e-6;
  // A case whose applied displacement is 0 has no strain to design at (session 42's red team:
  // "must lie between 0 ... and 0").
  if (!(end != 0.0))
    throw InputError(file, p + "/at_strain",
                     "the case applies no displacement (output.applied_displacement: " +
                         fmt(c.output.applied->value) +
                         " mm): a design evaluates its objectives at applied strains, so the "
                         "case must load its patch");
  for (std::size_t k = 0; k < o.at_strain.size(); ++k) {
    const double lambda = o.at_strain[k] / end;
    if (!(std::isfinite(lambda) && lambda >= kMinLoadFraction && lambda <= 1.0 + 1e-12))
      throw InputError(
          file, p + "/at_strain/" + std::to_string(k),
          // In compression the end is the smaller bound (session 42's red team: "between -1e-07
          // and -0.1").
          "must lie between " + fmt(end < 0.0 ? end : kMinLoadFraction * end) +
              (end < 0.0 ? " and " + fmt(kMinLoadFraction * end) +
                               " (the case's applied strain at its end, and 1e-6 of it: closer "
                               "to 0 is the unloaded state to the solver)"
                         : " (1e-6 of the end: smaller is the unloaded state to the solver) and " +
                               fmt(end) + ", the case's applied strain at its end") +
              " (output.applied_displacement: " + fmt(c.output.applied->value) +
              " mm over the gauge length " + fmt(c.output.applied->gauge_length) + " mm), got " +
              fmt(o.at_strain[k]));
    // One strain once (session 47's walkthrough: [0.2, 0.2] with targets [25, 20] passed
    // --check and ended "target not met" between the two), within 1e-9 of the end strain, the
    // tolerance at which the solver's steps take two levels as one (DesignSolve; session 54's
    // red team: [0.2, 0.2000000000000001] passed and ended the same way).
    for (std::size_t i = 0; i < k; ++i)
      if (std::abs(o.at_strain[i] - o.at_strain[k]) <= 1e-9 * std::abs(end))
        throw InputError(file, p + "/at_strain/" + std::to_string(k),
                         "repeats the strain " + fmt(o.at_strain[i]) + " of /at_strain/" +
                             std::to_string(i) +
                             (o.at_strain[i] == o.at_strain[k]
                                  ? std::string()
                                  : " (within 1e-9 of the case's end strain " + fmt(end) + ")") +
                             " (each strain once; its target or weight says how much it counts)");
  }
  const bool targets = o.kind != DesignObjective::Kind::kStrainVariance &&
                       o.kind != DesignObjective::Kind::kReactionLinearity;
  if (o.kind == DesignObjective::Kind::kReactionLinearity) {
    if (o.at_strain.size() < 2)
      throw InputError(file, p + "/at_strain", "a linearity term needs at least two strains");
    // The line runs from the unloaded state to the last strain, in tension or in compression
    // (session 46's red team: a compression case could not use the term, its strains being
    // negative). The range check above gives every strain the sign of the case's end.
    for (std::size_t k = 0; k + 1 < o.at_strain.size(); ++k)
      if (!(std::abs(o.at_strain[k]) < std::abs(o.at_strain.back())))
        throw InputError(file, p + "/at_strain/" + std::to_string(k),
                         "must be nearer 0 than the last strain (the line's end point, " +
                             fmt(o.at_strain.back()) + ")");
  }
  const bool from_twin = twin && (o.kind == DesignObjective::Kind::kReaction ||
                                  o.kind == DesignObjective::Kind::kDisplacement);
  if (from_twin) {
    if (j.contains("target"))
      throw InputError(file, p + "/target",
                       "the twin (/twin) gives this term's targets: remove one or the other");
    o.target.assign(o.at_strain.size(), 0.0);  // set_twin_targets() fills them
  } else if (targets) {
    if (!j.contains("target")) throw InputError(file, p, "missing required key \"target\"");
    o.target = numbers(j.at("target"), file, p + "/target");
    if (o.target.size() != o.at_strain.size())
      throw InputError(file, p + "/target", "needs one target per applied strain");
  }
  if (o.kind == DesignObjective::Kind::kReaction ||
      o.kind == DesignObjective::Kind::kReactionLinearity) {
    std::vector<std::string> names;
    for (const auto& r : c.output.reactions) names.push_back(r.name);
    if (!j.contains("reaction")) throw InputError(file, p, "missing required key \"reaction\"");
    o.reaction = find_name(names, j.at("reaction"), file, p + "/reaction", "output.reactions");
    return;
  }
  if (!j.contains("component")) throw InputError(file, p, "missing required key \"component\"");
  const std::string comp =
      j.at("component").is_string() ? j.at("component").get<std::string>() : "";
  const std::vector<std::string>& allowed = component_names(o.kind);
  const auto ci = std::find(allowed.begin(), allowed.end(), comp);
  if (ci == allowed.end())
    throw InputError(file, p + "/component",
                     "must be one of " + allowed[0] + ", " + allowed[1] + ", " + allowed[2]);
  o.component = static_cast<int>(ci - allowed.begin());
  if (o.kind == DesignObjective::Kind::kDisplacement) {
    std::vector<std::string> names;
    for (const auto& q : c.output.points) names.push_back(q.name);
    if (!j.contains("point")) throw InputError(file, p, "missing required key \"point\"");
    o.point = find_name(names, j.at("point"), file, p + "/point", "output.points");
    return;
  }
  if (!j.contains("region")) throw InputError(file, p, "missing required key \"region\"");
  for (const char* d : {"u", "v"}) {
    const std::string rp = p + "/region/" + d;
    if (!j.at("region").contains(d))
      throw InputError(file, p + "/region", std::string("missing \"") + d + "\"");
    const auto r = numbers(j.at("region").at(d), file, rp);
    if (r.size() != 2 || !(r[0] <= r[1]) || r[0] < 0 || r[1] > 1)
      throw InputError(file, rp, "must be [lo, hi] with 0 <= lo <= hi <= 1 (lo = hi: a section)");
    (d[0] == 'u' ? o.u_range : o.v_range) = Eigen::Vector2d(r[0], r[1]);
  }
  o.samples_u = o.u_range(0) == o.u_range(1) ? 1 : 11;
  o.samples_v = o.v_range(0) == o.v_range(1) ? 1 : 11;
  if (j.contains("samples")) {
    const auto n = numbers(j.at("samples"), file, p + "/samples");
    if (n.size() != 2 || n[0] < 1 || n[1] < 1 || n[0] != std::floor(n[0]) ||
        n[1] != std::floor(n[1]) || n[0] > 1000 || n[1] > 1000)
      throw InputError(file, p + "/samples", "must be two integers in 1..1000 (u, v)");
    // Across a section (lo = hi) there is one sample: another count was overridden silently.
    for (int d = 0; d < 2; ++d) {
      const Eigen::Vector2d& r = d == 0 ? o.u_range : o.v_range;
      if (r(0) == r(1) && n[static_cast<std::size_t>(d)] != 1)
        throw InputError(file, p + "/samples/" + std::to_string(d),
                         std::string("must be 1: the region's ") + (d == 0 ? "u" : "v") +
                             " is a section (" + fmt(r(0)) + " to " + fmt(r(1)) +
                             "), with one sample across it");
    }
    o.samples_u = static_cast<int>(n[0]);
    o.samples_v = static_cast<int>(n[1]);
  }
  // The variance of one sample is 0 whatever the design (session 42's red team: "converged" at
  // J = 0 after 0 iterations).
  if (o.kind == DesignObjective::Kind::kStrainVariance && o.samples_u * o.samples_v < 2)
    throw InputError(file, j.contains("samples") ? p + "/samples" : p + "/region",
                     "a strain_variance term needs at least 2 samples (its variance over one "
                     "sample is 0 for every design): give its region an extent and more than "
                     "one sample along it");
}

/// The control grid of a field of the case (u fastest): nu = knots_u - degree_u - 1.
DesignFieldGrid field_grid(const json& case_root, DesignVariable::Field field) {
  DesignFieldGrid g;
  g.field = field;
  const json& f =
      case_root.at("material")
          .at(field == DesignVariable::Field::kStitchValue ? "stitch_value" : "knitting_angle");
  g.nu = static_cast<int>(f.at("knots_u").size()) - f.at("degrees")[0].get<int>() - 1;
  g.nv = static_cast<int>(f.at("knots_v").size()) - f.at("degrees")[1].get<int>() - 1;
  for (const auto& v : f.at("values")) g.values.push_back(v.get<double>());
  // Where each control value sits (the smoothness penalty's abscissae): the case loader has
  // checked the knots, as a B-spline basis does.
  const auto greville = [](const json& knots, int p) {
    return spline::BSplineBasis(p, knots.get<std::vector<double>>()).greville();
  };
  g.greville_u = greville(f.at("knots_u"), f.at("degrees")[0].get<int>());
  g.greville_v = greville(f.at("knots_v"), f.at("degrees")[1].get<int>());
  return g;
}

void read_optimizer(const json& j, const std::string& file, DesignOptimizerSpec& o) {
  if (!j.is_object()) throw InputError(file, "/optimizer", "must be an object");
  if (j.contains("method")) {
    const std::string m = j.at("method").is_string() ? j.at("method").get<std::string>() : "";
    if (m == "ceres")
      o.method = DesignOptimizerSpec::Method::kCeres;
    else if (m == "projected_gradient")
      o.method = DesignOptimizerSpec::Method::kProjectedGradient;
    else
      throw InputError(file, "/optimizer/method", "must be \"ceres\" or \"projected_gradient\"");
  }
  if (j.contains("max_iterations")) {
    const double n = number(j.at("max_iterations"), file, "/optimizer/max_iterations");
    if (n < 1 || n > 10000 || n != std::floor(n))
      throw InputError(file, "/optimizer/max_iterations", "must be an integer in 1..10000");
    o.max_iterations = static_cast<int>(n);
  }
  if (j.contains("function_tolerance")) {
    const double t = number(j.at("function_tolerance"), file, "/optimizer/function_tolerance");
    if (!(t > 0 && t < 1))
      throw InputError(file, "/optimizer/function_tolerance",
                       "must be a fraction of J in (0, 1), e.g. 1e-6");
    o.function_tolerance = t;
  }
  if (j.contains("x_tolerance")) {
    const double t = number(j.at("x_tolerance"), file, "/optimizer/x_tolerance");
    if (!(t >= 1e-14 && t < 1))
      throw InputError(file, "/optimizer/x_tolerance",
                       "must be a fraction of a variable's interval in [1e-14, 1), e.g. 1e-6");
    o.x_tolerance = t;
  }
}

}  // namespace

std::vector<DesignVariable> DesignProblem::expanded() const {
  std::vector<DesignVariable> out;
  for (const auto& v : variables)
    for (int i : v.indices) out.push_back({v.field, i});
  return out;
}

namespace {
DesignProblem load_design_json(const json& root, const std::string& path);
}  // namespace

DesignProblem load_design(const std::string& path) {
  const std::string text = io::read_input_file(path, io::kMaxJsonInputBytes);
  const json root = io::parse_json(text, path);
  try {
    return load_design_json(root, path);
  } catch (const InputError& e) {
    // The line of the field, as the case loader gives it (session 56's walkthrough: design-file
    // errors named the pointer only). An error inside another file keeps its own location.
    if (auto lined = io::error_with_line(e, text, path)) throw *lined;
    throw;
  }
}

namespace {
DesignProblem load_design_json(const json& root, const std::string& path) {
  DesignProblem d;
  d.file = path;
  if (!root.is_object()) throw InputError(path, "", "must be a JSON object");
  // A case file given for the design file (session 47's walkthrough: "/boundary_conditions:
  // unknown key" said nothing of what the file is).
  if (!root.contains("case") && root.contains("geometry") && root.contains("material"))
    throw InputError(path, "",
                     "is a case file (it has \"geometry\" and \"material\"), not a design file: "
                     "run it with knit-macro run, or write a design file whose \"case\" names it "
                     "(docs/design.md, \"The design file\")");
  const std::vector<std::string> top_keys = {"$schema",    "description", "case",      "variables",
                                             "objectives", "smoothness",  "optimizer", "twin"};
  if (auto u = io::find_unknown_key(root, "", top_keys))
    throw InputError(path, u->pointer, "unknown key" + u->note);
  if (!root.contains("case") || !root.at("case").is_string())
    throw InputError(path, "/case", "needs the case file (a string, relative to this file)");
  d.case_file = io::resolve_input_path(path, root.at("case").get<std::string>()).string();
  // A case file that cannot be read is named with the design file and /case (session 29: the
  // message named only the case's path); errors inside a readable case name the case file.
  {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(d.case_file, ec))
      throw InputError(
          path, "/case",
          d.case_file + (std::filesystem::exists(d.case_file, ec) ? " is not a regular file"
                                                                  : ": file not found"));
  }
  d.c = load_case(d.case_file);
  const json case_root = io::parse_json(d.c.text, d.case_file);
  if (d.c.material->name() != "knit")
    throw InputError(path, "/case",
                     "the design needs a knit case (" + d.case_file + " has the material \"" +
                         d.c.material->name() + "\")");
  // A wrong type is named as such (session 46's red team: "variables": "l" read "needs at
  // least one design variable").
  for (const auto& [key, what] :
       {std::pair{"variables", "design variable"}, std::pair{"objectives", "objective"}}) {
    const std::string ptr = std::string("/") + key;
    if (root.contains(key) && !root.at(key).is_array())
      throw InputError(
          path, ptr,
          std::string("must be an array of ") + what + "s, not " + root.at(key).type_name());
    if (!root.contains(key) || root.at(key).empty())
      throw InputError(path, ptr, std::string("needs at least one ") + what);
  }
  std::vector<std::pair<int, int>> used;
  std::vector<std::string> columns;  // history.csv's variable columns
  std::optional<std::vector<double>> loop_lengths;
  for (std::size_t k = 0; k < root.at("variables").size(); ++k) {
    const std::string p = "/variables/" + std::to_string(k);
    DesignVariableSpec v;
    read_variable(root.at("variables")[k], p, case_root, d.c, path, v, loop_lengths);
    for (std::size_t n = 0; n < v.indices.size(); ++n) {
      const int i = v.indices[n];
      const std::pair<int, int> key(static_cast<int>(v.field), i);
      const auto mine = v.indices.begin() + static_cast<std::ptrdiff_t>(n);
      if (std::find(v.indices.begin(), mine, i) != mine)
        throw InputError(path, p + "/indices/" + std::to_string(n),
                         "control value " + std::to_string(i) + " is listed twice");
      if (std::find(used.begin(), used.end(), key) != used.end())
        throw InputError(
            path, p + "/indices/" + std::to_string(n),
            "control value " + std::to_string(i) + " is already set by another variable");
      used.push_back(key);
    }
    // Variables are history.csv columns beside iteration, J, gradient_norm and seconds, named
    // "x<k>" when unnamed (session 37's red team: two "l" columns, or a variable "J" beside the
    // objective's, with exit 0).
    {
      const std::string column = v.name.empty() ? "x" + std::to_string(k) : v.name;
      // The schema's pattern for names, here so that it comes before the twin's and the
      // objectives' checks that use the columns (session 42's red team: "a,b" was reported as
      // a twin naming no variable, "the variables: a,b").
      const bool identifier = !column.empty() &&
                              !std::isdigit(static_cast<unsigned char>(column[0])) &&
                              std::all_of(column.begin(), column.end(), [](char ch) {
                                return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
                              });
      if (!identifier)
        throw InputError(path, p + "/name",
                         "\"" + column +
                             "\" is not a name: letters, digits and _, not starting with a "
                             "digit (it is a column of history.csv)");
      const std::vector<std::string> reserved = {"iteration", "J", "gradient_norm", "seconds"};
      if (std::find(reserved.begin(), reserved.end(), column) != reserved.end())
        throw InputError(path, p + "/name",
                         "\"" + column +
                             "\" is a column of history.csv already (iteration, J, "
                             "gradient_norm, seconds): choose another name");
      if (std::find(columns.begin(), columns.end(), column) != columns.end())
        throw InputError(path, v.name.empty() ? p : p + "/name",
                         "\"" + column +
                             "\" names an earlier variable too (history.csv has a column per "
                             "variable, \"x<k>\" for an unnamed one): each needs its own name");
      columns.push_back(column);
    }
    d.variables.push_back(v);
  }
  // The twin: a value inside its bounds for every variable, by its history.csv column.
  const bool twin = root.contains("twin");
  if (twin) {
    const json& t = root.at("twin");
    if (!t.is_object() || t.empty())
      throw InputError(path, "/twin",
                       "must be an object of one value per design variable (by name)");
    for (auto it = t.begin(); it != t.end(); ++it)
      if (std::find(columns.begin(), columns.end(), it.key()) == columns.end()) {
        throw InputError(
            path, "/twin/" + io::json_pointer_escape(it.key()),
            "names no design variable (the variables: " + io::join_names(columns) + ")");
      }
    for (std::size_t k = 0; k < columns.size(); ++k) {
      const std::string tp = "/twin/" + io::json_pointer_escape(columns[k]);
      if (!t.contains(columns[k]))
        throw InputError(
            path, "/twin",
            "gives no value for the variable \"" + columns[k] + "\" (a twin sets every variable)");
      const double x = number(t.at(columns[k]), path, tp);
      const DesignVariableSpec& v = d.variables[k];
      if (!(x >= v.lower && x <= v.upper))
        throw InputError(path, tp,
                         "must lie within the variable's bounds [" + fmt(v.lower) + ", " +
                             fmt(v.upper) + "], got " + fmt(x));
      d.twin.push_back(x);
    }
  }
  for (std::size_t k = 0; k < root.at("objectives").size(); ++k) {
    DesignObjective o;
    const std::string ptr = "/objectives/" + std::to_string(k);
    read_objective(root.at("objectives")[k], ptr, d.c, path, twin, o);
    d.twin_targets.push_back(twin && (o.kind == DesignObjective::Kind::kReaction ||
                                      o.kind == DesignObjective::Kind::kDisplacement));
    // Each term is reported by its name (summary.txt, the history): two of one name could not
    // be told apart (session 36's red team: two "term load_at_20" lines, exit 0). A given name
    // must be new; a default one (the type) already taken gets the term's index ("_1").
    const auto taken = [&](const std::string& name) {
      return std::any_of(d.objectives.begin(), d.objectives.end(),
                         [&](const DesignObjective& q) { return q.name == name; });
    };
    if (taken(o.name)) {
      if (root.at("objectives")[k].contains("name"))
        throw InputError(path, ptr + "/name",
                         "\"" + o.name +
                             "\" names an earlier term too; terms are reported by name, so each "
                             "needs its own");
      o.name += "_" + std::to_string(k);
      if (taken(o.name))
        throw InputError(path, ptr,
                         "its default name \"" + o.name + "\" is taken: give it a \"name\"");
    }
    d.objectives.push_back(o);
  }
  // The strain terms' samples, each evaluated with its sensitivities at every applied strain of
  // every design evaluation (session 46's red team: 1000 x 1000 samples at one strain took 540
  // MB and 10 s per evaluation, at three strains no iteration ended in 120 s, and under a
  // memory limit the design ended in "std::bad_alloc" naming nothing).
  {
    double total = 0.0, largest = 0.0;
    std::size_t at = 0;
    for (std::size_t k = 0; k < d.objectives.size(); ++k) {
      const DesignObjective& o = d.objectives[k];
      if (o.kind != DesignObjective::Kind::kStrainVariance &&
          o.kind != DesignObjective::Kind::kTargetStrain)
        continue;
      const double n = double(o.samples_u) * o.samples_v * double(o.at_strain.size());
      total += n;
      if (n > largest) {
        largest = n;
        at = k;
      }
    }
    const double entries = total * double(d.variables.size() + 1);
    if (total > kMaxStrainSamples || entries > kMaxStrainEntries) {
      const DesignObjective& o = d.objectives[at];
      const std::string ptr = "/objectives/" + std::to_string(at);
      const auto count = [](double x) { return std::to_string(static_cast<long long>(x)); };
      throw InputError(
          path, root.at("objectives")[at].contains("samples") ? ptr + "/samples" : ptr,
          "the strain terms ask for " + count(total) + " samples per design evaluation (this one " +
              std::to_string(o.samples_u) + " x " + std::to_string(o.samples_v) + " at " +
              std::to_string(o.at_strain.size()) + " strain(s)), each with a sensitivity per " +
              "variable: " + count(total) + " x (" + std::to_string(d.variables.size()) +
              " variables + 1) = " + count(entries) + " entries; at most " +
              count(kMaxStrainSamples) + " samples and " + count(kMaxStrainEntries) +
              " entries (about 50-70 bytes each) are allowed: fewer samples resolve a region's "
              "strain as well (the default is 11 x 11), or fewer variables or strains");
    }
  }
  if (d.variables.size() > kMaxDesignVariables)
    throw InputError(path, "/variables",
                     "has " + std::to_string(d.variables.size()) + " variables; at most " +
                         std::to_string(kMaxDesignVariables) +
                         " are allowed (the design's Jacobian is dense and each variable adds a "
                         "sensitivity solve per load level): tie control values into one "
                         "variable (\"indices\" with several entries) or design a coarser field");
  // The applied strains off the solve's load steps: DesignSolve solves the case scaled to the
  // largest level in its nominal steps (lambda_max k / steps) and each other level on its own.
  if (d.c.output.applied && !d.objectives.empty()) {
    const double end = d.c.output.applied->value / d.c.output.applied->gauge_length;
    double largest = 0.0;
    for (const DesignObjective& o : d.objectives)
      for (double e : o.at_strain) largest = std::max(largest, e / end);
    const double steps = d.c.solver.steps;
    std::vector<double> off;  // load fractions, each once
    for (std::size_t k = 0; k < d.objectives.size(); ++k)
      for (std::size_t i = 0; i < d.objectives[k].at_strain.size(); ++i) {
        const double lambda = d.objectives[k].at_strain[i] / end;
        const double n = lambda / largest * steps;
        if (std::abs(n - std::round(n)) <= 1e-9 * steps) continue;  // on a step
        if (std::any_of(off.begin(), off.end(),
                        [&](double l) { return std::abs(l - lambda) <= 1e-9 * largest; }))
          continue;
        off.push_back(lambda);
        if (off.size() > kMaxOffStepStrains)
          throw InputError(
              path, "/objectives/" + std::to_string(k) + "/at_strain/" + std::to_string(i),
              "is applied strain number " + std::to_string(off.size()) +
                  " off the load steps (the case's /solver/steps = " +
                  std::to_string(d.c.solver.steps) + " steps to the largest strain asked, " +
                  fmt(largest * end) + ": multiples of " + fmt(largest * end / steps) +
                  "); each such strain is a solve of the whole case per design evaluation, and " +
                  "at most " + std::to_string(kMaxOffStepStrains) +
                  " are allowed: put the strains on the steps, or ask for fewer");
      }
  }
  if (twin && std::none_of(d.twin_targets.begin(), d.twin_targets.end(), [](bool b) { return b; }))
    throw InputError(path, "/twin",
                     "no objective takes its targets from it (only reaction and displacement "
                     "terms do)");
  if (root.contains("smoothness") && root.at("smoothness").contains("weight"))
    d.smoothness = number(root.at("smoothness").at("weight"), path, "/smoothness/weight");
  if (root.contains("optimizer")) read_optimizer(root.at("optimizer"), path, d.optimizer);
  for (auto f : {DesignVariable::Field::kStitchValue, DesignVariable::Field::kKnittingAngle})
    if (std::any_of(d.variables.begin(), d.variables.end(),
                    [f](const DesignVariableSpec& v) { return v.field == f; }))
      d.fields.push_back(field_grid(case_root, f));
  io::JsonSchema::embedded("design").validate(root, path);
  return d;
}
}  // namespace

}  // namespace knit::macro

namespace knit::macro {

std::string design_case_text(const DesignProblem& d, const std::vector<double>& x) {
  std::vector<double> values;
  for (std::size_t k = 0; k < d.variables.size(); ++k)
    for (std::size_t i = 0; i < d.variables[k].indices.size(); ++i) values.push_back(x.at(k));
  json root =
      io::parse_json(case_with_design(d.c.text, d.case_file, d.expanded(), values).text, d.file);
  auto& db = root.at("material").at("database");
  db = std::filesystem::absolute(io::resolve_input_path(d.case_file, db.get<std::string>()))
           .lexically_normal()
           .string();
  return root.dump(2) + "\n";
}

}  // namespace knit::macro
