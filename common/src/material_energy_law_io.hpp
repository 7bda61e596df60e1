// HDF5 side of the energy-based law (/energy_law of the material database, format version 2).
// Private to common/src: material_database_io.cpp calls it.
#pragma once

#include <string>

#include "knit/io/hdf5.hpp"
#include "knit/material/database.hpp"

namespace knit::material::detail {

inline constexpr const char* kEnergyLawGroup = "/energy_law";

void write_energy_law(io::H5Group& root, const EnergyLawData& law, const EnergyFitDiagnostics& dg);

/// Reads /energy_law (must exist); throws knit::InputError naming `file` and the HDF5 path.
void read_energy_law(const io::H5Group& root, const std::string& file, EnergyLawData& law,
                     EnergyFitDiagnostics& dg);

}  // namespace knit::material::detail
