// JSON case reader and runner of `knit-meso rod` (see rod_case.hpp, schemas/rod.schema.json).
#include "knit/meso/rod/rod_case.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/json_input.hpp"
#include "knit/io/names.hpp"
#include "knit/io/output_target.hpp"
#include "knit/io/provenance.hpp"
#include "knit/meso/rod/builders.hpp"
#include "knit/meso/rod/output.hpp"
#include "knit/meso/rod/resolution.hpp"
#include "knit/spline/knot_vector.hpp"
#include "knit/spline/refine.hpp"

namespace knit::meso::rod {

namespace {

using nlohmann::json;

// Minimal checked access with JSON pointers (the embedded schema validation of knit/io
// replaces the structural part once available; the semantic checks stay here).
struct Reader {
  std::string file;

  [[noreturn]] void fail(const std::string& ptr, const std::string& msg) const {
    throw InputError(file, ptr, msg);
  }

  static std::string kind(const json& j) {
    if (j.is_number()) return "a number";
    if (j.is_string()) return "a string";
    if (j.is_array()) return "an array";
    if (j.is_object()) return "an object";
    if (j.is_boolean()) return "a boolean";
    return "null";
  }
  void object(const json& j, const std::string& ptr, std::set<std::string> allowed,
              std::set<std::string> required = {}) const {
    if (!j.is_object()) fail(ptr, "must be an object, got " + kind(j));
    if (auto u = io::find_unknown_key(j, ptr, {allowed.begin(), allowed.end()}))
      fail(ptr, "unknown key \"" + u->key + "\"" + u->note);
    for (const auto& r : required)
      if (!j.contains(r)) fail(ptr, "missing required key \"" + r + "\"");
  }
  double number(const json& j, const std::string& ptr, double lo = -1e300, double hi = 1e300,
                bool lo_open = false, bool hi_open = false) const {
    if (!j.is_number()) fail(ptr, "must be a number, got " + kind(j));
    const double v = j.get<double>();
    std::ostringstream b;
    b << "must be in " << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]")
      << ", got " << v;
    if (v < lo || v > hi || (lo_open && v == lo) || (hi_open && v == hi)) fail(ptr, b.str());
    return v;
  }
  double positive(const json& j, const std::string& ptr) const {
    if (!j.is_number()) fail(ptr, "must be a number, got " + kind(j));
    const double v = j.get<double>();
    if (!(v > 0)) fail(ptr, "must be positive, got " + j.dump());
    return v;
  }
  int integer(const json& j, const std::string& ptr, int lo) const {
    if (!io::json_is_integer(j))
      fail(ptr, "must be an integer, got " + (j.is_number() ? j.dump() : kind(j)));
    const long long v = io::json_integer_saturated(j);
    // The upper bound is part of the message (session 25: 1000001 was refused as "must be an
    // integer >= 1"); schemas/rod.schema.json states it too.
    constexpr long long kMax = 1000000;
    if (v < lo || v > kMax)
      fail(ptr, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(kMax) +
                    "], got " + j.dump());
    return static_cast<int>(v);
  }
  std::string string(const json& j, const std::string& ptr,
                     const std::set<std::string>& choices = {}) const {
    if (!j.is_string()) fail(ptr, "must be a string, got " + kind(j));
    const std::string s = j.get<std::string>();
    if (!choices.empty() && !choices.count(s)) {
      std::string list;
      for (const auto& a : choices) list += (list.empty() ? "\"" : ", \"") + a + "\"";
      fail(ptr, "must be one of " + list + ", got \"" + s + "\"");
    }
    return s;
  }
  Eigen::Vector3d vec3(const json& j, const std::string& ptr) const {
    if (!j.is_array() || j.size() != 3) fail(ptr, "must be an array of 3 numbers");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v(i) = number(j[i], ptr + "/" + std::to_string(i));
    return v;
  }
};

Section read_section(const Reader& R, const json& j, const std::string& ptr, Section s) {
  R.object(j, ptr, {"E", "nu", "d", "shear_factor"});
  if (j.contains("E")) s.E = R.positive(j["E"], ptr + "/E");
  if (j.contains("nu")) s.nu = R.number(j["nu"], ptr + "/nu", -1.0, 0.5, true, true);
  if (j.contains("d")) s.d = R.positive(j["d"], ptr + "/d");
  if (j.contains("shear_factor")) s.kappa = R.positive(j["shear_factor"], ptr + "/shear_factor");
  // The stiffnesses must be finite and positive: d = 1e308 made E A infinite, every residual
  // then scaled to 0, and the rod "converged" undeformed with 0 Newton iterations and exit 0;
  // d = 1e-300 made E I vanish (found by fuzzing the rod cases).
  const Eigen::Vector3d cg = s.C_Gamma(), ck = s.C_K();
  if (!(cg.allFinite() && ck.allFinite() && (cg.array() > 0.0).all() && (ck.array() > 0.0).all())) {
    std::ostringstream o;
    o << "the section's stiffnesses must be finite and positive, got E A = " << cg(2)
      << " N, E I = " << ck(0) << " N mm^2, G J = " << ck(2) << " N mm^2 (E = " << s.E
      << " MPa, d = " << s.d << " mm)";
    R.fail(ptr, o.str());
  }
  return s;
}

EndCondition read_end(const Reader& R, const json& j, const std::string& ptr) {
  R.object(j, ptr, {"position", "rotation", "displacement", "rotation_vector", "force", "moment"},
           {"position", "rotation"});
  EndCondition c;
  c.fix_position = R.string(j["position"], ptr + "/position", {"fixed", "free"}) == "fixed";
  c.fix_rotation = R.string(j["rotation"], ptr + "/rotation", {"fixed", "free"}) == "fixed";
  if (j.contains("displacement")) {
    if (!c.fix_position)
      R.fail(ptr + "/displacement", "a displacement needs \"position\": \"fixed\"");
    c.displacement = R.vec3(j["displacement"], ptr + "/displacement");
  }
  if (j.contains("force")) {
    if (c.fix_position) R.fail(ptr + "/force", "a force needs \"position\": \"free\"");
    c.force = R.vec3(j["force"], ptr + "/force");
  }
  if (j.contains("rotation_vector")) {
    if (!c.fix_rotation)
      R.fail(ptr + "/rotation_vector", "a prescribed rotation needs \"rotation\": \"fixed\"");
    c.rotation = R.vec3(j["rotation_vector"], ptr + "/rotation_vector");
  }
  if (j.contains("moment")) {
    if (c.fix_rotation) R.fail(ptr + "/moment", "a moment needs \"rotation\": \"free\"");
    c.moment = R.vec3(j["moment"], ptr + "/moment");
  }
  return c;
}

// The analysis basis needs degree >= 2 (session 28): on degree 1, one element has no interior
// collocation point, so no balance equation at all (the elastica "completed" with the linear
// tip deflection, 0.0007 mm for 6.7 mm), and four elements gave a singular Jacobian.
constexpr int kMinAnalysisDegree = 2;
std::string too_low(int p) {
  return "the analysis degree must be >= 2 (on degree 1 the collocation has no interior point "
         "per element and the balance equations are lost), got " +
         std::to_string(p);
}

RodSpec read_curve(const Reader& R, const json& j, const std::string& ptr, const Section& sec) {
  if (!j.is_object()) R.fail(ptr, "must be an object, got " + Reader::kind(j));
  if (!j.contains("type")) R.fail(ptr, "missing required key \"type\"");
  const std::string type = R.string(j["type"], ptr + "/type", {"line", "bspline"});
  if (type == "line") {
    R.object(j, ptr, {"type", "from", "to", "degree", "elements"},
             {"type", "from", "to", "degree", "elements"});
    const Eigen::Vector3d a = R.vec3(j["from"], ptr + "/from"), b = R.vec3(j["to"], ptr + "/to");
    if ((b - a).norm() <= 0) R.fail(ptr + "/to", "must differ from \"from\"");
    const int p = R.integer(j["degree"], ptr + "/degree", 1);
    const int ne = R.integer(j["elements"], ptr + "/elements", 1);
    if (p > 12) R.fail(ptr + "/degree", "must be <= 12, got " + std::to_string(p));
    if (p < kMinAnalysisDegree) R.fail(ptr + "/degree", too_low(p));
    return straight_rod(a, b, p, ne, sec);
  }
  R.object(j, ptr, {"type", "degree", "knots", "control_points", "weights", "refine"},
           {"type", "degree", "knots", "control_points"});
  const int p = R.integer(j["degree"], ptr + "/degree", 1);
  const json& jk = j["knots"];
  if (!jk.is_array()) R.fail(ptr + "/knots", "must be an array of numbers");
  std::vector<double> U;
  for (size_t i = 0; i < jk.size(); ++i)
    U.push_back(R.number(jk[i], ptr + "/knots/" + std::to_string(i)));
  const json& jc = j["control_points"];
  if (!jc.is_array() || jc.size() < 2)
    R.fail(ptr + "/control_points", "must be an array of at least 2 points");
  Eigen::MatrixXd P(jc.size(), 3);
  for (size_t i = 0; i < jc.size(); ++i)
    P.row(i) = R.vec3(jc[i], ptr + "/control_points/" + std::to_string(i)).transpose();
  try {
    spline::validate_knots(U, p, static_cast<int>(jc.size()));
  } catch (const spline::KnotVectorError& e) {
    R.fail(ptr + "/knots", e.what());
  }
  // Collocation of the strong form needs a C^1 curve: at an interior knot of multiplicity
  // m >= p the tangent (and so the rod's frame) jumps, and no collocation row holds the kink
  // (session 27: a straight line with a C^0 knot "diverged" under 1e-6 N, exit 1, and so did
  // the exact NURBS ring, whose quadrant knots are C^0). Refinement keeps the continuity.
  if (const auto kink = spline::first_non_c1_knot(U, p)) {
    std::ostringstream os;
    os << spline::describe_knot_break(*kink, p, "curve")
       << ", and collocation of the rod equations needs C^1; ";
    if (p == 1)
      os << "a degree-1 curve can have no interior knot: raise the degree";
    else
      os << "give interior knots multiplicity <= " << p - 1
         << " (a NURBS circle with C^0 quadrant knots is not C^1: use a C^1 parametrization)";
    R.fail(ptr + "/knots", os.str());
  }
  RodSpec s;
  s.basis = spline::BSplineBasis(p, U);
  s.r0 = P;
  s.section = sec;
  if (j.contains("weights")) {
    const json& jw = j["weights"];
    if (!jw.is_array() || jw.size() != jc.size())
      R.fail(ptr + "/weights", "must be an array of " + std::to_string(jc.size()) + " numbers");
    s.weights.resize(jw.size());
    for (size_t i = 0; i < jw.size(); ++i)
      s.weights(i) = R.positive(jw[i], ptr + "/weights/" + std::to_string(i));
  }
  if (j.contains("refine")) {
    // k-refinement of the exact geometry for the analysis: elevate to `degree`, then insert
    // uniform breakpoints up to `elements` spans (knot insertion keeps the curve unchanged).
    const json& jr = j["refine"];
    R.object(jr, ptr + "/refine", {"degree", "elements"}, {"degree", "elements"});
    const int pr = R.integer(jr["degree"], ptr + "/refine/degree", 1);
    const int ne = R.integer(jr["elements"], ptr + "/refine/elements", 1);
    if (pr < p) R.fail(ptr + "/refine/degree", "must be >= the curve degree " + std::to_string(p));
    if (pr > 12) R.fail(ptr + "/refine/degree", "must be <= 12, got " + std::to_string(pr));
    if (pr < kMinAnalysisDegree) R.fail(ptr + "/refine/degree", too_low(pr));
    const spline::SplineCurve fine =
        spline::refine(spline::SplineCurve(s.basis, s.r0, s.weights), pr, ne);
    s.basis = fine.basis();
    s.r0 = fine.control_points();
    s.weights = fine.rational() ? Eigen::VectorXd(fine.weights()) : Eigen::VectorXd();
  } else if (p < kMinAnalysisDegree) {
    R.fail(ptr + "/degree", too_low(p) + " (or add \"refine\" with a degree >= 2)");
  }
  return s;
}

}  // namespace

