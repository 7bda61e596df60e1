// Output-name rules (see knit/io/names.hpp).
#include "knit/io/names.hpp"

namespace knit::io {

namespace {
bool alnum(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}
}  // namespace

std::optional<std::string> output_name_problem(std::string_view name) {
  if (name.empty()) return "a name must not be empty";
  if (name.size() > kMaxOutputNameLength)
    return "a name has at most " + std::to_string(kMaxOutputNameLength) + " characters, got " +
           std::to_string(name.size());
  if (!alnum(name[0]) && name[0] != '_')
    return "a name starts with a letter, a digit or '_' (it becomes an HDF5 dataset and a CSV "
           "column)";
  for (char c : name)
    if (!alnum(c) && c != '_' && c != '.' && c != '+' && c != '-')
      return "a name may contain only letters, digits and _ . + - (it becomes an HDF5 dataset "
             "and a CSV column)";
  return std::nullopt;
}

std::string join_names(const std::vector<std::string>& names) {
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

}  // namespace knit::io
