// Sweep orchestration (issue #7): input, jobs and retries, exact checkpoints, thread pool,
// resume, failed cases -- with injected fake runners (no unit cell).
#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../output_test_util.hpp"
#include "knit/core/errors.hpp"
#include "knit/io/hdf5.hpp"
#include "knit/meso/fit/synthetic.hpp"
#include "knit/meso/sweep/checkpoint.hpp"
#include "knit/meso/sweep/sweep.hpp"
#include "test_sweep_util.hpp"

using namespace knit::meso::sweep;
using knit::material::LoadPath;
using knit::material::RawPath;

namespace {

/// Synthetic law, but only steps with F* increment <= max_increment converge (a stand-in for
/// a cell that needs small steps); steps after a failure are not reached.
PathRunner picky_runner(double max_df, std::atomic<int>* calls = nullptr) {
  return [max_df, calls](double l, const LoadPath& path) {
    if (calls) ++*calls;
    PathOutcome out = synthetic_runner()(l, path);
    const Eigen::Matrix2d dF =
        knit::material::deformation_gradient(path, 1.0 / path.steps) - Eigen::Matrix2d::Identity();
    if (dF.cwiseAbs().maxCoeff() > max_df) {
      for (int k = 0; k < path.steps; ++k) {
        out.raw.status[static_cast<std::size_t>(k)] = k < 2 ? 0 : (k == 2 ? 1 : 2);
        if (k >= 2) {
          out.raw.F.row(k).setZero();
          out.raw.S.row(k).setConstant(99.0);  // garbage that must not reach the database
        }
      }
    }
    return out;
  };
}

SweepInput synthetic_input(int steps = 6) {
  return parse_sweep_input(knit_test::synthetic_sweep_json(steps), "test.json");
}

SweepOptions quiet(const std::filesystem::path& out) {
  SweepOptions o;
  o.output = out;
  o.progress = nullptr;
  o.log = nullptr;
  return o;
}

}  // namespace

// The estimate of --max-output-size (session 44's red team): the case files stay far below the
// default cap, and the estimate is not below what a sweep writes (database and checkpoints,
// here with --keep-parts, on the synthetic runner).
TEST_CASE("sweep output size: the case files are far below the cap, the estimate above the files",
          "[unit]") {
  const std::filesystem::path cases = std::filesystem::path(KNIT_SOURCE_DIR) / "cases" / "sweep";
  for (const char* name : {"default", "dense", "reduced", "wale_compressed_rays"}) {
    // (a path, not a chain of string +: GCC 12's -Warray-bounds false positive on the latter)
    const auto in = load_sweep_input((cases / (std::string(name) + ".json")).string());
    INFO(name << ": " << estimate_output_bytes(in) << " bytes");
    CHECK(estimate_output_bytes(in) < knit::meso::sweep::kDefaultMaxOutputBytes / 20);
    CHECK_NOTHROW(check_output_size(in, knit::meso::sweep::kDefaultMaxOutputBytes));
  }
  const auto dir = knit_test::scratch("sweep_output_size");
  auto in = parse_sweep_input(
      R"({"loop_lengths": [4.5, 5.0], "runner": "synthetic", "steps": 20, "fit": false,
          "load_paths": {"preset": "default", "holdout": {"count": 20, "steps": 500}}})",
      "s.json");
  SweepOptions o;
  o.output = dir / "db.h5";
  o.keep_parts = true;
  o.progress = nullptr;
  o.log = nullptr;
  REQUIRE(run_sweep(in, o, synthetic_runner(in)).wrote_database);
  std::uint64_t written = std::filesystem::file_size(o.output);
  for (const auto& e : std::filesystem::directory_iterator(dir / "db.h5.parts"))
    written += std::filesystem::file_size(e.path());
  const std::uint64_t est = estimate_output_bytes(in);
  CHECK(est >= written);
  CHECK(est < 2 * written);
  CHECK_NOTHROW(check_output_size(in, 0));  // 0: no cap
  try {
    check_output_size(in, est - 1);
    FAIL("not refused");
  } catch (const knit::InputError& e) {
    CHECK(e.file() == "s.json");
    CHECK(e.pointer() == "/load_paths/holdout");
  }
}

TEST_CASE("sweep input: the default, dense, wale-compressed-rays and reduced case files",
          "[unit]") {
  const auto d = load_sweep_input(std::string(KNIT_SOURCE_DIR) + "/cases/sweep/default.json");
  CHECK(d.loop_lengths == std::vector<double>{4.5, 5.0, 5.5, 6.0, 6.5});
  // The paper's 13 paths, then 2 uniaxial + 16 biaxial + 7 gradient coverage paths and 12
  // held-out paths (issue 11; 60 held-out runs over the five loop lengths).
  REQUIRE(d.paths.size() == 13 + 25 + 12);
  CHECK(make_jobs(d).size() == 5 * 50);
  CHECK_FALSE(d.subtract_residual);
  // the shared definition (knit/material/load_paths.hpp) is used, not a copy
  const auto shared = knit::material::default_load_paths(20);
  for (std::size_t i = 0; i < 13; ++i) {
    CHECK(d.paths[i].kind == shared[i].kind);
    CHECK(d.paths[i].steps == 20);
    CHECK(d.paths[i].set == "paper");
    CHECK((d.paths[i].target - shared[i].target).norm() < 1e-15);
  }
  int uni = 0, bi = 0, grad = 0, hold = 0;
  for (std::size_t i = 13; i < d.paths.size(); ++i) {
    const auto& p = d.paths[i];
    CHECK(d.path_ids[i] == -1);
    if (p.set == "holdout") {
      ++hold;
    } else {
      CHECK(p.set == "coverage");
      uni += p.kind == knit::material::PathKind::kUniaxial ? 1 : 0;
      bi += p.kind == knit::material::PathKind::kBiaxial ? 1 : 0;
      grad += p.kind == knit::material::PathKind::kGradient ? 1 : 0;
    }
  }
  CHECK(uni == 2);
  CHECK(bi == 16);
  CHECK(grad == 7);
  CHECK(hold == 12);
  CHECK(d.runner == RunnerKind::kCell);
  CHECK(d.fit_options.n_ctrl1 == 11);
  // The dense input: the default plus 48 quasi-random fill paths (coverage, 6 steps), with the
  // fuller held-out check (24 paths per loop length, the default's 12 and 12 more).
  const auto dense = load_sweep_input(std::string(KNIT_SOURCE_DIR) + "/cases/sweep/dense.json");
  REQUIRE(dense.paths.size() == d.paths.size() + 48 + 12);
  int fill = 0;
  for (const auto& p : dense.paths)
    fill += p.set == "coverage" && p.kind == knit::material::PathKind::kGradient && p.steps == 6;
  CHECK(fill == 48);
  // The variant with rays into the shear-with-wale-compressed octant: the default plus 6
  // explicit paths, which are exactly the rays of `rays: 24` (default box, 8 steps, J >= 0.5)
  // whose end lies in E11 >= 0, E22 < 0, as its description says.
  const auto wcr =
      load_sweep_input(std::string(KNIT_SOURCE_DIR) + "/cases/sweep/wale_compressed_rays.json");
  REQUIRE(wcr.paths.size() == d.paths.size() + 6);
  knit::material::CoverageOptions co;
  co.box.E11_min = -0.35;
  co.box.E11_max = 0.60;
  co.biaxial_steps = co.gradient_steps = 8;
  const std::size_t without = knit::material::coverage_load_paths(co).size();
  co.rays = 24;
  const auto all = knit::material::coverage_load_paths(co);
  std::vector<Eigen::Matrix2d> octant;
  for (std::size_t k = without; k < all.size(); ++k) {
    const Eigen::Matrix2d E =
        knit::material::green_lagrange(knit::material::deformation_gradient(all[k], 1.0));
    if (E(0, 0) >= 0 && E(1, 1) < 0) octant.push_back(all[k].H);
  }
  REQUIRE(octant.size() == 6);
  for (std::size_t k = 0; k < 6; ++k) {
    const auto& p = wcr.paths[d.paths.size() + k];
    CHECK(p.set == "coverage");
    CHECK(p.steps == 8);
    CHECK((p.H - octant[k]).cwiseAbs().maxCoeff() < 1e-11);
  }
  const auto r = load_sweep_input(std::string(KNIT_SOURCE_DIR) + "/cases/sweep/reduced.json");
  // Session 24: the sweep input was read with an ifstream, /dev/zero until memory ran out.
  CHECK_THROWS_WITH(load_sweep_input("/dev/zero"), Catch::Contains("not a regular file"));
  CHECK(r.loop_lengths.size() == 1);
  CHECK(r.path_ids == std::vector<int>{0, 4, 7, 11, 12, -1, -1, -1, -1});
  CHECK(r.paths[4].kind == knit::material::PathKind::kShear);
  // one path of each new kind (issue 11)
  CHECK(r.paths[5].kind == knit::material::PathKind::kUniaxial);
  CHECK(r.paths[5].axis == 1);
  CHECK(r.paths[5].target(0) == 0.2);
  CHECK(r.paths[6].set == "coverage");
  CHECK(r.paths[7].kind == knit::material::PathKind::kGradient);
  CHECK(r.paths[7].H(0, 1) == 0.3);
  CHECK(r.paths[8].set == "holdout");
}

