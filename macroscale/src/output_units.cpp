#include "knit/macro/output_units.hpp"

#include <algorithm>
#include <set>

#include "knit/io/names.hpp"

namespace knit::macro {

UnitLabels unit_labels(const std::string& declared) {
  UnitLabels u;
  // The parts between commas, every blank removed (as the knit material's check of /units).
  std::vector<std::string> parts(1);
  bool control = false;
  for (const char ch : declared) {
    if (ch == ',')
      parts.emplace_back();
    else if (ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r' || ch == '\v' || ch == '\f')
      continue;
    else {
      control = control || io::is_control_character(ch);
      parts.back() += ch;
    }
  }
  if (declared.empty() || parts == std::vector<std::string>{"mm", "N", "MPa"}) return u;
  u.root = declared;
  const bool three = !control && parts.size() == 3 &&
                     std::none_of(parts.begin(), parts.end(), [](const std::string& p) {
                       return p.empty() || p.find('"') != std::string::npos;
                     });
  if (three) {
    u.length = parts[0];
    u.force = parts[1];
    u.stress = parts[2];
  } else {
    u.length = u.force = u.stress = "";
  }
  return u;
}

std::string UnitLabels::of(const std::string& mm_unit) const {
  if (mm_unit != "mm" && mm_unit != "1/mm" && mm_unit != "N/mm" && mm_unit != "N" &&
      mm_unit != "MPa")
    return mm_unit;  // dimensionless, rad, s
  if (length.empty()) return "in the case's units (/units: " + root + ")";
  if (mm_unit == "mm") return length;
  if (mm_unit == "1/mm") return "1/" + length;
  if (mm_unit == "N/mm") return force + "/" + length;
  if (mm_unit == "N") return force;
  return stress;
}

std::string UnitLabels::suffix(const std::string& mm_unit) const {
  if (length.empty()) return "";
  return "_" + of(mm_unit);
}

std::vector<std::string> load_strain_columns(const Case& c) {
  const UnitLabels u = unit_labels(c.units);
  const std::string L = u.suffix("mm"), F = u.suffix("N");
  std::vector<std::string> header = {"step", "load_factor"};
  if (c.output.applied) header.insert(header.end(), {"applied_displacement" + L, "strain"});
  for (const ReactionOutput& r : c.output.reactions) header.push_back(r.name + F);
  for (const OutputPoint& p : c.output.points)
    header.insert(header.end(), {p.name + "_ux" + L, p.name + "_uy" + L, p.name + "_uz" + L});
  header.insert(header.end(),
                {"iterations", "residual", "seconds", "negative_pivots", "determinant_sign"});
  return header;
}

std::string repeated_load_strain_column(const Case& c) {
  std::set<std::string> seen;
  for (const std::string& h : load_strain_columns(c))
    if (!seen.insert(h).second) return h;
  return "";
}

}  // namespace knit::macro
