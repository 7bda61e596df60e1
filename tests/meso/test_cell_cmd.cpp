// The `knit-meso cell` and `knit-meso path` commands end to end: files written, CSV columns
// consistent (pure shear: E11 = E22 = 0, E12 = sin(gamma)/2 per step), bad input exits with 2.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {
int run(const std::string& args) {
  const std::string cmd = std::string(KNIT_BIN_DIR) + "/knit-meso " + args + " > /dev/null 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> r;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) r.push_back(cell);
    rows.push_back(r);
  }
  return rows;
}
}  // namespace

TEST_CASE("knit-meso cell writes the geometry and its summary", "[unit]") {
  const std::string out = std::string(KNIT_BINARY_DIR) + "/test_cell_cmd_cell";
  fs::remove_all(out);
  REQUIRE(run("cell --loop-length 4.5 --out " + out) == 0);
  CHECK(fs::file_size(out + "/cell.vtp") > 1000);
  std::ifstream in(out + "/cell.json");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string js = ss.str();
  for (const char* key : {"\"w\"", "\"c\"", "\"measured_length\"", "\"min_clearance\"",
                          "\"crossings_with_next_course\"", "\"in_front\""})
    CHECK(js.find(key) != std::string::npos);
  CHECK(run("cell --loop-length -1 --out " + out) == 2);
}

TEST_CASE("knit-meso path: shear CSV rows and VTP files", "[unit]") {
  const std::string out = std::string(KNIT_BINARY_DIR) + "/test_cell_cmd_path";
  fs::remove_all(out);
  REQUIRE(run("path --loop-length 4.5 --shear 20 --steps 3 --elements 16 --out " + out) == 0);
  const auto rows = read_csv(out + "/path.csv");
  REQUIRE(rows.size() == 5);  // header + steps 0..3
  const auto& h = rows[0];
  auto col = [&](const std::string& name) {
    for (std::size_t i = 0; i < h.size(); ++i)
      if (h[i] == name) return i;
    FAIL("no column " << name);
    return std::size_t(0);
  };
  for (int k = 0; k <= 3; ++k) {
    const auto& r = rows[k + 1];
    const double g = 20.0 * M_PI / 180.0 * k / 3.0;
    CHECK(std::abs(std::stod(r[col("E11")])) < 1e-12);
    CHECK(std::abs(std::stod(r[col("E22")])) < 1e-12);
    CHECK(std::stod(r[col("E12")]) == Approx(0.5 * std::sin(g)).margin(1e-12));
  }
  CHECK(fs::exists(out + "/yarn_0003.vtp"));
  CHECK(fs::exists(out + "/yarn.pvd"));
  CHECK(run("path --loop-length 4.5 --out " + out) == 2);  // neither --biaxial nor --shear
}
