// HDF5 reading and writing of the material database (layout: schemas/database.layout.json,
// docs/database.md). HDF5 is reached only through knit/io/hdf5.hpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/hdf5.hpp"
#include "knit/io/provenance.hpp"
#include "knit/material/database.hpp"
#include "material_energy_law_io.hpp"

namespace knit::material {

namespace {

/// The raw arrays of a path by name, for the per-step checks of the reader and the writer.
std::array<std::pair<const char*, const RowMatrixX*>, 4> raw_arrays(const RawPath& r) {
  return {{{"F", &r.F}, {"P", &r.P}, {"E", &r.E}, {"S", &r.S}}};
}

/// Why row s of raw array `d` ("F", "P", "E" or "S") is no converged state of a textile cell,
/// in the words both the reader and the writer use: "not finite", "holds |value| X (F, E at
/// most 1e3; P, S at most 1e9 MPa)" (deformation gradients and strains beyond
/// kMaxRawKinematic, stresses beyond kMaxRawStress: session 29, 1e308 made the paper fit's rms
/// inf), or "" when it is one.
std::string raw_step_problem(const char* d, const RowMatrixX& m, Eigen::Index s) {
  if (!m.row(s).allFinite()) return "not finite";
  const double bound = (*d == 'F' || *d == 'E') ? kMaxRawKinematic : kMaxRawStress;
  const double v = m.row(s).cwiseAbs().maxCoeff();
  if (v > bound)
    return "holds |value| " + io::format_number(v) + " (F, E at most 1e3; P, S at most 1e9 MPa)";
  // A deformation gradient keeps the cell's area ratio J = det F > 0 (F11 F22 - F12 F21 in the
  // row's order F11, F12, F21, F22): J <= 0 is a cell turned inside out or collapsed, and an F
  // of zeros is none at all (session 53's red team: F = 0 in a format-2 file was
  // refitted with exit 0).
  if (*d == 'F' && m.cols() == 4) {
    const double J = m(s, 0) * m(s, 3) - m(s, 1) * m(s, 2);
    if (!(J > 0.0))
      return "has det F = " + io::format_number(J) +
             " (a deformation gradient keeps the area ratio det F > 0)";
  }
  return {};
}

/// Why converged step s of `r` is no consistent state, in the words of the reader and the
/// writer, or "" when it is one: its strain must be the Green-Lagrange strain of its F (eq. 9,
/// E = (F^T F - I) / 2; columns E11, E22, E12) and its stress the second Piola-Kirchhoff stress
/// of its F and P (eq. 9, S = sym(F^-1 P), as the sweep and synth write it; columns S11, S22,
/// S12), to round-off (1e-9 of the terms' size). The fits take E and S, the report
/// and the figures F and P: session 53's red team list, a hand-edited E or S was fitted with
/// exit 0 while every plot of F and P showed the cell's curves. Called after raw_step_problem,
/// so F is finite with det F > 0 and every number is bounded.
std::string raw_consistency_problem(const RawPath& r, Eigen::Index s) {
  if (r.F.cols() != 4 || r.P.cols() != 4 || r.E.cols() != 3 || r.S.cols() != 3) return {};
  Eigen::Matrix2d F, P;
  F << r.F(s, 0), r.F(s, 1), r.F(s, 2), r.F(s, 3);
  P << r.P(s, 0), r.P(s, 1), r.P(s, 2), r.P(s, 3);
  const auto num = [](double v) { return io::format_number(v); };
  const Eigen::Matrix2d E = green_lagrange(F);
  const Eigen::Vector3d e(E(0, 0), E(1, 1), E(0, 1));
  const double de = (r.E.row(s).transpose() - e).cwiseAbs().maxCoeff();
  if (!(de <= 1e-9 * (1.0 + F.cwiseAbs().maxCoeff() * F.cwiseAbs().maxCoeff())))
    return "E and F disagree: the stored strain differs by " + num(de) +
           " from the Green-Lagrange strain of its F, (F^T F - I) / 2 = (" + num(e(0)) + ", " +
           num(e(1)) + ", " + num(e(2)) + ") (E11, E22, E12; eq. 9)";
  const Eigen::Matrix2d S = second_piola_kirchhoff(F, P);
  const Eigen::Vector3d sv(S(0, 0), S(1, 1), S(0, 1));
  const double ds = (r.S.row(s).transpose() - sv).cwiseAbs().maxCoeff();
  // |F^-1| |P| bounds the round-off of F^-1 P (|F^-1| = |F| / det F for a 2 x 2 matrix).
  const double J = F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
  const double size = F.cwiseAbs().rowwise().sum().maxCoeff() / J * P.cwiseAbs().maxCoeff() +
                      r.S.row(s).cwiseAbs().maxCoeff();
  if (!(ds <= 1e-9 * size))
    return "S and F, P disagree: the stored stress differs by " + num(ds) +
           " MPa from the second Piola-Kirchhoff stress of its F and P, sym(F^-1 P) = (" +
           num(sv(0)) + ", " + num(sv(1)) + ", " + num(sv(2)) + ") MPa (S11, S22, S12; eq. 9)";
  return {};
}

/// The bounds a sweep input allows for a path's end (schemas/sweep.schema.json): Green-Lagrange
/// end strains of biaxial and uniaxial paths in (-0.5, 2] (1 + 2E > 0: a real stretch), the
/// shear angle of a pure-shear path in (0, 80) degrees. Every writer (sweep, synth, fit) puts 0
/// into the components a kind does not use (load_paths.hpp).
constexpr double kMinEndStrain = -0.5;  // excluded
constexpr double kMaxEndStrain = 2.0;
constexpr double kMaxShearAngle = 80.0 * 3.14159265358979323846 / 180.0;  // rad, excluded

/// Why the end of path `p` (its attributes target, axis and H, read from the file) is none a
/// sweep runs, in the words of the reader's message ("attribute target[0] is 1e+300, ..."), or
/// "" when it is one. Session 53's red team: a target of 1e300, an axis of 99 on an
/// old-format database went through `knit-meso fit` into the refitted file with exit 0.
std::string path_end_problem(const LoadPath& p) {
  const auto num = [](double v) { return io::format_number(v); };
  if (p.axis != 0 && p.axis != 1)
    return "attribute axis is " + std::to_string(p.axis) +
           ": it must be 0 (course) or 1 (wale) (a uniaxial path's prescribed direction; 0 on "
           "other paths)";
  // Which target components the kind uses, and their range.
  bool used[2] = {false, false};
  if (p.kind == PathKind::kBiaxial) used[0] = used[1] = true;
  if (p.kind == PathKind::kShear || p.kind == PathKind::kUniaxial) used[0] = true;
  for (int c = 0; c < 2; ++c) {
    const double t = p.target(c);
    const std::string at = "attribute target[" + std::to_string(c) + "] is " + num(t);
    if (!used[c]) {
      if (t != 0.0)
        return at + ", but a " + to_string(p.kind) + " path does not use it (written as 0)";
    } else if (p.kind == PathKind::kShear) {
      if (!(t > 0.0 && t < kMaxShearAngle))
        return at + ": a shear path's end angle must be in (0, " + num(kMaxShearAngle) +
               ") rad, (0, 80) degrees (schemas/sweep.schema.json)";
    } else if (!(t > kMinEndStrain && t <= kMaxEndStrain)) {
      return at + ": a " + to_string(p.kind) + " path's end Green-Lagrange strain must be in (" +
             num(kMinEndStrain) + ", " + num(kMaxEndStrain) + "] (schemas/sweep.schema.json)";
    }
  }
  // H: F = I + t H on a gradient path, zeros elsewhere. Its end must be a deformation
  // (det(I + H) > 0) within the bound of a database's F.
  if (p.H.cwiseAbs().maxCoeff() > kMaxRawKinematic)
    return "attribute H holds |value| " + num(p.H.cwiseAbs().maxCoeff()) + " (at most 1e3, as F)";
  if (p.kind == PathKind::kGradient) {
    const double J = (1.0 + p.H(0, 0)) * (1.0 + p.H(1, 1)) - p.H(0, 1) * p.H(1, 0);
    if (!(J > 0.0))
      return "attribute H ends the gradient path at det(I + H) = " + num(J) +
             " (a deformation keeps det F > 0)";
  } else if (!p.H.isZero(0.0)) {
    return "attribute H is not zero, but a " + to_string(p.kind) + " path does not use it";
  }
  return {};
}

/// The range a yarn attribute (/yarn@name) must be in, when `v` is outside it; "" when it is
/// inside. The ranges of the cell parameters the sweep takes them from (schemas/cell.schema.json,
/// CellOptions::validate): diameter > 0 mm, youngs_modulus in [1e-3, 1e8] MPa, poisson_ratio in
/// (-1, 0.5), friction >= 0. Other names (none is written today) need only be finite. Session
/// 53's red team: youngs_modulus -800 in a format-2 file was read by knit-macro and
/// refitted by knit-meso fit into a new database, exit 0.
std::string yarn_value_problem(const std::string& name, double v) {
  if (name == "diameter" && !(v > 0.0)) return "a yarn diameter is > 0 mm";
  if (name == "youngs_modulus" && !(v >= 1e-3 && v <= 1e8))
    return "a yarn's Young's modulus is in [0.001, 1e8] MPa";
  if (name == "poisson_ratio" && !(v > -1.0 && v < 0.5)) return "a Poisson ratio is in (-1, 0.5)";
  if (name == "friction" && !(v >= 0.0)) return "a friction coefficient is >= 0";
  return {};
}

using io::H5File;
using io::H5Group;

std::string loop_group(std::size_t k) {
  return "/loop_" + std::to_string(k);
}
std::string path_group(std::size_t q) {
  std::ostringstream os;
  os << "path_" << (q < 10 ? "0" : "") << q;
  return os.str();
}

/// The oldest format version this build still reads (version 1: no /energy_law).
constexpr int kOldestReadableVersion = 1;
constexpr const char* kDatabaseUnits = "length mm, force N, stress MPa";

void write_surface(H5Group& g, const ResponseSurfaceData& d) {
  g.set_attribute(".", "degree_1", d.degree1);
  g.set_attribute(".", "degree_2", d.degree2);
  g.set_attribute(".", "parameters",
                  "xi1 = biaxial path index / (paths - 1) (paths ordered by angle of the end "
                  "strain), xi2 = load-step fraction; domain [0, 1]^2");
  g.write("knots_1", d.knots1);
  g.write("knots_2", d.knots2);
  g.write("E_ctrl", RowMatrixX(d.E_ctrl));
  g.write("S_ctrl", RowMatrixX(d.S_ctrl));
  for (const char* n : {"E_ctrl", "S_ctrl"}) {
    g.set_attribute(n, "index", "row a = i + n1 * j (i: xi1 index, j: xi2 index)");
    g.set_attribute(n, "columns", n[0] == 'E' ? "E11, E22 (Green-Lagrange)" : "S11, S22 (MPa)");
  }
  g.set_attribute(".", "n1", d.n1());
  g.set_attribute(".", "n2", d.n2());
  H5Group s = g.create_group("shear");
  s.set_attribute(".", "degree", d.shear_degree);
  s.write("knots", d.shear_knots);
  s.write("E12_ctrl", d.E12_ctrl);
  s.write("S12_ctrl", d.S12_ctrl);
  s.set_attribute("E12_ctrl", "units", "tensor shear strain E12 (not 2E12)");
  s.set_attribute("S12_ctrl", "units", "MPa");
}

ResponseSurfaceData read_surface(const H5Group& g) {
  ResponseSurfaceData d;
  d.degree1 = g.attribute_int(".", "degree_1");
  d.degree2 = g.attribute_int(".", "degree_2");
  d.knots1 = g.read_doubles("knots_1");
  d.knots2 = g.read_doubles("knots_2");
  d.E_ctrl = g.read_matrix("E_ctrl");
  d.S_ctrl = g.read_matrix("S_ctrl");
  const H5Group s = g.open_group("shear");
  d.shear_degree = s.attribute_int(".", "degree");
  d.shear_knots = s.read_doubles("knots");
  const auto e = s.read_doubles("E12_ctrl"), t = s.read_doubles("S12_ctrl");
  d.E12_ctrl = Eigen::Map<const Eigen::VectorXd>(e.data(), static_cast<Eigen::Index>(e.size()));
  d.S12_ctrl = Eigen::Map<const Eigen::VectorXd>(t.data(), static_cast<Eigen::Index>(t.size()));
  return d;
}

/// "file: rest" -> "rest" (the io adapter's messages start with the file name).
std::string strip_file(const std::string& msg, const std::string& file) {
  const std::string prefix = file + ": ";
  return msg.rfind(prefix, 0) == 0 ? msg.substr(prefix.size()) : msg;
}

}  // namespace

void write_database(const std::filesystem::path& file, const Database& db,
                    const std::function<void(io::H5File&)>& extra) {
  if (const auto bad = first_unstorable_step(db))
    throw std::runtime_error(file.string() + ": database not written: " + *bad +
                             ", though marked converged (status 0)");
  io::AtomicFile out(file);
  const bool existed = std::filesystem::exists(file);
  try {
    H5File f = H5File::create(out.temp_path());
    f.set_attribute(".", "format", kDatabaseFormatName);
    f.set_attribute(".", "format_version", kDatabaseFormatVersion);  // always the current format
    f.set_attribute(".", "software_version", db.provenance.software_version);
    f.set_attribute(".", "git_revision", db.provenance.git_revision);
    f.set_attribute(".", "created", db.provenance.created);
    f.set_attribute(".", "generator", db.generator);
    // The writing process (program, host, command line) in the io module's common form.
    io::write_provenance(f, io::Provenance::current(db.provenance.input));
    f.set_attribute(".", "units", kDatabaseUnits);
    f.set_attribute(".", "voigt_order", "E = (E11, E22, 2E12), S = (S11, S22, S12)");
    f.set_attribute(".", "frame", "material frame: 1 = course, 2 = wale");
    H5Group sw = f.create_group("/sweep");
    sw.set_attribute(".", "input_json", db.sweep_input);
    // The load paths of the first loop length (the sweep uses the same set for all).
    std::vector<int> kind, steps, axis;
    std::vector<std::string> set;
    RowMatrixX target(0, 2), H(0, 4);
    if (!db.entries.empty()) {
      const auto& raw = db.entries.front().raw;
      const auto n = static_cast<Eigen::Index>(raw.size());
      target.resize(n, 2);
      H.resize(n, 4);
      for (std::size_t q = 0; q < raw.size(); ++q) {
        const LoadPath& lp = raw[q].path;
        kind.push_back(static_cast<int>(lp.kind));
        steps.push_back(lp.steps);
        axis.push_back(lp.axis);
        set.push_back(lp.set);
        const auto i = static_cast<Eigen::Index>(q);
        target.row(i) = lp.target.transpose();
        H.row(i) << lp.H(0, 0), lp.H(0, 1), lp.H(1, 0), lp.H(1, 1);
      }
    }
    sw.write("load_path_kind", kind);
    sw.write("load_path_steps", steps);
    sw.write("load_path_target", target);
    sw.write("load_path_axis", axis);
    sw.write("load_path_H", H);
    sw.write_strings("load_path_set", set);
    sw.set_attribute("load_path_kind", "values",
                     "0 = biaxial, 1 = pure shear, 2 = uniaxial stress, 3 = gradient F = I + t H");
    sw.set_attribute("load_path_target", "columns",
                     "biaxial: end (E11, E22) Green-Lagrange; shear: (gamma rad, 0); uniaxial: "
                     "(end Green-Lagrange strain along axis, 0); gradient: unused");
    sw.set_attribute("load_path_axis", "values",
                     "uniaxial: 0 = E11 (course) prescribed, 1 = E22 (wale); else unused");
    sw.set_attribute("load_path_H", "columns", "H11, H12, H21, H22 of gradient paths");
    sw.set_attribute("load_path_set", "values",
                     "paper (the eq. 17 fan and shear curve), coverage (extra fitted paths), "
                     "holdout (never fitted: checks of the law)");
    H5Group yarn = f.create_group("/yarn");
    for (const auto& [k, v] : db.yarn) yarn.set_attribute(".", k, v);
    // Attributes cannot carry attributes: a group's "units" names those of its attributes
    // (session 38's red team: only the root's global "units" covered them).
    yarn.set_attribute(".", "units", "lengths (diameter, ...) mm, moduli and stresses MPa");
    f.write("/loop_lengths", db.loop_lengths());
    f.set_attribute("/loop_lengths", "units", "mm");
    const StrainDomain dom = db.domain();
    H5Group dg = f.create_group("/domain");
    dg.set_attribute(".", "E11_min", dom.E11_min);
    dg.set_attribute(".", "E11_max", dom.E11_max);
    dg.set_attribute(".", "E22_min", dom.E22_min);
    dg.set_attribute(".", "E22_max", dom.E22_max);
    dg.set_attribute(".", "E12_max", dom.E12_max);
    dg.set_attribute(".", "units", "Green-Lagrange strains (1); E12 the tensor shear strain");
    for (std::size_t k = 0; k < db.entries.size(); ++k) {
      const LoopLengthEntry& e = db.entries[k];
      H5Group g = f.create_group(loop_group(k));
      g.set_attribute(".", "loop_length", e.loop_length);
      g.set_attribute(".", "wale_width", e.cell.wale_width);
      g.set_attribute(".", "course_height", e.cell.course_height);
      g.set_attribute(".", "thickness", e.cell.thickness);
      g.set_attribute(".", "fitted", e.surface ? 1 : 0);
      g.set_attribute(".", "units", "loop_length, wale_width, course_height, thickness: mm");
      H5Group raw = g.create_group("raw");
      raw.set_attribute(".", "paths", static_cast<int>(e.raw.size()));
      for (std::size_t q = 0; q < e.raw.size(); ++q) {
        const RawPath& r = e.raw[q];
        H5Group p = raw.create_group(path_group(q));
        p.set_attribute(".", "kind", to_string(r.path.kind));
        p.set_attribute(".", "target", std::vector<double>{r.path.target(0), r.path.target(1)});
        p.set_attribute(".", "steps", r.path.steps);
        p.set_attribute(".", "axis", r.path.axis);
        p.set_attribute(
            ".", "H",
            std::vector<double>{r.path.H(0, 0), r.path.H(0, 1), r.path.H(1, 0), r.path.H(1, 1)});
        p.set_attribute(".", "set", r.path.set);
        p.write("F", r.F);
        p.write("P", r.P);
        p.write("E", r.E);
        p.write("S", r.S);
        p.write("status", r.status);
        p.set_attribute("F", "columns", "F11, F12, F21, F22; rows: load steps 1..steps");
        p.set_attribute("P", "columns", "P11, P12, P21, P22 (MPa); rows: load steps 1..steps");
        p.set_attribute("E", "columns", "E11, E22, E12 (tensor); rows: load steps 1..steps");
        p.set_attribute("S", "columns", "S11, S22, S12 (MPa); rows: load steps 1..steps");
        p.set_attribute(
            "status", "values",
            "0 = converged, 1 = did not converge, 2 = not reached; the fits take only 0");
      }
      if (e.surface) {
        H5Group fg = g.create_group("fit");
        write_surface(fg, *e.surface);
        H5Group d = fg.create_group("diagnostics");
        d.write("rms", e.diagnostics.rms);
        d.write("max", e.diagnostics.max);
        d.set_attribute(".", "components", "E1, E2, S1, S2, S12");
        d.set_attribute(".", "units", "rms and max: E1, E2 strain (1); S1, S2, S12 MPa");
        d.set_attribute(".", "max_relative", e.diagnostics.max_relative);
        d.set_attribute(".", "points_used", e.diagnostics.points_used);
        d.set_attribute(".", "points_skipped", e.diagnostics.points_skipped);
        d.set_attribute(".", "options_json", e.diagnostics.options_json);
      }
    }
    if (db.energy_law) detail::write_energy_law(f, *db.energy_law, db.energy_diagnostics);
    if (extra) extra(f);
    f.close();
    // In the try too: a failed fsync or rename of the commit leaves the earlier file as well,
    // and says so (session 34: "db.h5: fsync failed", no word of the earlier file).
    out.commit();
  } catch (const std::exception& e) {
    throw database_not_written(file, existed, out.temp_path(), e);
  }
}

std::vector<std::string> carry_over_unwritten(const io::H5File& from, io::H5File& to,
                                              const std::string& refit_note) {
  std::vector<std::string> copied;
  for (const std::string& name : from.children("/")) {
    const std::string path = "/" + name;
    if (!to.exists(path)) {
      to.copy_from(from, path);
      copied.push_back(path);
    } else if (path == "/sweep" && from.is_group(path) && to.is_group(path)) {
      for (const std::string& child : from.children(path))
        if (!to.exists(path + "/" + child)) {
          to.copy_from(from, path + "/" + child);
          copied.push_back(path + "/" + child);
        }
    }
  }
  if (std::find(copied.begin(), copied.end(), "/sweep/report") != copied.end())
    to.set_attribute("/sweep/report", "refitted", refit_note);
  return copied;
}

std::vector<std::string> items_not_carried(const io::H5File& from, const io::H5File& to,
                                           bool energy_refit, bool paper_refit) {
  std::vector<std::string> out;
  // Groups the refit rewrote: the energy law, each loop length's fitted surfaces (session 41's
  // review: skipped whatever --law said, so --law paper lost a user's items in /energy_law).
  auto rewritten = [&](const std::string& path) {
    if (path == "/energy_law") return energy_refit;
    if (!paper_refit) return false;
    const std::string fit = "/fit";
    return path.rfind("/loop_", 0) == 0 && path.size() > fit.size() &&
           path.compare(path.size() - fit.size(), fit.size(), fit) == 0 &&
           path.find('/', 1) == path.size() - fit.size();
  };
  auto attributes = [&](const std::string& path) {
    const std::vector<std::string> have = to.attribute_names(path);
    for (const std::string& a : from.attribute_names(path))
      if (std::find(have.begin(), have.end(), a) == have.end()) out.push_back(path + "@" + a);
  };
  std::function<void(const std::string&)> walk = [&](const std::string& group) {
    attributes(group);
    for (const std::string& name : from.children(group)) {
      const std::string path = (group == "/" ? "" : group) + "/" + name;
      if (rewritten(path)) continue;
      if (!to.exists(path)) {
        out.push_back(path);
      } else if (from.is_group(path) && to.is_group(path)) {
        walk(path);
      } else if (from.is_dataset(path) && to.is_dataset(path)) {
        attributes(path);
      } else {
        out.push_back(path);  // a group where a dataset is written, or the reverse
      }
    }
  };
  walk("/");
  return out;
}

std::runtime_error database_not_written(const std::filesystem::path& target, bool existed,
                                        const std::filesystem::path& temp,
                                        const std::exception& e) {
  // The writer's messages name the temporary file, which AtomicFile removes: name the target
  // and say what became of it (session 22: a full file system named only the temporary).
  std::string why = strip_file(strip_file(e.what(), temp.string()), target.string());
  for (const char* inner : {"database not written (no file was created): ",
                            "database not written (the earlier file is left as it was): "})
    if (why.rfind(inner, 0) == 0) why = why.substr(std::string(inner).size());
  return std::runtime_error(
      target.string() + ": database not written (" +
      (existed ? "the earlier file is left as it was" : "no file was created") + "): " + why);
}

void refuse_replacing_swept_database(const std::filesystem::path& file, const std::string& option) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec) || !io::is_hdf5_file(file)) return;
  std::string generator, date;
  try {
    const H5File f = H5File::open_read(file);
    if (!f.has_attribute(".", "generator")) return;
    generator = f.attribute_string(".", "generator");
    if (f.has_attribute(".", "date_utc")) date = f.attribute_string(".", "date_utc");
  } catch (const std::exception&) {
    return;  // not ours to judge here: check_output_target decides about the file
  }
  if (generator != "sweep") return;
  throw InputError(file.string(), "/@generator",
                   "holds a material database swept on the unit cell (generator \"sweep\"" +
                       (date.empty() ? std::string() : ", written " + date) +
                       "), which a synthetic stand-in does not replace (" + option +
                       "): write the stand-in to another file, or move the swept database "
                       "away first");
}

