// The unit labels of a run's outputs (session 48's red team: a case in "m, kN, kPa" was written
// with mm, N and MPa on every label), and the columns of its load_strain.csv, which carry them.
#pragma once

#include <string>
#include <vector>

#include "knit/macro/case.hpp"

namespace knit::macro {

/// The symbols of a case's /units: "L, F, S" (three symbols, blanks ignored) gives the length,
/// force and stress symbols; no /units, or mm, N, MPa written with any blanks, the defaults;
/// anything else (the benchmarks' "consistent (dimensionless benchmark)") has no symbols, and
/// every dimensional label refers to /units.
struct UnitLabels {
  std::string root = "mm, N, MPa", length = "mm", force = "N", stress = "MPa";
  /// The label of a quantity whose mm-N-MPa unit is mm_unit ("mm", "1/mm", "N/mm", "N",
  /// "MPa"; others pass unchanged) in these units.
  std::string of(const std::string& mm_unit) const;
  /// "_" + of(mm_unit) for a CSV column name, "" when the units have no symbols.
  std::string suffix(const std::string& mm_unit) const;
};
UnitLabels unit_labels(const std::string& declared);

/// What is wrong with a case's /units, "" if nothing (session 49's red team: "mm, N, kPa"
/// labelled forces N where they are mN, "MPa, N, mm" labelled displacements MPa, and control
/// characters went into the outputs' labels): a control character anywhere; with three symbols
/// "L, F, S", a length, force or stress symbol that is a known unit of another kind, or known
/// symbols whose stress is not force per length squared (mm, N, MPa; m, N, Pa; m, kN, kPa;
/// in, lbf, psi ...). Unknown symbols and other text pass (a consistent set without names).
std::string units_problem(const std::string& declared);

/// The header of load_strain.csv: step, load factor, [applied displacement, strain], one column
/// per reaction, three per output point, then the solver's columns; suffixed with the units.
std::vector<std::string> load_strain_columns(const Case& c);

/// The first column name of load_strain_columns(c) that repeats, "" if none (a reaction or
/// point named like another column: "strain", or "tip_ux" beside the point "tip" when the
/// units have no symbols).
std::string repeated_load_strain_column(const Case& c);

}  // namespace knit::macro
