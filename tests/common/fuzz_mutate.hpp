// Deterministic input mutations for the bounded fuzz tests (test_fuzz_*.cpp): byte flips,
// truncations, deep nesting, huge and odd numbers, type swaps, duplicated keys, block
// overwrites. A fixed seed makes every run test the same inputs; a failing input is printed
// with the mutation that made it. The long, coverage-guided runs use libFuzzer (tests/fuzz/,
// docs/io.md).
#pragma once

#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace knit::testing {

struct Mutant {
  std::string data;
  std::string how;  ///< e.g. "flip bit 3 of byte 120"
};

class Mutator {
 public:
  explicit Mutator(std::uint32_t seed) : rng_(seed) {}

  std::size_t below(std::size_t n) {
    return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_);
  }

  /// Binary mutations (any file): bit flips, truncation, block overwrite/zero, byte insertion.
  Mutant binary(const std::string& in) {
    Mutant m{in, ""};
    if (in.empty()) return m;
    switch (below(5)) {
      case 0: {
        const std::size_t flips = 1 + below(4);
        for (std::size_t k = 0; k < flips; ++k) {
          const std::size_t at = below(in.size());
          const int bit = static_cast<int>(below(8));
          m.data[at] = static_cast<char>(m.data[at] ^ (1 << bit));
          m.how += "flip bit " + std::to_string(bit) + " of byte " + std::to_string(at) + "; ";
        }
        break;
      }
      case 1: {
        const std::size_t at = below(in.size());
        m.data.resize(at);
        m.how = "truncate to " + std::to_string(at) + " bytes";
        break;
      }
      case 2: {
        const std::size_t at = below(in.size()), len = 1 + below(16);
        for (std::size_t k = at; k < std::min(in.size(), at + len); ++k)
          m.data[k] = static_cast<char>(below(256));
        m.how = "random bytes at " + std::to_string(at) + " (+" + std::to_string(len) + ")";
        break;
      }
      case 3: {
        const std::size_t at = below(in.size()), len = 1 + below(64);
        const char v = below(2) ? '\0' : '\xff';
        for (std::size_t k = at; k < std::min(in.size(), at + len); ++k) m.data[k] = v;
        m.how = std::string(v ? "0xff" : "zero") + " bytes at " + std::to_string(at) + " (+" +
                std::to_string(len) + ")";
        break;
      }
      default: {
        const std::size_t at = below(in.size());
        m.data.insert(at, 1, static_cast<char>(below(256)));
        m.how = "insert a byte at " + std::to_string(at);
      }
    }
    return m;
  }

  /// JSON-aware text mutations: values replaced by huge/odd numbers, other types or deep
  /// nesting; duplicated keys; plus the binary ones.
  Mutant json_text(const std::string& in) {
    Mutant m{in, ""};
    const auto values = value_starts(in);
    const std::size_t kind = below(8);
    if (kind < 3 || values.empty()) return binary(in);
    const auto [at, len] = values[below(values.size())];
    static const std::vector<std::string> numbers = {
        "1e400",  "-1e400", "1e10",    "2147483648", "-2147483649", "9223372036854775808",
        "1e-400", "-0",     "0.5",     "1e308",      "-1",          "0",
        "256",    "15",     "1000001", "3.0000001",  "1e16"};
    static const std::vector<std::string> others = {"\"\"",  "\"x\"",  "[]",    "{}",
                                                    "null",  "true",   "false", "[1, 2, 3]",
                                                    "\".\"", "\"..\"", "\"/\"", "[[[[0]]]]"};
    std::string repl;
    if (kind == 3) {
      repl = numbers[below(numbers.size())];
      m.how = "value at byte " + std::to_string(at) + " := " + repl;
    } else if (kind == 4) {
      repl = others[below(others.size())];
      m.how = "value at byte " + std::to_string(at) + " := " + repl;
    } else if (kind == 5) {
      const std::size_t depth = below(2) ? 300 : 40000;
      repl = std::string(depth, '[') + "1" + std::string(depth, ']');
      m.how = "value at byte " + std::to_string(at) + " := nested " + std::to_string(depth);
    } else if (kind == 6) {
      repl = "\"" + std::string(below(2) ? 30000 : 70, 'n') + "\"";
      m.how = "value at byte " + std::to_string(at) + " := long string";
    } else {
      // Duplicate the key whose value starts here (if it is a member).
      const std::size_t colon = in.rfind(':', at);
      const std::size_t q2 = colon == std::string::npos ? colon : in.rfind('"', colon);
      const std::size_t q1 = q2 == std::string::npos || q2 == 0 ? q2 : in.rfind('"', q2 - 1);
      if (q1 == std::string::npos) return binary(in);
      const std::string member = in.substr(q1, at + len - q1);
      m.data.insert(at + len, ", " + member);
      m.how = "duplicate member " + in.substr(q1, q2 - q1 + 1);
      return m;
    }
    m.data.replace(at, len, repl);
    return m;
  }

 private:
  std::mt19937 rng_;

  /// (start, length) of the scalar values (numbers, strings, literals) in JSON text.
  static std::vector<std::pair<std::size_t, std::size_t>> value_starts(const std::string& t) {
    std::vector<std::pair<std::size_t, std::size_t>> out;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const char c = t[i];
      if (c == '"') {
        std::size_t j = i + 1;
        while (j < t.size() && t[j] != '"') j += t[j] == '\\' ? 2 : 1;
        std::size_t k = j + 1;
        while (k < t.size() && (t[k] == ' ' || t[k] == '\n')) ++k;
        if (k >= t.size() || t[k] != ':') out.emplace_back(i, j + 1 - i);  // not a key
        i = j;
      } else if (c == '-' || (c >= '0' && c <= '9') || c == 't' || c == 'f' || c == 'n') {
        std::size_t j = i;
        while (j < t.size() && t[j] != ',' && t[j] != ']' && t[j] != '}' && t[j] != ' ' &&
               t[j] != '\n')
          ++j;
        out.emplace_back(i, j - i);
        i = j - 1;
      }
    }
    return out;
  }
};

/// Number of mutants per fuzz test: KNIT_FUZZ_INPUTS if set (1..10^7), else `fallback`. The
/// sanitizer build sets 500 (tests/CMakeLists.txt) — the Release suite runs the full 2,000;
/// longer runs on demand: KNIT_FUZZ_INPUTS=100000 build/bin/test_common "fuzz*".
inline int fuzz_inputs(int fallback = 2000) {
  const char* v = std::getenv("KNIT_FUZZ_INPUTS");
  if (v == nullptr) return fallback;
  char* end = nullptr;
  const long n = std::strtol(v, &end, 10);
  return (end != v && *end == '\0' && n >= 1 && n <= 10000000) ? static_cast<int>(n) : fallback;
}

}  // namespace knit::testing