RodCase load_rod_case(const std::filesystem::path& path) {
  const std::string file = path.string();
  Reader R{file};
  // Structure, types and ranges: the embedded schemas/rod.schema.json (errors with JSON pointer
  // and line); the Reader below re-checks what it reads and adds the semantic checks (names,
  // knot vectors, parameter ranges, load/support combinations).
  const json j = io::load_and_validate(path, "rod");
  R.object(j, "", {"$schema", "description", "section", "rods", "steps", "output"}, {"rods"});
  RodCase c;
  c.file = file;
  if (j.contains("description")) c.description = R.string(j["description"], "/description");
  Section sec;
  if (j.contains("section")) sec = read_section(R, j["section"], "/section", sec);
  const json& jr = j["rods"];
  if (!jr.is_array() || jr.empty()) R.fail("/rods", "must be a non-empty array");
  std::map<std::string, int> names;
  // Memory and time grow with the elements of all rods (session 52's red team, one elastica:
  // 2,000 took 6 s and 188 MB, 8,000 25 s and 610 MB, 100,000 more than 2 minutes; the
  // schema's 1e6 would need about 70 GB and end by the OOM killer without a word).
  constexpr long long kMaxRodElements = 20000;
  long long elements = 0;
  for (size_t k = 0; k < jr.size(); ++k) {
    const std::string ptr = "/rods/" + std::to_string(k);
    R.object(jr[k], ptr,
             {"name", "curve", "section", "d1", "start", "end", "line_force", "line_moment"},
             {"name", "curve", "start", "end"});
    const json& r = jr[k];
    const std::string name = R.string(r["name"], ptr + "/name");
    if (names.count(name)) R.fail(ptr + "/name", "duplicate rod name \"" + name + "\"");
    Section s = sec;
    if (r.contains("section")) s = read_section(R, r["section"], ptr + "/section", sec);
    RodSpec spec = read_curve(R, r["curve"], ptr + "/curve", s);
    elements += spec.basis.num_elements();
    if (elements > kMaxRodElements)
      R.fail(ptr + "/curve",
             "the rods up to this one have " + std::to_string(elements) +
                 " elements, more than the " + std::to_string(kMaxRodElements) +
                 " a case may have (about 1.5 GB and a minute of solving; 8,000 took 610 MB and "
                 "25 s): use fewer elements");
    spec.name = name;
    if (r.contains("d1")) spec.d1_hint = R.vec3(r["d1"], ptr + "/d1");
    spec.start = read_end(R, r["start"], ptr + "/start");
    spec.end = read_end(R, r["end"], ptr + "/end");
    if (r.contains("line_force")) spec.line_force = R.vec3(r["line_force"], ptr + "/line_force");
    if (r.contains("line_moment"))
      spec.line_moment = R.vec3(r["line_moment"], ptr + "/line_moment");
    try {
      names[name] = c.system.add_rod(std::move(spec));
    } catch (const std::invalid_argument& e) {
      R.fail(ptr + "/curve", e.what());
    }
  }
  if (j.contains("steps")) {
    const json& js = j["steps"];
    R.object(js, "/steps",
             {"count", "max_cutbacks", "tolerance", "max_iterations", "predictor", "min_increment",
              "max_total_iterations"});
    if (js.contains("count")) c.path.steps = R.integer(js["count"], "/steps/count", 1);
    if (js.contains("max_cutbacks"))
      c.path.max_cutbacks = R.integer(js["max_cutbacks"], "/steps/max_cutbacks", 0);
    if (js.contains("tolerance")) {
      c.path.newton.tol = R.positive(js["tolerance"], "/steps/tolerance");
      // 1e308 accepted every first iterate: 0 Newton iterations, an undeformed rod and exit 0
      // (session 21).
      if (c.path.newton.tol > 1e-2)
        R.fail("/steps/tolerance",
               "must be at most 0.01 (a dimensionless residual), got " + js["tolerance"].dump());
      // Below the double's round-off no residual gets there in general: 1e-300 with a million
      // iterations ran for minutes to "did not converge" (session 49's red team).
      if (c.path.newton.tol < kMinRodTolerance)  // as the schema says it
        R.fail("/steps/tolerance",
               "must be at least 2.2e-16 (the round-off of a double: a dimensionless residual "
               "does not get below it), got " +
                   js["tolerance"].dump());
    }
    if (js.contains("max_iterations"))
      c.path.newton.max_iterations = R.integer(js["max_iterations"], "/steps/max_iterations", 1);
    if (js.contains("min_increment"))
      c.path.min_increment =
          R.number(js["min_increment"], "/steps/min_increment", 0.0, 1.0, true, false);
    if (js.contains("max_total_iterations"))
      c.path.max_total_iterations =
          R.integer(js["max_total_iterations"], "/steps/max_total_iterations", 0);
    if (js.contains("predictor")) {
      if (!js["predictor"].is_boolean()) R.fail("/steps/predictor", "must be a boolean");
      c.path.predictor = js["predictor"].get<bool>();
    }
  }
  if (j.contains("output")) {
    const json& jo = j["output"];
    R.object(jo, "/output", {"points", "samples_per_element", "vtp", "check_resolution"});
    if (jo.contains("check_resolution")) {
      if (!jo["check_resolution"].is_boolean())
        R.fail("/output/check_resolution", "must be a boolean");
      c.check_resolution = jo["check_resolution"].get<bool>();
    }
    if (jo.contains("samples_per_element"))
      c.samples_per_element =
          R.integer(jo["samples_per_element"], "/output/samples_per_element", 1);
    if (jo.contains("vtp")) {
      if (!jo["vtp"].is_boolean()) R.fail("/output/vtp", "must be a boolean");
      c.write_vtp = jo["vtp"].get<bool>();
    }
    if (jo.contains("points")) {
      const json& jp = jo["points"];
      if (!jp.is_array()) R.fail("/output/points", "must be an array");
      std::set<std::string> seen;
      for (size_t i = 0; i < jp.size(); ++i) {
        const std::string ptr = "/output/points/" + std::to_string(i);
        R.object(jp[i], ptr, {"name", "rod", "xi"}, {"name", "rod", "xi"});
        NamedPoint np;
        np.name = R.string(jp[i]["name"], ptr + "/name");
        // A CSV column name (name_ux, ...): the same rule as knit-macro's output points
        // (knit/io/names.hpp; session 54: "ti,p" passed here, refused there).
        if (const auto problem = io::output_name_problem(np.name)) R.fail(ptr + "/name", *problem);
        if (!seen.insert(np.name).second)
          R.fail(ptr + "/name", "duplicate point name \"" + np.name + "\"");
        const std::string rod = R.string(jp[i]["rod"], ptr + "/rod");
        if (!names.count(rod)) R.fail(ptr + "/rod", "no rod named \"" + rod + "\"");
        np.rod = names[rod];
        const auto& b = c.system.spec(np.rod).basis;
        np.xi = R.number(jp[i]["xi"], ptr + "/xi", b.lo(), b.hi());
        c.points.push_back(np);
      }
    }
  }
  // A prescribed end rotation turns an end by at most kMaxStepRotation per load step.
  for (int k = 0; k < c.system.num_rods(); ++k)
    for (const auto& [where, bc] :
         {std::pair{"start", &c.system.spec(k).start}, std::pair{"end", &c.system.spec(k).end}}) {
      const double turn = bc->rotation.stableNorm();  // no overflow at 1e300
      const int steps = std::max(1, c.path.steps);
      if (!(turn / steps <= kMaxStepRotation)) {
        std::ostringstream o;
        o.precision(4);
        const double need = std::ceil(turn / kMaxStepRotation);
        const std::string ptr = "/rods/" + std::to_string(k) + "/" + where + "/rotation_vector";
        if (!(need <= kMaxRodSteps)) {  // no step count resolves it (1e300 rad, say)
          o << "turns its end by " << turn << " rad, more than " << kMaxRodSteps
            << " load steps (/steps/count's maximum) of a third of a turn resolve; a rotation "
               "vector is in radians (its length the angle, its direction the axis)";
          R.fail(ptr, o.str());
        }
        o << ptr << " turns its end by " << turn << " rad, " << turn / steps << " rad in each of "
          << steps << " load step(s): more than a third of a turn per step (" << kMaxStepRotation
          << " rad); an end rotation is reached modulo a full turn, so a "
             "step of pi or more is solved the shorter way round (the rod curls the other way, "
             "or not at all at a full turn); use at least "
          << static_cast<long>(need) << " steps";
        R.fail("/steps/count", o.str());
      }
    }
  // Loads the solver cannot see (session 29, found by a helper's fuzzing audit): the residual is
  // scaled per row (force rows L/EA, moment rows 1/EA, ...: row_scales()), so on a long slender
  // rod a real load is within the tolerance at the reference state. A 1000 mm rod of d = 0.1 mm
  // with an end moment of 1e-7 N mm (tip deflection M L^2 / 2EI = 12.7 mm) "completed" with 0
  // Newton iterations and u = 0, exit 0. The full load's scaled residual at the reference state
  // must exceed the tolerance by kLoadResolution (choice: 1e3, three digits of the load resolved).
  // The largest over the first step, the quarters and the end of the path (session 41's red
  // team: a prescribed end rotation of 2 pi, exp(lambda theta), is the identity at lambda = 1,
  // and the valid roll-up was refused, naming /steps/tolerance).
  {
    Eigen::VectorXd F;
    double raw = 0.0, scaled = 0.0;
    const double l0 = c.path.lambda_start, l1 = c.path.lambda_end;
    for (const double t : {1.0 / std::max(1, c.path.steps), 0.25, 0.5, 0.75, 1.0}) {
      c.system.residual(c.system.initial_state(), l0 + t * (l1 - l0), F);
      if (F.size() == 0) continue;
      raw = std::max(raw, F.cwiseAbs().maxCoeff());
      scaled = std::max(scaled, F.cwiseProduct(c.system.row_scales()).cwiseAbs().maxCoeff());
    }
    if (raw > 0.0 && scaled <= kLoadResolution * c.path.newton.tol) {
      // The suggestion: scaled x 1e-3 rounded down to two digits, so that it passes this check.
      double suggest = scaled * 1e-3;
      const double p10 = std::pow(10.0, std::floor(std::log10(suggest)) - 1.0);
      suggest = std::floor(suggest / p10) * p10;
      std::ostringstream o;
      o.precision(3);
      o << "the loads' residual at the reference state, " << scaled
        << " (dimensionless: force rows scaled by L/EA, moment rows by 1/EA), is within "
        << kLoadResolution << " x the tolerance " << c.path.newton.tol
        << ": the solver would resolve them to fewer than three digits, or stop at once with "
           "nothing moved; ";
      // No tolerance the case may set resolves them (session 50's red team: E = 1e300 was
      // told to lower the tolerance to 1.2e-18, which /steps/tolerance refuses).
      if (!(suggest >= kMinRodTolerance)) {
        double ea = 0.0;
        for (int k = 0; k < c.system.num_rods(); ++k)
          ea = std::max(ea, c.system.spec(k).section.C_Gamma()(2));
        o << "no tolerance resolves them (the smallest is " << kMinRodTolerance
          << ", a double's round-off): the loads are negligible beside the rods' stiffness "
             "(largest EA "
          << ea << " N); check the section (/section: E and d) and the loads' size";
      } else {
        o << "lower /steps/tolerance to about " << std::setprecision(2) << suggest
          << " or below, or raise the loads";
      }
      R.fail("/steps/tolerance", o.str());
    }
  }
  return c;
}

