// The whole chain through the only contract between the two executables (issue #7): the
// reduced mesoscale sweep (cases/sweep/reduced.json: one loop length, 5 paper load cases, 6 steps,
// plus 4 issue-11 paths, real unit cell with contact) writes a material database, and knit-macro
// runs the paper's wale-wise tensile case (Sect. 3.1.2, l = 4.5 mm) on it, reduced to 10 % strain
// in 4 steps. Checks: both executables succeed, the load is positive and grows with the strain, and
// the patch's centre moves by half the jaw displacement (symmetry of the uniform patch).
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../output_test_util.hpp"
#include "knit/io/hdf5.hpp"

namespace fs = std::filesystem;

namespace {

int run(const std::string& cmd) {
  const int rc = std::system((cmd + " > /dev/null 2>&1").c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

}  // namespace

TEST_CASE("reduced sweep database drives a knit-macro tensile case", "[case][chain]") {
  const fs::path bin = KNIT_BIN_DIR;
  const fs::path dir = fs::path(KNIT_BINARY_DIR) / "test_tmp" / "chain_sweep_macro";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path db = dir / "reduced.h5";
  REQUIRE(run((bin / "knit-meso").string() + " sweep " + KNIT_SOURCE_DIR +
              "/cases/sweep/reduced.json --output " + db.string() +
              " --threads 2 --plain --force") == 0);
  REQUIRE(fs::exists(db));

  nlohmann::json c;
  std::ifstream(fs::path(KNIT_SOURCE_DIR) / "cases/paper/s312_uniform_45_wale.json") >> c;
  c["material"]["database"] = db.string();
  c["solver"]["steps"] = 4;
  c["output"]["grid"] = {11, 11};
  for (auto& bc : c["boundary_conditions"])
    if (bc.contains("prescribe")) bc["prescribe"]["y"] = 5.0;  // 10 % of L = 50 mm
  const fs::path case_file = dir / "tensile.json";
  std::ofstream(case_file) << c.dump(2);
  const fs::path out = dir / "out";
  REQUIRE(run((bin / "knit-macro").string() + " run " + case_file.string() + " --output " +
              out.string()) == 0);

  const auto rows = knit_test::read_csv(out / "load_strain.csv");
  REQUIRE(rows.size() >= 1 + 4);  // header and one row per converged step
  const auto& header = rows.front();
  auto col = [&](const std::string& name) {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    FAIL("no column " << name << " in load_strain.csv");
    return -1;
  };
  const int load = col("load_N"), strain = col("strain"), cy = col("center_uy_mm");
  double previous = 0.0;
  for (std::size_t r = 1; r < rows.size(); ++r) {
    if (std::stod(rows[r][strain]) == 0.0) continue;  // the reference state, if written
    const double f = std::stod(rows[r][load]);
    CHECK(f > previous);  // tension, stiffening or not, grows monotonically
    previous = f;
  }
  CHECK(std::stod(rows.back()[strain]) == Approx(0.10).epsilon(1e-9));
  CHECK(std::stod(rows.back()[cy]) == Approx(2.5).epsilon(1e-6));
  // results.h5 names the database and when it was written (session 38: the report refuses
  // results of another database by this date).
  {
    const auto h5 = knit::io::H5File::open_read(out / "results.h5");
    const auto dbf = knit::io::H5File::open_read(db);
    CHECK(h5.attribute_string(".", "material_database") == db.string());
    CHECK(!dbf.attribute_string(".", "date_utc").empty());
    CHECK(h5.attribute_string(".", "material_database_date_utc") ==
          dbf.attribute_string(".", "date_utc"));
  }
  fs::remove_all(dir);
}
