// Builds the shell's Material from the case's "material" object, discriminated by "type".
// Add a branch here for each material ("saint_venant_kirchhoff" now; "knit" comes with the
// material database). Bad input throws knit::InputError with ctx.file and a JSON pointer
// below ctx.pointer.
#pragma once

#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "knit/macro/material.hpp"
#include "knit/spline/surface.hpp"

namespace knit::macro {

struct CaseContext {
  std::string file;     ///< the case file (messages, relative paths)
  std::string pointer;  ///< JSON pointer of the material object
  /// The refined patch (parameter domain). Valid only during make_material: copy what you need.
  const spline::SplineSurface* patch = nullptr;
  /// The shell's thickness (/geometry/thickness, mm; 0 = unknown): a knit database's stresses
  /// are per its cell's thickness t = 2d, which the case must use.
  double thickness = 0.0;
};

std::unique_ptr<Material> make_material(const nlohmann::json& material, const CaseContext& ctx);

}  // namespace knit::macro
