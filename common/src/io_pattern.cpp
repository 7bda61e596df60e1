// Linear-time regular expressions for schema patterns (see knit/io/pattern.hpp).
// Parse (recursive descent over the PATTERN, which is trusted and short) -> syntax tree ->
// Pike VM program; the search keeps one thread per program counter, so its cost is
// O(|subject| x |program|) with no recursion over the subject.
#include "knit/io/pattern.hpp"

#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace knit::io {

namespace {

/// A set of code points as sorted ranges, possibly negated.
struct CharClass {
  std::vector<std::pair<char32_t, char32_t>> ranges;
  bool negated = false;
  bool contains(char32_t c) const {
    bool in = false;
    for (const auto& [lo, hi] : ranges)
      if (c >= lo && c <= hi) {
        in = true;
        break;
      }
    return in != negated;
  }
};

struct Node {
  enum Kind { kClass, kConcat, kAlt, kRepeat, kBol, kEol, kEmpty } kind = kEmpty;
  CharClass cls;
  std::vector<Node> kids;
  int min = 0, max = -1;  // kRepeat; max -1 = unbounded
};

constexpr int kMaxRepeat = 1000;

/// Decodes one UTF-8 code point at s[i] and advances i; invalid bytes map to U+DC80+byte.
char32_t next_code_point(std::string_view s, std::size_t& i) {
  const auto b = static_cast<unsigned char>(s[i]);
  int len = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
  if (len == 0 || i + len > s.size()) {
    ++i;
    return b < 0x80 ? b : 0xDC00 + b;
  }
  char32_t cp = len == 1 ? b : (b & (0x7F >> len));
  for (int k = 1; k < len; ++k) {
    const auto c = static_cast<unsigned char>(s[i + k]);
    if ((c >> 6) != 0x2) {
      ++i;
      return 0xDC00 + b;
    }
    cp = (cp << 6) | (c & 0x3F);
  }
  i += len;
  return cp;
}

class Parser {
 public:
  explicit Parser(std::string_view p) : p_(p) {}

  Node parse() {
    Node n = alternation();
    if (i_ < p_.size()) fail("unexpected ')'");
    return n;
  }

 private:
  std::string_view p_;
  std::size_t i_ = 0;

  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument(what + " at offset " + std::to_string(i_));
  }
  bool more() const { return i_ < p_.size(); }
  char peek() const { return p_[i_]; }

  Node alternation() {
    Node first = concatenation();
    if (!more() || peek() != '|') return first;
    Node alt;
    alt.kind = Node::kAlt;
    alt.kids.push_back(std::move(first));
    while (more() && peek() == '|') {
      ++i_;
      alt.kids.push_back(concatenation());
    }
    return alt;
  }

  Node concatenation() {
    Node cat;
    cat.kind = Node::kConcat;
    while (more() && peek() != '|' && peek() != ')') cat.kids.push_back(repeat());
    return cat;
  }

  int number() {
    if (!more() || peek() < '0' || peek() > '9') fail("expected a number in {}");
    long v = 0;
    while (more() && peek() >= '0' && peek() <= '9') {
      v = v * 10 + (peek() - '0');
      if (v > kMaxRepeat) fail("counted repeat above " + std::to_string(kMaxRepeat));
      ++i_;
    }
    return static_cast<int>(v);
  }

  Node repeat() {
    Node a = atom();
    while (more()) {
      int lo, hi;
      const char c = peek();
      if (c == '*') {
        lo = 0, hi = -1, ++i_;
      } else if (c == '+') {
        lo = 1, hi = -1, ++i_;
      } else if (c == '?') {
        lo = 0, hi = 1, ++i_;
      } else if (c == '{') {
        ++i_;
        lo = hi = number();
        if (more() && peek() == ',') {
          ++i_;
          hi = more() && peek() == '}' ? -1 : number();
        }
        if (!more() || peek() != '}') fail("expected '}'");
        ++i_;
        if (hi >= 0 && hi < lo) fail("{n,m} with m < n");
      } else {
        break;
      }
      if (a.kind == Node::kBol || a.kind == Node::kEol) fail("quantified anchor");
      if (more() && peek() == '?') ++i_;  // lazy: same language
      Node r;
      r.kind = Node::kRepeat;
      r.min = lo;
      r.max = hi;
      r.kids.push_back(std::move(a));
      a = std::move(r);
    }
    return a;
  }

  static CharClass single(char32_t c) { return CharClass{{{c, c}}, false}; }

