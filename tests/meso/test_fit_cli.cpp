// knit-meso synth / fit from the command line: a raw-only synthetic database is refitted in
// place; bad options are input errors (exit 2) naming the file and the field.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "knit/material/database.hpp"

namespace fs = std::filesystem;

namespace {
int run(const std::string& args) {
  const std::string cmd = std::string(KNIT_BIN_DIR) + "/knit-meso " + args + " > /dev/null 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
}  // namespace

TEST_CASE("knit-meso synth --no-fit, then fit, refits from the raw data", "[unit]") {
  const fs::path dir = fs::path(KNIT_BINARY_DIR) / "test_tmp";
  fs::create_directories(dir);
  const fs::path db = dir / "cli_synth.h5";
  REQUIRE(run("synth --no-fit --loop-lengths 4.5,6.5 --out " + db.string()) == 0);
  auto raw = knit::material::read_database(db);
  REQUIRE(raw.entries.size() == 2);
  CHECK(!raw.entries[0].surface);
  CHECK(raw.entries[1].raw.size() == 13);
  const fs::path opts = dir / "cli_opts.json";
  std::ofstream(opts) << R"({"control_points_1": 9, "smoothing": 1e-6})";
  REQUIRE(run("fit " + db.string() + " --options " + opts.string()) == 0);
  const auto fitted = knit::material::read_database(db);
  REQUIRE(fitted.entries[0].surface);
  CHECK(fitted.entries[0].surface->n1() == 9);
  CHECK(fitted.entries[0].diagnostics.max_relative < 0.02);
  CHECK(fitted.entries[0].diagnostics.options_json.find("\"control_points_1\":9") !=
        std::string::npos);
  std::ofstream(opts) << R"({"loss": "l1"})";
  CHECK(run("fit " + db.string() + " --options " + opts.string()) == 2);
  CHECK(run("fit " + (dir / "missing.h5").string()) == 2);
}
