// The energy law's own uniaxial response beside the cell's: knit/material/uniaxial_curve.hpp.
#include "knit/material/uniaxial_curve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace knit::material {

UniaxialDeviation uniaxial_deviation(const UniaxialCurve& c, double max_strain, double min_share) {
  UniaxialDeviation d;
  const std::size_t n = std::min({c.strain.size(), c.cell.size(), c.law.size()});
  double smax = 0.0;
  for (std::size_t i = 0; i < n; ++i) smax = std::max(smax, std::abs(c.cell[i]));
  if (!(smax > 0.0)) return d;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(c.strain[i] <= max_strain) || !(std::abs(c.cell[i]) >= min_share * smax)) continue;
    ++d.states;
    const double ratio = c.law[i] / c.cell[i];
    const double dev =
        std::isfinite(ratio) ? std::abs(ratio - 1.0) : std::numeric_limits<double>::infinity();
    if (d.states == 1 || dev > d.deviation) {
      d.deviation = dev;
      d.ratio = std::isfinite(ratio) ? ratio : std::nan("");
      d.strain = c.strain[i];
    }
  }
  return d;
}

}  // namespace knit::material