  /// Escape after '\'; appends to cls (inside or outside a class).
  void escape(CharClass& cls) {
    if (!more()) fail("trailing backslash");
    const char c = p_[i_++];
    auto hex = [&](int n) {
      char32_t v = 0;
      for (int k = 0; k < n; ++k) {
        if (!more()) fail("short hex escape");
        const char h = p_[i_++];
        const int d = h >= '0' && h <= '9'   ? h - '0'
                      : h >= 'a' && h <= 'f' ? h - 'a' + 10
                      : h >= 'A' && h <= 'F' ? h - 'A' + 10
                                             : -1;
        if (d < 0) fail("bad hex digit");
        v = v * 16 + static_cast<char32_t>(d);
      }
      return v;
    };
    auto add = [&](char32_t lo, char32_t hi) { cls.ranges.emplace_back(lo, hi); };
    auto add_negated = [&](const std::vector<std::pair<char32_t, char32_t>>& in) {
      char32_t from = 0;  // complement of sorted, disjoint ranges
      for (const auto& [lo, hi] : in) {
        if (lo > from) add(from, lo - 1);
        from = hi + 1;
      }
      add(from, 0x10FFFF);
    };
    static const std::vector<std::pair<char32_t, char32_t>> digit{{'0', '9'}};
    static const std::vector<std::pair<char32_t, char32_t>> word{
        {'0', '9'}, {'A', 'Z'}, {'_', '_'}, {'a', 'z'}};
    static const std::vector<std::pair<char32_t, char32_t>> space{
        {'\t', '\r'}, {' ', ' '}, {0xA0, 0xA0}, {0x2028, 0x2029}, {0xFEFF, 0xFEFF}};
    switch (c) {
      case 'd':
        for (auto r : digit) add(r.first, r.second);
        break;
      case 'D':
        add_negated(digit);
        break;
      case 'w':
        for (auto r : word) add(r.first, r.second);
        break;
      case 'W':
        add_negated(word);
        break;
      case 's':
        for (auto r : space) add(r.first, r.second);
        break;
      case 'S':
        add_negated(space);
        break;
      case 'n':
        add('\n', '\n');
        break;
      case 'r':
        add('\r', '\r');
        break;
      case 't':
        add('\t', '\t');
        break;
      case 'f':
        add('\f', '\f');
        break;
      case 'v':
        add('\v', '\v');
        break;
      case '0':
        add(0, 0);
        break;
      case 'x': {
        const char32_t v = hex(2);
        add(v, v);
        break;
      }
      case 'u': {
        const char32_t v = hex(4);
        add(v, v);
        break;
      }
      default:
        if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '1' && c <= '9'))
          fail(std::string("unsupported escape \\") + c);
        add(static_cast<unsigned char>(c), static_cast<unsigned char>(c));
    }
  }

  CharClass bracket() {  // after '['
    CharClass cls;
    if (more() && peek() == '^') {
      cls.negated = true;
      ++i_;
    }
    bool first = true;
    while (true) {
      if (!more()) fail("unterminated [");
      if (peek() == ']' && !first) {
        ++i_;
        break;
      }
      first = false;
      CharClass item;
      if (peek() == '\\') {
        ++i_;
        escape(item);
      } else {
        const char32_t c = next_code_point(p_, i_);
        item = single(c);
      }
      // A range a-b (both single characters; '-' before ']' is a literal).
      if (item.ranges.size() == 1 && item.ranges[0].first == item.ranges[0].second && more() &&
          peek() == '-' && i_ + 1 < p_.size() && p_[i_ + 1] != ']') {
        ++i_;
        CharClass to;
        if (peek() == '\\') {
          ++i_;
          escape(to);
        } else {
          to = single(next_code_point(p_, i_));
        }
        if (to.ranges.size() != 1 || to.ranges[0].first != to.ranges[0].second)
          fail("bad range end");
        if (to.ranges[0].first < item.ranges[0].first) fail("range out of order");
        item.ranges[0].second = to.ranges[0].first;
      }
      cls.ranges.insert(cls.ranges.end(), item.ranges.begin(), item.ranges.end());
    }
    return cls;
  }

  Node atom() {
    Node n;
    const char c = peek();
    if (c == '(') {
      ++i_;
      if (more() && peek() == '?') {
        if (i_ + 1 < p_.size() && p_[i_ + 1] == ':')
          i_ += 2;
        else
          fail("lookaround and named groups are not supported");
      }
      n = alternation();
      if (!more() || peek() != ')') fail("missing ')'");
      ++i_;
      return n;
    }
    if (c == '*' || c == '+' || c == '?' || c == '{') fail("nothing to repeat");
    n.kind = Node::kClass;
    if (c == '^') {
      ++i_;
      n.kind = Node::kBol;
    } else if (c == '$') {
      ++i_;
      n.kind = Node::kEol;
    } else if (c == '.') {
      ++i_;
      n.cls.ranges = {{'\n', '\n'}, {'\r', '\r'}, {0x2028, 0x2029}};
      n.cls.negated = true;
    } else if (c == '[') {
      ++i_;
      n.cls = bracket();
    } else if (c == '\\') {
      ++i_;
      escape(n.cls);
    } else {
      n.cls = single(next_code_point(p_, i_));
    }
    return n;
  }
};

