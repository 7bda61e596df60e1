// Reading the fit options' numbers from JSON (knit-meso fit --options / --energy-options, the
// sweep's "fit" and "energy_fit"): one place for the type and range checks of both fits.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "knit/core/errors.hpp"
#include "knit/io/json_input.hpp"
#include "knit/meso/fit/response_fit.hpp"

namespace knit::meso::fit {

/// j[key] into v if present: an integer that fits an int, checked before narrowing
/// (get<int>() of 4294967297 gave 1: issue 14). Errors name file and pointer + "/" + key.
inline void read_int_option(const nlohmann::json& j, const char* key, const std::string& file,
                            const std::string& pointer, int& v) {
  if (!j.contains(key)) return;
  const nlohmann::json& x = j[key];
  const std::string p = pointer + "/" + key;
  if (!io::json_is_integer(x)) throw InputError(file, p, "must be an integer");
  const long long i = io::json_integer_saturated(x);
  if (i < -2147483648ll || i > 2147483647ll)
    throw InputError(file, p, "must fit a 32-bit integer, got " + x.dump());
  v = static_cast<int>(i);
}

/// j[key] into v if present: a number (JSON has no NaN or infinity; 1e400 fails the parse).
inline void read_double_option(const nlohmann::json& j, const char* key, const std::string& file,
                               const std::string& pointer, double& v) {
  if (!j.contains(key)) return;
  if (!j[key].is_number()) throw InputError(file, pointer + "/" + key, "must be a number");
  v = j[key].get<double>();
}

/// j["loss"] into v if present: "none", "huber" or "cauchy" (Loss of response_fit.hpp, used by
/// both fits). Errors name file and pointer + "/loss".
inline void read_loss_option(const nlohmann::json& j, const std::string& file,
                             const std::string& pointer, Loss& v) {
  if (!j.contains("loss")) return;
  const std::string l = j["loss"].is_string() ? j["loss"].get<std::string>() : "";
  if (l == "none")
    v = Loss::kNone;
  else if (l == "huber")
    v = Loss::kHuber;
  else if (l == "cauchy")
    v = Loss::kCauchy;
  else
    throw InputError(file, pointer + "/loss", "must be \"none\", \"huber\" or \"cauchy\"");
}

}  // namespace knit::meso::fit