TEST_CASE("sweep report: only a paper path that stops, or a runner error, fails the sweep",
          "[unit]") {
  // docs/sweep.md: coverage and held-out paths often end where the cell jams or buckles; such a
  // path is kept with its converged steps and counted as stopped, not failed. A paper path that
  // stops fails the sweep (its fan is the eq. 17 fit's grid), and a runner that threw fails it
  // whatever the path (session 32, a mutation audit: treating a stopped coverage path as a
  // failure passed every test).
  SweepReport r;
  for (const char* set : {"paper", "coverage", "holdout"})
    for (JobStatus st :
         {JobStatus::kConverged, JobStatus::kPartial, JobStatus::kFailed, JobStatus::kError}) {
      JobResult j;
      j.status = st;
      j.raw.path.set = set;
      const bool fails =
          st == JobStatus::kError || (st != JobStatus::kConverged && std::string(set) == "paper");
      INFO(set << ", " << to_string(st));
      CHECK(fails_sweep(j) == fails);
      r.results.push_back(j);
    }
  // Of the 12: 2 paper (partial, failed) + 3 errors fail; the other 4 not converged stopped.
  CHECK(r.failed_cases() == 5);
  CHECK(r.stopped_cases() == 4);
}

TEST_CASE("sweep input: errors name the JSON pointer", "[unit]") {
  auto pointer_of = [](const std::string& text) {
    try {
      parse_sweep_input(text, "s.json");
    } catch (const knit::InputError& e) {
      return e.pointer() + (e.message().find("stepz") != std::string::npos ? "|stepz" : "");
    }
    return std::string("<no error>");
  };
  CHECK(pointer_of(R"({"loop_lengths": [4.5, 4.0]})") == "/loop_lengths/1");
  // Retries whose last attempt would run for hours are refused when the input is read (session
  // 55: max_retries 6 x step_factor 8 is 262,144 times a path's steps; 10,000 steps x 16
  // substeps x 8^6 overflowed the attempt's int). The default paths have 20 steps: 20 x 8^4 =
  // 81,920 solves pass, 20 x 8^5 = 655,360 do not; coverage paths by their own retries.
  CHECK(pointer_of(R"({"loop_lengths": [5], "retry": {"max_retries": 4, "step_factor": 8}})") ==
        "<no error>");
  CHECK(pointer_of(R"({"loop_lengths": [5], "retry": {"max_retries": 5, "step_factor": 8}})") ==
        "/retry/max_retries");
  CHECK(pointer_of(R"({"loop_lengths": [5], "retry": {"max_retries_coverage": 6, "step_factor": 8},
      "load_paths": {"preset": "default", "extra": [{"kind": "uniaxial", "axis": "wale", "E": 0.2,
      "steps": 4, "set": "coverage"}]}})") == "/retry/max_retries_coverage");  // 4 x 8^6
  CHECK_THROWS_WITH(
      parse_sweep_input(R"({"loop_lengths": [5], "retry": {"max_retries": 6, "step_factor": 8}})",
                        "s.json"),
      Catch::Contains("s.json: /retry/max_retries: a paper path (/steps, 20 cell solves on its "
                      "first attempt) would take more than 200000 on its last retry"));
  CHECK(pointer_of(R"({"loop_lengths": [4.5, -1]})") == "/loop_lengths/1");
  // Session 36's red team: 4.5 and 4.500000000000001 were two loop lengths, both "l=4.50".
  CHECK_THROWS_WITH(parse_sweep_input(R"({"loop_lengths": [4.5, 4.500000000000001]})", "t.json"),
                    "t.json: /loop_lengths/1: loop lengths must increase by at least 0.001 mm, "
                    "got 4.500000000000001 after 4.5");
  // Exactly 0.001 mm apart is enough, though not in binary (the review of session 38: 4.001
  // and 4.002 were refused).
  for (const char* pair : {"[4.001, 4.002]", "[4.009, 4.01]", "[4, 4.001]"})
    CHECK_NOTHROW(parse_sweep_input(std::string(R"({"loop_lengths": )") + pair + "}", "t.json"));
  CHECK_THROWS(parse_sweep_input(R"({"loop_lengths": [4, 4.000999]})", "t.json"));
  CHECK_NOTHROW(parse_sweep_input(R"({"loop_lengths": [4.5, 4.501]})", "t.json"));
  // Paths that end at the reference state carry no data (session 36's red team: a paper
  // biaxial path to (0, 0) folded the surface after the whole sweep).
  // (A shear path of 0 deg is the schema's: gamma_deg > 0.)
  const auto with_extra = [](const char* path) {
    return parse_sweep_input(std::string(R"({"loop_lengths": [4.5], "load_paths": {"preset": )"
                                         R"("default", "extra": [)") +
                                 path + "]}}",
                             "t.json");
  };
  for (const char* path : {R"({"kind": "biaxial", "E11": 0, "E22": 0})",
                           R"({"kind": "uniaxial", "axis": "wale", "E": 0})",
                           R"({"kind": "gradient", "H": [[0, 0], [0, 0]]})"}) {
    INFO(path);
    CHECK_THROWS_WITH(
        with_extra(path),
        Catch::StartsWith("t.json: /load_paths/extra/0: the path ends at the reference state"));
  }
  // Nor within round-off of it (session 43's red team: a shear path to 1e-300 deg gave a shear
  // curve of noise and "fit ok"); ends of 1e-3 (the box's floor) and more are data.
  for (const char* path : {R"({"kind": "biaxial", "E11": 1e-300, "E22": 1e-300})",
                           R"({"kind": "shear", "gamma_deg": 1e-6})",
                           R"({"kind": "uniaxial", "axis": "course", "E": -9e-4})",
                           R"({"kind": "gradient", "H": [[1e-5, 0], [0, 0]]})"}) {
    INFO(path);
    CHECK_THROWS_WITH(with_extra(path),
                      Catch::StartsWith("t.json: /load_paths/extra/0: the path ends within "
                                        "round-off of the reference state") &&
                          Catch::Contains("0.001"));
  }
  for (const char* path :
       {R"({"kind": "biaxial", "E11": 1e-3, "E22": 0})", R"({"kind": "shear", "gamma_deg": 0.1})"})
    CHECK_NOTHROW(with_extra(path));
  CHECK_THROWS_WITH(with_extra(R"({"kind": "shear", "gamma_deg": 0.05})"),
                    Catch::Contains("(shear angle 0.05 deg, below 0.0572958 deg = 0.001 rad)"));
  CHECK(pointer_of(R"({"loop_lengths": [4.5], "load_paths": {"preset": "default", )"
                   R"("gamma_max_deg": 1e-300}})") == "/load_paths/gamma_max_deg");
  CHECK(pointer_of(R"({"loop_lengths": [4.5], "load_paths": {"preset": "default", )"
                   R"("e_max": 1e-6}})") == "/load_paths/e_max");
  CHECK(pointer_of(R"({"loop_lengths": [4.5], "steps": 0})") == "/steps");
  // unknown keys: reported on the object that holds them, naming the key
  CHECK(pointer_of(R"({"loop_lengths": [4.5], "stepz": 3})") == "|stepz");
  CHECK(pointer_of(
            R"({"loop_lengths": [4.5], "load_paths": {"preset": "default", "select": [13]}})") ==
        "/load_paths/select/0");
  CHECK(pointer_of(
            R"({"loop_lengths": [4.5], "load_paths": [{"kind": "shear", "gamma_deg": 95}]})") ==
        "/load_paths/0/gamma_deg");
  CHECK(pointer_of(R"({"loop_lengths": [4.5], "fit": {"control_points_1": 2}})").rfind("/fit", 0) ==
        0);
  // the cell parameters follow the cell's own schema (schemas/cell.schema.json)
  CHECK(pointer_of(R"({"loop_lengths": [4.5], "cell": {"contact": {"mu": -1}}})") ==
        "/cell/contact/mu");
  CHECK(pointer_of(R"({"loop_lengths": [4.5], "cell": 3})") == "/cell");
  CHECK(pointer_of(R"({"steps": 4})") == "");  // required loop_lengths: the document itself
  // Session 24: a box of 1e-300 ran, its coverage paths all at zero strain.
  auto box = [](const std::string& b) {
    return R"({"loop_lengths": [4.5], "load_paths": {"preset": "default", "box": )" + b +
           R"(, "coverage": true}})";
  };
  CHECK(pointer_of(box(R"({"E11": [-1e-300, 1e-300]})")) == "/load_paths/box/E11");
  CHECK(pointer_of(box(R"({"E22": [-0.3, 0.0009]})")) == "/load_paths/box/E22");
  CHECK(pointer_of(box(R"({"E12_max": 1e-300})")) == "/load_paths/box/E12_max");
  CHECK(pointer_of(box(R"({"E11": [-0.001, 0.001], "E22": [-0.001, 0.001], "E12_max": 0.001})")) ==
        "<no error>");
}

// Session 44's red team: rays with "fill_min_J": 0 ran to J = det F = 0 in the default box, and
// the schema-valid input failed with exit 1 and "load path: no upper-triangular F for this
// strain", naming no file or field. Refused up front now, where a ray would pass J = 0.05.
TEST_CASE("sweep input: rays towards a collapsed cell are refused at fill_min_J", "[unit]") {
  const auto input = [](const std::string& coverage, const std::string& box = "") {
    return R"({"loop_lengths": [4.5], "load_paths": {"preset": "default", )" +
           (box.empty() ? "" : R"("box": )" + box + ", ") + R"("coverage": )" + coverage + "}}";
  };
  const auto error_of = [](const std::string& text) {
    try {
      parse_sweep_input(text, "s.json");
    } catch (const knit::InputError& e) {
      return std::string(e.what());
    } catch (const std::exception& e) {
      return std::string("not an input error: ") + e.what();
    }
    return std::string("<no error>");
  };
  for (const char* j : {"0", "0.01"}) {
    INFO("fill_min_J " << j);
    CHECK_THAT(error_of(input(R"({"rays": 20, "fill_min_J": )" + std::string(j) + "}")),
               Catch::StartsWith("s.json: /load_paths/coverage/fill_min_J: is " + std::string(j) +
                                 ", but 3 of the 20 rays (/load_paths/coverage/rays) would run "
                                 "past J = det F = 0.05 in this box") &&
                   Catch::Contains("with rays it must be >= 0.05"));
  }
  CHECK(error_of(input(R"({"rays": 20, "fill_min_J": 0.05})")) == "<no error>");
  CHECK(error_of(input(R"({"fill_min_J": 0})")) == "<no error>");  // no rays: fill points skip
  // A box whose rays all reach its surface first: fill_min_J does not shorten them.
  CHECK(error_of(input(R"({"rays": 20, "fill_min_J": 0})",
                       R"({"E11": [-0.1, 0.1], "E22": [-0.1, 0.1], "E12_max": 0.1})")) ==
        "<no error>");
}

