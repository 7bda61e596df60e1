// JSON input of the unit-cell parameters (schemas/cell.schema.json): yarn section, loop shape,
// discretization, contact law and solver settings. Every field is optional; the defaults are
// those of CellOptions (documented in docs/unit-cell.md). Bad input throws knit::InputError
// naming the file and the JSON pointer of the field.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "knit/meso/homog/periodic_cell.hpp"

namespace knit::meso::homog {

/// Reads `file` over the defaults `base`.
CellOptions read_cell_options(const std::string& file, CellOptions base = {});

/// Reads an already parsed cell object `j` over `base`; errors name `file` and the pointer
/// `pointer` + the field inside `j` (e.g. "/cell/contact/mu" when the object is embedded in a
/// sweep input). The object is checked against schemas/cell.schema.json first.
CellOptions cell_options_from_json(const nlohmann::json& j, const std::string& file,
                                   const std::string& pointer = "", CellOptions base = {});

}  // namespace knit::meso::homog
