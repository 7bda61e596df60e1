#include "knit/macro/load_drop.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace knit::macro {

std::vector<LoadDrop> find_load_drops(const Case& c, const std::vector<StepRow>& rows,
                                      double tolerance) {
  std::vector<LoadDrop> drops;
  if (!c.output.applied || rows.size() < 2) return drops;
  for (size_t r = 0; r < c.output.reactions.size(); ++r) {
    if (c.output.reactions[r].component != c.output.applied->component) continue;
    // The load's direction: the sign of its largest value. A drop is a fall of the load along
    // it, F_k - F_k+1 times that sign: the magnitude |F_k| - |F_k+1| took a change of sign for
    // a rise (session 39's walkthrough: 0.146 -> -0.530 N was not named, and -0.508 -> 0.148 N
    // was called a fall "from -0.5077 to 0.1477").
    double max_load = 0.0, sign = 0.0;
    for (const StepRow& row : rows)
      if (std::abs(row.reactions[r]) > max_load) {
        max_load = std::abs(row.reactions[r]);
        sign = row.reactions[r] > 0.0 ? 1.0 : -1.0;
      }
    LoadDrop d;
    d.reaction = c.output.reactions[r].name;
    d.max_load = max_load;
    d.direction = sign;
    for (size_t k = 0; k + 1 < rows.size(); ++k) {
      const double f0 = rows[k].reactions[r], f1 = rows[k + 1].reactions[r];
      const double drop = sign * (f0 - f1);
      if (!(drop > tolerance * max_load) || !(drop > c.solver.absolute_tolerance)) continue;
      if (++d.count == 1) d.first_from_step = rows[k].step, d.first_to_step = rows[k + 1].step;
      if (drop > d.largest) {
        d.largest = drop;
        d.from_step = rows[k].step, d.to_step = rows[k + 1].step;
        d.from_load = f0, d.to_load = f1;
        d.from_strain = rows[k].strain, d.to_strain = rows[k + 1].strain;
      }
    }
    if (d.count > 0) drops.push_back(d);
  }
  return drops;
}

std::string load_drop_message(const LoadDrop& d, double tolerance, const std::string& force) {
  const std::string N = " " + force;
  std::ostringstream m;
  m.precision(4);
  m << "load drop: reaction '" << d.reaction << "' falls from " << d.from_load << " to "
    << d.to_load << N << " (by " << d.largest << N;
  if (d.direction < 0.0) m << " along its largest load, " << -d.max_load << N;
  m << "; " << 100.0 * d.largest / d.max_load << " % of its largest " << d.max_load << N
    << ") between step " << d.from_step << " (strain " << d.from_strain << ") and step "
    << d.to_step << " (strain " << d.to_strain << ") while the applied displacement grows";
  // Which drop is named (session 39's walkthrough had to read the header to learn it is the
  // largest), and where the first one was.
  if (d.count > 1)
    m << "; the largest of " << d.count << " drops in all, the first between step "
      << d.first_from_step << " and step " << d.first_to_step;
  m << " (threshold " << tolerance
    << " x the largest load). A tensile test's load does not fall: a snap of the material "
       "law or a lost stability (summary.txt's stability line tells the second)";
  return m.str();
}

}  // namespace knit::macro
