// Case JSON -> Case (case.hpp). Every check names the file and the JSON pointer; unknown keys
// are errors at every level (the same rules as schemas/case.schema.json).
#include <algorithm>
#include <cctype>
#include <charconv>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/io/input_file.hpp"
#include "knit/io/json_input.hpp"
#include "knit/io/names.hpp"
#include "knit/macro/case.hpp"
#include "knit/macro/geometry_check.hpp"
#include "knit/macro/material_factory.hpp"
#include "knit/macro/output_units.hpp"
#include "knit/macro/refinement.hpp"
#include "knit/spline/basis.hpp"
#include "knit/spline/knot_vector.hpp"

namespace knit::macro {

namespace {
/// The largest ratio of two NURBS weights of a case (a geometry check, session 40).
constexpr double kMaxWeightRatio = 1e6;
}  // namespace

namespace {

/// Upper bounds of the solver's tolerances (schemas/case.schema.json "maximum"): relative to the
/// load, and in N.
constexpr double kMaxRelativeTolerance = 1e-2;
constexpr double kMaxAbsoluteTolerance = 1e-3;
/// Upper bound of /solver/extra_quadrature_points (the schema's "maximum"): p + 4 points a
/// direction integrate polynomials of degree 2p + 7 exactly; more only costs memory and time.
constexpr int kMaxExtraQuadraturePoints = 3;

/// Bounds of lengths relative to the patch's size D, the diagonal of its control net's bounding
/// box (the surface lies inside that box). A thickness below 1e-4 D makes every internal force
/// vanish against the solver's absolute tolerance (t = 1e-300 "converged" every step with 0
/// iterations and left the free control points where the predictor put them); a shell thicker
/// than its own size is no shell. A gauge length is a distance between jaws on the patch: below
/// 0.01 D or above 10 D the printed strain (displacement / gauge length) says nothing (1e308 gave
/// strain 0 at every step).
constexpr double kMinThicknessPerSize = 1e-4;
constexpr double kMaxThicknessPerSize = 1.0;
/// The farthest a control point's coordinate may lie from the origin, relative to the patch's
/// size D (session 46): at 1e8 D a double keeps about 8 of its 16 digits for the patch itself.
constexpr double kMaxOffsetPerSize = 1e8;
constexpr double kMinGaugePerSize = 1e-2;
/// The smallest non-zero prescribed displacement, relative to the patch's size D (session 29).
constexpr double kMinPrescribedPerSize = 1e-12;
constexpr double kMaxPrescribedPerSize = 100.0;
constexpr double kMaxGaugePerSize = 10.0;

/// " mm", or the case's length unit (session 49: a case in m said mm in its messages).
std::string length_unit(const Case& c) {
  return " " + unit_labels(c.units).of("mm");
}

/// "[lo, hi] mm (a and b times the patch's size D = ... mm)", in the case's length unit.
std::string relative_range(double lo, double hi, double size, const Case& c) {
  const std::string mm = length_unit(c);
  std::ostringstream o;
  o << "[" << lo * size << ", " << hi * size << "]" << mm << " (" << lo << " to " << hi
    << " times the patch's size D = " << size << mm
    << ", the diagonal of its control net's bounding box)";
  return o.str();
}

using nlohmann::json;

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }

  [[noreturn]] void fail(const std::string& ptr, const std::string& msg) const {
    throw InputError(file_, ptr, msg);
  }

