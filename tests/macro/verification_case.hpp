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

/// A 10 x 10 St. Venant-Kirchhoff square (t = 1, E = 1, nu = 0; z held, x on the edge u = 0, y
/// at one corner) whose edge u = 1 is moved by -5 in 10 load steps: a uniform compression to
/// the stretch s = 0.5, past the uniaxial limit point s = 1/sqrt(3) (load factor 0.845), so
/// the tangents of the last steps are indefinite. `degree` and `elements` x `elements` of the
/// refinement.
inline nlohmann::json compressed_square(int degree, int elements) {
  nlohmann::json j = nlohmann::json::parse(R"({
    "geometry": {"degrees": [1, 1], "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
                 "control_points": [[0, 0, 0], [10, 0, 0], [0, 10, 0], [10, 10, 0]],
                 "thickness": 1.0},
    "material": {"type": "saint_venant_kirchhoff", "youngs_modulus": 1.0, "poisson_ratio": 0.0},
    "boundary_conditions": [{"all": true, "fix": ["z"]}, {"edge": "u0", "fix": ["x"]},
                            {"corner": "u0v0", "fix": ["y"]},
                            {"edge": "u1", "prescribe": {"x": -5.0}}],
    "loads": [], "solver": {"steps": 10},
    "output": {"vtk": false, "reactions": [{"name": "Fx", "edge": "u0", "component": "x"}]}})");
  j["refinement"] = {{"degree", degree}, {"elements", {elements, elements}}};
  return j;
}

}  // namespace knit::macro::test
