#include "knit/macro/material_factory.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "knit/core/errors.hpp"
#include "knit/io/json_input.hpp"
#include "knit/macro/knit_material.hpp"
#include "knit/macro/svk_material.hpp"

namespace knit::macro {

namespace {

double positive_number(const nlohmann::json& j, const std::string& key, const CaseContext& ctx,
                       bool strictly = true) {
  const std::string p = ctx.pointer + "/" + key;
  if (!j.contains(key))
    throw InputError(ctx.file, ctx.pointer, "missing required key \"" + key + "\"");
  const auto& v = j.at(key);
  if (!v.is_number())
    throw InputError(ctx.file, p, "must be a number, got " + std::string(v.type_name()));
  const double x = v.get<double>();
  if (strictly ? !(x > 0.0) : !(x >= 0.0))
    throw InputError(
        ctx.file, p,
        std::string("must be ") + (strictly ? "positive" : "non-negative") + ", got " + v.dump());
  return x;
}

}  // namespace

std::unique_ptr<Material> make_material(const nlohmann::json& m, const CaseContext& ctx) {
  if (!m.is_object())
    throw InputError(ctx.file, ctx.pointer, "must be an object, got " + std::string(m.type_name()));
  if (!m.contains("type") || !m.at("type").is_string())
    throw InputError(ctx.file, ctx.pointer + (m.contains("type") ? "/type" : ""),
                     "needs a string \"type\" (one of: \"saint_venant_kirchhoff\", \"knit\")");
  const std::string type = m.at("type").get<std::string>();
  if (type == "knit") return make_knit_material(m, ctx);
  if (type == "saint_venant_kirchhoff") {
    const std::vector<std::string> allowed = {"type", "youngs_modulus", "poisson_ratio",
                                              "description"};
    if (auto u = io::find_unknown_key(m, ctx.pointer, allowed))
      throw InputError(ctx.file, u->pointer,
                       "unknown key for a saint_venant_kirchhoff material" + u->note);
    const double E = positive_number(m, "youngs_modulus", ctx);
    // From 1 Pa (a gel) to 1e9 MPa (beyond any solid): E = 1e-170 underflowed the stresses
    // and ran 0 iterations to a wrong answer with exit 0 (session 29, a helper's fuzzing audit).
    if (!(E >= 1e-6 && E <= 1e9))
      throw InputError(ctx.file, ctx.pointer + "/youngs_modulus",
                       "must lie in [1e-6, 1e9] MPa, got " + m.at("youngs_modulus").dump());
    if (!m.contains("poisson_ratio"))
      throw InputError(ctx.file, ctx.pointer, "missing required key \"poisson_ratio\"");
    const auto& nu = m.at("poisson_ratio");
    if (!nu.is_number())
      throw InputError(ctx.file, ctx.pointer + "/poisson_ratio", "must be a number");
    const double v = nu.get<double>();
    if (!(v > -1.0 && v < 0.5))
      throw InputError(ctx.file, ctx.pointer + "/poisson_ratio",
                       "must lie in (-1, 0.5), got " + nu.dump());
    return std::make_unique<SaintVenantKirchhoff>(E, v);
  }
  throw InputError(
      ctx.file, ctx.pointer + "/type",
      "unknown material type \"" + type + "\" (known: \"saint_venant_kirchhoff\", \"knit\")");
}

}  // namespace knit::macro
