// The case files of cases/verification, read by the macroscale tests (one reader; session 32
// left four copies of it).
#pragma once

#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace knit::macro::test {

/// cases/verification/<name>, parsed; a missing file is an error naming it.
inline nlohmann::json verification_case(const std::string& name) {
  const std::string path = std::string(KNIT_SOURCE_DIR) + "/cases/verification/" + name;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  return nlohmann::json::parse(in);
}

}  // namespace knit::macro::test
