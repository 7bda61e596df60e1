// Bounded, deterministic fuzzing of the case loader (issue 14): 2,000 mutants of the case
// files in cases/ (byte flips, truncations, deep nesting, huge numbers, type swaps, duplicated
// keys) must each either load or throw knit::InputError: no other exception, no crash, no
// hang. Loading only (parse_case: JSON, schema, geometry, refinement, material, database) —
// no solve. Longer coverage-guided runs: the libFuzzer target tests/fuzz/ (docs/io.md).
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../common/fuzz_mutate.hpp"
#include "../common/test_material_util.hpp"
#include "knit/core/errors.hpp"
#include "knit/macro/case.hpp"
#include "knit/material/database.hpp"

namespace fs = std::filesystem;

namespace {
std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The paper's cases read "../../out/database.h5": a small fitted database put there.
fs::path fuzz_root() {
  const fs::path root =
      fs::path(KNIT_BINARY_DIR) / "test_tmp" / ("fuzz_case_" + std::to_string(::getpid()));
  fs::create_directories(root / "cases" / "paper");
  fs::create_directories(root / "out");
  knit::material::write_database(root / "out" / "database.h5",
                                 knit::material::testing::make_test_law_database());
  return root;
}
}  // namespace

TEST_CASE("fuzz: mutated case files load or throw InputError", "[unit][fuzz]") {
  const fs::path root = fuzz_root();
  struct Seed {
    std::string text, label;
  };
  std::vector<Seed> seeds;
  for (const char* dir : {"verification", "paper"})
    for (const auto& e : fs::directory_iterator(fs::path(KNIT_SOURCE_DIR) / "cases" / dir))
      if (e.path().extension() == ".json")
        seeds.push_back(
            {slurp(e.path()), (root / "cases" / "paper" / e.path().filename()).string()});
  std::sort(seeds.begin(), seeds.end(),
            [](const Seed& a, const Seed& b) { return a.label < b.label; });
  REQUIRE(seeds.size() >= 5);
  for (const Seed& s : seeds) CHECK_NOTHROW(knit::macro::parse_case(s.text, s.label));

  const int kInputs = knit::testing::fuzz_inputs();
  knit::testing::Mutator mut(20261130);
  int loaded = 0, refused = 0;
  std::vector<std::string> failures;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < kInputs; ++k) {
    const Seed& seed = seeds[static_cast<std::size_t>(k) % seeds.size()];
    const knit::testing::Mutant m = mut.json_text(seed.text);
    try {
      knit::macro::parse_case(m.data, seed.label);
      ++loaded;
    } catch (const knit::InputError&) {
      ++refused;
    } catch (const std::exception& e) {
      failures.push_back("input " + std::to_string(k) + " (" + seed.label + ", " + m.how +
                         "): " + typeid(e).name() + ": " + e.what());
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(kInputs << " mutants in " << s << " s: " << loaded << " loaded, " << refused << " refused");
  for (std::size_t i = 0; i < std::min<std::size_t>(failures.size(), 10); ++i)
    UNSCOPED_INFO(failures[i]);
  CHECK(failures.empty());
  CHECK(refused > kInputs / 4);  // the mutations do reach the checks
  std::error_code ec;
  fs::remove_all(root, ec);
}