// Session 44's red team: "coverage": {"gamma_deg": 0, "directions": 0, "stretch": [[0, 0]]} gave a
// shear-with-stretch path of ten states at F = I, which the energy law fitted (exit 0), and
// gamma_deg 0.0001 one ending at H12 = 1.7e-6. Generated paths are now held to the end of an
// explicit path (largest |H| >= 1e-3, session 43), refused at gamma_deg.
TEST_CASE("sweep input: shear-with-stretch coverage paths without an end are refused at gamma_deg",
          "[unit]") {
  const auto error_of = [](const std::string& coverage) {
    try {
      parse_sweep_input(R"({"loop_lengths": [4.5], "load_paths": {"preset": "default", )"
                        R"("coverage": )" +
                            coverage + "}}",
                        "s.json");
    } catch (const knit::InputError& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  CHECK_THAT(error_of(R"({"gamma_deg": 0, "directions": 0, "stretch": [[0.2, 0], [0, 0]]})"),
             Catch::StartsWith("s.json: /load_paths/coverage/gamma_deg: is 0 deg, and the stretch "
                               "[0, 0] (/load_paths/coverage/stretch/1) is below 0.001 too: its "
                               "shear-with-stretch path ends at the reference state") &&
                 Catch::Contains("give gamma_deg >= 0.0573 (0.001 rad) or stretches of at least "
                                 "0.001"));
  CHECK_THAT(error_of(R"({"gamma_deg": 0.0001})"),  // the default stretches hold [0, 0]
             Catch::StartsWith("s.json: /load_paths/coverage/gamma_deg: is 0.0001 deg") &&
                 Catch::Contains("(/load_paths/coverage/stretch/0, the default)") &&
                 Catch::Contains("ends within 0.001 of the reference state"));
  CHECK(error_of(R"({"gamma_deg": 0.0573, "stretch": [[0, 0]]})") == "<no error>");
  CHECK(error_of(R"({"gamma_deg": 0, "stretch": [[0.001, 0], [0, -0.001]]})") == "<no error>");
  CHECK(error_of(R"({"gamma_deg": 0, "stretch": []})") == "<no error>");
  CHECK(error_of("true") == "<no error>");
}

// Session 25: an input without e_max ran the fan to 0.35 while the header of
// default_load_paths and docs/database.md say 0.40.
TEST_CASE("sweep input: the preset's fan without e_max and e_min is the documented default",
          "[unit]") {
  const auto in = parse_sweep_input(
      R"({"loop_lengths": [4.5], "load_paths": {"preset": "default", "select": [0, 6]}})",
      "s.json");
  const auto fan = knit::material::default_load_paths(20);
  REQUIRE(in.paths.size() == 2);
  CHECK(in.paths[0].target.isApprox(fan[0].target));
  CHECK(in.paths[1].target.isApprox(fan[6].target));
  CHECK(in.paths[0].target(0) == Approx(0.40));
  CHECK(in.paths[0].target(1) == Approx(-0.15));
}

TEST_CASE("sweep input: cell parameters inline or from a file relative to the sweep file",
          "[unit]") {
  const auto dir = knit_test::scratch("sweep_unit_cellfile");
  knit_test::write_text(dir / "cell.json",
                        R"({"analysis": {"elements": 20}, "contact": {"mu": 0.2}})");
  knit_test::write_text(dir / "s.json", R"({"loop_lengths": [4.5], "cell": "cell.json"})");
  const auto a = load_sweep_input(dir / "s.json");
  CHECK(a.cell_file == (dir / "cell.json").string());
  const auto b = parse_sweep_input(
      R"({"loop_lengths": [4.5], "cell": {"analysis": {"elements": 20}, "contact": {"mu": 0.2}}})",
      "b.json");
  CHECK(a.job_definition() == b.job_definition());  // the content counts, not where it is
  // The error of loading a sweep input (the test fails if there is none).
  auto error_of = [](const std::filesystem::path& input) {
    try {
      load_sweep_input(input);
    } catch (const knit::InputError& e) {
      return e;
    }
    FAIL("no error: " << input);
    return knit::InputError("", "", "");
  };
  knit_test::write_text(dir / "bad.json", R"({"contact": {"mu": -1}})");
  knit_test::write_text(dir / "s2.json", R"({"loop_lengths": [4.5], "cell": "bad.json"})");
  const knit::InputError bad = error_of(dir / "s2.json");
  CHECK(bad.file() == (dir / "bad.json").string());
  CHECK(bad.pointer() == "/contact/mu");
  // A cell file that is not there (or not JSON): the sweep input and /cell are named beside it
  // (session 21; it said "missing.json: file not found" alone).
  knit_test::write_text(dir / "s3.json", R"({"loop_lengths": [4.5], "cell": "missing.json"})");
  const knit::InputError missing = error_of(dir / "s3.json");
  CHECK(missing.file() == (dir / "s3.json").string());
  CHECK(missing.pointer() == "/cell");
  CHECK(std::string(missing.what()).find("missing.json: file not found") != std::string::npos);
}

// Session 44's red team: "fit": false with an "energy_fit" object ran with exit 0, the energy
// options ignored without a word. Refused at /energy_fit, as knit-meso fit refuses
// --energy-options with --law paper (session 38).
TEST_CASE("sweep input: energy_fit options with \"fit\": false are refused at /energy_fit",
          "[unit]") {
  const auto error_of = [](const std::string& tail) {
    try {
      parse_sweep_input(R"({"loop_lengths": [4.5], "fit": false)" + tail + "}", "s.json");
    } catch (const knit::InputError& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  for (const char* ef : {R"({"tube": 0.045})", "{}"}) {
    INFO(ef);
    CHECK(error_of(std::string(R"(, "energy_fit": )") + ef) ==
          "s.json: /energy_fit: the energy law's fit options, but \"fit\": false fits no law (the "
          "energy law is fitted after the paper's): leave \"energy_fit\" out or set it false, or "
          "fit the laws");
  }
  CHECK(error_of(R"(, "energy_fit": false)") == "<no error>");
  CHECK(error_of("") == "<no error>");
  CHECK_NOTHROW(parse_sweep_input(
      R"({"loop_lengths": [4.5], "fit": {"smoothing": 1e-3}, "energy_fit": {"tube": 0.045}})",
      "a"));
}

TEST_CASE("sweep input: job definition ignores the fit options", "[unit]") {
  const auto a = parse_sweep_input(R"({"loop_lengths": [4.5], "fit": {"smoothing": 1e-3}})", "a");
  const auto b = parse_sweep_input(R"({"loop_lengths": [4.5], "fit": false})", "b");
  const auto c = parse_sweep_input(R"({"loop_lengths": [4.5], "steps": 19})", "c");
  CHECK(a.job_definition() == b.job_definition());
  CHECK(fingerprint(a.job_definition()) != fingerprint(c.job_definition()));
  // The digest is a pinned FNV-1a 64 variant (offset basis 1469598103934665603; the standard's
  // gives af63dc4c8601ec8c for "a"): earlier versions' checkpoints were written with it
  // (docs/sweep.md; session 38's red team found the slip).
  CHECK(fingerprint("") == "14650fb0739d0383");
  CHECK(fingerprint("a") == "44bd8ad473cd9906");
  CHECK_FALSE(b.fit);
  // explicit paths
  const auto e = parse_sweep_input(
      R"({"loop_lengths": [5], "steps": 7, "load_paths": [{"kind": "biaxial", "E11": 0.3, "E22": 0},
          {"kind": "shear", "gamma_deg": 30, "steps": 4}]})",
      "e");
  REQUIRE(e.paths.size() == 2);
  CHECK(e.paths[0].steps == 7);
  CHECK(e.paths[1].steps == 4);
  CHECK(e.paths[1].target(0) == Approx(M_PI / 6));
}

TEST_CASE("sweep job: exact serialization round trip", "[unit]") {
  const auto in = synthetic_input();
  const auto jobs = make_jobs(in);
  JobResult r = run_job(jobs[3], in.retry, synthetic_runner());
  r.raw.S(2, 1) = 1.0 / 3.0;
  r.raw.P(0, 0) = -std::nextafter(1e-300, 1.0);
  r.message = "multi\nline";
  const JobResult q = deserialize(serialize(r));
  CHECK(q.index == r.index);
  CHECK(q.status == r.status);
  CHECK(q.raw.status == r.raw.status);
  CHECK((q.raw.S.array() == r.raw.S.array()).all());
  CHECK((q.raw.P.array() == r.raw.P.array()).all());
  CHECK((q.raw.F.array() == r.raw.F.array()).all());
  CHECK(q.cell.course_height == r.cell.course_height);
  CHECK(q.message == "multi line");
  // issue 11: the kind, axis, H and set of every path kind survive bit-exactly
  for (const auto kind :
       {knit::material::PathKind::kUniaxial, knit::material::PathKind::kGradient}) {
    JobResult u = r;
    u.raw.path.kind = kind;
    u.raw.path.axis = 1;
    u.raw.path.H << 0.1, 1.0 / 3.0, -std::nextafter(1e-300, 1.0), -0.05;
    u.raw.path.set = "holdout";
    const JobResult v = deserialize(serialize(u));
    CHECK(v.raw.path.kind == kind);
    CHECK(v.raw.path.axis == 1);
    CHECK((v.raw.path.H.array() == u.raw.path.H.array()).all());
    CHECK(v.raw.path.set == "holdout");
    Job j = jobs[3];
    j.load_path = u.raw.path;
    CHECK(matches(v, j));
    j.load_path.set = "coverage";
    CHECK_FALSE(matches(v, j));
  }
  CHECK(matches(q, jobs[3]));
  CHECK_FALSE(matches(q, jobs[4]));
  CHECK_THROWS(deserialize(serialize(r).substr(0, 200)));
  CHECK_THROWS(deserialize("garbage"));
}

TEST_CASE("sweep job: non-convergence retried with smaller steps and the recorded steps unchanged",
          "[unit]") {
  const auto in = synthetic_input(6);
  const auto jobs = make_jobs(in);
  const Job& j = jobs[0];  // biaxial (0.35, -0.15): dF per step ~0.05 with 6 steps
  const JobResult plain = run_job(j, in.retry, synthetic_runner());
  REQUIRE(plain.status == JobStatus::kConverged);
  CHECK(plain.attempts == 1);
  // Converges only with half the step: one retry (factor 2) succeeds.
  const double dF = plain.raw.F.row(0).cwiseAbs().maxCoeff() - 1.0;  // first step's |F - 1|
  std::atomic<int> calls{0};
  const JobResult retried = run_job(j, in.retry, picky_runner(std::abs(dF) * 0.75, &calls));
  CHECK(calls == 2);
  CHECK(retried.status == JobStatus::kConverged);
  CHECK(retried.attempts == 2);
  CHECK(retried.step_factor == 2);
  CHECK((retried.raw.F - plain.raw.F).cwiseAbs().maxCoeff() < 1e-14);
  CHECK((retried.raw.S - plain.raw.S).cwiseAbs().maxCoeff() < 1e-12);
  // Never converges beyond step 2: partial after 1 + max_retries attempts, statuses recorded.
  calls = 0;
  const JobResult bad = run_job(j, in.retry, picky_runner(1e-9, &calls));
  CHECK(calls == 1 + in.retry.max_retries);
  CHECK(bad.status == JobStatus::kPartial);
  // best attempt: the refined one reaches sub-step 2 -> recorded step 1 only (rows 0..1)
  CHECK(bad.raw.status[0] == kStepConverged);
  CHECK(bad.raw.status.back() == kStepNotReached);
  CHECK(bad.converged_steps() >= 1);
  CHECK(bad.converged_steps() < 6);
  // Among attempts that reach as far, the first (the coarsest) is kept (session 32, a mutation
  // audit: keeping the last of equals passed): a runner whose every attempt converges exactly
  // one recorded step (the first m sub-steps of m x 6).
  const JobResult tie = run_job(j, in.retry, [](double l, const LoadPath& p) {
    PathOutcome out = synthetic_runner()(l, p);
    const int m = p.steps / 6;
    for (int k = 0; k < p.steps; ++k)
      out.raw.status[static_cast<std::size_t>(k)] = k < m ? 0 : (k == m ? 1 : 2);
    out.message = "attempt with " + std::to_string(m) + " sub-steps";
    return out;
  });
  CHECK(tie.attempts == 1 + in.retry.max_retries);
  CHECK(tie.status == JobStatus::kPartial);
  CHECK(tie.converged_steps() == 1);
  CHECK(tie.step_factor == 1);
  CHECK(tie.message == "attempt with 1 sub-steps");
  for (int k = 0; k < 6; ++k)
    if (bad.raw.status[static_cast<std::size_t>(k)] != 0) CHECK(bad.raw.S.row(k).isZero());
  // A runner that throws: recorded as an error, not thrown.
  const JobResult err = run_job(j, in.retry, [](double, const LoadPath&) -> PathOutcome {
    throw std::runtime_error("boom");
  });
  CHECK(err.status == JobStatus::kError);
  CHECK(err.message.find("boom") != std::string::npos);
  CHECK(err.converged_steps() == 0);
  // First step never converges: failed.
  const JobResult none = run_job(j, in.retry, [](double l, const LoadPath& p) {
    PathOutcome o = synthetic_runner()(l, p);
    std::fill(o.raw.status.begin(), o.raw.status.end(), kStepNotReached);
    o.raw.status[0] = kStepFailed;
    return o;
  });
  CHECK(none.status == JobStatus::kFailed);
  CHECK(none.raw.status[0] == kStepFailed);
}

TEST_CASE("sweep job: substeps refine the first attempt per path set, the recorded steps stay",
          "[unit]") {
  // "substeps" (session 18): each recorded step is reached through that many cell solves on
  // the first attempt; the database keeps the path's own steps (every m-th solve).
  const auto in0 = synthetic_input(6);
  const Job j = make_jobs(in0)[0];  // a paper path
  REQUIRE(j.load_path.set == "paper");
  const JobResult plain = run_job(j, in0.retry, synthetic_runner());
  std::vector<int> seen;
  const PathRunner counting = [&seen](double l, const LoadPath& p) {
    seen.push_back(p.steps);
    return synthetic_runner()(l, p);
  };
  SweepInput in = in0;
  in.retry.substeps_paper = 3;
  in.retry.substeps_coverage = 5;
  const JobResult fine = run_job(j, in.retry, counting);
  REQUIRE(seen == std::vector<int>{18});
  CHECK(fine.status == JobStatus::kConverged);
  CHECK(fine.attempts == 1);
  CHECK(fine.step_factor == 3);
  CHECK(fine.raw.status.size() == 6);
  CHECK((fine.raw.F - plain.raw.F).cwiseAbs().maxCoeff() < 1e-14);
  CHECK((fine.raw.S - plain.raw.S).cwiseAbs().maxCoeff() < 1e-12);
  // Another set: its own count.
  Job c = j;
  c.load_path.set = "coverage";
  seen.clear();
  run_job(c, in.retry, counting);
  CHECK(seen == std::vector<int>{30});
  c.load_path.set = "holdout";
  seen.clear();
  run_job(c, in.retry, counting);
  CHECK(seen == std::vector<int>{6});
  // The input: parsed per set, bounds named by JSON pointer, and part of the job definition
  // only when set (older checkpoints keep their identity).
  const std::string base = knit_test::synthetic_sweep_json(6);
  REQUIRE(base.back() == '}');
  const auto with = [&](const std::string& extra) {
    return base.substr(0, base.size() - 1) + ", " + extra + "}";
  };
  const SweepInput parsed = parse_sweep_input(with(R"("substeps": {"holdout": 4})"), "s.json");
  CHECK(parsed.retry.substeps_holdout == 4);
  CHECK(parsed.retry.substeps_paper == 1);
  CHECK(parsed.retry.substeps_coverage == 1);
  CHECK(parsed.job_definition() != in0.job_definition());
  CHECK(parse_sweep_input(with(R"("substeps": {"holdout": 1})"), "s.json").job_definition() ==
        in0.job_definition());
  try {
    parse_sweep_input(with(R"("substeps": {"coverage": 0})"), "s.json");
    FAIL("substeps 0 accepted");
  } catch (const knit::InputError& e) {
    CHECK(e.pointer() == "/substeps/coverage");
  }
}

TEST_CASE("sweep input: fit options large enough to overflow are refused by JSON pointer",
          "[unit]") {
  // Found by feeding each option 1e308: the paper fit's smoothing then failed inside Ceres and
  // the energy fit's floor at its first evaluation, neither naming the option.
  const std::string base = knit_test::synthetic_sweep_json(6);
  const auto replaced = [&](const std::string& from, const std::string& to) {
    const auto at = base.find(from);
    REQUIRE(at != std::string::npos);
    return std::string(base).replace(at, from.size(), to);
  };
  CHECK_NOTHROW(parse_sweep_input(base, "s.json"));
  const std::pair<std::string, std::string> cases[] = {
      {R"("smoothing": 1e-6)", R"("smoothing": 1e308)"},
      {R"("smoothing": 1e-6)", R"("smoothing": 1e-6, "foot_point_penalty": 1e308)"},
      {R"("network_iterations": 100)", R"("network_iterations": 100, "floor": 1e308)"},
      {R"("network_iterations": 100)", R"("network_iterations": 100, "smoothing": 1e308)"}};
  const char* pointers[] = {"/fit/smoothing", "/fit/foot_point_penalty", "/energy_fit/floor",
                            "/energy_fit/smoothing"};
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    INFO(pointers[i]);
    try {
      parse_sweep_input(replaced(cases[i].first, cases[i].second), "s.json");
      FAIL("accepted");
    } catch (const knit::InputError& e) {
      CHECK(e.pointer() == pointers[i]);
      CHECK(std::string(e.what()).find("must be <= 1000") != std::string::npos);
    }
  }
}