  const json& object(const json& j, const std::string& ptr) const {
    if (!j.is_object()) fail(ptr, "must be an object, got " + std::string(j.type_name()));
    return j;
  }
  const json& array(const json& j, const std::string& ptr) const {
    if (!j.is_array()) fail(ptr, "must be an array, got " + std::string(j.type_name()));
    return j;
  }
  /// Unknown keys are errors; required keys must be present.
  void keys(const json& j, const std::string& ptr, std::initializer_list<const char*> allowed,
            std::initializer_list<const char*> required = {}) const {
    object(j, ptr);
    if (auto u = io::find_unknown_key(j, ptr, {allowed.begin(), allowed.end()}))
      fail(u->pointer, "unknown key" + u->note);
    for (const char* k : required)
      if (!j.contains(k)) fail(ptr, std::string("missing required key \"") + k + "\"");
  }
  double number(const json& j, const std::string& ptr) const {
    if (!j.is_number()) fail(ptr, "must be a number, got " + std::string(j.type_name()));
    const double x = j.get<double>();
    if (!std::isfinite(x)) fail(ptr, "must be finite");
    return x;
  }
  double positive(const json& j, const std::string& ptr) const {
    const double x = number(j, ptr);
    if (!(x > 0.0)) fail(ptr, "must be positive, got " + j.dump());
    return x;
  }
  int integer(const json& j, const std::string& ptr, int lo, int hi) const {
    if (!io::json_is_integer(j)) fail(ptr, "must be an integer, got " + j.dump());
    const long long v = io::json_integer_saturated(j);
    if (v < lo || v > hi)
      fail(ptr,
           "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + j.dump());
    return static_cast<int>(v);
  }
  bool boolean(const json& j, const std::string& ptr) const {
    if (!j.is_boolean()) fail(ptr, "must be true or false, got " + j.dump());
    return j.get<bool>();
  }
  std::string string(const json& j, const std::string& ptr) const {
    if (!j.is_string()) fail(ptr, "must be a string, got " + std::string(j.type_name()));
    return j.get<std::string>();
  }
  Eigen::Vector3d vec3(const json& j, const std::string& ptr) const {
    if (!j.is_array() || j.size() != 3) fail(ptr, "must be an array of 3 numbers");
    return {number(j[0], ptr + "/0"), number(j[1], ptr + "/1"), number(j[2], ptr + "/2")};
  }
  /// A parametric point in [0,1]^2.
  Eigen::Vector2d param(const json& j, const std::string& ptr) const {
    if (!j.is_array() || j.size() != 2) fail(ptr, "must be a parametric point [theta1, theta2]");
    Eigen::Vector2d t(number(j[0], ptr + "/0"), number(j[1], ptr + "/1"));
    if (t.minCoeff() < 0.0 || t.maxCoeff() > 1.0)
      fail(ptr, "parametric point (" + j[0].dump() + ", " + j[1].dump() +
                    ") is outside the domain [0,1]^2");
    return t;
  }
  Edge edge(const json& j, const std::string& ptr) const {
    const std::string s = string(j, ptr);
    const auto e = parse_edge(s);
    if (!e) fail(ptr, "no edge \"" + s + "\" (the patch's edges are u0, u1, v0, v1)");
    return *e;
  }
  Eigen::Vector2d corner(const json& j, const std::string& ptr) const {
    const std::string s = string(j, ptr);
    const auto c = parse_corner(s);
    if (!c) fail(ptr, "no corner \"" + s + "\" (the corners are u0v0, u1v0, u0v1, u1v1)");
    return *c;
  }
  int component(const json& j, const std::string& ptr) const {
    const std::string s = string(j, ptr);
    const int c = parse_component(s);
    if (c < 0) fail(ptr, "no component \"" + s + "\" (use x, y or z)");
    return c;
  }
  std::vector<double> numbers(const json& j, const std::string& ptr) const {
    array(j, ptr);
    std::vector<double> v;
    for (size_t i = 0; i < j.size(); ++i) v.push_back(number(j[i], ptr + "/" + std::to_string(i)));
    return v;
  }

 private:
  std::string file_;
};

/// Smallest non-empty knot span relative to the largest one (session 56's red team: a first
/// span of 1e-13 read "missing support: rigid-body rotation" on a clamped plate; 0.5 and
/// 0.5 + 1e-14 blamed the area quadrature on the surface's curvature; spans of 1e-5 to 1e-8
/// ended in "singular tangent stiffness"; a span of 1e-4 of the largest still converged).
constexpr double kMinKnotSpanRatio = 1e-4;

/// "" or why the knot vector U has a non-empty span shorter than kMinKnotSpanRatio of its
/// largest: the span, its knots' indices and the ratio.
std::string short_span(const std::vector<double>& U) {
  double largest = 0.0;
  for (std::size_t i = 1; i < U.size(); ++i) largest = std::max(largest, U[i] - U[i - 1]);
  for (std::size_t i = 1; i < U.size(); ++i) {
    const double h = U[i] - U[i - 1];
    if (h > 0.0 && h < kMinKnotSpanRatio * largest) {
      // The knots as written (the shortest text that reads back the same double).
      const auto exact = [](double x) {
        char buf[32];
        return std::string(buf, std::to_chars(buf, buf + sizeof buf, x).ptr);
      };
      std::ostringstream os;
      os.precision(3);
      os << "the knot span [" << exact(U[i - 1]) << ", " << exact(U[i]) << "] (knots " << i - 1
         << " and " << i << ") is ";
      os << h / largest << " of the largest span, below " << kMinKnotSpanRatio
         << ": its elements are degenerate (singular tangents, quadrature off)";
      return os.str();
    }
  }
  return {};
}

spline::BSplineBasis read_basis(const Reader& r, const json& g, int p, const char* key) {
  const std::string ptr = std::string("/geometry/") + key;
  const std::vector<double> U = r.numbers(g.at(key), ptr);
  try {
    spline::validate_knots(U, p);
  } catch (const spline::KnotVectorError& e) {
    r.fail(ptr, e.what());
  }
  if (U.front() != 0.0 || U.back() != 1.0)
    r.fail(ptr,
           "the knot vector must run from 0 to 1 (parametric points and edges refer to [0,1]^2)");
  if (const std::string why = short_span(U); !why.empty())
    r.fail(ptr,
           why +
               "; merge the two knots into one (its multiplicity at most the degree - 1) or space "
               "them farther apart");
  // The Kirchhoff-Love shell needs a C^1 geometry (eqs. 10-15: curvatures from second
  // derivatives). An interior knot of multiplicity m >= p leaves the surface C^(p-m) there,
  // and refinement keeps that continuity: C^0 acts as a hinge (session 27: a kinked plate
  // deflected 36 % more than the smooth one, exit 0), C^-1 tears the patch apart (a torn strip
  // carried 1e-13 N at 30 % strain, exit 0). The design fields may be C^-1; the geometry not.
  if (const auto kink = spline::first_non_c1_knot(U, p)) {
    std::ostringstream os;
    os << spline::describe_knot_break(*kink, p, "surface") << " ("
       << (kink->multiplicity > p ? "torn apart" : "a hinge")
       << "), and a Kirchhoff-Love shell needs C^1; ";
    if (p == 1)
      os << "a degree-1 geometry can have no interior knot: leave them out and subdivide "
            "with \"refinement\", or raise the degree";
    else
      os << "give interior knots multiplicity <= " << p - 1;
    r.fail(ptr, os.str());
  }
  return spline::BSplineBasis(p, U);
}

void read_geometry(const Reader& r, const json& root, Case& c) {
  if (!root.contains("geometry")) r.fail("", "missing required key \"geometry\"");
  const json& g = root.at("geometry");
  r.keys(g, "/geometry",
         {"degrees", "knots_u", "knots_v", "control_points", "weights", "thickness", "description"},
         {"degrees", "knots_u", "knots_v", "control_points", "thickness"});
  const json& d = g.at("degrees");
  if (!d.is_array() || d.size() != 2) r.fail("/geometry/degrees", "must be [p_u, p_v]");
  const int pu = r.integer(d[0], "/geometry/degrees/0", 1, spline::kMaxDegree);
  const int pv = r.integer(d[1], "/geometry/degrees/1", 1, spline::kMaxDegree);
  spline::BSplineBasis bu = read_basis(r, g, pu, "knots_u"), bv = read_basis(r, g, pv, "knots_v");
  const json& cp = r.array(g.at("control_points"), "/geometry/control_points");
  const int n = bu.size() * bv.size();
  if (static_cast<int>(cp.size()) != n)
    r.fail("/geometry/control_points",
           std::to_string(cp.size()) + " control points, but the knot vectors and degrees define " +
               std::to_string(bu.size()) + " x " + std::to_string(bv.size()) + " = " +
               std::to_string(n) + " (u index fastest)");
  Eigen::MatrixXd P(n, 3);
  for (int a = 0; a < n; ++a)
    P.row(a) = r.vec3(cp[a], "/geometry/control_points/" + std::to_string(a)).transpose();
  Eigen::VectorXd w;
  if (g.contains("weights")) {
    const std::vector<double> wv = r.numbers(g.at("weights"), "/geometry/weights");
    if (static_cast<int>(wv.size()) != n)
      r.fail("/geometry/weights",
             std::to_string(wv.size()) + " weights for " + std::to_string(n) + " control points");
    w.resize(n);
    for (int a = 0; a < n; ++a) {
      if (!(wv[a] > 0.0))
        r.fail("/geometry/weights/" + std::to_string(a), "weights must be positive");
      w(a) = wv[a];
    }
    // Weights orders of magnitude apart (session 40's red team: a weight of 1e-320 beside 1 was
    // reported at /geometry/control_points as a degenerate Jacobian, "coincident or collinear
    // control points?"). Named at the weight farthest from the median in log (the review: the
    // smallest blamed an ordinary 1 beside a 1e6).
    if (w.maxCoeff() > kMaxWeightRatio * w.minCoeff()) {
      std::vector<double> logs(wv.size());
      for (std::size_t a = 0; a < wv.size(); ++a) logs[a] = std::log(wv[a]);
      std::vector<double> sorted = logs;
      std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
      const double median = sorted[sorted.size() / 2];
      std::size_t far = 0;
      for (std::size_t a = 1; a < logs.size(); ++a)
        if (std::abs(logs[a] - median) > std::abs(logs[far] - median)) far = a;
      std::ostringstream m;
      m.precision(10);
      m << "the weights must lie within a factor of " << kMaxWeightRatio
        << " of each other; they range from " << w.minCoeff() << " to " << w.maxCoeff()
        << ", and this one, " << wv[far] << ", lies farthest from their median "
        << std::exp(median);
      r.fail("/geometry/weights/" + std::to_string(far), m.str());
    }
  }
  c.thickness = r.positive(g.at("thickness"), "/geometry/thickness");
  c.input_surface = spline::SplineSurface(bu, bv, P, w);
  const double size = patch_size(c.input_surface);
  // Session 29 (a helper's fuzzing audit): control points of 1e308 gave an infinite size, and
  // the message blamed the thickness ("must lie in [inf, inf] mm").
  if (!(std::isfinite(size) && size > 0.0))
    r.fail("/geometry/control_points",
           "the patch's size (its largest extent) is " + std::to_string(size) + length_unit(c) +
               ": the control points must span a finite, non-degenerate patch");
  // Session 46's red team: a flat patch at z = 1e300 was refused as "folded geometry ...
  // control points out of order?": so far from the origin its own extent is lost to round-off.
  for (Eigen::Index a = 0; a < P.rows(); ++a)
    if (P.row(a).cwiseAbs().maxCoeff() > kMaxOffsetPerSize * size) {
      std::ostringstream m;
      m.precision(4);
      m << "lies " << P.row(a).cwiseAbs().maxCoeff() << length_unit(c)
        << " from the origin in a coordinate, more than " << kMaxOffsetPerSize
        << " times the patch's size (" << size << length_unit(c)
        << "): the patch's own shape would be lost to round-off; move it nearer the origin";
      r.fail("/geometry/control_points/" + std::to_string(a), m.str());
    }
  if (!(c.thickness >= kMinThicknessPerSize * size && c.thickness <= kMaxThicknessPerSize * size))
    r.fail("/geometry/thickness",
           "the thickness must lie in " +
               relative_range(kMinThicknessPerSize, kMaxThicknessPerSize, size, c) + ", got " +
               g.at("thickness").dump() +
               "; are the control points and the thickness in the same length unit (mm for a "
               "knit case)?");
  c.surface = c.input_surface;
  if (root.contains("refinement")) {
    const json& rf = root.at("refinement");
    r.keys(rf, "/refinement", {"degree", "elements", "description"}, {"degree", "elements"});
    const int p = r.integer(rf.at("degree"), "/refinement/degree", 1, spline::kMaxDegree);
    if (p < std::max(pu, pv))
      r.fail("/refinement/degree", "degree " + std::to_string(p) + " is below the patch's degree " +
                                       std::to_string(std::max(pu, pv)) +
                                       " (degree elevation only)");
    const json& el = rf.at("elements");
    if (!el.is_array() || el.size() != 2)
      r.fail("/refinement/elements", "must be [elements_u, elements_v]");
    const int eu = r.integer(el[0], "/refinement/elements/0", 1, 256);
    const int ev = r.integer(el[1], "/refinement/elements/1", 1, 256);
    // Refuse a refinement that cannot fit in memory before making it (a lower bound; the
    // exact estimate below judges the refined patch).
    if (const MemoryEstimate low = estimate_refinement_memory(p, eu, ev);
        low.total() > memory_limit_bytes())
      r.fail("/refinement",
             std::to_string(eu) + " x " + std::to_string(ev) + " elements of degree " +
                 std::to_string(p) + " (at least " + std::to_string(eu + p) + " x " +
                 std::to_string(ev + p) + " control points) need at least " + low.describe() +
                 ", more than the " + format_bytes(memory_limit_bytes()) +
                 " available (KNIT_MAX_MEMORY_MB overrides); use fewer elements or a lower "
                 "degree");
    c.surface = refine_patch(c.input_surface, p, eu, ev);
    // The refinement's uniform knots can fall just beside an input knot.
    for (const auto& [basis, k] : {std::pair{&c.surface.basis_u(), 0}, {&c.surface.basis_v(), 1}})
      if (const std::string why = short_span(basis->knots()); !why.empty())
        r.fail("/refinement/elements/" + std::to_string(k),
               "after refinement " + why +
                   ": a uniform knot of the refinement falls beside an input knot; choose a "
                   "number of elements whose knots meet the input knots, or move the input knot");
  }
  // The analysis basis must be C^1 everywhere, which degree 1 is not between elements (session
  // 28: "refinement" to degree 1 put C^0 hinge lines inside the C^1 rule of the input knots),
  // and the bending strains of eq. 12 need second derivatives, which vanish on degree-1 spans.
  if (root.contains("refinement")) {
    if (c.surface.basis_u().degree() < 2 || c.surface.basis_v().degree() < 2)
      r.fail(
          "/refinement/degree",
          "the analysis degree must be >= 2 (a Kirchhoff-Love shell needs C^1 between "
          "elements and second derivatives for its curvatures), got " +
              std::to_string(std::min(c.surface.basis_u().degree(), c.surface.basis_v().degree())));
  } else if (pu < 2 || pv < 2) {
    r.fail(std::string("/geometry/degrees/") + (pu < 2 ? "0" : "1"),
           "degree 1 cannot be analysed as a Kirchhoff-Love shell (its curvatures need second "
           "derivatives and C^1 between elements); add \"refinement\": {\"degree\": 2 or more, "
           "\"elements\": [n_u, n_v]} to elevate the analysis basis");
  }
  // Refuse what cannot fit in memory now, not with std::bad_alloc at the start of the run.
  const MemoryEstimate mem = estimate_shell_memory(c.surface);
  const std::uint64_t limit = memory_limit_bytes();
  if (mem.total() > limit)
    r.fail(root.contains("refinement") ? "/refinement" : "/geometry",
           std::to_string(c.surface.size_u()) + " x " + std::to_string(c.surface.size_v()) +
               " control points of degree (" + std::to_string(c.surface.basis_u().degree()) + ", " +
               std::to_string(c.surface.basis_v().degree()) + ") need about " + mem.describe() +
               ", more than the " + format_bytes(limit) +
               " available (KNIT_MAX_MEMORY_MB overrides); use fewer elements or a lower degree");
}

void read_bcs(const Reader& r, const json& root, Case& c) {
  const double size = patch_size(c.input_surface);
  if (!root.contains("boundary_conditions")) return;
  const json& bcs = r.array(root.at("boundary_conditions"), "/boundary_conditions");
  for (size_t k = 0; k < bcs.size(); ++k) {
    const std::string ptr = "/boundary_conditions/" + std::to_string(k);
    const json& j = bcs[k];
    r.keys(j, ptr,
           {"edge", "corner", "point", "all", "fix", "prescribe", "clamp", "symmetry", "radius",
            "description"});
    BoundaryCondition bc;
    bc.pointer = ptr;
    const int targets = int(j.contains("edge")) + int(j.contains("corner")) +
                        int(j.contains("point")) + int(j.contains("all"));
    if (targets != 1)
      r.fail(ptr, "needs exactly one target: \"edge\", \"corner\", \"point\" or \"all\"");
    if (j.contains("edge")) {
      bc.target = BoundaryCondition::Target::kEdge;
      bc.edge = r.edge(j.at("edge"), ptr + "/edge");
    } else if (j.contains("corner")) {
      bc.target = BoundaryCondition::Target::kCorner;
      bc.corner = r.corner(j.at("corner"), ptr + "/corner");
    } else if (j.contains("point")) {
      // Choice: a point constraint acts on a control point, which interpolates the surface only
      // at the corners of an open-knot patch; interior points would need a penalty (not done).
      const Eigen::Vector2d t = r.param(j.at("point"), ptr + "/point");
      if ((t.array() * (1.0 - t.array())).abs().maxCoeff() > 0.0)
        r.fail(
            ptr + "/point",
            "displacement conditions at parametric points are supported at the corners only (the "
            "control net interpolates the surface there); use an edge or a corner");
      bc.target = BoundaryCondition::Target::kCorner;
      bc.corner = t;
    } else {
      if (!r.boolean(j.at("all"), ptr + "/all"))
        r.fail(ptr + "/all", "must be true (every control point)");
      bc.target = BoundaryCondition::Target::kAll;
    }
    if (j.contains("radius")) {
      if (bc.target != BoundaryCondition::Target::kCorner)
        r.fail(ptr + "/radius", "a radius spreads a corner condition: it needs \"corner\"");
      bc.radius = r.number(j.at("radius"), ptr + "/radius");
      if (bc.radius < 0)
        r.fail(ptr + "/radius", "must be >= 0 (" + unit_labels(c.units).of("mm") + "), got " +
                                    j.at("radius").dump());
    }
    if (j.contains("fix")) {
      const json& f = r.array(j.at("fix"), ptr + "/fix");
      for (size_t i = 0; i < f.size(); ++i)
        bc.fix[r.component(f[i], ptr + "/fix/" + std::to_string(i))] = true;
    }
    if (j.contains("prescribe")) {
      const json& p = r.object(j.at("prescribe"), ptr + "/prescribe");
      r.keys(p, ptr + "/prescribe", {"x", "y", "z"});
      for (auto it = p.begin(); it != p.end(); ++it) {
        const int comp = parse_component(it.key());
        if (bc.fix[comp]) r.fail(ptr + "/prescribe/" + it.key(), "component is also in \"fix\"");
        bc.prescribe[comp] = r.number(it.value(), ptr + "/prescribe/" + it.key());
        // Below 1e-12 of the patch's size a displacement is round-off of the geometry, and
        // below about 1e-154 mm its square underflows to 0: 1e-200 ran 0 iterations to a noise
        // load with exit 0 (session 29, a helper's fuzzing audit). 0 stays "held at 0".
        const double v = *bc.prescribe[comp];
        if (v != 0.0 && std::abs(v) < kMinPrescribedPerSize * size)
          r.fail(ptr + "/prescribe/" + it.key(),
                 "a prescribed displacement of " + it.value().dump() + length_unit(c) +
                     " is below 1e-12 of the patch's size (" + std::to_string(size) +
                     length_unit(c) +
                     "): round-off, not a load; give 0 or a displacement the patch can feel");
        // Above 100 times the patch's size no fabric follows (2.1e9 mm on a 50 mm patch ran to
        // reactions of 1e49 N with exit 0; session 29).
        if (std::abs(v) > kMaxPrescribedPerSize * size)
          r.fail(ptr + "/prescribe/" + it.key(),
                 "a prescribed displacement of " + it.value().dump() + length_unit(c) +
                     " is more than 100 times the patch's size (" + std::to_string(size) +
                     length_unit(c) + "): check the units (" + unit_labels(c.units).root + ")");
      }
    }
    if (j.contains("clamp")) {
      bc.clamp = r.boolean(j.at("clamp"), ptr + "/clamp");
      if (bc.clamp && bc.target != BoundaryCondition::Target::kEdge)
        r.fail(ptr + "/clamp", "only an edge can be clamped");
    }
    if (j.contains("symmetry")) {
      if (bc.target != BoundaryCondition::Target::kEdge)
        r.fail(ptr + "/symmetry", "a symmetry plane needs an edge");
      bc.symmetry = r.component(j.at("symmetry"), ptr + "/symmetry");
    }
    const bool any = bc.fix[0] || bc.fix[1] || bc.fix[2] || bc.prescribe[0] || bc.prescribe[1] ||
                     bc.prescribe[2] || bc.clamp || bc.symmetry >= 0;
    if (!any)
      r.fail(ptr, "constrains nothing (give \"fix\", \"prescribe\", \"clamp\" or \"symmetry\")");
    c.bcs.push_back(bc);
  }
}

void read_loads(const Reader& r, const json& root, Case& c) {
  if (!root.contains("loads")) return;
  const json& loads = r.array(root.at("loads"), "/loads");
  for (size_t k = 0; k < loads.size(); ++k) {
    const std::string ptr = "/loads/" + std::to_string(k);
    const json& j = r.object(loads[k], ptr);
    if (!j.contains("type")) r.fail(ptr, "missing required key \"type\" (point, edge or area)");
    const std::string type = r.string(j.at("type"), ptr + "/type");
    Load l;
    if (type == "point") {
      r.keys(j, ptr, {"type", "at", "corner", "force", "description"}, {"force"});
      if (j.contains("at") == j.contains("corner"))
        r.fail(ptr, "a point load needs either \"at\" or \"corner\"");
      l.kind = Load::Kind::kPoint;
      l.at = j.contains("at") ? r.param(j.at("at"), ptr + "/at")
                              : r.corner(j.at("corner"), ptr + "/corner");
      l.value = r.vec3(j.at("force"), ptr + "/force");
    } else if (type == "edge") {
      r.keys(j, ptr, {"type", "edge", "force_per_length", "description"},
             {"edge", "force_per_length"});
      l.kind = Load::Kind::kEdge;
      l.edge = r.edge(j.at("edge"), ptr + "/edge");
      l.value = r.vec3(j.at("force_per_length"), ptr + "/force_per_length");
    } else if (type == "area") {
      r.keys(j, ptr, {"type", "force_per_area", "description"}, {"force_per_area"});
      l.kind = Load::Kind::kArea;
      l.value = r.vec3(j.at("force_per_area"), ptr + "/force_per_area");
    } else {
      r.fail(ptr + "/type", "unknown load type \"" + type + "\" (point, edge or area)");
    }
    c.loads.push_back(l);
  }
}

void read_solver(const Reader& r, const json& root, Case& c) {
  if (!root.contains("solver")) return;
  const json& s = root.at("solver");
  r.keys(s, "/solver",
         {"steps", "tolerance", "absolute_tolerance", "max_iterations", "max_cutbacks",
          "line_search", "line_search_first", "threads", "thickness_integration",
          "extra_quadrature_points", "description"});
  SolverOptions& o = c.solver;
  if (s.contains("steps")) o.steps = r.integer(s.at("steps"), "/solver/steps", 1, 100000);
  // Upper bounds (session 21, found by fuzzing: a tolerance of 1e308 accepted every first
  // iterate, 0 Newton iterations, and the run ended with exit 0).
  if (s.contains("tolerance")) {
    o.tolerance = r.positive(s.at("tolerance"), "/solver/tolerance");
    if (o.tolerance > kMaxRelativeTolerance)
      r.fail("/solver/tolerance",
             "must be at most 0.01 (relative to the load), got " + s.at("tolerance").dump());
  }
  if (s.contains("absolute_tolerance")) {
    o.absolute_tolerance = r.positive(s.at("absolute_tolerance"), "/solver/absolute_tolerance");
    if (o.absolute_tolerance > kMaxAbsoluteTolerance)
      r.fail("/solver/absolute_tolerance", "must be at most 0.001 " + unit_labels(c.units).of("N") +
                                               ", got " + s.at("absolute_tolerance").dump());
  }
  if (s.contains("max_iterations"))
    o.max_iterations = r.integer(s.at("max_iterations"), "/solver/max_iterations", 1, 1000);
  if (s.contains("max_cutbacks"))
    o.max_cutbacks = r.integer(s.at("max_cutbacks"), "/solver/max_cutbacks", 0, 40);
  if (s.contains("line_search"))
    o.line_search = r.boolean(s.at("line_search"), "/solver/line_search");
  if (s.contains("line_search_first"))
    o.line_search_first = r.boolean(s.at("line_search_first"), "/solver/line_search_first");
  if (s.contains("threads")) c.threads = r.integer(s.at("threads"), "/solver/threads", 1, 64);
  if (s.contains("extra_quadrature_points"))
    c.extra_quadrature_points =
        r.integer(s.at("extra_quadrature_points"), "/solver/extra_quadrature_points", 0,
                  kMaxExtraQuadraturePoints);
  if (s.contains("thickness_integration")) {
    const std::string ti = r.string(s.at("thickness_integration"), "/solver/thickness_integration");
    if (ti == "gauss3")
      c.integration = ThicknessIntegration::kGauss3;
    else if (ti == "analytic")
      c.integration = ThicknessIntegration::kAnalytic;
    else
      r.fail("/solver/thickness_integration",
             "must be \"gauss3\" or \"analytic\", got \"" + ti + "\"");
  }
}

void read_output(const Reader& r, const json& root, Case& c) {
  if (!root.contains("output")) return;
  const json& o = root.at("output");
  r.keys(o, "/output",
         {"grid", "every", "vtk", "hdf5", "points", "reactions", "applied_displacement",
          "description"});
  OutputOptions& out = c.output;
  if (o.contains("grid")) {
    const json& g = o.at("grid");
    if (!g.is_array() || g.size() != 2) r.fail("/output/grid", "must be [samples_u, samples_v]");
    out.grid_u = r.integer(g[0], "/output/grid/0", 2, 1001);
    out.grid_v = r.integer(g[1], "/output/grid/1", 2, 1001);
  }
  if (o.contains("every")) out.every = r.integer(o.at("every"), "/output/every", 1, 100000);
  if (o.contains("vtk")) out.vtk = r.boolean(o.at("vtk"), "/output/vtk");
  if (o.contains("hdf5")) out.hdf5 = r.boolean(o.at("hdf5"), "/output/hdf5");
  std::set<std::string> names;
  // Names become HDF5 datasets and CSV columns: checked here, before any work (a point
  // named "." used to fail only when the results were written).
  auto unique_name = [&](const json& j, const std::string& ptr) {
    const std::string n = r.string(j, ptr);
    if (const auto problem = io::output_name_problem(n)) r.fail(ptr, *problem);
    if (!names.insert(n).second) r.fail(ptr, "the name \"" + n + "\" is used twice");
    return n;
  };
  if (o.contains("points")) {
    const json& ps = r.array(o.at("points"), "/output/points");
    for (size_t k = 0; k < ps.size(); ++k) {
      const std::string ptr = "/output/points/" + std::to_string(k);
      r.keys(ps[k], ptr, {"name", "at"}, {"name", "at"});
      out.points.push_back(
          {unique_name(ps[k].at("name"), ptr + "/name"), r.param(ps[k].at("at"), ptr + "/at")});
    }
  }
  if (o.contains("reactions")) {
    const json& rs = r.array(o.at("reactions"), "/output/reactions");
    for (size_t k = 0; k < rs.size(); ++k) {
      const std::string ptr = "/output/reactions/" + std::to_string(k);
      r.keys(rs[k], ptr, {"name", "edge", "corner", "component", "rows", "radius"},
             {"name", "component"});
      if (rs[k].contains("edge") == rs[k].contains("corner"))
        r.fail(ptr, "needs either \"edge\" or \"corner\"");
      ReactionOutput ro;
      ro.name = unique_name(rs[k].at("name"), ptr + "/name");
      ro.at_edge = rs[k].contains("edge");
      if (ro.at_edge)
        ro.edge = r.edge(rs[k].at("edge"), ptr + "/edge");
      else
        ro.corner = r.corner(rs[k].at("corner"), ptr + "/corner");
      if (!ro.at_edge && rs[k].contains("rows")) r.fail(ptr + "/rows", "rows apply to edges only");
      if (rs[k].contains("radius")) {
        if (ro.at_edge) r.fail(ptr + "/radius", "a radius applies to corners only");
        ro.radius = r.number(rs[k].at("radius"), ptr + "/radius");
        if (ro.radius < 0)
          r.fail(ptr + "/radius", "must be >= 0 (" + unit_labels(c.units).of("mm") + "), got " +
                                      rs[k].at("radius").dump());
      }
      ro.component = r.component(rs[k].at("component"), ptr + "/component");
      if (rs[k].contains("rows")) {
        ro.rows = r.integer(rs[k].at("rows"), ptr + "/rows", 1, 2);
      } else if (ro.at_edge && edge_is_clamped(c.bcs, ro.edge)) {
        // A clamped edge's second row of control points carries part of its support force
        // (session 46's walkthrough: a clamped jaw read 5.72 N with one row against 14.78 N,
        // silently): its default is both rows.
        ro.rows = 2;
      }
      out.reactions.push_back(ro);
    }
  }
  if (o.contains("applied_displacement")) {
    const std::string ptr = "/output/applied_displacement";
    const json& a = o.at(ptr.substr(8));
    r.keys(a, ptr, {"edge", "corner", "component", "gauge_length"}, {"component", "gauge_length"});
    if (a.contains("edge") == a.contains("corner"))
      r.fail(ptr, "needs either \"edge\" or \"corner\"");
    AppliedDisplacement ad;
    ad.at_edge = a.contains("edge");
    if (ad.at_edge)
      ad.edge = r.edge(a.at("edge"), ptr + "/edge");
    else
      ad.corner = r.corner(a.at("corner"), ptr + "/corner");
    ad.component = r.component(a.at("component"), ptr + "/component");
    ad.gauge_length = r.positive(a.at("gauge_length"), ptr + "/gauge_length");
    const double size = patch_size(c.input_surface);
    if (!(ad.gauge_length >= kMinGaugePerSize * size && ad.gauge_length <= kMaxGaugePerSize * size))
      r.fail(ptr + "/gauge_length",
             "the gauge length (the distance between the jaws) must lie in " +
                 relative_range(kMinGaugePerSize, kMaxGaugePerSize, size, c) + ", got " +
                 a.at("gauge_length").dump());
    // The condition that prescribes the component there: one on the same edge or corner, else
    // (a corner) one on an edge through it, else one on all control points (session 48's red
    // team: a corner whose edge was prescribed was refused with "no boundary condition
    // prescribes this component", which was false). Two that disagree are refused by the run
    // (a displacement takes one value).
    using Target = BoundaryCondition::Target;
    const auto on_edge = [](const Eigen::Vector2d& corner, Edge e) {
      switch (e) {
        case Edge::kU0:
          return corner(0) == 0.0;
        case Edge::kU1:
          return corner(0) == 1.0;
        case Edge::kV0:
          return corner(1) == 0.0;
        case Edge::kV1:
          return corner(1) == 1.0;
      }
      return false;
    };
    int best = 3;  // 0 the same place, 1 an edge through the corner, 2 everywhere
    for (const BoundaryCondition& bc : c.bcs) {
      if (!bc.prescribe[ad.component]) continue;
      int rank = 3;
      if (bc.target == Target::kAll)
        rank = 2;
      else if (ad.at_edge)
        rank = bc.target == Target::kEdge && bc.edge == ad.edge ? 0 : 3;
      else if (bc.target == Target::kCorner)
        rank = bc.corner == ad.corner ? 0 : 3;
      else if (bc.target == Target::kEdge)
        rank = on_edge(ad.corner, bc.edge) ? 1 : 3;
      if (rank < best) {
        best = rank;
        ad.value = *bc.prescribe[ad.component];
      }
    }
    if (best == 3)
      r.fail(ptr, ad.at_edge
                      ? "no boundary condition prescribes this component on that edge (or on "
                        "all control points)"
                      : "no boundary condition prescribes this component at that corner (on "
                        "it, on an edge through it or on all control points)");
    out.applied = ad;
  }
}

}  // namespace

