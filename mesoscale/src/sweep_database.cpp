// Assembly of the sweep's results into the material database, the fit, the atomic write, and
// the synthetic runner (see sweep.hpp).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "knit/core/errors.hpp"
#include "knit/io/atomic.hpp"
#include "knit/io/csv.hpp"
#include "knit/io/hdf5.hpp"
#include "knit/io/json_input.hpp"
#include "knit/io/output_target.hpp"
#include "knit/meso/fit/synthetic.hpp"
#include "knit/meso/sweep/sweep.hpp"

namespace knit::meso::sweep {

namespace fs = std::filesystem;

namespace {
/// design/notes.md: w linear in l between (4.5, 1.26) and (6.5, 1.41); c = l^2/(18.27 w); t = 2d.
material::CellParameters notes_cell(double l, double d) {
  material::CellParameters c;
  c.wale_width = 1.26 + (l - 4.5) * (1.41 - 1.26) / 2.0;
  c.course_height = l * l / (18.27 * c.wale_width);
  c.thickness = 2 * d;
  return c;
}

/// cell["group"]["key"] of the cell parameters (schemas/cell.schema.json), or the default.
double cell_value(const nlohmann::json& cell, const char* group, const char* key, double dflt) {
  if (cell.is_object() && cell.contains(group) && cell[group].contains(key))
    return cell[group][key].get<double>();
  return dflt;
}
}  // namespace

material::Database assemble_database(const SweepInput& in, const std::vector<JobResult>& results) {
  material::Database db;
  db.provenance = material::current_provenance();
  db.provenance.input = in.file;
  db.generator = in.runner == RunnerKind::kCell ? "sweep" : "sweep (synthetic runner)";
  db.sweep_input = in.json;
  if (!in.cell_file.empty()) {
    // The cell parameters inline, not the name of their file (session 39's walkthrough: the
    // database kept "cell": "myyarn.json", so neither its allowance, loop shape nor contact
    // law was in the file, and the stored input could not be run anywhere else).
    nlohmann::json j = nlohmann::json::parse(in.json);
    j["cell"] = nlohmann::json::parse(in.cell_json);
    db.sweep_input = j.dump(2);
  }
  const nlohmann::json cell = nlohmann::json::parse(in.cell_json);
  // The cell's defaults (docs/unit-cell.md) where the input says nothing.
  const double d = cell_value(cell, "yarn", "d", 0.38);
  db.yarn = {{"diameter", d},
             {"youngs_modulus", cell_value(cell, "yarn", "E", 800.0)},
             {"poisson_ratio", cell_value(cell, "yarn", "nu", 0.3)},
             {"friction", cell_value(cell, "contact", "mu", 0.15)}};
  const std::size_t np = in.paths.size();
  for (std::size_t l = 0; l < in.loop_lengths.size(); ++l) {
    material::LoopLengthEntry e;
    e.loop_length = in.loop_lengths[l];
    e.cell = notes_cell(e.loop_length, d);
    bool have_cell = false;
    for (std::size_t p = 0; p < np; ++p) {
      const JobResult& r = results.at(l * np + p);
      material::RawPath raw = r.raw;
      raw.index = static_cast<int>(p);
      if (in.subtract_residual && !r.residual.isZero()) {
        Eigen::Matrix2d S0;
        S0 << r.residual(0), r.residual(2), r.residual(2), r.residual(1);
        for (Eigen::Index k = 0; k < raw.F.rows(); ++k) {
          if (raw.status[static_cast<std::size_t>(k)] != kStepConverged) continue;
          Eigen::Matrix2d F, S;
          F << raw.F(k, 0), raw.F(k, 1), raw.F(k, 2), raw.F(k, 3);
          S << raw.S(k, 0), raw.S(k, 2), raw.S(k, 2), raw.S(k, 1);
          S -= S0;
          const Eigen::Matrix2d P = material::first_piola_kirchhoff(F, S);
          raw.S.row(k) << S(0, 0), S(1, 1), S(0, 1);
          raw.P.row(k) << P(0, 0), P(0, 1), P(1, 0), P(1, 1);
        }
      }
      e.raw.push_back(std::move(raw));
      if (!have_cell && r.cell.wale_width > 0) {
        e.cell = r.cell;
        have_cell = true;
      }
    }
    db.entries.push_back(std::move(e));
  }
  return db;
}

std::vector<fit::FitSummary> fit_sweep_database(material::Database& db,
                                                const fit::FitOptions& options, int threads) {
  const std::size_t n = db.entries.size();
  std::vector<fit::FitSummary> out(n);
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (;;) {
      const std::size_t k = next++;
      if (k >= n) return;
      std::vector<material::RawPath> usable;
      for (const auto& r : db.entries[k].raw)
        if (r.path.set == "paper" && std::count(r.status.begin(), r.status.end(), 0) > 0)
          usable.push_back(r);
      out[k] = fit::fit_loop_length(usable, options);
    }
  };
  std::vector<std::thread> pool;
  const int nt = std::max(1, std::min<int>(threads, static_cast<int>(n)));
  for (int t = 1; t < nt; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  for (std::size_t k = 0; k < n; ++k) {
    if (out[k].ok()) {
      db.entries[k].surface = out[k].surface;
      db.entries[k].diagnostics = out[k].diagnostics;
    } else {
      db.entries[k].surface.reset();
    }
  }
  return out;
}

void write_sweep_database(const fs::path& output, const material::Database& db,
                          const SweepInput& in, const std::vector<JobResult>& results,
                          const SweepReport& report) {
  if (output.has_parent_path()) fs::create_directories(output.parent_path());
  // The database and its report in one temporary next to `output`, fsynced and renamed onto
  // it (write_database; session 26: the database was written atomically onto a temporary of
  // its own, whose nested temporary a kill left behind for good).
  material::write_database(output, db, [&](io::H5File& f) {
    io::H5Group g = f.create_group("/sweep/report");
    const auto nl = static_cast<Eigen::Index>(in.loop_lengths.size());
    const auto np = static_cast<Eigen::Index>(in.paths.size());
    Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> status(nl, np),
        attempts(nl, np), factor(nl, np), conv(nl, np), in_fit(nl, np);
    material::RowMatrixX seconds(nl, np), residual(nl * np, 3);
    std::vector<std::string> messages;
    for (Eigen::Index l = 0; l < nl; ++l)
      for (Eigen::Index p = 0; p < np; ++p) {
        const JobResult& r = results.at(static_cast<std::size_t>(l * np + p));
        status(l, p) = static_cast<int>(r.status);
        attempts(l, p) = r.attempts;
        factor(l, p) = r.step_factor;
        conv(l, p) = r.converged_steps();
        // the fit (fit_sweep_database) uses a case's converged steps, if it has any
        in_fit(l, p) = in.fit && r.raw.path.set == "paper" && r.converged_steps() > 0 ? 1 : 0;
        seconds(l, p) = r.seconds;
        residual.row(l * np + p) = r.residual.transpose();
        messages.push_back(r.message);
      }
    g.write("case_status", status);
    g.set_attribute("case_status", "values", "0 = converged, 1 = partial, 2 = failed, 3 = error");
    g.write("case_attempts", attempts);
    g.write("case_step_factor", factor);
    g.write("case_converged_steps", conv);
    g.write("case_in_fit", in_fit);
    g.set_attribute("case_in_fit", "values",
                    "1 = its converged steps entered the paper's response-surface fit (eq. 17: "
                    "the paper's paths only; non-converged steps never do). The energy law "
                    "(/energy_law) fits the converged steps of every path whose set is not "
                    "\"holdout\", up to where the cell gave way (/energy_law/diagnostics)");
    g.write("case_seconds", seconds);
    g.set_attribute("case_seconds", "units", "s");
    g.write_strings("case_messages", messages);
    g.write("residual_S", residual);
    g.set_attribute("residual_S", "columns",
                    "S11, S22, S12 (MPa) of the equilibrated cell at F* = I; rows: loop length "
                    "index * cases + case index");
    g.set_attribute(
        "residual_S", "treatment",
        in.subtract_residual ? "subtracted from raw S (and P = F S)" : "kept in raw S and P");
    g.set_attribute(".", "rows_columns", "rows: loop lengths, columns: load cases");
    g.set_attribute(".", "failed_cases", report.failed_cases());
    g.set_attribute(".", "seconds_cases", report.seconds_cases);
    g.set_attribute(".", "seconds_fit", report.seconds_fit);
    g.set_attribute(".", "ranks", report.ranks);
    g.set_attribute(".", "threads", report.threads);
    g.set_attribute(".", "step_status_values",
                    "raw/path_NN/status: 0 = converged, 1 = did not converge, 2 = not reached");
    if (!report.case_builds.empty()) {
      g.write_strings("case_builds", report.case_builds);
      g.set_attribute("case_builds", "meaning",
                      "the knit-meso builds whose cases this database holds, oldest first (more "
                      "than one when a sweep was resumed by another build)");
    }
    std::vector<int> ids = in.path_ids;
    g.write("default_path_index", ids);
    std::vector<std::string> fit_status;
    for (const auto& fs_ : report.fits)
      fit_status.push_back(fs_.ok() ? "ok" : "not fitted: " + fs_.reason);
    if (!fit_status.empty()) g.write_strings("fit_status", fit_status);
  });
}

// ---- the output's size --------------------------------------------------------------------

namespace {
// Bytes per recorded step and per case, measured on the synthetic runner's output (a sweep of
// 100 held-out paths with 2 and with 2,000 steps: 116 bytes per step in the database, 285 in
// a checkpoint's hex floats; 17 kB of HDF5 groups and attributes per case), rounded up. The
// cell runner's numbers are longer (the review of session 44: up to about 338 bytes per
// checkpoint step, 14 hex floats of up to 23 characters and their separators), and a database
// carries about 100 kB of its own (the fits, the sweep's report): both are bounded here.
constexpr std::uint64_t kDatabaseBytesPerStep = 120, kCheckpointBytesPerStep = 340;
constexpr std::uint64_t kBytesPerCase = 18'000, kBytesPerDatabase = 128'000;

std::uint64_t path_bytes(const material::LoadPath& p) {
  return static_cast<std::uint64_t>(std::max(p.steps, 0)) *
             (kDatabaseBytesPerStep + kCheckpointBytesPerStep) +
         kBytesPerCase;
}
}  // namespace

std::uint64_t estimate_output_bytes(const SweepInput& in) {
  std::uint64_t per_loop = 0;
  for (const auto& p : in.paths) per_loop += path_bytes(p);
  return per_loop * static_cast<std::uint64_t>(in.loop_lengths.size()) + kBytesPerDatabase;
}

void check_output_size(const SweepInput& in, std::uint64_t max_bytes) {
  const std::uint64_t est = estimate_output_bytes(in);
  if (max_bytes == 0 || est <= max_bytes) return;
  // The field whose paths make most of it (session 44's red team: 1,000 held-out paths of
  // 10,000 steps at 100 loop lengths were accepted as 101,300 cases, about 240 GB).
  struct Share {
    std::uint64_t bytes = 0;
    int paths = 0, max_steps = 0;
  };
  std::map<std::string, Share> by;
  for (std::size_t i = 0; i < in.paths.size(); ++i) {
    auto& s = by[i < in.path_fields.size() ? in.path_fields[i] : "/load_paths"];
    s.bytes += path_bytes(in.paths[i]);
    s.paths += 1;
    s.max_steps = std::max(s.max_steps, in.paths[i].steps);
  }
  const auto top = std::max_element(by.begin(), by.end(), [](const auto& a, const auto& b) {
    return a.second.bytes < b.second.bytes;
  });
  const std::size_t loops = in.loop_lengths.size();
  const std::string& field = top->first;
  const std::string what = field == "/load_paths/holdout"    ? " (its count and steps)"
                           : field == "/load_paths/coverage" ? " (its directions and *_steps)"
                           : field == "/steps"               ? " (the steps of the preset's paths)"
                                                             : " (their number and steps)";
  throw InputError(in.file, field,
                   "the estimated output size " + io::format_bytes(est) +
                       " (the database and its "
                       "checkpoints: " +
                       std::to_string(loops * in.paths.size()) + " cases, " +
                       std::to_string(loops) + " loop lengths (/loop_lengths) x " +
                       std::to_string(in.paths.size()) + " paths) exceeds the cap of " +
                       io::format_bytes(max_bytes) + "; " +
                       io::format_bytes(top->second.bytes * loops) + " of it are the " +
                       std::to_string(top->second.paths) + " paths of " + field + what +
                       ", of up to " + std::to_string(top->second.max_steps) +
                       " steps: use fewer loop lengths, paths or steps, or raise the cap with "
                       "--max-output-size (0: no cap); nothing was run");
}

// ---- runners ----------------------------------------------------------------------------------

PathRunner synthetic_runner() {
  return [](double l, const material::LoadPath& path) {
    if (const char* d = std::getenv("KNIT_SWEEP_TEST_DELAY_MS"))
      std::this_thread::sleep_for(std::chrono::milliseconds(std::atoi(d)));
    fit::SyntheticOptions so;
    so.paths = {path};
    PathOutcome out;
    out.raw = fit::synthetic_paths(so, l).front();
    out.cell = notes_cell(l, 0.38);
    out.message = "synthetic law";
    if (const char* f = std::getenv("KNIT_SWEEP_TEST_COUNT_FILE")) {
      static std::mutex m;
      std::lock_guard<std::mutex> lk(m);
      std::ofstream(f, std::ios::app)
          << l << ' ' << path.target(0) << ' ' << path.target(1) << '\n';
    }
    return out;
  };
}

PathRunner synthetic_runner(const SweepInput& in) {
  // The stand-in's stiffness (l_ref / l)^2 grows without bound as l -> 0: a sweep with a loop
  // length of 1e-320 mm ran every case and then failed at the database write (exit 1, naming
  // a raw dataset, the checkpoints kept for a --resume that fails again). Refused before any
  // case runs, at its JSON pointer, when S or P = F S may exceed what a database holds at
  // E_ij = m, the largest |E_ij| along the input's steps, with |F_ij| <= f (every coefficient
  // of the law is positive, so |S| at E_ij = m bounds |S| at every strain with |E_ij| <= m,
  // and |P_ij| <= 2 f max|S|). A uniaxial path's prescribed stretch counts; its lateral
  // strain, found by the runner, is a contraction within the floor m >= 1. As cell_runner
  // refuses a cell it cannot build. (Reviews of session 30: the corner E_ij = 2 missed
  // gradient paths reaching E_ij = 6; P = F S, which the reader bounds too, was not checked.)
  double m = 1.0, f = 1.0;
  for (const auto& path : in.paths)
    for (int k = 1; k <= path.steps; ++k) {
      const Eigen::Matrix2d F = material::deformation_gradient(path, double(k) / path.steps);
      const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
      m = std::max(m, E.cwiseAbs().maxCoeff());
      f = std::max(f, F.cwiseAbs().maxCoeff());
    }
  const Eigen::Vector3d corner = Eigen::Vector3d::Constant(m);
  for (std::size_t k = 0; k < in.loop_lengths.size(); ++k) {
    const Eigen::Vector3d s = fit::SyntheticLaw{}.stress(corner, in.loop_lengths[k]);
    if (!(2.0 * f * s.cwiseAbs().maxCoeff() <= material::kMaxRawStress))
      throw InputError(in.file, io::json_pointer_append("/loop_lengths", k),
                       "the synthetic stand-in's stiffness (4.5 / l)^2 MPa at l = " +
                           io::format_number(in.loop_lengths[k]) +
                           " mm gives stresses beyond what a database holds (" +
                           io::format_number(material::kMaxRawStress) +
                           " MPa for S and P = F S at |E_ij| = " + io::format_number(m) +
                           ", |F_ij| = " + io::format_number(f) +
                           " along the paths); give loop lengths of a knit (a few mm)");
  }
  return synthetic_runner();
}

PathRunner make_runner(const SweepInput& in) {
  return in.runner == RunnerKind::kSynthetic ? synthetic_runner(in) : cell_runner(in);
}

}  // namespace knit::meso::sweep
