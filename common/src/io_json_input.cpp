// JSON reading, JSON pointers and the embedded schema table (see knit/io/json_input.hpp).
#include "knit/io/json_input.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <utility>

#include "knit/core/errors.hpp"
#include "knit/io/input_file.hpp"

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
  std::size_t line_start = 0;  // offset of the current line's first character
  bool record = true;          // fill `lines` (otherwise only look for duplicate keys)
  std::map<std::string, int> lines;
  struct Duplicate {
    std::string pointer;
    int first_line, second_line;
  };
  std::vector<Duplicate> duplicates;
  struct BadNumber {
    std::string pointer, token;
    int line;
    std::size_t column;
  };
  std::vector<BadNumber> bad_numbers;  // numbers that do not fit a double (1e400)

  bool at_ws() const { return t[i] == ' ' || t[i] == '\t' || t[i] == '\n' || t[i] == '\r'; }
  void ws() {
    while (i < t.size() && at_ws()) {
      if (t[i] == '\n') {
        ++line;
        line_start = i + 1;
      }
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
      const std::size_t start = i;
      while (i < t.size() && t[i] != ',' && t[i] != '}' && t[i] != ']' && !at_ws()) ++i;
      const std::string token(t.substr(start, i - start));
      if (!token.empty() && (token[0] == '-' || (token[0] >= '0' && token[0] <= '9')) &&
          !std::isfinite(std::strtod(token.c_str(), nullptr)))
        bad_numbers.push_back({ptr, token, line, start - line_start + 1});
    }
  }
};
}  // namespace

std::string closest_key(const std::string& key, const std::vector<std::string>& known) {
  // One quantity's names across knitscale's files first (session 48's walkthrough: the yarn's
  // "diameter" of a database, written in a cell input whose key is "d", got no suggestion): a
  // database's /yarn and a case's material use the long names, a cell input the short ones.
  // Only where a companion key says it is that kind of object (session 48's review: "E" is also
  // a strain, in a sweep's uniaxial load path).
  static const std::array<const char*, 3> kSameQuantity[] = {
      {"diameter", "d", "nu"},
      {"youngs_modulus", "E", "nu"},
      {"poisson_ratio", "nu", "E"},
      {"E", "youngs_modulus", "poisson_ratio"},
      {"nu", "poisson_ratio", "youngs_modulus"}};
  const auto has = [&](const char* k) {
    return std::find(known.begin(), known.end(), k) != known.end();
  };
  for (const auto& [name, other, companion] : kSameQuantity)
    if (key == name && has(other) && has(companion)) return other;
  // Levenshtein distance, case-insensitive, two rows.
  const auto distance = [](const std::string& a, const std::string& b) {
    std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      cur[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                          std::tolower(static_cast<unsigned char>(b[j - 1]));
        cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (same ? 0 : 1)});
      }
      std::swap(prev, cur);
    }
    return prev[b.size()];
  };
  std::string best;
  std::size_t best_d = std::max<std::size_t>(1, std::min<std::size_t>(2, key.size() / 3));
  for (const auto& k : known) {
    const std::size_t d = distance(key, k);
    if (d <= best_d && (best.empty() || d < best_d)) {
      best = k;
      best_d = d;
    }
  }
  return best;
}

std::string unknown_key_note(const std::string& key, const std::vector<std::string>& known) {
  const std::string best = closest_key(key, known);
  std::string list;
  if (!known.empty() && known.size() <= kMaxListedKeys)
    for (const auto& k : known) list += (list.empty() ? "\"" : ", \"") + k + "\"";
  if (best.empty() && list.empty()) return "";
  std::string note = " (";
  if (!best.empty()) note += "did you mean \"" + best + "\"?";
  if (!list.empty()) note += (best.empty() ? "allowed: " : " allowed: ") + list;
  return note + ")";
}

std::optional<UnknownKey> find_unknown_key(const nlohmann::json& j, const std::string& pointer,
                                           const std::vector<std::string>& allowed) {
  if (!j.is_object()) return std::nullopt;
  for (auto it = j.begin(); it != j.end(); ++it)
    if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end())
      return UnknownKey{it.key(), json_pointer_append(pointer, it.key()),
                        unknown_key_note(it.key(), allowed)};
  return std::nullopt;
}

std::map<std::string, int> json_pointer_lines(std::string_view text) {
  LineScanner s;
  s.t = text;
  s.value("");
  return std::move(s.lines);
}

std::string with_line(std::string_view text, const std::vector<std::string>& pointers,
                      std::string message) {
  const auto newline = text.find('\n');
  const bool one_line = newline == std::string_view::npos ||
                        text.find_first_not_of(" \t\r\n", newline) == std::string_view::npos;
  if (one_line || message.find("(line ") != std::string::npos) return message;
  const auto lines = json_pointer_lines(text);
  for (const auto& p : pointers)
    if (auto it = lines.find(p); it != lines.end())
      return message + " (line " + std::to_string(it->second) + ")";
  return message;
}