std::uint64_t estimate_output_bytes(const RodCase& c) {
  std::uint64_t points = 0;
  for (int k = 0; k < c.system.num_rods(); ++k) {
    const auto spans = spline::unique_knots(c.system.spec(k).basis.knots()).size() - 1;
    points += spans * static_cast<std::uint64_t>(c.samples_per_element) + 1;
  }
  const auto steps = static_cast<std::uint64_t>(std::max(1, c.path.steps)) + 1;
  const std::uint64_t vtp = c.write_vtp ? steps * (points * 200 + 2000) : 0;
  const std::uint64_t csv = steps * (40 + 60 * static_cast<std::uint64_t>(c.points.size()));
  return vtp + csv;
}

void check_output_size(const RodCase& c, std::uint64_t max_bytes) {
  const std::uint64_t est = estimate_output_bytes(c);
  if (max_bytes == 0 || est <= max_bytes) return;
  // Over the cap with the reference state and one step alone: the mesh, not the steps, is too
  // large (session 41: 1e6 elements of degree 12 were refused at /steps/count).
  // (The estimate is the files per state times the states, steps + 1.)
  const auto states = static_cast<std::uint64_t>(std::max(1, c.path.steps)) + 1;
  if (est / states * 2 > max_bytes)
    throw InputError(c.file, "/output/samples_per_element",
                     "the estimated output size " + io::format_bytes(est) + " exceeds the cap of " +
                         io::format_bytes(max_bytes) +
                         " with even two VTP files of the centerlines (the reference state and "
                         "one step) over it: the rods have too many elements for their output; "
                         "use fewer elements, fewer /output/samples_per_element or /output/vtp "
                         "false, or raise the cap with --max-output-size");
  {
    throw InputError(
        c.file, "/steps/count",
        "the estimated output size " + io::format_bytes(est) + " (" +
            std::to_string(c.path.steps + 1) +
            " VTP files of the centerlines) exceeds the cap of " + io::format_bytes(max_bytes) +
            ": use fewer steps, /output/vtp false or fewer /output/samples_per_element, "
            "or raise the cap with --max-output-size");
  }
}

