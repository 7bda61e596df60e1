// JSON reading, JSON pointers and the embedded schema table (see knit/io/json_input.hpp).
#include "knit/io/json_input.hpp"

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "knit/core/errors.hpp"

namespace knit::io {

// Defined in the generated file embedded_schemas.cpp (cmake/EmbedSchemas.cmake).
namespace detail {
std::vector<std::pair<std::string, std::string>> embedded_schema_table();
}

nlohmann::json parse_json(std::string_view text, const std::string& source) {
  try {
    return nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the 1-based offset of the character where parsing failed.
    const std::size_t at = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i < at; ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    // Keep nlohmann's explanation, without its "[json.exception...] parse error at ...:" prefix.
    std::string what = e.what();
    if (auto p = what.find("parse error"); p != std::string::npos) {
      what = what.substr(p);
      if (auto q = what.find(": "); q != std::string::npos) what = what.substr(q + 2);
    }
    throw knit::InputError(source, "",
                           "invalid JSON at line " + std::to_string(line) + ", column " +
                               std::to_string(col) + ": " + what);
  }
}

nlohmann::json read_json_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::error_code ec;
    const bool exists = std::filesystem::exists(file, ec);
    throw knit::InputError(file.string(), "", exists ? "cannot read file" : "file not found");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  return parse_json(text, file.string());
}

std::string json_pointer_escape(std::string_view token) {
  std::string out;
  out.reserve(token.size());
  for (char c : token) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

std::string json_pointer_append(const std::string& parent, std::string_view token) {
  return parent + "/" + json_pointer_escape(token);
}

std::string json_pointer_append(const std::string& parent, std::size_t index) {
  return parent + "/" + std::to_string(index);
}

namespace {
const std::vector<std::pair<std::string, std::string>>& table() {
  static const auto t = [] {
    auto v = detail::embedded_schema_table();
    std::sort(v.begin(), v.end());
    return v;
  }();
  return t;
}
}  // namespace

const std::string& embedded_schema(const std::string& name) {
  for (const auto& [n, text] : table())
    if (n == name) return text;
  std::string avail;
  for (const auto& [n, text] : table()) avail += (avail.empty() ? "" : ", ") + n;
  throw std::out_of_range("no embedded JSON schema \"" + name +
                          "\" (available: " + (avail.empty() ? "none" : avail) + "); schemas/" +
                          name + ".schema.json is compiled in when cmake runs");
}

std::vector<std::string> embedded_schema_names() {
  std::vector<std::string> names;
  for (const auto& [n, text] : table()) names.push_back(n);
  return names;
}

nlohmann::json load_and_validate(const std::filesystem::path& path,
                                 const std::string& schema_name) {
  const JsonSchema& schema = JsonSchema::embedded(schema_name);
  nlohmann::json j = read_json_file(path);
  schema.validate(j, path.string());
  return j;
}

}  // namespace knit::io
