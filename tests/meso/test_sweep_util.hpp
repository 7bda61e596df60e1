// Helpers of the sweep tests: scratch directories, a small synthetic sweep input, database
// comparison.
#pragma once

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "knit/material/database.hpp"

namespace knit_test {

/// An empty scratch directory under the build tree.
inline std::filesystem::path scratch(const std::string& name) {
  const auto d = std::filesystem::path(KNIT_BINARY_DIR) / "test_scratch" / name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline void write_text(const std::filesystem::path& p, const std::string& s) {
  std::ofstream(p) << s;
}

/// A synthetic-runner sweep: 2 loop lengths x the 13 default cases x 6 steps, small fit. The
/// energy-based law is fitted with 100 network iterations (default 4,000): the tests of the
/// sweep compare raw data, response surfaces, checkpoints and outputs, never the law's
/// accuracy (tests/meso/test_fit_energy.cpp), and its fit was ~70 % of their time (~20 s each
/// under ASan + UBSan).
inline std::string synthetic_sweep_json(int steps = 6) {
  return R"({"description": "test", "loop_lengths": [4.5, 5.5], "steps": )" +
         std::to_string(steps) +
         R"(, "runner": "synthetic", "retry": {"max_retries": 1},
  "fit": {"control_points_1": 6, "control_points_2": 5, "shear_control_points": 5, "smoothing": 1e-6},
  "energy_fit": {"network_iterations": 100}})";
}

/// Largest difference of the raw data and fitted control points of two databases (they must
/// have the same structure; a structural difference is a test failure).
inline double database_difference(const knit::material::Database& a,
                                  const knit::material::Database& b) {
  REQUIRE(a.entries.size() == b.entries.size());
  double d = 0;
  for (std::size_t l = 0; l < a.entries.size(); ++l) {
    const auto &ea = a.entries[l], &eb = b.entries[l];
    REQUIRE(ea.loop_length == eb.loop_length);
    REQUIRE(ea.raw.size() == eb.raw.size());
    for (std::size_t p = 0; p < ea.raw.size(); ++p) {
      REQUIRE(ea.raw[p].status == eb.raw[p].status);
      d = std::max(d, (ea.raw[p].F - eb.raw[p].F).cwiseAbs().maxCoeff());
      d = std::max(d, (ea.raw[p].P - eb.raw[p].P).cwiseAbs().maxCoeff());
      d = std::max(d, (ea.raw[p].E - eb.raw[p].E).cwiseAbs().maxCoeff());
      d = std::max(d, (ea.raw[p].S - eb.raw[p].S).cwiseAbs().maxCoeff());
    }
    REQUIRE(ea.surface.has_value() == eb.surface.has_value());
    if (ea.surface) {
      const auto &sa = *ea.surface, &sb = *eb.surface;
      REQUIRE(sa.E_ctrl.rows() == sb.E_ctrl.rows());
      d = std::max(d, (sa.E_ctrl - sb.E_ctrl).cwiseAbs().maxCoeff());
      d = std::max(d, (sa.S_ctrl - sb.S_ctrl).cwiseAbs().maxCoeff());
      d = std::max(d, (sa.S12_ctrl - sb.S12_ctrl).cwiseAbs().maxCoeff());
    }
  }
  return d;
}

}  // namespace knit_test