Database read_database(const std::filesystem::path& file, bool with_raw) {
  const std::string fname = file.string();
  std::string where;  // HDF5 path being read, for messages
  try {
    if (!std::filesystem::exists(file)) throw InputError(fname, "", "file not found");
    // A directory, a FIFO or a device (session 36's red team: "not an HDF5 file" for each).
    if (std::error_code ec; !std::filesystem::is_regular_file(file, ec))
      throw InputError(fname, "", "not a regular file (a directory, a device or a pipe?)");
    if (!io::is_hdf5_file(file)) throw InputError(fname, "", "not an HDF5 file (or truncated)");
    H5File f = H5File::open_read(file);
    // Real data as written, in doubles (session 47's red team: theta stored as integers ran
    // with 3.85 N for 82.8 N, exit 0).
    f.require_real_data();
    Database db;
    where = "/";
    if (!f.has_attribute(".", "format") || f.attribute_string(".", "format") != kDatabaseFormatName)
      throw InputError(fname, "/",
                       std::string("not a material database (attribute format != \"") +
                           kDatabaseFormatName + "\")");
    // A database written with checksums but without its structure checksum was opened for
    // writing after it was written (session 36: h5py "r+" scaled /energy_law/theta by 1.5,
    // HDF5 recomputed the Fletcher32 sums and dropped the trailer, and knit-macro ran the
    // edited law as an old, unverifiable file with exit 0: 27,148 N instead of 84.6 N).
    // Only files written before the checksums existed are read unverified: no dataset of the
    // file carries a checksum (session 43's red team: /loop_lengths re-created without one by
    // h5py's delete-and-create let the file pass as old, with /energy_law/theta scaled by 1.5
    // and its Fletcher32 sums recomputed: 27,148 N instead of 84.6 N, exit 0 again).
    if (!f.structure_sealed() && f.any_checksum())
      throw InputError(
          fname, "",
          "the file was written with checksums but its structure checksum is gone: it was "
          "changed after it was written (opened for writing: h5py's \"r+\" and \"a\" modes "
          "drop the checksum even without a change), or it was cut short or extended (a copy "
          "interrupted, bytes appended), so a change to its law or data cannot be ruled out; use "
          "the "
          "database as knit-meso wrote it (a copy made with cp keeps the checksum), or write a "
          "new one (knit-meso sweep, or knit-meso fit from the original)");
    db.checksummed = f.any_checksum();
    db.format_version = f.attribute_int(".", "format_version");
    if (db.format_version < kOldestReadableVersion || db.format_version > kDatabaseFormatVersion)
      throw InputError(fname, "/",
                       "format_version " + std::to_string(db.format_version) +
                           " is not supported (this build reads versions " +
                           std::to_string(kOldestReadableVersion) + " to " +
                           std::to_string(kDatabaseFormatVersion) + ")");
    // Format 3 came after the checksums (d72a908 after c7dca30): every format-3 file knit-meso
    // wrote carries them, so one without any was rewritten by another program (session 47's
    // red team: every dataset and attribute copied by value with h5py, /energy_law/theta
    // scaled by 1.5, read as an old, unverifiable file: 17,408 N for 82.8 N, exit 0).
    if (db.format_version >= 3 && !f.any_checksum())
      throw InputError(
          fname, "",
          "format_version " + std::to_string(db.format_version) +
              " databases are written with checksums, and this one has none: it was rewritten "
              "by another program (a copy made dataset by dataset, h5py), so a change to its law "
              "or data cannot be ruled out; use the database as knit-meso wrote it (a copy made "
              "with cp keeps the checksums), or write a new one (knit-meso sweep, or knit-meso "
              "fit from the original)");
    auto require_group = [&](const std::string& p) {
      if (!f.is_group(p)) throw InputError(fname, p, "group missing");
    };
    auto require_dataset = [&](const std::string& p) {
      if (!f.is_dataset(p)) throw InputError(fname, p, "dataset missing");
    };
    // The units every database is written in (session 29: "m, kN, kPa" was read, unread).
    if (f.has_attribute(".", "units") && f.attribute_string(".", "units") != kDatabaseUnits)
      throw InputError(fname, "/",
                       "attribute units is \"" + f.attribute_string(".", "units") +
                           "\"; knitscale's databases are in \"" + kDatabaseUnits +
                           "\" (no conversion is made)");
    db.provenance.software_version = f.attribute_string(".", "software_version");
    db.provenance.git_revision = f.attribute_string(".", "git_revision");
    db.provenance.created = f.attribute_string(".", "created");
    if (f.has_attribute(".", "date_utc"))
      db.provenance.date_utc = f.attribute_string(".", "date_utc");
    db.generator = f.attribute_string(".", "generator");
    require_group("/sweep");
    db.sweep_input = f.attribute_string("/sweep", "input_json");
    // A failed sweep's database, written for the diagnosis (session 48's walkthrough: a case
    // ran on one with exit 0, its failed cases unmentioned; the macroscale warns).
    if (f.is_group("/sweep/report") && f.has_attribute("/sweep/report", "failed_cases")) {
      db.sweep_failed_cases = f.attribute_int("/sweep/report", "failed_cases");
      if (db.sweep_failed_cases < 0)
        throw InputError(fname, "/sweep/report",
                         "attribute failed_cases is " + std::to_string(db.sweep_failed_cases) +
                             ", a count must be >= 0");
    }
    require_group("/yarn");
    for (const auto& n : f.attribute_names("/yarn")) {
      if (n == "units") continue;  // the text naming the others' units (since session 38)
      db.yarn[n] = f.attribute_double("/yarn", n);
      if (!std::isfinite(db.yarn[n]))
        throw InputError(fname, "/yarn", "attribute " + n + " is not finite");
      if (const std::string range = yarn_value_problem(n, db.yarn[n]); !range.empty())
        throw InputError(fname, "/yarn",
                         "attribute " + n + " is " + io::format_number(db.yarn[n]) + ", but " +
                             range + ": a damaged database");
    }
    require_dataset("/loop_lengths");
    const auto ls = f.read_doubles("/loop_lengths");
    // Session 52's red team: an old (unchecksummed) file with /loop_lengths = [] was refitted
    // with exit 0 into a database that every reader refused; and /loop_1 beside a
    // /loop_lengths of one entry was carried over as a user's group.
    if (ls.empty())
      throw InputError(fname, "/loop_lengths",
                       "no loop length: a material database holds at least one");
    if (f.exists(loop_group(ls.size())))
      throw InputError(fname, loop_group(ls.size()),
                       "a loop-length group beyond the " + std::to_string(ls.size()) +
                           " entries of /loop_lengths");
    // Session 29 (a helper's fuzzing audit): [5, 4] was read, refitted and written back with
    // exit 0 (the family of eq. 25 throws on it later, naming no file).
    for (std::size_t k = 0; k < ls.size(); ++k)
      if (!(std::isfinite(ls[k]) && ls[k] > 0.0) || (k > 0 && !(ls[k] > ls[k - 1])))
        throw InputError(fname, "/loop_lengths",
                         "loop lengths must be finite, positive and strictly increasing (entry " +
                             std::to_string(k) + ": " + io::format_number(ls[k]) + ")");
    for (std::size_t k = 0; k < ls.size(); ++k) {
      const std::string g = loop_group(k);
      where = g;
      require_group(g);
      LoopLengthEntry e;
      e.loop_length = f.attribute_double(g, "loop_length");
      if (e.loop_length != ls[k])
        throw InputError(fname, g,
                         "loop_length " + std::to_string(e.loop_length) +
                             " differs from /loop_lengths[" + std::to_string(k) + "]");
      e.cell.wale_width = f.attribute_double(g, "wale_width");
      e.cell.course_height = f.attribute_double(g, "course_height");
      e.cell.thickness = f.attribute_double(g, "thickness");
      // 0 is "not known" (databases without cell parameters); NaN or negative is damage.
      for (const auto& [a, v] : {std::pair<const char*, double>{"wale_width", e.cell.wale_width},
                                 {"course_height", e.cell.course_height},
                                 {"thickness", e.cell.thickness}})
        if (!(std::isfinite(v) && v >= 0.0))
          throw InputError(fname, g + "/" + a,
                           "attribute " + std::string(a) + " must be finite and >= 0 mm, got " +
                               io::format_number(v));
      require_group(g + "/raw");
      if (with_raw) {
        const int np = f.attribute_int(g + "/raw", "paths");
        // The count must be the groups' (session 43's red team: paths = 7 on an unchecked
        // file refitted the law on 7 of its 50 paths with exit 0).
        const std::size_t groups = f.children(g + "/raw").size();
        if (np < 0 || static_cast<std::size_t>(np) != groups)
          throw InputError(fname, g + "/raw",
                           "attribute paths is " + std::to_string(np) + " but the group holds " +
                               std::to_string(groups) +
                               " paths: the file was changed after it was written");
        for (int q = 0; q < np; ++q) {
          const std::string p = g + "/raw/" + path_group(static_cast<std::size_t>(q));
          where = p;
          require_group(p);
          RawPath r;
          r.index = q;
          try {
            r.path.kind = path_kind_from_string(f.attribute_string(p, "kind"));
          } catch (const std::invalid_argument& ex) {
            throw InputError(fname, p, std::string("attribute kind: ") + ex.what());
          }
          // axis, H and set came with issue 11 (format 2); older files have biaxial/shear paths
          // of the paper's set only. From format 2 on they are always written: a missing one is
          // a damaged file, not an old one (a deleted set read as "paper" put coverage paths
          // into the eq. 17 fan and held-out paths into the fit).
          if (db.format_version >= 2)
            for (const char* a : {"axis", "H", "set"})
              if (!f.has_attribute(p, a))
                throw InputError(fname, p,
                                 std::string("attribute ") + a + " is missing (format " +
                                     std::to_string(db.format_version) +
                                     " writes axis, H and set on every path)");
          if (f.has_attribute(p, "axis")) r.path.axis = f.attribute_int(p, "axis");
          if (f.has_attribute(p, "H")) {
            const auto h = f.attribute_doubles(p, "H");
            if (h.size() != 4) throw InputError(fname, p, "attribute H must have 4 values");
            r.path.H << h[0], h[1], h[2], h[3];
            if (!r.path.H.allFinite()) throw InputError(fname, p, "attribute H must be finite");
          }
          r.path.set = f.has_attribute(p, "set") ? f.attribute_string(p, "set") : "paper";
          if (!is_valid_path_set(r.path.set))
            throw InputError(
                fname, p,
                "attribute set '" + r.path.set + "' is not one of paper, coverage, holdout");
          const auto t = f.attribute_doubles(p, "target");
          if (t.size() != 2) throw InputError(fname, p, "attribute target must have 2 values");
          r.path.target = {t[0], t[1]};
          if (!r.path.target.allFinite())
            throw InputError(fname, p, "attribute target must be finite");
          // Every format version (format 3 files edited with checksums kept included).
          if (const std::string why = path_end_problem(r.path); !why.empty())
            throw InputError(fname, p, why + ": a damaged database");
          r.path.steps = f.attribute_int(p, "steps");
          for (const char* d : {"F", "P", "E", "S", "status"}) require_dataset(p + "/" + d);
          r.F = f.read_matrix(p + "/F");
          r.P = f.read_matrix(p + "/P");
          r.E = f.read_matrix(p + "/E");
          r.S = f.read_matrix(p + "/S");
          r.status = f.read_ints(p + "/status");
          const auto n = static_cast<Eigen::Index>(r.status.size());
          if (r.F.rows() != n || r.F.cols() != 4 || r.P.rows() != n || r.P.cols() != 4 ||
              r.E.rows() != n || r.E.cols() != 3 || r.S.rows() != n || r.S.cols() != 3)
            throw InputError(fname, p,
                             "F, P must be steps x 4 and E, S steps x 3 with steps = " +
                                 std::to_string(n) + " (the length of status)");
          // A converged step is data: its numbers must be finite (found by writing NaN into F:
          // `knit-meso fit` copied it into the refitted database with exit code 0).
          for (Eigen::Index s = 0; s < n; ++s) {
            const int st = r.status[static_cast<std::size_t>(s)];
            if (st < 0 || st > 2)
              throw InputError(fname, p + "/status",
                               "step " + std::to_string(s + 1) + ": status " + std::to_string(st) +
                                   " (0 converged, 1 did not converge, 2 not reached)");
            if (st != 0) continue;
            for (const auto& [d, m] : raw_arrays(r)) {
              const std::string why = raw_step_problem(d, *m, s);
              if (why == "not finite")
                throw InputError(fname, p + "/" + d,
                                 "step " + std::to_string(s + 1) +
                                     " is marked converged (status 0) but is not finite");
              if (!why.empty())
                throw InputError(
                    fname, p + "/" + d,
                    "step " + std::to_string(s + 1) + " " + why + ": a damaged database");
            }
            // Named at the path: which of the datasets was changed cannot be told.
            if (const std::string why = raw_consistency_problem(r, s); !why.empty())
              throw InputError(
                  fname, p, "step " + std::to_string(s + 1) + ": " + why + ": a damaged database");
          }
          // A path has at least one load step (schemas/sweep.schema.json: steps >= 1); one of
          // no rows is no data (session 53's red team list: it was read).
          if (n == 0)
            throw InputError(fname, p + "/status",
                             "the path has no load step (0 rows; a sweep's path has at least 1): "
                             "a damaged database");
          // The path's planned steps are its rows (a stopped path keeps its unreached steps,
          // status 2): the red team's steps -3 on a 20-row path was read and written back.
          if (r.path.steps != n)
            throw InputError(fname, p,
                             "attribute steps is " + std::to_string(r.path.steps) +
                                 ", but the path has " + std::to_string(n) +
                                 " rows (the length of status): a damaged database");
          e.raw.push_back(std::move(r));
        }
      }
      where = g;
      if (f.attribute_int(g, "fitted") != 0) {
        const std::string fg = g + "/fit";
        require_group(fg);
        require_group(fg + "/shear");
        require_group(fg + "/diagnostics");
        where = fg;
        const H5Group fit = f.open_group(fg);
        e.surface = read_surface(fit);
        try {
          validate(*e.surface);
        } catch (const std::exception& ex) {
          throw InputError(fname, fg, ex.what());
        }
        const auto rms = f.read_doubles(fg + "/diagnostics/rms");
        const auto mx = f.read_doubles(fg + "/diagnostics/max");
        if (rms.size() != 5 || mx.size() != 5)
          throw InputError(fname, fg + "/diagnostics", "rms and max need 5 components");
        // The fit's errors are data the report and a refit pass on: finite (session 33, a
        // helper's audit: a NaN written here by h5py, which drops the checksum trailer, went
        // through `knit-meso fit` into the refitted file with exit 0).
        for (int c = 0; c < 5; ++c) {
          for (const auto& [name, v] : {std::pair{"rms", rms[c]}, std::pair{"max", mx[c]}})
            if (!std::isfinite(v))
              throw InputError(fname, fg + "/diagnostics/" + name,
                               "entry " + std::to_string(c) + " (" + FitDiagnostics::kNames[c] +
                                   ") is not finite");
          e.diagnostics.rms(c) = rms[c];
          e.diagnostics.max(c) = mx[c];
        }
        e.diagnostics.max_relative = f.attribute_double(fg + "/diagnostics", "max_relative");
        if (!std::isfinite(e.diagnostics.max_relative))
          throw InputError(fname, fg + "/diagnostics", "attribute max_relative is not finite");
        e.diagnostics.points_used = f.attribute_int(fg + "/diagnostics", "points_used");
        e.diagnostics.points_skipped = f.attribute_int(fg + "/diagnostics", "points_skipped");
        e.diagnostics.options_json = f.attribute_string(fg + "/diagnostics", "options_json");
      }
      db.entries.push_back(std::move(e));
    }
    // Version 2: the energy-based law, when it was fitted (version 1 never has it).
    if (db.format_version >= 2 && f.exists(detail::kEnergyLawGroup)) {
      where = detail::kEnergyLawGroup;
      db.energy_law.emplace();
      detail::read_energy_law(f, fname, *db.energy_law, db.energy_diagnostics);
      if (!db.entries.empty() && (db.energy_law->l_min > db.entries.front().loop_length ||
                                  db.energy_law->l_max < db.entries.back().loop_length))
        throw InputError(fname, detail::kEnergyLawGroup,
                         "the law's loop-length range does not cover /loop_lengths");
      // The uniaxial curves' rows are the database's loop lengths (session 42: knit-macro
      // takes a case's l between two rows as the laws it uses; a row at 7 mm of a 4.5-6.5 mm
      // database was read).
      const auto& pl = db.energy_diagnostics.per_loop;
      const bool curves = std::any_of(pl.begin(), pl.end(), [](const auto& p) {
        return !p.uniaxial[0].empty() || !p.uniaxial[1].empty();
      });
      for (std::size_t k = 0; curves && k < std::max(pl.size(), db.entries.size()); ++k) {
        std::ostringstream os;
        os << std::setprecision(10);
        if (pl.size() != db.entries.size()) {
          os << "has " << pl.size() << " rows and /loop_lengths " << db.entries.size();
        } else {
          const double want = db.entries[k].loop_length;
          if (std::abs(pl[k].loop_length - want) <= 1e-9 * std::max(1.0, want)) continue;
          os << "entry " << k << " (" << pl[k].loop_length
             << " mm) is not the database's loop length /loop_lengths[" << k << "] = " << want
             << " mm";
        }
        os << ", where curves in /energy_law/diagnostics/uniaxial refer to its rows";
        throw InputError(fname, std::string(detail::kEnergyLawGroup) + "/diagnostics/loop_length",
                         os.str());
      }
    }
    // Written by an older build: the file stays version 1 in memory until it is rewritten.
    return db;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    // The HDF5 layer names its own object ("FILE: /loop_0: attribute wale_width missing"):
    // that path is kept, not prefixed with `where` again (session 25: "/loop_0: /loop_0: ...").
    const std::string why = strip_file(e.what(), fname);
    throw InputError(fname, where == "/" || why.rfind('/', 0) == 0 ? "" : where, why);
  }
}

