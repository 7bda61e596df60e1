// knit-macro run and its output directory (issue 14, docs/io.md "Output targets"): it never
// deletes what it did not write, refuses a target it cannot write before any work (exit 2,
// naming the option and the path), locks the output against a concurrent run, and refuses a
// run whose estimated output is larger than the cap; what it writes: the sampled fields,
// `output.every`, and a non-finite sample named where it is.
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../output_test_util.hpp"
#include "knit/io/hdf5.hpp"
#include "knit/macro/case.hpp"
#include "knit/macro/run.hpp"
#include "knit/macro/shell_model.hpp"
#include "knit/macro/svk_material.hpp"
#include "verification_case.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

fs::path scratch(const std::string& tag) {
  const fs::path d = fs::path(KNIT_BINARY_DIR) / "test_scratch" /
                     ("run_outputs_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

using knit::macro::test::verification_case;

/// The tensile case with a few steps and a small output grid, written to d/t.json.
std::string small_case(const fs::path& d, int grid = 5, int steps = 2) {
  json j = verification_case("tensile_svk.json");
  j["solver"]["steps"] = steps;
  j["output"]["grid"] = {grid, grid};
  std::ofstream(d / "t.json") << j.dump(2);
  return (d / "t.json").string();
}

knit_test::CommandResult macro(const std::string& args) {
  std::string command = KNIT_BIN_DIR;  // appended, not chained (GCC 12's -Warray-bounds false
  command += "/knit-macro run ";       // positive on the inlined temporaries, session 40)
  command += args;
  return knit_test::run_command(command);
}

}  // namespace

TEST_CASE("knit-macro run never deletes files it did not write", "[unit][outputs]") {
  const fs::path d = scratch("loss");
  const std::string c = small_case(d);
  fs::create_directories(d / "work");
  std::ofstream(d / "work" / "keep.txt") << "precious";
  // The current directory as the output (the reported data loss).
  auto r = knit_test::run_command("cd " + (d / "work").string() + " && " + KNIT_BIN_DIR +
                                  "/knit-macro run " + c + " --output \"$(pwd)\"");
  CHECK(r.rc == 2);
  CHECK(knit_test::contains(r.output, "--output"));
  CHECK(fs::exists(d / "work" / "keep.txt"));
  CHECK(!knit_test::contains(r.output, "step    1"));  // refused before the run
  // Any non-empty directory without the marker.
  r = macro(c + " --output " + (d / "work").string());
  CHECK(r.rc == 2);
  CHECK(knit_test::contains(r.output, "not a knitscale output"));
  CHECK(fs::exists(d / "work" / "keep.txt"));
  // An empty directory and knitscale's own earlier output are replaced.
  fs::create_directories(d / "empty");
  REQUIRE(macro(c + " --output " + (d / "empty").string()).rc == 0);
  CHECK(fs::exists(d / "empty" / "load_strain.csv"));
  CHECK(fs::exists(d / "empty" / ".knitscale-output"));
  {  // The marker's provenance names the case (session 43's walkthrough: "input": "").
    std::ifstream in(d / "empty" / ".knitscale-output");
    std::string first, prov;
    std::getline(in, first);
    std::getline(in, prov);
    CHECK(nlohmann::json::parse(prov).at("input") == c);
  }
  REQUIRE(macro(c + " --output " + (d / "empty").string()).rc == 0);
  CHECK(fs::exists(d / "empty" / "load_strain.csv"));
  for (const auto& e : fs::directory_iterator(d))  // no partial, old or lock files left
    CHECK((e.path().filename().string().find('.') == std::string::npos ||
           e.path().extension() == ".json"));
  fs::remove_all(d);
}

// Session 26 (found by a helper's audit): the reproduction pipeline's output directory (marked
// by scripts/pipeline.mk) was replaced by a run's; a rerun in which no step converged replaced
// the earlier results with its empty output.
TEST_CASE("knit-macro run keeps other programs' outputs and earlier results of a failed rerun",
          "[unit][outputs]") {
  const fs::path d = scratch("owner");
  const std::string c = small_case(d);
  fs::create_directories(d / "pipeline" / "figures");
  std::ofstream(d / "pipeline" / ".knitscale-output")
      << "knitscale output: the reproduction pipeline (scripts/pipeline.mk)\n";
  std::ofstream(d / "pipeline" / "figures" / "f.png") << "png";
  auto r = macro(c + " --output " + (d / "pipeline").string());
  CHECK(r.rc == 2);
  CHECK(knit_test::contains(r.output, "is the output of the reproduction pipeline"));
  CHECK(fs::exists(d / "pipeline" / "figures" / "f.png"));

  REQUIRE(macro(c + " --output " + (d / "out").string()).rc == 0);
  std::ifstream good_in(d / "out" / "load_strain.csv");
  const std::string good((std::istreambuf_iterator<char>(good_in)), {});
  json j = json::parse(std::ifstream(c));
  j["solver"]["max_iterations"] = 1;  // no step can converge
  j["solver"]["tolerance"] = 1e-30;
  j["solver"]["max_cutbacks"] = 1;
  std::ofstream(d / "fail.json") << j.dump(2);
  r = macro((d / "fail.json").string() + " --output " + (d / "out").string());
  CHECK(r.rc == 1);
  CHECK(knit_test::contains(r.output, "no load step converged: nothing written"));
  std::ifstream again_in(d / "out" / "load_strain.csv");
  CHECK(std::string((std::istreambuf_iterator<char>(again_in)), {}) == good);
  CHECK_FALSE(knit_test::contains(r.output, "; outputs in"));
  // A run that stops after converged steps replaces the earlier output (the report reads a
  // stopped run's results), and says so (session 40's red team: it did not).
  {
    json crush = json::parse(std::ifstream(c));
    for (auto& bc : crush["boundary_conditions"])
      if (bc.contains("prescribe")) bc["prescribe"]["y"] = -60.0;  // folds after a few steps
    crush["solver"]["steps"] = 20;
    std::ofstream(d / "crush.json") << crush.dump(2);
    REQUIRE(macro(c + " --output " + (d / "replaced").string()).rc == 0);
    r = macro((d / "crush.json").string() + " --output " + (d / "replaced").string());
    CHECK(r.rc == 1);
    const auto outputs_in = [&](const char* dir, const char* then) {
      std::string said = "; outputs in ";
      said += (d / dir).string();
      return said + then;
    };
    CHECK(knit_test::contains(r.output,
                              outputs_in("replaced", " (they replace the earlier outputs there")));
    // Session 46's red team: the completed earlier output was lost to the stopped rerun. It
    // is kept as DIR.last-completed (said in the message); a second stopped rerun keeps it,
    // and a completed one keeps none.
    const fs::path kept = d / "replaced.last-completed";
    CHECK(knit_test::contains(r.output,
                              "the completed earlier output is kept in " + kept.string() + ")"));
    const auto first_line = [](const fs::path& f) {
      std::ifstream in(f);
      std::string line;
      std::getline(in, line);
      return line;
    };
    CHECK(first_line(kept / "summary.txt") == "status: completed");
    CHECK(first_line(d / "replaced" / "summary.txt") == "status: stopped");
    CHECK_FALSE(
        knit_test::contains(knit_test::read_text(kept / ".knitscale-output"), "replaced by pid"));
    r = macro((d / "crush.json").string() + " --output " + (d / "replaced").string());
    CHECK(r.rc == 1);
    CHECK(first_line(kept / "summary.txt") == "status: completed");
    REQUIRE(macro(c + " --output " + (d / "replaced").string()).rc == 0);
    CHECK(first_line(kept / "summary.txt") == "status: completed");  // left as it was
    CHECK(first_line(d / "replaced" / "summary.txt") == "status: completed");
    // A completed run that is not trustworthy (its material failed; it exits 1 as well) is not
    // kept over the clean one kept before (the review of session 46).
    std::ofstream(kept / "summary.txt", std::ios::app) << "# the clean one\n";
    std::ofstream(d / "replaced" / "summary.txt", std::ios::app)
        << "material failures: 3 evaluations (a stand-in)\n";
    r = macro((d / "crush.json").string() + " --output " + (d / "replaced").string());
    CHECK(r.rc == 1);
    CHECK(knit_test::contains(knit_test::read_text(kept / "summary.txt"), "# the clean one"));
    r = macro((d / "crush.json").string() + " --output " + (d / "fresh").string());
    CHECK(r.rc == 1);
    CHECK(knit_test::contains(r.output, outputs_in("fresh", "\n")));
  }
  // An earlier output that a killed replacement had moved aside (no DIR, DIR.old-<dead pid>)
  // is put back and kept by the failed rerun as well.
  fs::rename(d / "out", d / "out.old-999999999");
  // (what the run that moved it aside writes into its marker just before, since session 29)
  std::ofstream(d / "out.old-999999999" / ".knitscale-output", std::ios::app)
      << "replaced by pid 999999999\n";
  r = macro((d / "fail.json").string() + " --output " + (d / "out").string());
  CHECK(r.rc == 1);
  std::ifstream back_in(d / "out" / "load_strain.csv");
  CHECK(std::string((std::istreambuf_iterator<char>(back_in)), {}) == good);
  // Into a new, or an empty, directory the failed run still writes its summary.
  fs::create_directories(d / "empty");
  for (const char* dir : {"new", "empty"}) {
    r = macro((d / "fail.json").string() + " --output " + (d / dir).string());
    CHECK(r.rc == 1);
    CHECK(fs::exists(d / dir / "summary.txt"));
    // No VTU, so no results.pvd (it was an empty collection; session 38's red team).
    CHECK_FALSE(fs::exists(d / dir / "results.pvd"));
    std::ifstream sum_in(d / dir / "summary.txt");
    CHECK(knit_test::contains(std::string((std::istreambuf_iterator<char>(sum_in)), {}),
                              "vtk: none (no step converged, so no results.pvd)"));
  }
  fs::remove_all(d);
}

// Session 26: an interrupted run ended silently (the sweep said what it kept; run, design and
// fit did not).
TEST_CASE("knit-macro run: an interrupt says what became of the outputs", "[unit][outputs]") {
  const fs::path d = scratch("interrupt");
  const std::string c = small_case(d, 5, 100000);  // runs far longer than the 1 s below
  // No cap: 100,000 steps of output would be ~6 GB (refused by the default cap of 2 GB).
  // SIGINT once the run has begun its output (the review of session 56: after a fixed 1 s, a
  // loaded machine or the sanitizer build may not have got that far), at most 30 s on.
  const std::string out = (d / "out").string();
  const auto r = knit_test::run_command(
      std::string(KNIT_BIN_DIR) + "/knit-macro run " + c + " --output " + out +
      " --max-output-size 0 & p=$!; i=0; while [ $i -lt 600 ] && ! ls -d " + out +
      ".partial-* >/dev/null 2>&1; do sleep 0.05; i=$((i+1)); done; sleep 0.2; kill -INT $p; "
      "wait $p");
  CHECK(r.rc == 130);  // 128 + SIGINT: ended by the signal
  CHECK(knit_test::contains(r.output,
                            "knit-macro run: interrupted; outputs not yet complete "
                            "are not written, earlier outputs stay as they were; a "
                            "left-over OUTPUT.lock and OUTPUT.partial-<pid> beside an output "
                            "are removed by the next run into it"));
  CHECK_FALSE(fs::exists(d / "out"));
  // What the line says is left (session 56's walkthrough), and that the next run removes it.
  CHECK(fs::exists(d / "out.lock"));
  const auto partial = [&] {
    for (const auto& e : fs::directory_iterator(d))
      if (e.path().filename().string().rfind("out.partial-", 0) == 0) return true;
    return false;
  };
  CHECK(partial());
  const std::string quick = small_case(d, 5, 2);
  REQUIRE(knit_test::run_command(std::string(KNIT_BIN_DIR) + "/knit-macro run " + quick +
                                 " --output " + (d / "out").string())
              .rc == 0);
  CHECK_FALSE(fs::exists(d / "out.lock"));
  CHECK_FALSE(partial());
  fs::remove_all(d);
}

TEST_CASE("knit-macro run refuses an output it cannot write before the run", "[unit][outputs]") {
  const fs::path d = scratch("targets");
  const std::string c = small_case(d);
  std::ofstream(d / "file") << "a file";
  fs::create_symlink(d / "missing", d / "dangling");
  const std::string targets[] = {(d / "file").string(),
                                 (d / "dangling").string(),
                                 (d / "file" / "sub").string(),
                                 "..",
                                 ".",
                                 "/"};
  for (const std::string& t : targets) {
    INFO("--output " << t);
    // Run inside d: what a wrong rename would touch stays in the scratch directory.
    const auto r = knit_test::run_command("cd " + d.string() + " && " + KNIT_BIN_DIR +
                                          "/knit-macro run " + c + " --output \"" + t + "\"");
    CHECK(r.rc == 2);
    CHECK(knit_test::contains(r.output, "--output"));
    CHECK(!knit_test::contains(r.output, "step    1"));
  }
  CHECK(fs::is_regular_file(d / "file"));
  CHECK(fs::is_symlink(fs::symlink_status(d / "dangling")));
  if (::geteuid() != 0) {  // root writes everywhere
    fs::create_directories(d / "ro");
    fs::permissions(d / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    const auto r = macro(c + " --output " + (d / "ro" / "out").string());
    CHECK(r.rc == 2);
    CHECK(knit_test::contains(r.output, "not writable"));
    fs::permissions(d / "ro", fs::perms::owner_all);
  }
  fs::remove_all(d);
}

TEST_CASE("knit-macro run: an output in use by another run is refused", "[unit][outputs]") {
  const fs::path d = scratch("lock");
  const std::string c = small_case(d);
  const std::string out = (d / "out").string();
  {
    knit_test::LockHolder other(d / "out.lock");
    REQUIRE(other.pid() > 0);
    const auto r = macro(c + " --output " + out);
    CHECK(r.rc == 2);
    CHECK(knit_test::contains(r.output, "pid " + std::to_string(other.pid())));
    CHECK(!fs::exists(out));
    other.release();  // killed: its lock file stays behind
    CHECK(fs::exists(d / "out.lock"));
    CHECK(macro(c + " --output " + out).rc == 0);  // the stale lock is taken over
  }
  CHECK(fs::exists(d / "out" / "load_strain.csv"));
  CHECK(!fs::exists(d / "out.lock"));  // released at the end of the run
  fs::remove_all(d);
}

TEST_CASE("knit-macro run: the estimated output size is capped before the run", "[unit][outputs]") {
  const fs::path d = scratch("size");
  const std::string out = (d / "out").string();
  {  // The reported case: 1001 x 1001 samples (386 s, 7.8 GB) is refused at once.
    const std::string c = small_case(d, 1001, 10);
    const auto r = macro(c + " --output " + out);
    CHECK(r.rc == 2);
    CHECK(knit_test::contains(r.output, "/output/grid"));
    CHECK(knit_test::contains(r.output, "estimated output size"));
    CHECK(knit_test::contains(r.output, "GB"));
    CHECK(!fs::exists(out));
  }
  const std::string c = small_case(d, 5, 2);
  auto r = macro(c + " --output " + out + " --max-output-size 10k");
  CHECK(r.rc == 2);
  CHECK(knit_test::contains(r.output, "--max-output-size"));
  r = macro(c + " --output " + out + " --max-output-size 400k");  // > a tenth: warns, runs
  CHECK(r.rc == 0);
  CHECK(knit_test::contains(r.output, "warning:"));
  r = macro(c + " --output " + out + " --max-output-size lots");
  CHECK(r.rc == 2);
  CHECK(knit_test::contains(r.output, "--max-output-size"));
  fs::remove_all(d);
}

TEST_CASE("knit-macro run: the output size estimate bounds what is written", "[unit][outputs]") {
  // An upper bound, so that a run the cap let through stays below it (session 37's red team: a
  // 21 x 21 grid of 20 steps wrote 4.56 MB under a cap of 4 MB it had passed with an estimate
  // of 3.6 MB), and not far above: 1-2 % on large grids, up to 30 % on tiny ones.
  for (const int grid : {2, 21, 61})
    for (const int steps : {1, 3}) {
      const fs::path d = scratch("estimate");
      const std::string file = small_case(d, grid, steps);
      const knit::macro::Case c = knit::macro::load_case(file);
      knit::macro::RunOptions ro;
      ro.output_dir = d / "out";
      REQUIRE(knit::macro::run_case(c, ro).report.status == knit::macro::RunStatus::kCompleted);
      std::uintmax_t bytes = 0;
      for (const auto& e : fs::recursive_directory_iterator(d / "out"))
        if (e.is_regular_file()) bytes += e.file_size();
      const double est = static_cast<double>(knit::macro::estimate_output_bytes(c));
      INFO(grid << " x " << grid << " samples, " << steps << " steps: estimated " << est
                << " bytes, written " << bytes);
      CHECK(est >= static_cast<double>(bytes));
      CHECK(est <= 1.3 * static_cast<double>(bytes));
      if (grid == 61) CHECK(est <= 1.03 * static_cast<double>(bytes));
      fs::remove_all(d);
    }
}

TEST_CASE("results.h5: the fields are the shell's samples on the output grid", "[unit][outputs]") {
  // The Scordelis-Lo roof (curved: every strain, curvature and resultant is non-zero somewhere)
  // on a 4 x 3 grid: row k = i + 4 j at (theta1, theta2) = (i / 3, j / 2), the Voigt shears
  // (2E12, 2k12) stored as tensor components, n and m as they are (session 32: a writer with
  // E12 = 2E12, or grid rows in the other order, survived the suite).
  using namespace knit::macro;
  const fs::path d = scratch("fields");
  json j = verification_case("scordelis_lo.json");
  j["solver"]["steps"] = 1;
  j["output"]["grid"] = {4, 3};
  const Case c = parse_case(j.dump(), "roof.json");
  RunOptions ro;
  ro.output_dir = d / "out";
  const RunResult r = run_case(c, ro);
  REQUIRE(r.succeeded());
  const Problem p = setup_problem(c);
  auto h5 = knit::io::H5File::open_read(d / "out" / "results.h5");
  const std::string g = "fields/step_0001/";
  const auto X = h5.read_matrix(g + "X"), x = h5.read_matrix(g + "x");
  std::map<std::string, std::vector<double>> f;
  for (const char* n : {"E11", "E22", "E12", "kappa11", "kappa22", "kappa12", "n11", "n22", "n12",
                        "m11", "m22", "m12"})
    f[n] = h5.read_doubles(g + n);
  Eigen::Vector3d largest = Eigen::Vector3d::Zero();  // |2E12|, |2k12|, |m12| over the grid
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();   // |E11|, |k11|, |m11|
  for (int jj = 0; jj < 3; ++jj)
    for (int i = 0; i < 4; ++i) {
      const int k = i + 4 * jj;
      const ShellSample s = p.model->sample(r.u, Eigen::Vector2d(i / 3.0, jj / 2.0));
      INFO("grid point " << k);
      CHECK((X.row(k).transpose() - s.X).norm() <= 1e-12 * s.X.norm());
      CHECK((x.row(k).transpose() - s.x).norm() <= 1e-12 * s.x.norm());
      const double want[12] = {s.E(0),     s.E(1),           0.5 * s.E(2), s.kappa(0),
                               s.kappa(1), 0.5 * s.kappa(2), s.n(0),       s.n(1),
                               s.n(2),     s.m(0),           s.m(1),       s.m(2)};
      const char* names[12] = {"E11", "E22", "E12", "kappa11", "kappa22", "kappa12",
                               "n11", "n22", "n12", "m11",     "m22",     "m12"};
      for (int q = 0; q < 12; ++q)
        CHECK(f[names[q]][k] == Approx(want[q]).epsilon(1e-12).margin(1e-300));
      largest = largest.cwiseMax(
          Eigen::Vector3d(std::abs(s.E(2)), std::abs(s.kappa(2)), std::abs(s.m(2))));
      normal = normal.cwiseMax(
          Eigen::Vector3d(std::abs(s.E(0)), std::abs(s.kappa(0)), std::abs(s.m(0))));
    }
  // The shears are well above round-off (against the normal components), so their factor is
  // seen: on this grid |2E12| reaches 1 % of |E11|, |2k12| and |m12| more than |k11| and |m11|.
  CHECK(largest(0) > 1e-3 * normal(0));
  CHECK(largest(1) > 1e-3 * normal(1));
  CHECK(largest(2) > 1e-3 * normal(2));
  for (const char* n : {"n11", "n22", "n12", "m11", "m22", "m12"})
    CHECK_THAT(h5.attribute_string(g + n, "measure"),
               Catch::StartsWith("2nd Piola-Kirchhoff stress resultant"));
  fs::remove_all(d);
}

TEST_CASE("output every: every n-th step and the last, and a stopped run writes its last state",
          "[unit][outputs]") {
  using namespace knit::macro;
  const fs::path d = scratch("every");
  auto steps_written = [](const fs::path& out) {
    auto h5 = knit::io::H5File::open_read(out / "results.h5");
    std::vector<std::string> vtu;
    for (const auto& e : fs::directory_iterator(out / "vtk")) vtu.push_back(e.path().stem());
    std::sort(vtu.begin(), vtu.end());
    CHECK(vtu == h5.children("fields"));  // the VTU files and the HDF5 groups agree
    CHECK(h5.read_doubles("steps/load_factor").size() == h5.read_doubles("steps/step").size());
    return h5.children("fields");
  };
  json j = verification_case("tensile_svk.json");
  j["solver"]["steps"] = 5;
  j["output"]["grid"] = {3, 3};
  j["output"]["every"] = 2;
  RunOptions ro;
  ro.output_dir = d / "every2";
  REQUIRE(run_case(parse_case(j.dump(), "t.json"), ro).succeeded());
  CHECK(steps_written(ro.output_dir) ==
        std::vector<std::string>{"step_0002", "step_0004", "step_0005"});
  // Every row of the load-strain curve is kept whatever `every` is.
  CHECK(knit::io::H5File::open_read(ro.output_dir / "results.h5")
            .read_doubles("steps/load_factor")
            .size() == 5u);
  // The estimate counts ceil(steps / every) output steps: 3 for 5 steps, 2 for 4; it is
  // n X + C (C = 48 kB for the small files), so 3 est(4) - 2 est(5) = C.
  const std::uint64_t five = estimate_output_bytes(parse_case(j.dump(), "t.json"));
  j["solver"]["steps"] = 4;
  const std::uint64_t four = estimate_output_bytes(parse_case(j.dump(), "t.json"));
  CHECK(3 * four - 2 * five == 49152u);
  // A run that stops (the Sze cantilever in one step with 8 iterations and 2 cut-backs
  // converges at 0.25 only) writes the state it reached although 1 is not a multiple of 1000.
  json sze = verification_case("sze_cantilever.json");
  sze["solver"]["steps"] = 1;
  sze["solver"]["max_iterations"] = 8;
  sze["solver"]["max_cutbacks"] = 2;
  sze["output"]["grid"] = {3, 3};
  sze["output"]["every"] = 1000;
  ro.output_dir = d / "stopped";
  const RunResult s = run_case(parse_case(sze.dump(), "sze.json"), ro);
  REQUIRE(s.report.status == RunStatus::kNotConverged);
  REQUIRE(s.rows.size() == 1u);
  CHECK(steps_written(ro.output_dir) == std::vector<std::string>{"step_0001"});
  fs::remove_all(d);
}

namespace {

/// St. Venant-Kirchhoff whose stress is NaN at one point of the output grid, (theta1, theta2) =
/// (1, 0.25), where no quadrature point lies.
struct NanAtOnePoint final : knit::macro::Material {
  knit::macro::SaintVenantKirchhoff svk{1000.0, 0.3};
  std::string name() const override { return "nan_at_one_point"; }
  bool hyperelastic() const override { return true; }
  knit::macro::MaterialResponse evaluate(const Eigen::Vector3d& E,
                                         const knit::macro::MaterialPoint& w) const override {
    knit::macro::MaterialResponse r = svk.evaluate(E, w);
    if (std::abs(w.theta(0) - 1.0) < 1e-12 && std::abs(w.theta(1) - 0.25) < 1e-12)
      r.S.setConstant(NAN);
    return r;
  }
};

}  // namespace

TEST_CASE("a non-finite output sample is named by its field, step and grid point",
          "[unit][outputs]") {
  // A 3 x 5 grid: the bad sample is row k = 2 + 3 * 1 (theta1 = 2 / 2, theta2 = 1 / 4), in both
  // steps; n11 is the first field it spoils.
  using namespace knit::macro;
  const fs::path d = scratch("nan");
  json j = verification_case("tensile_svk.json");
  j["solver"]["steps"] = 2;
  j["output"]["grid"] = {3, 5};
  Case c = parse_case(j.dump(), "t.json");
  c.material = std::make_shared<NanAtOnePoint>();
  RunOptions ro;
  ro.output_dir = d / "out";
  const RunResult r = run_case(c, ro);
  CHECK(r.report.status == RunStatus::kCompleted);
  CHECK_FALSE(r.succeeded());
  CHECK_THAT(r.output_failure,
             Catch::StartsWith("output field n11 is not finite at step 1, (theta1, theta2) = (1, "
                               "0.25) of the output grid (2 non-finite sample(s) in all)"));
  fs::remove_all(d);
}
