// Names chosen by the user that become file, HDF5 or CSV names (output points, reactions):
// checked when the input is loaded, before any work, with plain character tests (no
// std::regex, whose recursive matcher overflowed the stack on a 30,000-character name).
//
// A valid name has 1..kMaxOutputNameLength characters from [A-Za-z0-9_.+-], starts with a
// letter, digit or '_' (so never "." or ".." and never a hidden file), and is unique in its
// input (the loader checks uniqueness).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace knit::io {

inline constexpr std::size_t kMaxOutputNameLength = 64;

/// Why `name` is not a valid output name, or nullopt if it is.
std::optional<std::string> output_name_problem(std::string_view name);

/// A control character (C0 or DEL): never meant in a path or a marker line, which is written
/// line by line (output paths, input file names, the marker's input line, unit symbols).
inline bool is_control_character(char ch) {
  return static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f;
}
inline bool has_control_character(std::string_view s) {
  for (const char ch : s)
    if (is_control_character(ch)) return true;
  return false;
}

/// The names joined by ", " for a message ("design, knitmap, run"); "" for none.
std::string join_names(const std::vector<std::string>& names);

}  // namespace knit::io
