// Layering (design/style.md habit 5): mesoscale and macroscale never include each other; the
// material database is their only contract. The build enforces it through per-target include
// directories; this test also catches relative includes that would sneak around them.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

namespace fs = std::filesystem;

namespace {
std::vector<std::string> offending_includes(const fs::path& dir, const std::regex& forbidden) {
  std::vector<std::string> hits;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const auto ext = entry.path().extension().string();
    if (ext != ".cpp" && ext != ".hpp" && ext != ".h" && ext != ".cc") continue;
    std::ifstream in(entry.path());
    std::string line;
    int lineno = 0;
    while (std::getline(in, line)) {
      ++lineno;
      if (line.find("#include") != std::string::npos && std::regex_search(line, forbidden))
        hits.push_back(entry.path().string() + ":" + std::to_string(lineno) + ": " + line);
    }
  }
  return hits;
}
}  // namespace

TEST_CASE("mesoscale and macroscale do not include each other", "[unit][layering]") {
  const fs::path root = KNIT_SOURCE_DIR;
  const auto meso_hits =
      offending_includes(root / "mesoscale", std::regex(R"(knit/macro/|macroscale/)"));
  const auto macro_hits =
      offending_includes(root / "macroscale", std::regex(R"(knit/meso/|mesoscale/)"));
  const auto common_hits = offending_includes(
      root / "common", std::regex(R"(knit/macro/|knit/meso/|macroscale/|mesoscale/)"));
  for (const auto& h : meso_hits) UNSCOPED_INFO(h);
  for (const auto& h : macro_hits) UNSCOPED_INFO(h);
  for (const auto& h : common_hits) UNSCOPED_INFO(h);
  CHECK(meso_hits.empty());
  CHECK(macro_hits.empty());
  CHECK(common_hits.empty());
}

TEST_CASE("macroscale includes Ceres in its design adapter only", "[unit][layering]") {
  // docs/design.md "The optimizer": the bounded least-squares solver of `knit-macro design`
  // is Ceres, seen by macroscale/src/design_ceres.cpp alone (as the fit files in mesoscale).
  const fs::path root = KNIT_SOURCE_DIR;
  const auto hits = offending_includes(root / "macroscale", std::regex(R"(<ceres/)"));
  for (const auto& h : hits) UNSCOPED_INFO(h);
  REQUIRE(hits.size() == 1);
  CHECK(hits[0].find("macroscale/src/design_ceres.cpp:") != std::string::npos);
}