TEST_CASE(
    "sweep: any number of threads gives the same database and failed cases are kept and "
    "reported but not fitted",
    "[unit]") {
  const auto dir = knit_test::scratch("sweep_unit_threads");
  const auto in = synthetic_input();
  auto o1 = quiet(dir / "one.h5");
  o1.threads = 1;
  const SweepReport r1 = run_sweep(in, o1, synthetic_runner());
  CHECK(r1.ok());
  CHECK(r1.computed == 26);
  CHECK_FALSE(std::filesystem::exists(dir / "one.h5.parts"));
  auto o3 = quiet(dir / "three.h5");
  o3.threads = 3;
  const SweepReport r3 = run_sweep(in, o3, synthetic_runner());
  const auto d1 = knit::material::read_database(dir / "one.h5");
  const auto d3 = knit::material::read_database(dir / "three.h5");
  CHECK(knit_test::database_difference(d1, d3) == 0.0);
  CHECK(r3.threads == 3);
  // No more workers than cases (session 21: --threads 4096 started 4096 threads for 7 cases).
  auto o_many = quiet(dir / "many.h5");
  o_many.threads = 4096;
  const SweepReport r_many = run_sweep(in, o_many, synthetic_runner());
  CHECK(r_many.threads == 26);
  CHECK(knit_test::database_difference(d1, knit::material::read_database(dir / "many.h5")) == 0.0);
  REQUIRE(d1.entries.size() == 2);
  CHECK(d1.entries[0].surface.has_value());
  CHECK(d1.generator.find("synthetic") != std::string::npos);

  // Case 5 of the second loop length never gets past its first steps.
  const int bad = 13 + 5;
  const auto jobs = make_jobs(in);
  const PathRunner flaky = [&](double l, const LoadPath& p) {
    if (l == jobs[bad].loop_length && p.target == jobs[bad].load_path.target)
      return picky_runner(1e-9)(l, p);
    return synthetic_runner()(l, p);
  };
  auto of = quiet(dir / "flaky.h5");
  of.threads = 2;
  const SweepReport rf = run_sweep(in, of, flaky);
  CHECK(rf.failed_cases() == 1);
  CHECK_FALSE(rf.ok());
  CHECK(rf.results[bad].status == JobStatus::kPartial);
  CHECK(rf.fits_ok());
  const auto df = knit::material::read_database(dir / "flaky.h5");
  const auto& raw = df.entries[1].raw[5];
  CHECK(raw.status[0] == 0);
  CHECK(raw.status.back() == kStepNotReached);
  CHECK(raw.S.bottomRows(1).isZero());  // the failed steps carry no garbage
  {
    const auto f = knit::io::H5File::open_read(dir / "flaky.h5");
    const auto st = f.read_int_matrix("/sweep/report/case_status");
    REQUIRE(st.rows() == 2);
    CHECK(st(1, 5) == static_cast<int>(JobStatus::kPartial));
    CHECK(st.sum() == st(1, 5));
    // The codes are explained beside them, in the enum's order (session 33, a helper's audit:
    // dropping the attribute passed the suite).
    const std::string values = f.attribute_string("/sweep/report/case_status", "values");
    for (JobStatus s :
         {JobStatus::kConverged, JobStatus::kPartial, JobStatus::kFailed, JobStatus::kError})
      CHECK_THAT(values,
                 Catch::Contains(std::to_string(static_cast<int>(s)) + " = " + to_string(s)));
    CHECK(f.read_int_matrix("/sweep/report/case_converged_steps")(1, 5) ==
          std::count(raw.status.begin(), raw.status.end(), 0));
    CHECK(f.read_int_matrix("/sweep/report/case_in_fit").minCoeff() == 1);
    CHECK(f.read_strings("/sweep/report/case_messages").size() == 26);
  }
  // Every other case is as in the clean run.
  for (std::size_t p = 0; p < 13; ++p)
    if (p != 5) CHECK((df.entries[1].raw[p].S - d1.entries[1].raw[p].S).isZero());

  // Case 7 of the first loop length fails at its first step: no converged state. It fails the
  // sweep, stays out of the fit (which is made from the other 12 paper paths) and out of
  // case_in_fit (session 32, a mutation audit: counting a path with no converged step as usable
  // for the fit, or as in it, passed every test).
  const int dead = 7;
  const PathRunner dying = [&](double l, const LoadPath& p) {
    PathOutcome out = synthetic_runner()(l, p);
    if (l == jobs[dead].loop_length && p.target == jobs[dead].load_path.target) {
      for (int k = 0; k < p.steps; ++k) out.raw.status[static_cast<std::size_t>(k)] = k ? 2 : 1;
      out.raw.F.setZero();
      out.raw.S.setConstant(99.0);
    }
    return out;
  };
  const SweepReport rd = run_sweep(in, quiet(dir / "dead.h5"), dying);
  CHECK(rd.failed_cases() == 1);
  CHECK(rd.results[dead].status == JobStatus::kFailed);
  CHECK(rd.fits_ok());
  REQUIRE(rd.fits.size() == 2);
  CHECK(rd.fits[0].ok());
  const auto f = knit::io::H5File::open_read(dir / "dead.h5");
  const auto in_fit = f.read_int_matrix("/sweep/report/case_in_fit");
  CHECK(in_fit(0, dead) == 0);
  CHECK(in_fit.sum() == 25);
}