const EnergyLawData& require_energy_law(const Database& db, const std::string& file) {
  if (db.energy_law) return *db.energy_law;
  const std::string fix = "run `knit-meso fit " + (file.empty() ? std::string("DB") : file) +
                          " --law energy` to add it (no re-simulation needed)";
  if (db.format_version < 2)
    throw InputError(file, detail::kEnergyLawGroup,
                     "a format-version-" + std::to_string(db.format_version) +
                         " database has no energy-based law; " + fix);
  throw InputError(file, detail::kEnergyLawGroup,
                   "group missing: the database was fitted without the energy-based law; " + fix);
}

std::string raw_path_location(std::size_t k, std::size_t q) {
  return loop_group(k) + "/raw/" + path_group(q);
}

std::optional<std::string> first_unstorable_step(const Database& db) {
  for (std::size_t k = 0; k < db.entries.size(); ++k)
    for (std::size_t q = 0; q < db.entries[k].raw.size(); ++q) {
      const RawPath& r = db.entries[k].raw[q];
      // The reader's rule (a path has at least one load step): the review of session 54.
      if (r.status.empty())
        return raw_path_location(k, q) + "/status: the path has no load step (0 rows)";
      for (std::size_t s = 0; s < r.status.size(); ++s) {
        if (r.status[s] != 0) continue;
        const auto i = static_cast<Eigen::Index>(s);
        for (const auto& [d, m] : raw_arrays(r))
          if (i < m->rows()) {
            const std::string why = raw_step_problem(d, *m, i);
            if (!why.empty())
              return raw_path_location(k, q) + "/" + d + ": step " + std::to_string(s + 1) + " " +
                     (why == "not finite" ? "is not finite" : why);
          }
        const bool complete = i < r.F.rows() && i < r.P.rows() && i < r.E.rows() && i < r.S.rows();
        if (!complete) continue;
        if (const std::string why = raw_consistency_problem(r, i); !why.empty())
          return raw_path_location(k, q) + ": step " + std::to_string(s + 1) + ": " + why;
      }
    }
  return std::nullopt;
}

}  // namespace knit::material