namespace {
/// The end of the rod CSV's second comment: how the path ended (PathReport::message), by which
/// a later run judges an output written before its marker said whether it completed.
std::string path_end_comment(const std::string& message) {
  return "; path: " + message;
}
}  // namespace

CasePathReport run_rod_case(const RodCase& c, const std::filesystem::path& outdir,
                            std::ostream* log) {
  const RodSystem& sys = c.system;
  const std::string provenance = io::Provenance::current(c.file).to_json_string();
  // OUT.partial-<pid>, renamed onto OUT by commit()
  io::AtomicDirectory dir(outdir, io::AtomicDirectory::OnAbandon::Remove, "output directory",
                          c.file);
  // An earlier output written before its marker said whether it completed (session 49) is
  // judged from its load_displacement.csv, whose comment has said how the path ended since the
  // first rod outputs ("...; path: completed"; session 50: before, such outputs were replaced
  // by a stopped rerun).
  dir.judge_earlier_by_files([](const std::filesystem::path& out) {
    std::ifstream in(out / "load_displacement.csv");
    const std::string done = path_end_comment(to_string(PathStop::kCompleted));
    bool completed = false;
    for (std::string line; std::getline(in, line) && (line.empty() || line[0] == '#');)
      completed = completed || line.ends_with(done);
    return completed;
  });

  std::vector<std::string> header{"step", "lambda", "iterations"};
  for (const auto& p : c.points)
    for (const char* comp : {"_ux", "_uy", "_uz"}) header.push_back(p.name + comp);
  struct CsvRow {
    int step;
    double lambda;
    std::vector<double> u;
  };
  std::vector<CsvRow> rows;
  std::vector<std::pair<double, std::string>> pvd;
  auto record = [&](int step, double lambda, const Eigen::VectorXd& x) {
    CsvRow row{step, lambda, {}};
    for (const auto& p : c.points) {
      const Eigen::Vector3d u = sys.position(p.rod, p.xi, x) - sys.reference_position(p.rod, p.xi);
      row.u.insert(row.u.end(), {u(0), u(1), u(2)});
    }
    rows.push_back(std::move(row));
    if (c.write_vtp) {
      char name[64];
      std::snprintf(name, sizeof name, "centerline_%04d.vtp", step);
      write_vtp(dir / name, sample_centerlines(sys, x, c.samples_per_element), provenance);
      pvd.emplace_back(lambda, name);
    }
  };
  Eigen::VectorXd x = sys.initial_state();
  record(0, c.path.lambda_start, x);
  CasePathReport rep;
  static_cast<PathReport&>(rep) =
      solve_path(sys, x, c.path, [&](int step, double lambda, const Eigen::VectorXd& xs) {
        record(step, lambda, xs);
        if (log) *log << "step " << step << ": lambda = " << lambda << "\n";
      });
  // No load step completed: nothing to write but the reference state (the partial directory is
  // removed with `dir`), an earlier output stays as it was.
  if (!rep.completed && rows.size() <= 1) {
    rep.written = false;
    return rep;
  }
  // Newton iterations per target step (cut-back sub-increments summed).
  std::vector<int> iters(rows.size(), 0);
  {
    size_t r = 1;
    for (const auto& st : rep.steps) {
      if (r >= rows.size()) break;
      iters[r] += st.iterations;
      if (std::abs(st.lambda - rows[r].lambda) <= 1e-12 * std::max(1.0, std::abs(st.lambda))) ++r;
    }
  }
  // Resolution check (knit/meso/rod/resolution.hpp): the same path on the bisected mesh.
  if (rep.completed && c.check_resolution) {
    // The named points and the whole centerline: the ends and every span's midpoint (review of
    // session 28: with only the clamped root named, one element of degree 3 "changed by 0 %").
    std::vector<RodPoint> where;
    for (const auto& p : c.points) where.push_back({p.rod, p.xi});
    for (int k = 0; k < sys.num_rods(); ++k) {
      const std::vector<double> br = spline::unique_knots(sys.spec(k).basis.knots());
      for (std::size_t i = 0; i < br.size(); ++i) {
        where.push_back({k, br[i]});
        if (i + 1 < br.size()) where.push_back({k, 0.5 * (br[i] + br[i + 1])});
      }
    }
    rep.resolution = check_resolution(sys, x, c.path, where);
  }
  io::CsvWriter csv(dir / "load_displacement.csv", header);
  csv.add_comment("provenance: " + provenance);
  csv.add_comment("displacements u = r - r0 [mm] of the named points" +
                  path_end_comment(rep.message));
  if (rep.resolution)
    csv.add_comment("resolution: " + rep.resolution->describe() + " (tolerance " +
                    std::to_string(static_cast<int>(100 * kResolutionTolerance)) + " %)");
  for (size_t r = 0; r < rows.size(); ++r) {
    std::vector<io::CsvCell> cells{rows[r].step, rows[r].lambda, iters[r]};
    for (double v : rows[r].u) cells.emplace_back(v);
    csv.add_row(cells);
  }
  csv.commit();
  if (c.write_vtp) write_pvd(dir / "centerline.pvd", pvd);
  dir.set_completed(rep.completed);  // a stopped run keeps a completed earlier output beside
  dir.commit();
  rep.earlier_kept_in = dir.replaced_kept_in();
  return rep;
}

}  // namespace knit::meso::rod