TEST_CASE("sweep: resume recomputes only the missing or foreign cases, the same database",
          "[unit]") {
  const auto dir = knit_test::scratch("sweep_unit_resume");
  const auto in = synthetic_input();
  const auto jobs = make_jobs(in);
  const auto out = dir / "db.h5";
  {  // a "killed" sweep: the checkpoints of 9 cases exist
    CheckpointStore store(out, in.job_definition(), static_cast<int>(jobs.size()), false, false);
    for (int i : {0, 1, 2, 3, 7, 8, 13, 20, 25})
      store.store(run_job(jobs[static_cast<std::size_t>(i)], in.retry, synthetic_runner()));
  }
  // Job 0's record copied over job 1's (sealed and readable, but another case's): job 1 is
  // recomputed, not resumed with job 0's data (a helper's audit, session 33: taking every
  // readable record passed this test).
  const auto parts = CheckpointStore::parts_dir(out);
  std::filesystem::copy_file(parts / "job_00000.txt", parts / "job_00001.txt",
                             std::filesystem::copy_options::overwrite_existing);
  // without --resume or --force: refused (bad input, exit 2)
  CHECK_THROWS_AS(run_sweep(in, quiet(out), synthetic_runner()), knit::InputError);
  // a different sweep cannot resume these checkpoints
  auto other = synthetic_input(7);
  auto ro = quiet(out);
  ro.resume = true;
  CHECK_THROWS_AS(run_sweep(other, ro, synthetic_runner()), knit::InputError);
  std::atomic<int> calls{0};
  const PathRunner counting = [&](double l, const LoadPath& p) {
    ++calls;
    return synthetic_runner()(l, p);
  };
  ro.threads = 2;
  const SweepReport r = run_sweep(in, ro, counting);
  CHECK(calls == 26 - 8);
  CHECK(r.resumed == 8);
  CHECK(r.computed == 18);
  auto full = quiet(dir / "full.h5");
  run_sweep(in, full, synthetic_runner());
  CHECK(knit_test::database_difference(knit::material::read_database(out),
                                       knit::material::read_database(dir / "full.h5")) == 0.0);
  CHECK_FALSE(std::filesystem::exists(CheckpointStore::parts_dir(out)));
}

