// A regular-expression matcher for the JSON Schema "pattern" keyword that runs in time linear in
// the subject and uses no recursion over it (a Pike VM over a Thompson NFA, R. Cox, "Regular
// Expression Matching: the Virtual Machine Approach", 2009).
//
// Why not std::regex: libstdc++'s executor recurses once per matched character, so a 30,000-
// character name against "^[^,\"/\\n]+$" overflows the stack (issue 14). Schemas are trusted
// (they are compiled in), subjects are not.
//
// Supported (ECMAScript syntax, no flags): literals; "."; classes "[...]" and "[^...]" with
// ranges; escapes \d \D \w \W \s \S \n \r \t \f \v \0 \xHH \uHHHH and escaped punctuation;
// anchors ^ and $ (whole subject); groups "(...)" and "(?:...)"; alternation "|"; quantifiers
// * + ? {n} {n,} {n,m} (lazy forms "*?" etc. accepted: they do not change whether a string
// matches). Not supported (std::invalid_argument when compiled): backreferences, lookaround,
// \b \B, named groups, counted repeats above 1000.
// Matching is over Unicode code points of UTF-8 text ("." and "[^x]" consume one code point);
// invalid UTF-8 bytes are taken as single code points U+DC80+byte.
#pragma once

#include <memory>
#include <string>
#include <string_view>

namespace knit::io {

class Pattern {
 public:
  /// Compiles; throws std::invalid_argument("... at offset N") for unsupported syntax.
  explicit Pattern(std::string_view pattern);
  Pattern(Pattern&&) noexcept;
  Pattern& operator=(Pattern&&) noexcept;
  ~Pattern();
  /// Unanchored search (as JSON Schema's "pattern"): true if some substring matches.
  bool search(std::string_view subject) const;

 private:
  struct Program;
  std::unique_ptr<Program> prog_;
};

}  // namespace knit::io
