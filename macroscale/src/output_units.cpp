#include "knit/macro/output_units.hpp"

#include <algorithm>
#include <cmath>
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

namespace {

/// Known symbols in SI (m, N, Pa).
struct KnownUnit {
  const char* symbol;
  int kind;  ///< 0 length, 1 force, 2 stress
  double si;
};
constexpr KnownUnit kKnownUnits[] = {{"m", 0, 1.0},
                                     {"cm", 0, 1e-2},
                                     {"mm", 0, 1e-3},
                                     {"um", 0, 1e-6},
                                     {"km", 0, 1e3},
                                     {"in", 0, 0.0254},
                                     {"ft", 0, 0.3048},
                                     {"N", 1, 1.0},
                                     {"mN", 1, 1e-3},
                                     {"kN", 1, 1e3},
                                     {"MN", 1, 1e6},
                                     {"lbf", 1, 4.4482216152605},
                                     {"Pa", 2, 1.0},
                                     {"kPa", 2, 1e3},
                                     {"MPa", 2, 1e6},
                                     {"GPa", 2, 1e9},
                                     {"psi", 2, 6894.757293168361},
                                     {"N/mm2", 2, 1e6},
                                     {"N/mm^2", 2, 1e6},
                                     {"N/m2", 2, 1.0},
                                     {"N/m^2", 2, 1.0}};

const KnownUnit* known_unit(const std::string& s) {
  for (const KnownUnit& u : kKnownUnits)
    if (s == u.symbol) return &u;
  return nullptr;
}

}  // namespace

std::string units_problem(const std::string& declared) {
  // Tabs are blanks, as in unit_labels; a line break or any other control character would go
  // into the outputs' labels (a CSV comment, HDF5 attributes).
  if (std::any_of(declared.begin(), declared.end(),
                  [](char ch) { return ch != '\t' && io::is_control_character(ch); }))
    return "a control character in the units (they label every output): give printable text";
  const UnitLabels u = unit_labels(declared);
  if (u.length.empty()) return {};
  static const char* const kKinds[] = {"length", "force", "stress"};
  const std::string symbols[3] = {u.length, u.force, u.stress};
  const KnownUnit* known[3];
  for (int k = 0; k < 3; ++k) {
    known[k] = known_unit(symbols[k]);
    if (known[k] && known[k]->kind != k)
      return std::string("\"L, F, S\" gives the length, force and stress units in this order; \"") +
             symbols[k] + "\" is a " + kKinds[known[k]->kind] + " unit, given as the " + kKinds[k];
  }
  if (known[0] && known[1] && known[2]) {
    const double f_over_l2 = known[1]->si / (known[0]->si * known[0]->si);
    if (std::abs(f_over_l2 / known[2]->si - 1.0) > 1e-9) {
      std::string fits;
      for (const KnownUnit& s : kKnownUnits)
        if (s.kind == 2 && std::abs(f_over_l2 / s.si - 1.0) <= 1e-9 && fits.empty())
          fits = s.symbol;
      return "not consistent: a stress in " + symbols[1] + " per " + symbols[0] + "^2 is " +
             (fits.empty() ? std::string("none of the known stress units") : fits) + ", not " +
             symbols[2] + " (the material's moduli and the loads must be in one set of units)";
    }
  }
  return {};
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