// Session 26 (found by a helper's audit): --force deleted a DB.h5.parts that the sweep had not
// written -- a directory with the user's files, or a plain file -- with exit 0; and a damaged
// manifest was reported as "a different sweep input".
TEST_CASE("sweep: --force discards only checkpoints the sweep wrote", "[unit]") {
  namespace fs = std::filesystem;
  const auto dir = knit_test::scratch("sweep_unit_parts");
  const auto in = synthetic_input();
  const auto jobs = make_jobs(in);
  const int n = static_cast<int>(jobs.size());
  const auto out = dir / "db.h5";
  const fs::path parts = CheckpointStore::parts_dir(out);
  // A directory of the user's, and a plain file, of that name: refused, kept.
  fs::create_directories(parts / "sub");
  std::ofstream(parts / "mine.txt") << "mine";
  std::ofstream(parts / "sub" / "deep.txt") << "deep";
  for (bool resume : {false, true}) {
    CHECK_THROWS_WITH(CheckpointStore(out, in.job_definition(), n, resume, !resume),
                      Catch::Contains("which the sweep does not write"));
  }
  CHECK(fs::exists(parts / "mine.txt"));
  CHECK(fs::exists(parts / "sub" / "deep.txt"));
  fs::remove_all(parts);
  std::ofstream(parts) << "a file";
  CHECK_THROWS_WITH(CheckpointStore(out, in.job_definition(), n, false, true),
                    Catch::Contains("not a directory of sweep checkpoints"));
  CHECK(fs::is_regular_file(parts));
  fs::remove(parts);
  // Somebody else's manifest.json: not ours either.
  fs::create_directories(parts);
  std::ofstream(parts / "manifest.json") << R"({"format": "other-tool"})";
  CHECK_THROWS_WITH(CheckpointStore(out, in.job_definition(), n, false, true),
                    Catch::Contains("not a sweep's"));
  fs::remove_all(parts);
  // Ours: discarded by --force, file by file.
  {
    CheckpointStore store(out, in.job_definition(), n, false, false);
    store.store(run_job(jobs[0], in.retry, synthetic_runner()));
  }
  // Job records of index 100000 and beyond have 6 digits: still ours.
  fs::copy_file(parts / "job_00000.txt", parts / "job_100000.txt");
  CHECK_NOTHROW(CheckpointStore(out, in.job_definition(), n, true, false));
  // A damaged manifest beside our records: --resume says so, --force discards them.
  std::ofstream(parts / "manifest.json") << "{";
  CHECK_THROWS_WITH(CheckpointStore(out, in.job_definition(), n, true, false),
                    Catch::Contains("manifest is missing or damaged"));
  {
    CheckpointStore store(out, in.job_definition(), n, false, true);
    CHECK_FALSE(fs::exists(parts / "job_00000.txt"));
    CHECK(fs::exists(parts / "manifest.json"));
    // A file put into the directory meanwhile stays, with the directory.
    std::ofstream(parts / "notes.txt") << "notes";
    store.remove();
    CHECK(fs::exists(parts / "notes.txt"));
    CHECK_FALSE(fs::exists(parts / "manifest.json"));
  }
  // A hidden file of the user's beside our records, or one named like our temporaries but of
  // another file: not ours, refused and kept (session 33, the I/O audit: taking every dot-file
  // for the store's passed the suite, and --force then deleted the user's file).
  for (const char* hidden : {".notes", ".mine.txt.tmp-1-2"}) {
    fs::remove_all(parts);
    {
      CheckpointStore store(out, in.job_definition(), n, false, false);
      store.store(run_job(jobs[0], in.retry, synthetic_runner()));
    }
    std::ofstream(parts / hidden) << "mine";
    INFO(hidden);
    CHECK_THROWS_WITH(
        CheckpointStore(out, in.job_definition(), n, false, true),
        Catch::Contains(std::string("holds \"") + hidden + "\", which the sweep does not write"));
    CHECK(knit_test::read_text(parts / hidden) == "mine");
    CHECK(fs::exists(parts / "job_00000.txt"));
  }
  fs::remove_all(parts);
  // An empty directory of that name records nothing, so nothing says it is ours (session 52's
  // red team: a successful sweep deleted the user's empty DB.h5.parts): the store uses it and
  // leaves it in place, emptied of its own files, with or without --resume or --force.
  for (const bool resume : {false, true})
    for (const bool force : {false, true}) {
      if (resume && force) continue;
      INFO("resume " << resume << ", force " << force);
      fs::create_directories(parts);
      {
        CheckpointStore store(out, in.job_definition(), n, resume, force);
        store.store(run_job(jobs[0], in.retry, synthetic_runner()));
        CHECK(fs::exists(parts / "job_00000.txt"));
        store.remove();
      }
      CHECK(fs::is_directory(parts));
      CHECK(fs::is_empty(parts));
    }
  // ... also when the sweep that used it is interrupted and resumed (the review of session 52:
  // the resumed sweep removed it): a plain rerun refuses its checkpoints, --resume continues
  // them and leaves the directory in place, --force discards them and keeps it.
  for (const bool force : {false, true}) {
    INFO("force " << force);
    fs::create_directories(parts);
    CheckpointStore(out, in.job_definition(), n, false, false)
        .store(run_job(jobs[0], in.retry, synthetic_runner()));  // interrupted here
    CHECK_THROWS_WITH(CheckpointStore(out, in.job_definition(), n, false, false),
                      Catch::Contains("exist: continue it with --resume"));
    {
      CheckpointStore store(out, in.job_definition(), n, !force, force);
      CHECK(store.load_finished(jobs).size() == (force ? 0u : 1u));
      store.remove();
    }
    CHECK(fs::is_directory(parts));
    CHECK(fs::is_empty(parts));
  }
  fs::remove_all(parts);
}

TEST_CASE("sweep: a job file copied from another sweep's checkpoints is recomputed on --resume",
          "[unit]") {
  // Session 36's red team: job files of a sweep with another friction, copied into this
  // sweep's parts directory, were taken on --resume with exit 0 (a record holds its path, not
  // the cell it was run with). Every record now names its sweep's fingerprint.
  namespace fs = std::filesystem;
  const auto dir = knit_test::scratch("sweep_unit_foreign_jobs");
  const auto in = synthetic_input();
  const auto jobs = make_jobs(in);
  const int n = static_cast<int>(jobs.size());
  auto other_definition = nlohmann::json::parse(in.job_definition());
  other_definition["session36_other_cell"] = 0.3;  // same paths, another sweep
  const auto other = dir / "other.h5", out = dir / "db.h5";
  {
    CheckpointStore a(other, other_definition.dump(), n, false, false);
    for (int i : {0, 3})
      a.store(run_job(jobs[static_cast<std::size_t>(i)], in.retry, synthetic_runner()));
    CheckpointStore b(out, in.job_definition(), n, false, false);
    b.store(run_job(jobs[1], in.retry, synthetic_runner()));
  }
  const auto parts = CheckpointStore::parts_dir(out);
  for (const char* f : {"job_00000.txt", "job_00003.txt"})
    fs::copy_file(CheckpointStore::parts_dir(other) / f, parts / f);
  const CheckpointStore b(out, in.job_definition(), n, true, false);
  const auto finished = b.load_finished(jobs);
  REQUIRE(finished.size() == 1);
  CHECK(finished.count(1) == 1);
  // A record written before session 36 (no sweep line, sealed as then) is still taken.
  std::string text = knit_test::read_text(parts / "job_00000.txt");
  const auto sweep_line = text.rfind("\nsweep ");
  REQUIRE(sweep_line != std::string::npos);
  text.resize(sweep_line + 1);
  knit_test::write_text(parts / "job_00000.txt",
                        text + "digest fnv1a64 " + knit::meso::sweep::fingerprint(text) + "\n");
  CHECK(b.load_finished(jobs).size() == 2);
}

TEST_CASE("sweep: checkpoints without a finished case are discarded, with or without --resume",
          "[unit]") {
  // Session 36's red team: a run stopped while it wrote its first manifest left only the
  // manifest's temporary; --resume then said "manifest is missing or damaged ... use --force"
  // and a plain run "checkpoints of an unfinished sweep exist".
  namespace fs = std::filesystem;
  const auto dir = knit_test::scratch("sweep_unit_empty_parts");
  const auto in = synthetic_input();
  const int n = static_cast<int>(make_jobs(in).size());
  const auto out = dir / "db.h5";
  const auto parts = CheckpointStore::parts_dir(out);
  for (const bool resume : {false, true}) {
    fs::remove_all(parts);
    fs::create_directories(parts);
    std::ofstream(parts / ".manifest.json.tmp-999999999-0") << "{\"form";
    INFO("resume " << resume);
    CHECK_NOTHROW(CheckpointStore(out, in.job_definition(), n, resume, false));
    CHECK(fs::exists(parts / "manifest.json"));
    CHECK_FALSE(fs::exists(parts / ".manifest.json.tmp-999999999-0"));
  }
  // A manifest of another sweep input without any record: nothing to lose either.
  {
    fs::remove_all(parts);
    CheckpointStore(out, R"({"other": 1})", n, false, false);
  }
  CHECK_NOTHROW(CheckpointStore(out, in.job_definition(), n, true, false));
  // With a record, the refusals stand.
  CheckpointStore(out, in.job_definition(), n, true, false)
      .store(run_job(make_jobs(in)[0], in.retry, synthetic_runner()));
  CHECK_THROWS_WITH(
      CheckpointStore(out, in.job_definition(), n, false, false),
      Catch::Contains("checkpoints of an unfinished sweep (or kept by --keep-parts) exist"));
  CHECK_THROWS_WITH(CheckpointStore(out, R"({"other": 1})", n, true, false),
                    Catch::Contains("different sweep input"));
  // The refusal says what differs, as pointers into the job definition with both values.
  {
    auto changed = in;
    changed.paths[1].steps += 3;
    const std::string want = "/paths/1/steps: " + std::to_string(in.paths[1].steps) +
                             " in the checkpoints, " + std::to_string(changed.paths[1].steps) +
                             " now";
    CHECK_THROWS_WITH(CheckpointStore(out, changed.job_definition(), n, true, false),
                      Catch::Contains(want) && Catch::Contains("manifest.json"));
    changed = in;
    changed.loop_lengths.push_back(9.0);
    CHECK_THROWS_WITH(CheckpointStore(out, changed.job_definition(), n, true, false),
                      Catch::Contains("/loop_lengths/" + std::to_string(in.loop_lengths.size()) +
                                      ": only now (9.0)"));
  }
  // The same input from another build (or from a manifest that names none, written before
  // session 45) resumes; the build joins the manifest's list when it stores its first case
  // (what the database records), and a refused resume changes nothing on disk.
  {
    const auto manifest_path = parts / "manifest.json";
    const std::string original = knit_test::read_text(manifest_path);
    auto m = nlohmann::json::parse(original);
    const std::string me = CheckpointStore::this_build();
    CHECK(me.rfind("knit-meso ", 0) == 0);
    CHECK(m["builds"] == nlohmann::json({me}));
    CHECK(CheckpointStore(out, in.job_definition(), n, true, false).builds() ==
          std::vector<std::string>{me});
    const std::string other = "knit-meso 0.0.9 (git 0123456789ab)";
    m["builds"] = {other, other};  // a duplicate is listed once
    knit_test::write_text(manifest_path, m.dump());
    {
      CheckpointStore s(out, in.job_definition(), n, true, false);
      CHECK(s.builds() == std::vector<std::string>{other});
      const auto done = s.load_finished(make_jobs(in));
      REQUIRE(done.size() == 1);
      CHECK(knit_test::read_text(manifest_path) == m.dump());  // nothing stored yet
      s.store(run_job(make_jobs(in)[1], in.retry, synthetic_runner()));
      CHECK(s.builds() == std::vector<std::string>{other, me});
    }
    CHECK(nlohmann::json::parse(knit_test::read_text(manifest_path))["builds"] ==
          nlohmann::json({other, me}));
    fs::remove(parts / "job_00001.txt");
    // The one-build form of 192295e ("software"), and a manifest naming none.
    m.erase("builds");
    m["software"] = other;
    knit_test::write_text(manifest_path, m.dump());
    CHECK(CheckpointStore(out, in.job_definition(), n, true, false).builds() ==
          std::vector<std::string>{other});
    m.erase("software");
    knit_test::write_text(manifest_path, m.dump());
    const auto unnamed = CheckpointStore(out, in.job_definition(), n, true, false).builds();
    REQUIRE(unnamed.size() == 1);
    CHECK(unnamed[0].find("names no build") != std::string::npos);
    // Refused (another input, or a damaged record): the mark and the manifest stay.
    knit_test::write_text(manifest_path, original);
    std::ofstream(parts / "database_written") << "x";
    CHECK_THROWS(CheckpointStore(out, R"({"other": 2})", n, true, false));
    CHECK(fs::exists(parts / "database_written"));
    const std::string record = knit_test::read_text(parts / "job_00000.txt");
    knit_test::write_text(parts / "job_00000.txt",
                          record.substr(0, record.rfind("digest ")) + "digest fnv1a64 0000\n");
    CHECK_THROWS(
        CheckpointStore(out, in.job_definition(), n, true, false).load_finished(make_jobs(in)));
    CHECK(fs::exists(parts / "database_written"));
    CHECK(knit_test::read_text(manifest_path) == original);
    knit_test::write_text(parts / "job_00000.txt", record);
    CHECK(CheckpointStore(out, in.job_definition(), n, true, false)
              .load_finished(make_jobs(in))
              .size() == 1);
    CHECK_FALSE(fs::exists(parts / "database_written"));
  }
  // Marked written (a sweep stopped after its database was in place, while it removed them;
  // session 38's red team: the next sweep said "checkpoints of an unfinished sweep exist"):
  // --resume takes them (and drops the mark: they are that run's again, and a --keep-parts
  // resume keeps them on purpose), a plain sweep discards them.
  CheckpointStore(out, in.job_definition(), n, true, false).mark_written();
  CHECK(fs::exists(parts / "database_written"));
  CHECK(CheckpointStore(out, in.job_definition(), n, true, false)
            .load_finished(make_jobs(in))
            .size() == 1);
  CHECK_FALSE(fs::exists(parts / "database_written"));
  CHECK_THROWS_WITH(
      CheckpointStore(out, in.job_definition(), n, false, false),
      Catch::Contains("checkpoints of an unfinished sweep (or kept by --keep-parts) exist"));
  CheckpointStore(out, in.job_definition(), n, true, false).mark_written();
  CHECK_NOTHROW(CheckpointStore(out, in.job_definition(), n, false, false));
  CHECK(fs::exists(parts / "manifest.json"));  // the new sweep's
  CHECK_FALSE(fs::exists(parts / "database_written"));
  CHECK(CheckpointStore(out, in.job_definition(), n, true, false)
            .load_finished(make_jobs(in))
            .empty());
}

