// Internal to the energy-law fits (fit_energy.cpp: ridge family and the shared front end;
// fit_network.cpp: network family): the data points and the network fit's entry point.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "knit/meso/fit/energy_fit.hpp"

namespace knit::meso::fit::detail {

struct Point {
  Eigen::Vector3d e, S;  // Voigt strain, stress
  double l;
  std::size_t loop;   // entry index
  double set_weight;  // weight_uniaxial / weight_shear / weight_paper / 1 (see EnergyFitOptions)
  int axis = -1;      // a state of a uniaxial-stress path: its axis (0 course, 1 wale); else -1
};

/// The stress range of each loop length (entry index 0..loops-1): the largest max - min of a
/// stress component over its points (MPa; 0 without points). The diagnostics' range, the
/// denominator of the "% of the stress range" errors, and the network fit's tube width.
std::vector<double> stress_ranges(const std::vector<Point>& pts, std::size_t loops);

/// Fits law.network (law.floor, l_min, l_max, box already set) to the points, with the
/// squared-residual weights `weight` (one per point), stress scale sS and strain scale sE.
/// Returns the reason on failure (empty on success); `iterations` counts L-BFGS iterations (of
/// every start), `objective` is the kept start's final objective and `seed` its seed.
std::string fit_network(material::EnergyLawData& law, const std::vector<double>& loop_lengths,
                        const std::vector<Point>& pts, const std::vector<double>& weight, double sS,
                        double sE, const EnergyFitOptions& o, int& iterations, double& objective,
                        int& seed);

}  // namespace knit::meso::fit::detail
