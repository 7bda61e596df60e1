// Bounded, deterministic fuzzing of the material database reader (issue 14): 2,000 mutants of
// a small database file (bit flips, truncations, random and zeroed blocks, inserted bytes)
// must each either load or throw knit::InputError: no other exception, no crash, no hang.
// Longer coverage-guided runs: the libFuzzer target tests/fuzz/ (docs/io.md).
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fuzz_mutate.hpp"
#include "knit/core/errors.hpp"
#include "knit/material/database.hpp"
#include "test_material_util.hpp"

namespace fs = std::filesystem;
using namespace knit::material;

TEST_CASE("fuzz: mutated database files load or throw InputError", "[unit][fuzz]") {
  const fs::path dir =
      fs::path(KNIT_BINARY_DIR) / "test_tmp" / ("fuzz_db_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Database db = testing::make_test_database("{\"a\": 1}");
  LoopLengthEntry e = testing::make_test_entry(5.0);
  for (const auto& p : default_load_paths(2)) {
    RawPath r;
    r.path = p;
    r.F = RowMatrixX::Constant(2, 4, 1.5);
    r.F.col(1).setZero();  // F = 1.5 I: det F > 0, as the reader requires of a converged step
    r.F.col(2).setZero();
    r.P = RowMatrixX::Constant(2, 4, 0.25);
    testing::set_strain_and_stress(r);  // E and S of F and P (eq. 9)
    r.status = {0, 1};
    e.raw.push_back(r);
  }
  e.surface = testing::make_test_surface(1.0);
  e.diagnostics.options_json = "{}";
  db.entries.push_back(e);
  const fs::path seed_file = dir / "seed.h5";
  write_database(seed_file, db);
  std::string seed;
  {
    std::ifstream in(seed_file, std::ios::binary);
    seed.assign(std::istreambuf_iterator<char>(in), {});
  }
  REQUIRE_NOTHROW(read_database(seed_file));

  const int kInputs = knit::testing::fuzz_inputs();
  knit::testing::Mutator mut(1130);
  int loaded = 0, refused = 0;
  std::vector<std::string> failures;
  const fs::path file = dir / "mutant.h5";
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < kInputs; ++k) {
    const knit::testing::Mutant m = mut.binary(seed);
    std::ofstream(file, std::ios::binary | std::ios::trunc) << m.data;
    try {
      read_database(file, k % 2 == 0);
      ++loaded;
    } catch (const knit::InputError&) {
      ++refused;
    } catch (const std::exception& ex) {
      failures.push_back("input " + std::to_string(k) + " (" + m.how + "): " + ex.what());
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(kInputs << " mutants of " << seed.size() << " bytes in " << s << " s: " << loaded
               << " loaded, " << refused << " refused");
  for (std::size_t i = 0; i < std::min<std::size_t>(failures.size(), 10); ++i)
    UNSCOPED_INFO(failures[i]);
  CHECK(failures.empty());
  CHECK(refused > kInputs / 4);
  std::error_code ec;
  fs::remove_all(dir, ec);
}
