// Design variables in the case text and the gradient of one reaction
// (knit/macro/design_gradient.hpp; docs/design.md).
#include "knit/macro/design_gradient.hpp"

#include <nlohmann/json.hpp>

#include "knit/core/errors.hpp"
#include "knit/io/json_input.hpp"
#include "knit/macro/design_sensitivity.hpp"

namespace knit::macro {

namespace {

std::string field_pointer(const DesignVariable& v) {
  return v.field == DesignVariable::Field::kStitchValue ? "/material/stitch_value"
                                                        : "/material/knitting_angle";
}

/// The JSON value of a design variable (checked: a control value of a spline field).
nlohmann::json& value_of(nlohmann::json& root, const DesignVariable& v, const std::string& file) {
  const std::string p = field_pointer(v);
  const nlohmann::json::json_pointer jp(p);
  if (!root.contains(jp) || !root.at(jp).is_object() || !root.at(jp).contains("values"))
    throw InputError(file, p,
                     "a design variable needs a spline field with control values here "
                     "(not a constant or an aligned field)");
  nlohmann::json& vals = root.at(jp).at("values");
  if (!vals.is_array() || v.index < 0 || v.index >= static_cast<int>(vals.size()))
    throw InputError(file, p + "/values",
                     "control value " + std::to_string(v.index) + " is outside the field's " +
                         std::to_string(vals.is_array() ? vals.size() : 0) + " values");
  return vals[static_cast<std::size_t>(v.index)];
}

}  // namespace

std::string case_text_with_design(const std::string& text, const std::string& file,
                                  const std::vector<DesignVariable>& vars,
                                  const std::vector<double>& values) {
  nlohmann::json root = io::parse_json(text, file);
  for (std::size_t k = 0; k < vars.size(); ++k) value_of(root, vars[k], file) = values.at(k);
  return root.dump(1);
}

Case case_with_design(const std::string& text, const std::string& file,
                      const std::vector<DesignVariable>& vars, const std::vector<double>& values) {
  return parse_case(case_text_with_design(text, file, vars, values), file);
}

std::vector<double> design_values(const std::string& text, const std::string& file,
                                  const std::vector<DesignVariable>& vars) {
  nlohmann::json root = io::parse_json(text, file);
  std::vector<double> v;
  for (const auto& d : vars) {
    const nlohmann::json& x = value_of(root, d, file);
    if (!x.is_number()) throw InputError(file, field_pointer(d) + "/values", "must be numbers");
    v.push_back(x.get<double>());
  }
  return v;
}

ReactionGradient reaction_gradient(const std::string& text, const std::string& file,
                                   const std::vector<DesignVariable>& vars, int reaction,
                                   double lambda) {
  const Case c = parse_case(text, file);
  if (reaction < 0 || reaction >= static_cast<int>(c.output.reactions.size()))
    throw InputError(file, "/output/reactions",
                     "no reaction " + std::to_string(reaction) + " among the case's outputs");
  const DesignSolve s(text, file, vars, {lambda});
  ReactionGradient out;
  out.status = s.status();
  out.message = s.message();
  if (out.status != RunStatus::kCompleted) return out;
  const Sensitive r = s.reaction(0, c.output.reactions[static_cast<std::size_t>(reaction)]);
  out.J = r.value;
  out.dJ = r.d.transpose();
  return out;
}

}  // namespace knit::macro