std::optional<knit::InputError> error_with_line(const knit::InputError& e, std::string_view text,
                                                const std::string& file) {
  if (e.file() != file || e.pointer().empty()) return std::nullopt;
  std::string msg = with_line(text, {e.pointer()}, e.message());
  if (msg == e.message()) return std::nullopt;
  return knit::InputError(file, e.pointer(), std::move(msg));
}

namespace {
/// Line and column (1-based) of byte offset `at`.
std::pair<std::size_t, std::size_t> line_column(std::string_view text, std::size_t at) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < std::min(at, text.size()); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return {line, col};
}

/// `s` with every byte that is not part of a well-formed UTF-8 sequence (RFC 3629: no overlong
/// forms, no surrogates, nothing above U+10FFFF) written as \xHH. nlohmann's parse errors quote
/// the bytes last read; from a Latin-1 or binary file they were raw and garbled the terminal.
std::string printable_utf8(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    unsigned lo = 0x80, hi = 0xBF;  // allowed range of the second byte
    if (b < 0x80)
      n = 1;
    else if (b >= 0xC2 && b <= 0xDF)
      n = 2;
    else if (b >= 0xE0 && b <= 0xEF) {
      n = 3;
      if (b == 0xE0) lo = 0xA0;
      if (b == 0xED) hi = 0x9F;
    } else if (b >= 0xF0 && b <= 0xF4) {
      n = 4;
      if (b == 0xF0) lo = 0x90;
      if (b == 0xF4) hi = 0x8F;
    }
    bool ok = n > 0 && i + n <= s.size();
    for (std::size_t k = 1; ok && k < n; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      ok = k == 1 ? (c >= lo && c <= hi) : (c >= 0x80 && c <= 0xBF);
    }
    if (ok) {
      out.append(s.substr(i, n));
      i += n;
    } else {
      static constexpr char kHex[] = "0123456789ABCDEF";
      out += "\\x";
      out += kHex[b >> 4];
      out += kHex[b & 15];
      ++i;
    }
  }
  return out;
}

[[noreturn]] void fail_at(std::string_view text, const std::string& source, std::size_t at,
                          const std::string& what) {
  const auto [line, col] = line_column(text, at);
  throw knit::InputError(source, "",
                         "invalid JSON at line " + std::to_string(line) + ", column " +
                             std::to_string(col) + ": " + printable_utf8(what));
}

/// Refuses nesting deeper than kMaxJsonDepth before anything recursive (the line scanner, the
/// schema validator, the loaders) sees the text: 40,000 levels overflowed the stack (issue 14).
void check_depth(std::string_view text, const std::string& source) {
  std::size_t depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        fail_at(text, source, i,
                "nested deeper than " + std::to_string(kMaxJsonDepth) + " arrays/objects");
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
}
}  // namespace

nlohmann::json parse_json(std::string_view text, const std::string& source) {
  check_depth(text, source);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is the 1-based offset of the character where parsing failed.
    // Keep nlohmann's explanation, without its "[json.exception...] parse error at ...:" prefix.
    std::string what = e.what();
    if (auto p = what.find("parse error"); p != std::string::npos) {
      what = what.substr(p);
      if (auto q = what.find(": "); q != std::string::npos) what = what.substr(q + 2);
    }
    fail_at(text, source, e.byte > 0 ? e.byte - 1 : 0, what);
  } catch (const nlohmann::json::exception& e) {
    // A number that does not fit a double (1e400; nlohmann's out_of_range 406 names neither
    // the file nor the place): find it with the scanner, which knows the pointer.
    LineScanner scan;
    scan.t = text;
    scan.record = false;
    scan.value("");
    if (!scan.bad_numbers.empty()) {
      const auto& b = scan.bad_numbers.front();
      throw knit::InputError(source, b.pointer,
                             "the number " + b.token + " is outside the range of a double (line " +
                                 std::to_string(b.line) + ", column " + std::to_string(b.column) +
                                 ")");
    }
    throw knit::InputError(source, "", "invalid JSON: " + printable_utf8(e.what()));
  }
  // nlohmann keeps the last of duplicate keys silently; a case file with a key twice is
  // almost certainly a mistake.
  LineScanner scan;
  scan.t = text;
  scan.record = false;
  scan.value("");
  if (!scan.duplicates.empty()) {
    const auto& d = scan.duplicates.front();
    // Both on one line: "(line 43, twice)", not "(lines 43 and 43)" (session 43's walkthrough).
    throw knit::InputError(source, d.pointer,
                           d.first_line == d.second_line
                               ? "duplicate key (line " + std::to_string(d.first_line) + ", twice)"
                               : "duplicate key (lines " + std::to_string(d.first_line) + " and " +
                                     std::to_string(d.second_line) + ")");
  }
  return j;
}

namespace {
std::string read_text(const std::filesystem::path& file) {
  return read_input_file(file, kMaxJsonInputBytes);
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
    throw knit::InputError(path.string(), e.pointer, with_line(text, {e.at, e.pointer}, e.message));
  }
  return j;
}

}  // namespace knit::io
