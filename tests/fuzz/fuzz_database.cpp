// libFuzzer target: bytes -> a file -> knit::material::read_database (with raw data).
//   build/fuzz/bin/fuzz_database -max_total_time=3600 -timeout=10 corpus/ seeds/
// Seeds: any small database, e.g. `knit-meso synth --out seeds/synth.h5 --steps 3`.
// An input must load or throw knit::InputError; any other exception aborts (a finding).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "knit/core/errors.hpp"
#include "knit/material/database.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("knit_fuzz_db_" + std::to_string(getpid()) + ".h5");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    knit::material::read_database(file, true);
  } catch (const knit::InputError&) {
  } catch (const std::exception& e) {
    std::cerr << "not an InputError: " << e.what() << "\n";
    std::abort();
  }
  return 0;
}
