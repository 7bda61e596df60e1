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

// ---- line numbers of JSON pointers -------------------------------------------------------------

namespace {
/// A scanner over valid JSON text that records the line where each value (or member key) starts.
struct LineScanner {
  std::string_view t;
  std::size_t i = 0;
  int line = 1;
  bool record = true;  // fill `lines` (otherwise only look for duplicate keys)
  std::map<std::string, int> lines;
  struct Duplicate {
    std::string pointer;
    int first_line, second_line;
  };
  std::vector<Duplicate> duplicates;

  bool at_ws() const { return t[i] == ' ' || t[i] == '\t' || t[i] == '\n' || t[i] == '\r'; }
  void ws() {
    while (i < t.size() && at_ws()) {
      if (t[i] == '\n') ++line;
      ++i;
    }
  }
  static void utf8(std::string& out, unsigned cp) {
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }
  unsigned hex4() {
    unsigned v = 0;
    for (int k = 0; k < 4 && i < t.size(); ++k, ++i) {
      const char c = t[i];
      v = v * 16 + static_cast<unsigned>(c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10);
    }
    return v;
  }
  std::string string() {  // at the opening quote; returns the decoded text
    std::string out;
    ++i;
    while (i < t.size() && t[i] != '"') {
      if (t[i] != '\\') {
        out += t[i++];
        continue;
      }
      const char e = t[i + 1];
      i += 2;
      switch (e) {
        case 'n':
          out += '\n';
          break;
        case 't':
          out += '\t';
          break;
        case 'r':
          out += '\r';
          break;
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'u': {
          unsigned cp = hex4();
          if (cp >= 0xD800 && cp < 0xDC00 && i + 1 < t.size() && t[i] == '\\' && t[i + 1] == 'u') {
            i += 2;
            cp = 0x10000 + ((cp - 0xD800) << 10) + (hex4() - 0xDC00);
          }
          utf8(out, cp);
          break;
        }
        default:
          out += e;  // \" \\ \/
      }
    }
    ++i;
    return out;
  }
  void value(const std::string& ptr) {
    ws();
    if (record) lines.emplace(ptr, line);  // a member's key line was recorded first: kept
    if (i >= t.size()) return;
    if (t[i] == '{') {
      ++i;
      ws();
      std::map<std::string, int> keys;  // key -> line, to find duplicates
      while (i < t.size() && t[i] != '}') {
        const int key_line = line;
        const std::string key = string();
        const std::string child = json_pointer_append(ptr, key);
        if (auto [it, fresh] = keys.emplace(key, key_line); !fresh)
          duplicates.push_back({child, it->second, key_line});
        if (record) lines[child] = key_line;
        ws();
        ++i;  // ':'
        value(child);
        ws();
        if (i < t.size() && t[i] == ',') ++i;
        ws();
      }
      ++i;
    } else if (t[i] == '[') {
      ++i;
      ws();
      for (std::size_t k = 0; i < t.size() && t[i] != ']'; ++k) {
        value(json_pointer_append(ptr, k));
        ws();
        if (i < t.size() && t[i] == ',') ++i;
        ws();
      }
      ++i;
    } else if (t[i] == '"') {
      string();
    } else {  // number, true, false, null
      while (i < t.size() && t[i] != ',' && t[i] != '}' && t[i] != ']' && !at_ws()) ++i;
    }
  }
};
}  // namespace

std::map<std::string, int> json_pointer_lines(std::string_view text) {
  LineScanner s;
  s.t = text;
  s.value("");
  return std::move(s.lines);
}

nlohmann::json parse_json(std::string_view text, const std::string& source) {
  try {
    nlohmann::json j = nlohmann::json::parse(text.begin(), text.end());
    // nlohmann keeps the last of duplicate keys silently; a case file with a key twice is
    // almost certainly a mistake.
    LineScanner scan;
    scan.t = text;
    scan.record = false;
    scan.value("");
    if (!scan.duplicates.empty()) {
      const auto& d = scan.duplicates.front();
      throw knit::InputError(source, d.pointer,
                             "duplicate key (lines " + std::to_string(d.first_line) + " and " +
                                 std::to_string(d.second_line) + ")");
    }
    return j;
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

namespace {
std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::error_code ec;
    const bool exists = std::filesystem::exists(file, ec);
    throw knit::InputError(file.string(), "", exists ? "cannot read file" : "file not found");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
}  // namespace

nlohmann::json read_json_file(const std::filesystem::path& file) {
  return parse_json(read_text(file), file.string());
}

std::filesystem::path resolve_input_path(const std::filesystem::path& input_file,
                                         const std::string& value) {
  const std::filesystem::path v(value);
  if (v.is_absolute()) return v;
  return (input_file.parent_path() / v).lexically_normal();
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
  return load_and_validate(path, JsonSchema::embedded(schema_name));
}

nlohmann::json load_and_validate(const std::filesystem::path& path, const JsonSchema& schema) {
  const std::string text = read_text(path);
  nlohmann::json j = parse_json(text, path.string());
  const auto errs = schema.errors(j);
  if (!errs.empty()) {
    const auto& e = errs.front();
    const auto lines = json_pointer_lines(text);
    auto it = lines.find(e.at);
    if (it == lines.end()) it = lines.find(e.pointer);
    std::string msg = e.message;
    if (it != lines.end()) msg += " (line " + std::to_string(it->second) + ")";
    throw knit::InputError(path.string(), e.pointer, msg);
  }
  return j;
}

}  // namespace knit::io
