// A fitted test database for the knit-material tests (the test law of test_material_util.hpp
// scaled by (4.5/l)^2 at each loop length), written to the build's test_tmp directory; with
// the synthetic stand-in's cell parameters (mesoscale/src/fit_synthetic.cpp) unless
// with_cells is false; with_energy adds the energy-based law of test_energy_util.hpp
// (4.5-6.5 mm), which the knit material then uses by default: the ridge family, or with
// energy_network the network family (knots 4.5, 5.5, 6.5 mm).
#pragma once

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "../common/test_energy_util.hpp"
#include "../common/test_material_util.hpp"
#include "knit/material/database.hpp"

namespace knit::testing {

/// Wale width and course height of the synthetic stand-in at loop length l (mm).
inline double synth_wale_width(double l) {
  return 1.26 + (l - 4.5) * (1.41 - 1.26) / 2.0;
}
inline double synth_course_height(double l) {
  return l * l / (18.27 * synth_wale_width(l));
}

inline std::string write_knit_test_database(const std::string& name,
                                            const std::vector<double>& loop_lengths,
                                            bool with_cells = true, bool with_energy = false,
                                            bool energy_network = false) {
  const std::filesystem::path dir = std::filesystem::path(KNIT_BINARY_DIR) / "test_tmp";
  std::filesystem::create_directories(dir);
  const std::filesystem::path f = dir / name;
  material::Database db;
  db.provenance = material::current_provenance();
  db.generator = "test";
  for (double l : loop_lengths) {
    material::LoopLengthEntry e;
    e.loop_length = l;
    if (with_cells) e.cell = {synth_wale_width(l), synth_course_height(l), 0.76};
    e.surface = material::testing::make_test_surface(std::pow(4.5 / l, 2));
    db.entries.push_back(e);
  }
  if (with_energy)
    db.energy_law = energy_network ? material::testing::make_test_network_law()
                                   : material::testing::make_test_energy_law();
  material::write_database(f, db);
  return f.string();
}

}  // namespace knit::testing
