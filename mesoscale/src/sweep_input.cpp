#include <Eigen/Dense>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "knit/core/errors.hpp"
#include "knit/io/input_file.hpp"
#include "knit/io/json_input.hpp"
#include "knit/meso/sweep/input.hpp"

namespace knit::meso::sweep {

namespace {

/// The shortest text that reads back as x (4.500000000000001, not %g's 4.5).
std::string shortest(double x) {
  char b[32];
  const auto r = std::to_chars(b, b + sizeof b, x);
  return std::string(b, r.ptr);
}

constexpr double kPi = 3.14159265358979323846;

/// Appends generated or explicit paths (not in the shared default set: path id -1), from the
/// input field `field`.
void append(SweepInput& in, const std::vector<material::LoadPath>& paths,
            const std::string& field) {
  for (const auto& p : paths) {
    in.paths.push_back(p);
    in.path_ids.push_back(-1);
    in.path_fields.push_back(field);
  }
}

/// "box": {"E11": [min, max], "E22": [min, max], "E12_max": m} over the defaults of StrainBox.
material::StrainBox read_box(const nlohmann::json& lp, const std::string& file) {
  material::StrainBox b;
  if (!lp.contains("box")) return b;
  const auto& j = lp.at("box");
  if (j.contains("E11")) {
    b.E11_min = j.at("E11").at(0).get<double>();
    b.E11_max = j.at("E11").at(1).get<double>();
  }
  if (j.contains("E22")) {
    b.E22_min = j.at("E22").at(0).get<double>();
    b.E22_max = j.at("E22").at(1).get<double>();
  }
  b.E12_max = j.value("E12_max", b.E12_max);
  // Each side at least kMinBoxExtent from 0 (session 23's note: a box of 1e-300 ran, its
  // coverage paths all at zero strain and the law fitted on the paper's paths alone).
  const double m = material::StrainBox::kMinExtent;
  std::ostringstream range;
  range << "must be [min <= -" << m << ", max >= " << m << "] (the box spans the strains the "
        << "cases visit; docs/unit-cell.md, \"Strain box\")";
  if (!(b.E11_min <= -m && b.E11_max >= m))
    throw InputError(file, "/load_paths/box/E11", range.str());
  if (!(b.E22_min <= -m && b.E22_max >= m))
    throw InputError(file, "/load_paths/box/E22", range.str());
  if (!(b.E12_max >= m)) {
    std::ostringstream e12;
    e12 << "must be >= " << m;
    throw InputError(file, "/load_paths/box/E12_max", e12.str());
  }
  return b;
}

/// "coverage": true (the defaults of CoverageOptions) or an object overriding them.
material::CoverageOptions read_coverage(const nlohmann::json& c, const material::StrainBox& box) {
  material::CoverageOptions o;
  o.box = box;
  if (!c.is_object()) return o;
  o.directions = c.value("directions", o.directions);
  o.biaxial_steps = c.value("biaxial_steps", o.biaxial_steps);
  o.uniaxial_steps = c.value("uniaxial_steps", o.uniaxial_steps);
  o.gradient_steps = c.value("gradient_steps", o.gradient_steps);
  o.fill_count = c.value("fill_count", o.fill_count);
  o.fill_steps = c.value("fill_steps", o.fill_steps);
  o.fill_min_J = c.value("fill_min_J", o.fill_min_J);
  o.rays = c.value("rays", o.rays);
  o.ray_steps = c.value("ray_steps", o.ray_steps);
  o.gradient_swapped = c.value("gradient_swapped", o.gradient_swapped);
  if (c.contains("gamma_deg")) o.gamma = c.at("gamma_deg").get<double>() * kPi / 180.0;
  if (c.contains("stretch")) {
    o.stretch.clear();
    for (const auto& e : c.at("stretch"))
      o.stretch.emplace_back(e.at(0).get<double>(), e.at(1).get<double>());
  }
  return o;
}

/// The smallest area ratio J = det F a ray may run to: that of an explicit gradient path
/// (det(I + H) > 0.05, explicit_paths).
constexpr double kMinRayJ = 0.05;

/// Rays are shortened to J = fill_min_J where they would leave the admissible states; below
/// kMinRayJ that is refused, naming the field (session 44's red team: fill_min_J 0 ran rays of
/// the default box to J = 0, a collapsed cell without a deformation gradient, and the sweep
/// ended with exit 1 and "load path: no upper-triangular F for this strain", naming nothing).
/// A ray that reaches the box's surface first is not shortened: fill_min_J does not matter
/// for it, and a box whose rays all do so takes any value.
void check_ray_floor(const material::CoverageOptions& co, const std::string& file) {
  if (co.rays == 0 || co.fill_min_J >= kMinRayJ) return;
  int below = 0;  // rays that reach J = kMinRayJ inside the box (shortened there)
  for (int k = 0; k < co.rays; ++k) {
    const Eigen::Vector3d E =
        material::box_ray_end(co.box, material::half_sphere_direction(k, co.rays), kMinRayJ);
    const double J2 = (1.0 + 2.0 * E(0)) * (1.0 + 2.0 * E(1)) - 4.0 * E(2) * E(2);
    if (J2 < std::pow(kMinRayJ * (1.0 + 1e-6), 2)) ++below;
  }
  if (below == 0) return;
  throw InputError(
      file, "/load_paths/coverage/fill_min_J",
      "is " + shortest(co.fill_min_J) + ", but " + std::to_string(below) + " of the " +
          std::to_string(co.rays) +
          " rays (/load_paths/coverage/rays) would run past J = det F = " + shortest(kMinRayJ) +
          " in this box, towards a collapsed cell (J = 0: no deformation gradient); "
          "with rays it must be >= " +
          shortest(kMinRayJ) +
          ", the floor of an explicit gradient path's det(I + H) (default 0.5: the "
          "cell locks up below)");
}

/// The generated shear-with-stretch paths, H = [[e1, sin gamma], [0, e2]], are held to the end
/// an explicit path must reach (explicit_paths: largest |H| >= StrainBox::kMinExtent; session
/// 44's red team: "gamma_deg": 0 with the stretch [0, 0] gave a path of ten states at F = I,
/// fitted by the energy law with exit 0, and 0.0001 deg one ending at H12 = 1.7e-6).
void check_gradient_ends(const material::CoverageOptions& co, const nlohmann::json& c,
                         const std::string& file) {
  const double m = material::StrainBox::kMinExtent;
  const bool given = c.is_object() && c.contains("stretch");
  for (std::size_t k = 0; k < co.stretch.size(); ++k) {
    const Eigen::Vector2d& e = co.stretch[k];
    const double reach = std::max({std::abs(e(0)), std::abs(e(1)), std::abs(std::sin(co.gamma))});
    if (reach >= m) continue;
    std::ostringstream o;
    // (the values in full, shortest(): the review of session 44 had "[0.001, 0] ... is below
    // 0.001" for 0.00099999999)
    o << "is " << co.gamma * 180.0 / kPi << " deg, and the stretch [" << shortest(e(0)) << ", "
      << shortest(e(1)) << "] (" << io::json_pointer_append("/load_paths/coverage/stretch", k)
      << (given ? "" : ", the default") << ") is below " << m
      << " too: its shear-with-stretch path ends "
      << (reach == 0.0 ? "at" : "within " + shortest(m) + " of")
      << " the reference state (largest |H| " << shortest(reach) << ", below " << m
      << ") and carries no data; give gamma_deg >= " << std::ceil(m * 180.0 / kPi * 1e4) / 1e4
      << " (" << m << " rad) or stretches of at least " << m
      << ", as for an explicit path, or leave \"stretch\" empty for no such paths";
    throw InputError(file, "/load_paths/coverage/gamma_deg", o.str());
  }
}

/// An explicit list of paths (schemas/sweep.schema.json, the array form).
std::vector<material::LoadPath> explicit_paths(const nlohmann::json& lp, int steps,
                                               const std::string& file,
                                               const std::string& pointer) {
  std::vector<material::LoadPath> out;
  for (std::size_t i = 0; i < lp.size(); ++i) {
    const auto& q = lp[i];
    material::LoadPath p;
    p.steps = q.value("steps", steps);
    p.set = q.value("set", std::string("paper"));
    p.kind = material::path_kind_from_string(q.at("kind").get<std::string>());
    switch (p.kind) {
      case material::PathKind::kBiaxial:
        p.target = {q.at("E11").get<double>(), q.at("E22").get<double>()};
        break;
      case material::PathKind::kShear:
        p.target = {q.at("gamma_deg").get<double>() * kPi / 180.0, 0.0};
        break;
      case material::PathKind::kUniaxial:
        p.axis = q.at("axis") == "wale" ? 1 : 0;
        p.target = {q.at("E").get<double>(), 0.0};
        break;
      case material::PathKind::kGradient: {
        const auto& H = q.at("H");
        p.H << H.at(0).at(0).get<double>(), H.at(0).at(1).get<double>(),
            H.at(1).at(0).get<double>(), H.at(1).at(1).get<double>();
        const Eigen::Matrix2d F = Eigen::Matrix2d::Identity() + p.H;
        if (!(F.determinant() > 0.05))
          throw InputError(file, io::json_pointer_append(pointer, i) + "/H",
                           "det(I + H) must be > 0.05 (an admissible deformation)");
        break;
      }
    }
    // A path that ends where it starts carries no data (session 36's red team: a paper
    // biaxial path to (0, 0) passed the early checks and folded the surface after the sweep).
    // Nor does one that ends within round-off of it (session 43's red team: a shear path to
    // 1e-300 deg gave a shear curve of noise and "fit ok"): its end must reach
    // StrainBox::kMinExtent (the shear angle in radians, the box's own smallest side).
    const bool gradient = p.kind == material::PathKind::kGradient;
    const double reach = gradient ? p.H.cwiseAbs().maxCoeff() : p.target.cwiseAbs().maxCoeff();
    if (!(reach >= material::StrainBox::kMinExtent)) {
      std::ostringstream o;
      o << "the path ends " << (reach == 0.0 ? "at" : "within round-off of")
        << " the reference state (";
      if (p.kind == material::PathKind::kShear)  // given in degrees (session 43's review)
        o << "shear angle " << reach * 180.0 / kPi << " deg, below "
          << material::StrainBox::kMinExtent * 180.0 / kPi
          << " deg = " << material::StrainBox::kMinExtent << " rad";
      else
        o << (gradient ? "largest |H| " : "largest end strain ") << reach << ", below "
          << material::StrainBox::kMinExtent;
      o << "): it carries no data; give it an end of at least that size";
      throw InputError(file, io::json_pointer_append(pointer, i), o.str());
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace

std::string fingerprint(const std::string& text) {
  // Not the standard FNV-1a 64: its offset basis is 14695981039346656037 (io_hdf5.cpp's). This
  // one lost the last digit when it was written; it stays, since every checkpoint digest and
  // manifest fingerprint of an earlier version was made with it (docs/sweep.md, session 38).
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string SweepInput::job_definition() const {
  nlohmann::json j;
  j["loop_lengths"] = loop_lengths;
  nlohmann::json p = nlohmann::json::array();
  for (const auto& q : paths)
    p.push_back({{"kind", material::to_string(q.kind)},
                 {"target", {q.target(0), q.target(1)}},
                 {"axis", q.axis},
                 {"H", {q.H(0, 0), q.H(0, 1), q.H(1, 0), q.H(1, 1)}},
                 {"set", q.set},
                 {"steps", q.steps}});
  j["paths"] = p;
  j["runner"] = runner == RunnerKind::kCell ? "cell" : "synthetic";
  j["cell"] = nlohmann::json::parse(cell_json);
  j["retry"] = {{"max_retries", retry.max_retries},
                {"step_factor", retry.step_factor},
                {"max_retries_coverage", retry.max_retries_extra}};
  // Only when set, so that the job definitions (and checkpoints) of sweeps without it stay as
  // they were.
  if (retry.substeps_paper != 1 || retry.substeps_coverage != 1 || retry.substeps_holdout != 1)
    j["substeps"] = {{"paper", retry.substeps_paper},
                     {"coverage", retry.substeps_coverage},
                     {"holdout", retry.substeps_holdout}};
  return j.dump();  // keys sorted (std::map): canonical
}

SweepInput parse_sweep_input(const std::string& text, const std::string& file) {
  nlohmann::json j = io::parse_json(text, file);
  io::JsonSchema::embedded("sweep").validate(j, file);

  SweepInput in;
  in.file = file;
  in.json = text;
  in.loop_lengths = j.at("loop_lengths").get<std::vector<double>>();
  // At least kMinLoopLengthSpacing apart (session 36's red team: 4.5 and 4.500000000000001
  // were two loop lengths, both reported as "l=4.50", and a repeated one was "got 4.500000
  // after 4.500000"); printed in full.
  constexpr double kMinLoopLengthSpacing = 1e-3;
  for (std::size_t k = 1; k < in.loop_lengths.size(); ++k)
    // (1e-9 mm of slack: 4.001 after 4 is 0.001 apart, though not in binary floating point)
    if (!(in.loop_lengths[k] >= in.loop_lengths[k - 1] + kMinLoopLengthSpacing - 1e-9))
      throw InputError(file, io::json_pointer_append("/loop_lengths", k),
                       "loop lengths must increase by at least 0.001 mm, got " +
                           shortest(in.loop_lengths[k]) + " after " +
                           shortest(in.loop_lengths[k - 1]));
  const int steps = j.value("steps", 20);

  const nlohmann::json lp = j.value("load_paths", nlohmann::json{{"preset", "default"}});
  if (lp.is_object()) {
    // Absent keys take the defaults of material::default_load_paths (one place: until session
    // 25 this read 0.35 for e_max where the header and docs/database.md say 0.40).
    const double e_max = lp.value("e_max", material::kDefaultFanEMax);
    const double e_min = lp.value("e_min", material::kDefaultFanEMin);
    const double g_max = lp.value("gamma_max_deg", 40.0) * kPi / 180.0;
    if (!(e_min < e_max)) throw InputError(file, "/load_paths/e_min", "must be smaller than e_max");
    // Ends that carry data (session 43's red team: gamma_max_deg 1e-300 gave a shear curve of
    // noise and "fit ok"; the box has the same floor).
    const double m = material::StrainBox::kMinExtent;
    if (!(e_max >= m))
      throw InputError(file, "/load_paths/e_max",
                       "must be >= " + io::format_number(m) + " (the fan's end strain)");
    if (!(g_max >= m))
      throw InputError(file, "/load_paths/gamma_max_deg",
                       "must be >= " + io::format_number(m * 180.0 / kPi) + " deg (" +
                           io::format_number(m) + " rad: the shear path's end)");
    const auto all = material::default_load_paths(steps, e_max, e_min, g_max);
    if (lp.contains("select")) {
      for (int id : lp.at("select").get<std::vector<int>>()) {
        in.paths.push_back(all.at(static_cast<std::size_t>(id)));
        in.path_ids.push_back(id);
      }
    } else {
      in.paths = all;
      for (std::size_t i = 0; i < all.size(); ++i) in.path_ids.push_back(static_cast<int>(i));
    }
    in.path_fields.assign(in.paths.size(), "/steps");
    const material::StrainBox box = read_box(lp, file);
    if (lp.contains("coverage")) {
      const material::CoverageOptions co = read_coverage(lp.at("coverage"), box);
      check_ray_floor(co, file);
      check_gradient_ends(co, lp.at("coverage"), file);
      append(in, material::coverage_load_paths(co), "/load_paths/coverage");
    }
    if (lp.contains("holdout")) {
      const auto& h = lp.at("holdout");
      append(in, material::holdout_load_paths(box, h.value("count", 24), h.value("steps", steps)),
             "/load_paths/holdout");
    }
    if (lp.contains("extra"))
      append(in, explicit_paths(lp.at("extra"), steps, file, "/load_paths/extra"),
             "/load_paths/extra");
  } else {
    append(in, explicit_paths(lp, steps, file, "/load_paths"), "/load_paths");
  }

  if (j.contains("runner"))
    in.runner = j.at("runner") == "synthetic" ? RunnerKind::kSynthetic : RunnerKind::kCell;
  if (j.contains("cell")) {
    nlohmann::json c = j.at("cell");
    std::string source = file, prefix = "/cell";
    if (c.is_string()) {
      const auto path = io::resolve_input_path(file, c.get<std::string>());
      try {
        c = io::read_json_file(path);
      } catch (const InputError& e) {
        // Said "x: file not found" without the sweep input and the field that named it.
        throw InputError(file, "/cell",
                         "the cell parameter file cannot be read: " + std::string(e.what()));
      }
      in.cell_file = source = path.string();
      prefix.clear();
    }
    // The cell's own schema, when this build has it (the cell module embeds it).
    const auto names = io::embedded_schema_names();
    if (std::find(names.begin(), names.end(), "cell") != names.end()) {
      const auto errs = io::JsonSchema::embedded("cell").errors(c);
      if (!errs.empty()) throw InputError(source, prefix + errs[0].pointer, errs[0].message);
    } else if (!c.is_object()) {
      throw InputError(source, prefix, "must be an object");
    }
    in.cell_json = c.dump();
  }
  in.subtract_residual = j.value("residual_stress", std::string("keep")) == "subtract";
  if (j.contains("retry")) {
    in.retry.max_retries = j.at("retry").value("max_retries", in.retry.max_retries);
    in.retry.step_factor = j.at("retry").value("step_factor", in.retry.step_factor);
    in.retry.max_retries_extra =
        j.at("retry").value("max_retries_coverage", in.retry.max_retries_extra);
  }
  if (j.contains("substeps")) {  // bounds: the schema's (1 to 16)
    const auto& s = j.at("substeps");
    in.retry.substeps_paper = s.value("paper", in.retry.substeps_paper);
    in.retry.substeps_coverage = s.value("coverage", in.retry.substeps_coverage);
    in.retry.substeps_holdout = s.value("holdout", in.retry.substeps_holdout);
  }
  // The last retry's cell solves per path: steps x substeps x step_factor^retries, counted in
  // 64 bits (session 55, from session 53's open list: max_retries 6 with step_factor 8 runs a
  // path's last retry with 262,144 times its steps, days for a path the sweep then gives up
  // on, and 10,000 steps x 16 substeps x 8^6 overflowed the attempt's int step count).
  for (std::size_t p = 0; p < in.paths.size(); ++p) {
    const material::LoadPath& lp = in.paths[p];
    const int retries = in.retry.retries_for(lp);
    long long solves = static_cast<long long>(lp.steps) * std::max(1, in.retry.substeps_for(lp));
    const long long first = solves;
    for (int a = 0; a < retries && solves <= kMaxCellSolvesPerAttempt; ++a)
      solves *= in.retry.step_factor;
    if (solves > kMaxCellSolvesPerAttempt)
      throw InputError(
          file, lp.set == "paper" ? "/retry/max_retries" : "/retry/max_retries_coverage",
          "a " + lp.set + " path (" +
              (p < in.path_fields.size() ? in.path_fields[p] : "/load_paths") + ", " +
              std::to_string(first) + " cell solves on its first attempt) would take more than " +
              std::to_string(kMaxCellSolvesPerAttempt) + " on its last retry (x step_factor " +
              std::to_string(in.retry.step_factor) + " per retry, " + std::to_string(retries) +
              " retries): hours for one path that did not converge at fewer steps; lower "
              "max_retries or step_factor");
  }
  if (j.contains("fit")) {
    const auto& f = j.at("fit");
    if (f.is_boolean()) {
      in.fit = f.get<bool>();
    } else {
      try {
        in.fit_options = fit::FitOptions::from_json(f.dump(), file);
      } catch (const InputError& e) {
        throw InputError(file, "/fit" + e.pointer(), e.message());
      }
    }
  }
  if (j.contains("energy_fit")) {
    const auto& f = j.at("energy_fit");
    // {} fits with the code's defaults too (the session's review).
    in.energy_fit_given = f.is_object() && !f.empty();
    if (f.is_boolean())
      in.energy_fit = f.get<bool>();
    else {
      in.energy_fit_options = fit::EnergyFitOptions::from_json(f.dump(), file, "/energy_fit");
      fit::EnergyFitOptions::refuse_other_family_keys(f.dump(), file, "/energy_fit");
    }
    // A ridge law too large to solve in minutes is refused before the cases (the review of
    // session 52: the fit refused it only after the whole sweep).
    if (const std::string why =
            in.energy_fit_options.ridge_size_refusal(static_cast<int>(in.loop_lengths.size()));
        !why.empty())
      throw InputError(file,
                       "/energy_fit" + in.energy_fit_options.ridge_size_key(
                                           static_cast<int>(in.loop_lengths.size())),
                       why);
    // Options of a fit that is not made are refused, not ignored unread (session 44's red
    // team: "fit": false with an "energy_fit" object ran with exit 0 and no word; knit-meso fit
    // refuses --energy-options with --law paper the same way, session 38).
    if (f.is_object() && !in.fit)
      throw InputError(file, "/energy_fit",
                       "the energy law's fit options, but \"fit\": false fits no law (the "
                       "energy law is fitted after the paper's): leave \"energy_fit\" out or "
                       "set it false, or fit the laws");
  }
  return in;
}

SweepInput load_sweep_input(const std::filesystem::path& file) {
  // The defensive reader of every input (session 24: an ifstream here read /dev/zero until
  // memory ran out and waited on a FIFO for ever).
  return parse_sweep_input(knit::io::read_input_file(file), file.string());
}

}  // namespace knit::meso::sweep
