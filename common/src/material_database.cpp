// The in-memory side of the material database (the HDF5 side is material_database_io.cpp).
#include <algorithm>
#include <chrono>
#include <ctime>
#include <stdexcept>

#include "knit/core/build_info.hpp"
#include "knit/material/database.hpp"

namespace knit::material {

std::vector<double> Database::loop_lengths() const {
  std::vector<double> l;
  for (const auto& e : entries) l.push_back(e.loop_length);
  return l;
}

StrainDomain Database::domain() const {
  StrainDomain d;
  for (const auto& e : entries)
    for (const auto& r : e.raw)
      for (int k = 0; k < r.steps(); ++k) {
        if (r.status[k] != 0) continue;
        d.E11_min = std::min(d.E11_min, r.E(k, 0));
        d.E11_max = std::max(d.E11_max, r.E(k, 0));
        d.E22_min = std::min(d.E22_min, r.E(k, 1));
        d.E22_max = std::max(d.E22_max, r.E(k, 1));
        d.E12_max = std::max(d.E12_max, std::abs(r.E(k, 2)));
      }
  return d;
}

LoopLengthFamily Database::family() const {
  std::vector<double> l;
  std::vector<ResponseSurfaceData> laws;
  for (const auto& e : entries) {
    if (!e.surface)
      throw std::invalid_argument("loop length " + std::to_string(e.loop_length) +
                                  " mm has no fitted response surface (run knit-meso fit)");
    l.push_back(e.loop_length);
    laws.push_back(*e.surface);
  }
  return LoopLengthFamily(std::move(l), std::move(laws));
}

Provenance current_provenance() {
  Provenance p;
  p.software_version = project_version();
  p.git_revision = git_revision();
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  p.created = buf;
  return p;
}

}  // namespace knit::material