TEST_CASE(
    "sweep: on_written is called with the database in place and the checkpoints not yet "
    "removed",
    "[unit]") {
  // The command changes its interrupt line there (session 36's red team: a stop while the
  // checkpoints were removed said "continue with --resume" of a complete database).
  namespace fs = std::filesystem;
  const auto dir = knit_test::scratch("sweep_unit_on_written");
  const auto in = synthetic_input();
  auto o = quiet(dir / "db.h5");
  int calls = 0;
  o.on_written = [&](const std::filesystem::path& written) {
    CHECK(written == dir / "db.h5");
    ++calls;
    CHECK(fs::exists(dir / "db.h5"));
    CHECK(fs::exists(CheckpointStore::parts_dir(dir / "db.h5") / "manifest.json"));
  };
  CHECK(run_sweep(in, o, synthetic_runner()).wrote_database);
  CHECK(calls == 1);
  CHECK_FALSE(fs::exists(CheckpointStore::parts_dir(dir / "db.h5")));
}

TEST_CASE("sweep: the residual stress at F* = I is subtracted (or kept) consistently", "[unit]") {
  const auto dir = knit_test::scratch("sweep_unit_residual");
  const Eigen::Vector3d S0(0.15, 0.07, 0.01);
  const PathRunner prestressed = [&](double l, const LoadPath& p) {
    PathOutcome o = synthetic_runner()(l, p);
    o.residual = S0;
    for (Eigen::Index k = 0; k < o.raw.S.rows(); ++k) {
      o.raw.S.row(k) += S0.transpose();
      Eigen::Matrix2d F, S;
      F << o.raw.F(k, 0), o.raw.F(k, 1), o.raw.F(k, 2), o.raw.F(k, 3);
      S << o.raw.S(k, 0), o.raw.S(k, 2), o.raw.S(k, 2), o.raw.S(k, 1);
      const Eigen::Matrix2d P = F * S;
      o.raw.P.row(k) << P(0, 0), P(0, 1), P(1, 0), P(1, 1);
    }
    return o;
  };
  const std::string text = R"({"loop_lengths": [5.0], "steps": 5, "runner": "synthetic",
      "load_paths": {"preset": "default", "select": [0, 12]}, "fit": false)";
  const auto sub = parse_sweep_input(text + R"(, "residual_stress": "subtract"})", "sub.json");
  CHECK_FALSE(parse_sweep_input(text + "}", "default.json").subtract_residual);
  const auto keep = parse_sweep_input(text + R"(, "residual_stress": "keep"})", "keep.json");
  CHECK(sub.subtract_residual);
  CHECK_FALSE(keep.subtract_residual);
  CHECK(sub.job_definition() == keep.job_definition());  // a post-processing choice
  run_sweep(sub, quiet(dir / "sub.h5"), prestressed);
  run_sweep(keep, quiet(dir / "keep.h5"), prestressed);
  run_sweep(sub, quiet(dir / "plain.h5"), synthetic_runner());
  const auto ds = knit::material::read_database(dir / "sub.h5");
  const auto dk = knit::material::read_database(dir / "keep.h5");
  const auto dp = knit::material::read_database(dir / "plain.h5");
  for (std::size_t p = 0; p < 2; ++p) {
    const auto &rs = ds.entries[0].raw[p], &rk = dk.entries[0].raw[p], &rp = dp.entries[0].raw[p];
    CHECK((rs.S - rp.S).cwiseAbs().maxCoeff() < 1e-14);
    CHECK((rs.P - rp.P).cwiseAbs().maxCoeff() < 1e-14);  // P = F (S - S0)
    CHECK((rk.S.rowwise() - S0.transpose() - rp.S).cwiseAbs().maxCoeff() < 1e-14);
  }
}

TEST_CASE("sweep: a hand-edited checkpoint is refused on --resume, naming file and record",
          "[unit]") {
  // Issue 14: an edited job file used to be accepted. Every record carries a digest now.
  const auto dir = knit_test::scratch("sweep_unit_digest");
  const auto in = synthetic_input();
  const auto jobs = make_jobs(in);
  const auto out = dir / "db.h5";
  {
    CheckpointStore store(out, in.job_definition(), static_cast<int>(jobs.size()), false, false);
    for (int i : {0, 3})
      store.store(run_job(jobs[static_cast<std::size_t>(i)], in.retry, synthetic_runner()));
  }
  const auto file = CheckpointStore::parts_dir(out) / "job_00003.txt";
  {  // intact: both records load
    CheckpointStore store(out, in.job_definition(), static_cast<int>(jobs.size()), true, false);
    CHECK(store.load_finished(jobs).size() == 2);
  }
  std::string text;
  {
    std::ifstream f(file);
    std::stringstream s;
    s << f.rdbuf();
    text = s.str();
  }
  // change one stress value of the last data row (the kind of edit a user makes by hand)
  const auto row = text.rfind("\n0 ");
  REQUIRE(row != std::string::npos);
  const auto pos = text.find("0x1.", row + 3);
  REQUIRE(pos != std::string::npos);
  text[pos + 4] = text[pos + 4] == '8' ? '9' : '8';
  knit_test::write_text(file, text);
  std::atomic<int> calls{0};
  const PathRunner counting = [&](double l, const LoadPath& p) {
    ++calls;
    return synthetic_runner()(l, p);
  };
  auto ro = quiet(out);
  ro.resume = true;
  std::string msg;
  try {
    run_sweep(in, ro, counting);
  } catch (const knit::InputError& e) {
    msg = e.what();
  }
  CHECK(msg.find(file.string()) == 0);
  CHECK(msg.find("checkpoint record of job 3") != std::string::npos);
  CHECK(msg.find("digest mismatch") != std::string::npos);
  CHECK(calls == 0);  // refused before any work
  // a record without its digest line (older or truncated) is refused too
  knit_test::write_text(file, text.substr(0, text.rfind("digest ")));
  CheckpointStore store(out, in.job_definition(), static_cast<int>(jobs.size()), true, false);
  CHECK_THROWS_AS(store.load_finished(jobs), knit::InputError);
}

