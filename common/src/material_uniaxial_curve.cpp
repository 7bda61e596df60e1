// The energy law's own uniaxial response beside the cell's: knit/material/uniaxial_curve.hpp.
#include "knit/material/uniaxial_curve.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace knit::material {

UniaxialDeviation uniaxial_deviation(const UniaxialCurve& c, double max_strain, double min_share) {
  UniaxialDeviation d;
  const std::size_t n = std::min({c.strain.size(), c.cell.size(), c.law.size()});
  // The states up to max_strain, and the curve interpolated at max_strain when it lies
  // between two of them (a run that ends between the cell's steps).
  std::vector<std::array<double, 3>> kept;
  for (std::size_t i = 0; i < n; ++i) {
    if (c.strain[i] <= max_strain) {
      kept.push_back({c.strain[i], c.cell[i], c.law[i]});
    } else {
      if (i > 0 && c.strain[i - 1] < max_strain) {
        const double t = (max_strain - c.strain[i - 1]) / (c.strain[i] - c.strain[i - 1]);
        kept.push_back({max_strain, (1 - t) * c.cell[i - 1] + t * c.cell[i],
                        (1 - t) * c.law[i - 1] + t * c.law[i]});
      }
      break;
    }
  }
  // The share is of the largest cell stress up to max_strain (session 41's review: of the
  // whole path's, it left out the states where a run that stops at E = 0.18 carries a law
  // 6-10 times the cell's).
  double smax = 0.0;
  for (const auto& s : kept) smax = std::max(smax, std::abs(s[1]));
  if (!(smax > 0.0)) return d;
  for (const auto& [strain, cell, law] : kept) {
    if (!(std::abs(cell) >= min_share * smax)) continue;
    ++d.states;
    const double ratio = law / cell;
    const double dev =
        std::isfinite(ratio) ? std::abs(ratio - 1.0) : std::numeric_limits<double>::infinity();
    if (d.states == 1 || dev > d.deviation) {
      d.deviation = dev;
      d.ratio = std::isfinite(ratio) ? ratio : std::nan("");
      d.strain = strain;
    }
  }
  return d;
}

}  // namespace knit::material