namespace {
Case parse_case_json(const json& root, const std::string& text, const std::string& file);
}  // namespace

Case parse_case(const std::string& text, const std::string& file) {
  // Parse errors name the line and column; duplicate keys are errors (knit/io).
  const json root = io::parse_json(text, file);
  try {
    return parse_case_json(root, text, file);
  } catch (const InputError& e) {
    // The line of the field, as the schema-driven readers give it (session 25: a case file's
    // errors named the pointer only). An error inside another file (the database) keeps its
    // own location.
    if (auto lined = io::error_with_line(e, text, file)) throw *lined;
    throw;
  }
}

namespace {
Case parse_case_json(const json& root, const std::string& text, const std::string& file) {
  Reader r(file);
  // A design file given for the case (session 47's walkthrough: "/case: unknown key" said
  // nothing of what the file is).
  if (root.is_object() && root.contains("case") && root.contains("variables") &&
      !root.contains("geometry"))
    throw InputError(file, "",
                     "is a design file (it has \"case\" and \"variables\"), not a case file: run "
                     "it with knit-macro design, or give the case file it names in \"case\"");
  r.keys(root, "",
         {"$schema", "description", "units", "geometry", "refinement", "material",
          "boundary_conditions", "loads", "solver", "output"},
         {"geometry", "material"});
  Case c;
  c.file = file;
  c.text = text;
  if (root.contains("description"))
    c.description = r.string(root.at("description"), "/description");
  if (root.contains("units")) {
    c.units = r.string(root.at("units"), "/units");
    if (const std::string why = units_problem(c.units); !why.empty()) r.fail("/units", why);
  }
  read_geometry(r, root, c);
  // A zero or flipped Jacobian anywhere (corners and edges included) is bad input, refused
  // before any work (knit/macro/geometry_check.hpp).
  // With NURBS weights that differ, the weights bend the map as well (the session's review:
  // weights 1, 1, 1e5, 1 were blamed on "coincident or collinear control points?" alone).
  const auto weights_note = [&]() -> std::string {
    if (!c.input_surface.rational()) return {};
    const Eigen::VectorXd& wt = c.input_surface.weights();
    if (wt.maxCoeff() <= wt.minCoeff()) return {};
    std::ostringstream m;
    m.precision(6);
    m << "; or the NURBS weights (/geometry/weights, from " << wt.minCoeff() << " to "
      << wt.maxCoeff() << "): weights far apart degenerate the map as well";
    return m.str();
  };
  if (const auto bad = find_geometry_defect(c.surface))
    r.fail("/geometry/control_points", bad->message + weights_note());
  if (const auto bad =
          find_geometry_defect(c.input_surface, dense_samples_per_span(c.input_surface)))
    r.fail("/geometry/control_points", bad->message + weights_note());
  // The shell's quadrature must integrate at least the area of every element (session 28: NURBS
  // weights 1, 1, 1, 10 on the one-element tensile patch, the same flat square, gave 23 % more
  // jaw force with the area integrated 0.5 % off; weights up to 1e4 ran with exit 0, results
  // hundreds of times off). The paper's cases: at most 8e-5.
  if (const auto bad = area_quadrature_defect(c.surface)) {
    std::ostringstream m;
    m.precision(2);
    m << "the shell's quadrature (p + 1 Gauss points per element and direction) integrates the "
         "area of the element ["
      << bad->lo(0) << ", " << bad->hi(0) << "] x [" << bad->lo(1) << ", " << bad->hi(1) << "] "
      << 100.0 * bad->error << " % off (more than " << 100.0 * kMaxAreaQuadratureError << " %): "
      << (c.surface.rational() ? "the NURBS weights or the curvature vary too much within it"
                               : "the surface curves too much within it")
      << "; use more elements (\"refinement\")"
      << (c.surface.rational() ? " or weights closer to each other" : "");
    r.fail(c.input_surface.rational() ? "/geometry/weights" : "/geometry/control_points", m.str());
  }
  CaseContext ctx;
  ctx.file = file;
  ctx.pointer = "/material";
  ctx.patch = &c.surface;
  ctx.thickness = c.thickness;
  c.material = make_material(root.at("material"), ctx);
  // A material with data in fixed units (the knit database: mm, N, MPa): a case declaring other
  // units would run with its numbers read as those (session 22).
  // Compared without blanks ("mm,N,MPa" and "mm, N, MPa " are the same units: session 43's
  // walkthrough had them refused); the symbols themselves are case-sensitive (mN, MN).
  const auto no_blanks = [](std::string u) {
    u.erase(std::remove_if(u.begin(), u.end(), [](unsigned char ch) { return std::isspace(ch); }),
            u.end());
    return u;
  };
  if (const std::string units = c.material->required_units();
      !units.empty() && root.contains("units") &&
      no_blanks(root.at("units").get<std::string>()) != no_blanks(units))
    r.fail("/units", "a " + c.material->name() + " case is in \"" + units +
                         "\" (its material database's units), got " + root.at("units").dump());
  read_bcs(r, root, c);
  read_loads(r, root, c);
  read_solver(r, root, c);
  // More Gauss points hold more quadrature data: the memory check of the geometry, again.
  if (c.extra_quadrature_points > 0) {
    const MemoryEstimate mem = estimate_shell_memory(c.surface, c.extra_quadrature_points);
    if (mem.total() > memory_limit_bytes())
      r.fail("/solver/extra_quadrature_points",
             std::to_string(c.extra_quadrature_points) +
                 " extra Gauss points per direction need about " + mem.describe() +
                 ", more than the " + format_bytes(memory_limit_bytes()) +
                 " available (KNIT_MAX_MEMORY_MB overrides); use fewer");
  }
  c.solver.force_unit = unit_labels(c.units).of("N");
  read_output(r, root, c);
  // The columns of load_strain.csv, unit suffixes included, must not repeat (session 48's
  // review: without suffixes, in a case's own units, a reaction "strain" hid the strain column
  // from a reader by name).
  if (const std::string rep = repeated_load_strain_column(c); !rep.empty())
    r.fail("/output",
           "the column \"" + rep +
               "\" of load_strain.csv would appear twice: a reaction or output point is named "
               "like another column (with its unit suffix, if the case's /units has symbols); "
               "rename it");
  if (c.integration == ThicknessIntegration::kAnalytic &&
      !c.material->has_analytic_thickness_integration())
    r.fail("/solver/thickness_integration",
           "the material \"" + c.material->name() + "\" has no analytic thickness integration");
  // The schema as the last word: the checks above are more specific, it catches what they miss.
  io::JsonSchema::embedded("case").validate(root, file);
  return c;
}
}  // namespace

Case load_case(const std::string& path) {
  // Regular files only, at most io::kMaxJsonInputBytes (a FIFO blocked, /dev/zero never ended).
  return parse_case(io::read_input_file(path), path);
}

}  // namespace knit::macro
