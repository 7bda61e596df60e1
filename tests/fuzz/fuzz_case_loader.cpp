// libFuzzer target: JSON text -> knit::macro::parse_case (loading only, no solve).
//   build/fuzz/bin/fuzz_case_loader -max_total_time=3600 -timeout=10 corpus/ cases/verification
// An input must load or throw knit::InputError; any other exception aborts (a finding).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <string>

#include "knit/core/errors.hpp"
#include "knit/macro/case.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // The label places the case in cases/verification (relative paths resolve from there).
    knit::macro::parse_case(text, KNIT_SOURCE_DIR "/cases/verification/fuzz.json");
  } catch (const knit::InputError&) {
  } catch (const std::exception& e) {
    std::cerr << "not an InputError: " << e.what() << "\n";
    std::abort();
  }
  return 0;
}