TEST_CASE("sweep: an infeasible fit is refused from the input, before any case runs", "[unit]") {
  // Issue 14: 3 steps for a cubic surface, only shear paths, too few paths -- each used to run
  // every case before the fit said so.
  namespace fit = knit::meso::fit;
  const fit::FitOptions cubic;
  CHECK(fit::check_feasible(cubic, knit::material::default_load_paths(20)).empty());
  CHECK(fit::check_feasible(cubic, knit::material::default_load_paths(20), 3).find("3 steps") !=
        std::string::npos);
  const auto all = knit::material::default_load_paths(6);
  CHECK(fit::check_feasible(cubic, {all[12]}).find("biaxial paths") != std::string::npos);
  CHECK(fit::check_feasible(cubic, {all[0], all[4], all[8], all[11]}).find("no pure-shear path") !=
        std::string::npos);
  // the fit refuses with the same words on the data (one function decides both)
  std::atomic<int> calls{0};
  const PathRunner counting = [&](double l, const LoadPath& p) {
    ++calls;
    return synthetic_runner()(l, p);
  };
  const auto dir = knit_test::scratch("sweep_unit_feasible");
  for (const std::string& text :
       {knit_test::synthetic_sweep_json(3),
        std::string(R"({"loop_lengths": [4.5], "steps": 6, "runner": "synthetic",
                        "load_paths": {"preset": "default", "select": [12]}})"),
        std::string(R"({"loop_lengths": [4.5], "steps": 6, "runner": "synthetic",
                        "load_paths": {"preset": "default", "select": [0, 6, 12]}})")}) {
    const SweepInput in = parse_sweep_input(text, "infeasible.json");
    std::string msg, ptr;
    try {
      run_sweep(in, quiet(dir / "db.h5"), counting);
    } catch (const knit::InputError& e) {
      msg = e.what();
      ptr = e.pointer();
    }
    CHECK(msg.rfind("infeasible.json: /load_paths: the response-surface fit cannot succeed", 0) ==
          0);
    CHECK(calls == 0);
  }
  CHECK_FALSE(std::filesystem::exists(CheckpointStore::parts_dir(dir / "db.h5")));
  // "fit": false runs the cases without a fit: no refusal
  const SweepInput nofit = parse_sweep_input(
      R"({"loop_lengths": [4.5], "steps": 3, "runner": "synthetic", "fit": false,
          "load_paths": {"preset": "default", "select": [12]}})",
      "nofit.json");
  CHECK_NOTHROW(run_sweep(nofit, quiet(dir / "nofit.h5"), counting));
  CHECK(calls == 1);
}

TEST_CASE("sweep: a sweep in which no case converged leaves the output as it was", "[unit]") {
  // Found with a loop length of 1 mm (too short for the cell's geometry): every case failed,
  // and the sweep replaced the database already at the output by one without a state.
  const auto dir = knit_test::scratch("sweep_unit_nothing");
  const auto out = dir / "db.h5";
  {
    std::ofstream f(out);
    f << "an earlier database";
  }
  const SweepReport r =
      run_sweep(synthetic_input(), quiet(out), [](double, const LoadPath&) -> PathOutcome {
        throw std::runtime_error("cell geometry: could not match the loop length");
      });
  CHECK_FALSE(r.wrote_database);
  CHECK(r.not_written.find("no case converged a single step") != std::string::npos);
  CHECK_FALSE(r.ok());
  CHECK(r.failed_cases() == static_cast<int>(r.results.size()));
  std::ifstream f(out);
  std::stringstream text;
  text << f.rdbuf();
  CHECK(text.str() == "an earlier database");
  CHECK_FALSE(std::filesystem::exists(out.string() + ".parts"));
}

TEST_CASE("sweep: a failing sweep keeps the database at the output and writes its own beside it",
          "[unit]") {
  // Session 38's red team: a sweep that failed (exit 1: a paper path did not converge, so the
  // loop length was not fitted) replaced a working database with one knit-macro cannot use.
  const auto dir = knit_test::scratch("sweep_unit_failing");
  const auto out = dir / "db.h5";
  const PathRunner failing = [](double l, const LoadPath& path) -> PathOutcome {
    if (path.set == "paper" && path.kind == knit::material::PathKind::kShear)
      throw std::runtime_error("the cell did not converge");
    return synthetic_runner()(l, path);
  };
  CHECK(failed_database_path(out) == dir / "db.failed.h5");
  CHECK(failed_database_path(dir / "db") == dir / "db.failed");
  {  // No database at the output: the failing sweep's goes there (its status for the diagnosis).
    const SweepReport r = run_sweep(synthetic_input(), quiet(out), failing);
    CHECK_FALSE(r.ok());
    CHECK(r.wrote_database);
    CHECK(r.written == out);
  }
  const SweepReport good = run_sweep(synthetic_input(), quiet(out), synthetic_runner());
  REQUIRE(good.ok());
  const auto bytes = [](const std::filesystem::path& f) {
    std::ifstream in(f, std::ios::binary);
    std::stringstream t;
    t << in.rdbuf();
    return t.str();
  };
  const std::string earlier = bytes(out);
  const SweepReport r = run_sweep(synthetic_input(), quiet(out), failing);
  CHECK_FALSE(r.ok());
  CHECK(r.failed_cases() > 0);
  CHECK(r.wrote_database);
  CHECK(r.written == dir / "db.failed.h5");
  CHECK(bytes(out) == earlier);
  CHECK(knit::material::read_database(dir / "db.failed.h5", false).entries.size() == 2);
  // A successful sweep replaces the output again.
  CHECK(run_sweep(synthetic_input(), quiet(out), synthetic_runner()).written == out);
}

TEST_CASE("sweep synthetic runner: a loop length whose stand-in stress overflows is an input error",
          "[unit]") {
  // Before: a loop length of 1e-320 mm ran every case and failed at the database write (exit 1,
  // naming a raw dataset; the checkpoints kept for a --resume that failed again). The stand-in's
  // stiffness is (4.5 / l)^2 MPa; the default paths stay within |E_ij| <= 1 and |F_ij| below
  // 1.5 or so, where S22 = 13.1 k and |P| up to 2 |F| |S|: at 5e-4 mm ~1.06e9 MPa and more,
  // above the 1e9 a database holds; at 2e-3 mm ~2e8.
  SweepInput in =
      parse_sweep_input(R"({"loop_lengths": [4.5, 6.5], "runner": "synthetic"})", "synth.json");
  CHECK_NOTHROW(make_runner(in));
  in.loop_lengths = {2e-3, 4.5};
  CHECK_NOTHROW(make_runner(in));
  for (double tiny : {5e-4, 1e-320}) {
    in.loop_lengths = {4.5, tiny};
    CHECK_THROWS_WITH(make_runner(in),
                      Catch::StartsWith("synth.json: /loop_lengths/1: the synthetic stand-in's"));
  }
  // A gradient path to F = [[3, 2], [2, 3]] reaches E_ij = 6 (review of session 30: judged at
  // E_ij = 2, 2e-3 mm passed and failed at the database write with ~1.3e10 MPa).
  in.loop_lengths = {2e-3, 4.5};
  knit::material::LoadPath g;
  g.kind = knit::material::PathKind::kGradient;
  g.H << 2.0, 2.0, 2.0, 2.0;
  g.steps = 4;
  in.paths.push_back(g);
  CHECK_THROWS_WITH(make_runner(in), Catch::Contains("at |E_ij| = 6, |F_ij| = 3 along the paths"));
  // ... and P = F S: at 0.01 mm S stays below 1e9 there (~5.3e8), but P reached 1.9e9, written
  // by the sweep and refused by the reader (review of session 30).
  in.loop_lengths = {0.01, 4.5};
  CHECK_THROWS_WITH(make_runner(in), Catch::StartsWith("synth.json: /loop_lengths/0:"));
}

TEST_CASE("sweep database: the residual is subtracted from the converged steps only", "[unit]") {
  // subtract_residual (docs/sweep.md): S -= S0 and P = F S at every converged step; a step that
  // did not converge is no data and keeps what the run left (session 33, a helper's audit:
  // subtracting on every step passed the suite). S0 = (S11, S22, S12) = (1, 2, 0.5) MPa.
  SweepInput in = synthetic_input();
  const auto jobs = make_jobs(in);
  std::vector<JobResult> results;
  for (const auto& j : jobs) {
    results.push_back(run_job(j, in.retry, synthetic_runner()));
    results.back().residual = Eigen::Vector3d(1.0, 2.0, 0.5);
  }
  JobResult& r = results.at(1);
  REQUIRE(r.raw.status.size() >= 3);
  r.raw.status[2] = kStepFailed;  // step 2 did not converge: its numbers are not data
  in.subtract_residual = false;
  const knit::material::Database plain = assemble_database(in, results);
  in.subtract_residual = true;
  const knit::material::Database sub = assemble_database(in, results);
  const auto& a = plain.entries.at(0).raw.at(1);
  const auto& b = sub.entries.at(0).raw.at(1);
  REQUIRE(a.steps() == b.steps());
  for (int k = 0; k < a.steps(); ++k) {
    INFO("step " << k);
    if (k == 2) {
      CHECK((b.S.row(k) - a.S.row(k)).norm() == 0.0);
      CHECK((b.P.row(k) - a.P.row(k)).norm() == 0.0);
      continue;
    }
    CHECK((a.S.row(k) - b.S.row(k) - Eigen::RowVector3d(1.0, 2.0, 0.5)).norm() < 1e-14);
    Eigen::Matrix2d F, S;
    F << b.F(k, 0), b.F(k, 1), b.F(k, 2), b.F(k, 3);
    S << b.S(k, 0), b.S(k, 2), b.S(k, 2), b.S(k, 1);
    const Eigen::Matrix2d P = F * S;
    CHECK((Eigen::RowVector4d(P(0, 0), P(0, 1), P(1, 0), P(1, 1)) - b.P.row(k)).norm() < 1e-13);
  }
}

TEST_CASE("sweep: shortened cuts long texts, never inside a UTF-8 sequence", "[unit]") {
  using knit::meso::sweep::shortened;
  CHECK(shortened("abc", 60) == "abc");
  CHECK(shortened(std::string(10, 'a'), 8) == "aaaaa...");
  // "é" is two bytes (0xC3 0xA9): a cut after 5 bytes of "aaaaé..." would split it.
  const std::string e = "\xC3\xA9";
  CHECK(shortened("aaaa" + e + e + e, 8) == "aaaa...");
  CHECK(shortened("aaa" + e + e + e, 8) == "aaa" + e + "...");
}
