// JSON input of the unit-cell parameters (schemas/cell.schema.json): yarn section, loop shape,
// discretization, contact law and solver settings. Every field is optional; the defaults are
// those of CellOptions (documented in docs/unit-cell.md). Bad input throws knit::InputError
// naming the file and the JSON pointer of the field.
#pragma once

#include <string>

#include "knit/meso/homog/periodic_cell.hpp"

namespace knit::meso::homog {

/// Reads `file` over the defaults `base`.
CellOptions read_cell_options(const std::string& file, CellOptions base = {});

}  // namespace knit::meso::homog
