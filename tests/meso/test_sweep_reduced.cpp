// The reduced sweep on the real unit cell, end to end (issue #7): cases/sweep/reduced.json
// (one loop length, 5 load cases, 6 steps) -> homogenization (eqs. 8-9) -> fit (eq. 17) ->
// a database that the macroscale reads (read_database without raw data, the loop-length
// family of eq. 25) and whose law reproduces the homogenized data.
#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>

#include "knit/material/database.hpp"
#include "knit/material/response_surface.hpp"
#include "knit/meso/sweep/mpi.hpp"
#include "test_sweep_util.hpp"

using namespace knit::material;

TEST_CASE("reduced sweep on the unit cell: cell -> fit -> database the macroscale reads",
          "[case]") {
  const auto dir = knit_test::scratch("sweep_reduced");
  const auto db_file = dir / "reduced.h5";
  const std::string cmd = std::string(KNIT_BIN_DIR) + "/knit-meso sweep " + KNIT_SOURCE_DIR +
                          "/cases/sweep/reduced.json --output " + db_file.string() +
                          " --threads 2 > " + (dir / "log.txt").string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  REQUIRE(WIFEXITED(rc));
  REQUIRE(WEXITSTATUS(rc) == 0);

  const Database db = read_database(db_file);
  CHECK(db.generator == "sweep");
  REQUIRE(db.entries.size() == 1);
  const LoopLengthEntry& e = db.entries[0];
  CHECK(e.loop_length == 4.5);
  // Sect. 3.1.1: the 4.5 mm cell is 1.26 mm x 0.88 mm, t = 2d
  CHECK(e.cell.wale_width == Approx(1.26).margin(1e-9));
  CHECK(e.cell.course_height == Approx(0.88).margin(1e-9));
  CHECK(e.cell.thickness == Approx(0.76).margin(1e-12));
  // 5 paper paths (6 steps) + one path of each new kind (issue 11: uniaxial, coverage biaxial,
  // gradient, held-out gradient; 4 steps)
  REQUIRE(e.raw.size() == 9);
  double srange = 0;
  for (const RawPath& r : e.raw) {
    const int n = r.path.set == "paper" ? 6 : 4;
    REQUIRE(r.steps() == n);
    for (int k = 0; k < n; ++k) {
      CHECK(r.status[static_cast<std::size_t>(k)] == 0);
      // F* as prescribed by the shared load-path definition; E from F exactly (eq. 9)
      const Eigen::Matrix2d F = deformation_gradient(r.path, (k + 1.0) / n);
      if (r.path.kind == PathKind::kUniaxial) {  // lateral stretch found: S11 = 0 (1e-4 MPa)
        CHECK(std::abs(r.F(k, 3) - F(1, 1)) < 1e-12);
        CHECK(std::abs(r.S(k, 0)) <= 1e-4);
        continue;
      }
      CHECK(std::abs(r.F(k, 0) - F(0, 0)) + std::abs(r.F(k, 1) - F(0, 1)) +
                std::abs(r.F(k, 3) - F(1, 1)) <
            1e-12);
      const Eigen::Matrix2d E = green_lagrange(F);
      CHECK(std::abs(r.E(k, 0) - E(0, 0)) < 1e-12);
      CHECK(std::abs(r.E(k, 2) - E(0, 1)) < 1e-12);
      srange = std::max(srange, r.S.row(k).cwiseAbs().maxCoeff());
    }
  }
  // Uniaxial-ish tension along the course (path 0: E = (0.35, -0.15)) pulls: S11 > 0.
  CHECK(e.raw[0].S(5, 0) > 0);
  // Wale tension (path 11 of the defaults: E = (-0.15, 0.35)): S22 > 0.
  CHECK(e.raw[3].S(5, 1) > 0);
  // Pure shear (eq. 7): E11 = E22 = 0 and E12 = sin(gamma)/2 exactly; S12 > 0.
  const RawPath& sh = e.raw[4];
  CHECK(sh.path.kind == PathKind::kShear);
  CHECK(std::abs(sh.E(5, 0)) < 1e-12);
  CHECK(std::abs(sh.E(5, 2) - 0.5 * std::sin(sh.path.target(0))) < 1e-12);
  CHECK(sh.S(5, 2) > 0);

  // Fitted, and the law reproduces the homogenized data at the data strains.
  REQUIRE(e.surface.has_value());
  const ResponseSurface law(*e.surface);
  double err = 0;
  for (int p = 0; p < 4; ++p)
    for (int k = 2; k < 6; ++k) {
      const auto& r = e.raw[static_cast<std::size_t>(p)];
      const auto ev = law.evaluate({r.E(k, 0), r.E(k, 1), 0.0});
      err =
          std::max(err, (ev.S.head<2>() - r.S.row(k).head<2>().transpose()).cwiseAbs().maxCoeff());
    }
  INFO("max stress error " << err << " MPa of a range of " << srange << " MPa");
  CHECK(err < 0.05 * srange);

  // What knit-macro loads: the fitted laws without the raw data, as a loop-length family.
  const Database macro = read_database(db_file, false);
  const LoopLengthFamily fam = macro.family();
  CHECK(fam.loop_lengths() == std::vector<double>{4.5});
  const ResponseSurface at(fam.at(4.5));
  const auto ev = at.evaluate({0.1, 0.0, 0.0});
  CHECK(std::isfinite(ev.S(0)));
  CHECK(ev.C(0, 0) > 0);  // stiff in tension

  // Under MPI (2 ranks, one thread each) the same database to 1e-12: the cell runs are
  // deterministic and independent of where they run.
  if (!knit::meso::sweep::MpiSession::compiled() ||
      std::system("command -v mpirun > /dev/null 2>&1") != 0) {
    WARN("MPI or mpirun missing: the 2-rank reduced sweep is skipped");
    return;
  }
  const auto mpi_file = dir / "reduced_mpi.h5";
  const std::string mcmd = "mpirun --allow-run-as-root --oversubscribe -np 2 " +
                           std::string(KNIT_BIN_DIR) + "/knit-meso sweep " + KNIT_SOURCE_DIR +
                           "/cases/sweep/reduced.json --output " + mpi_file.string() +
                           " --threads 1 > " + (dir / "mpi.txt").string() + " 2>&1";
  const int mrc = std::system(mcmd.c_str());
  REQUIRE(WIFEXITED(mrc));
  REQUIRE(WEXITSTATUS(mrc) == 0);
  CHECK(knit_test::database_difference(db, read_database(mpi_file)) <= 1e-12);
}