struct Inst {
  enum Op { kChar, kSplit, kJmp, kBol, kEol, kMatch } op;
  int x = 0, y = 0;  // targets (split: both; jmp: x); kChar: x = class index
};

}  // namespace

struct Pattern::Program {
  std::vector<Inst> code;
  std::vector<CharClass> classes;

  int emit(Inst::Op op, int x = 0, int y = 0) {
    code.push_back({op, x, y});
    if (code.size() > 200000) throw std::invalid_argument("pattern too large");
    return static_cast<int>(code.size()) - 1;
  }
  int here() const { return static_cast<int>(code.size()); }

  void compile(const Node& n) {
    switch (n.kind) {
      case Node::kEmpty:
        break;
      case Node::kClass:
        classes.push_back(n.cls);
        emit(Inst::kChar, static_cast<int>(classes.size()) - 1);
        break;
      case Node::kBol:
        emit(Inst::kBol);
        break;
      case Node::kEol:
        emit(Inst::kEol);
        break;
      case Node::kConcat:
        for (const Node& k : n.kids) compile(k);
        break;
      case Node::kAlt: {
        std::vector<int> jumps;
        for (std::size_t k = 0; k < n.kids.size(); ++k) {
          if (k + 1 < n.kids.size()) {
            const int split = emit(Inst::kSplit);
            code[split].x = here();
            compile(n.kids[k]);
            jumps.push_back(emit(Inst::kJmp));
            code[split].y = here();
          } else {
            compile(n.kids[k]);
          }
        }
        for (int j : jumps) code[j].x = here();
        break;
      }
      case Node::kRepeat: {
        const Node& e = n.kids.front();
        for (int k = 0; k < n.min; ++k) compile(e);
        if (n.max < 0) {  // e*: L1: split L2, L3; L2: e; jmp L1; L3:
          const int split = emit(Inst::kSplit);
          code[split].x = here();
          compile(e);
          emit(Inst::kJmp, split);
          code[split].y = here();
        } else {  // (e(e(e)?)?)? for the optional copies
          std::vector<int> splits;
          for (int k = n.min; k < n.max; ++k) {
            splits.push_back(emit(Inst::kSplit));
            code[splits.back()].x = here();
            compile(e);
          }
          for (int s : splits) code[s].y = here();
        }
        break;
      }
    }
  }
};

Pattern::Pattern(std::string_view pattern) : prog_(std::make_unique<Program>()) {
  if (pattern.size() > 10000) throw std::invalid_argument("pattern longer than 10000 characters");
  const Node tree = Parser(pattern).parse();
  prog_->compile(tree);
  prog_->emit(Inst::kMatch);
}

Pattern::Pattern(Pattern&&) noexcept = default;
Pattern& Pattern::operator=(Pattern&&) noexcept = default;
Pattern::~Pattern() = default;

bool Pattern::search(std::string_view s) const {
  const auto& code = prog_->code;
  const int n = static_cast<int>(code.size());
  // Thread lists as sparse sets of program counters; `mark` avoids adding a pc twice per step
  // (which also stops empty loops such as (a*)*).
  std::vector<int> cur, next, stack;
  std::vector<std::size_t> mark(static_cast<std::size_t>(n), 0);
  std::size_t generation = 0;
  cur.reserve(n);
  next.reserve(n);
  // Adds pc and everything reachable from it by epsilon moves at subject position pos.
  auto add = [&](std::vector<int>& list, int pc0, std::size_t pos) -> bool {
    stack.assign(1, pc0);
    while (!stack.empty()) {
      const int pc = stack.back();
      stack.pop_back();
      if (mark[pc] == generation) continue;
      mark[pc] = generation;
      const Inst& in = code[pc];
      switch (in.op) {
        case Inst::kMatch:
          return true;
        case Inst::kChar:
          list.push_back(pc);
          break;
        case Inst::kJmp:
          stack.push_back(in.x);
          break;
        case Inst::kSplit:
          stack.push_back(in.y);
          stack.push_back(in.x);
          break;
        case Inst::kBol:
          if (pos == 0) stack.push_back(pc + 1);
          break;
        case Inst::kEol:
          if (pos == s.size()) stack.push_back(pc + 1);
          break;
      }
    }
    return false;
  };
  std::size_t pos = 0;
  ++generation;
  if (add(cur, 0, 0)) return true;
  while (pos < s.size()) {
    const char32_t c = next_code_point(s, pos);
    ++generation;
    next.clear();
    for (int pc : cur)
      if (prog_->classes[static_cast<std::size_t>(code[pc].x)].contains(c) &&
          add(next, pc + 1, pos))
        return true;
    if (add(next, 0, pos)) return true;  // unanchored: a new match may start here
    std::swap(cur, next);
  }
  return false;
}

}  // namespace knit::io
