// JSON Schema validation (draft 2020-12 subset; see knit/io/json_input.hpp for the keywords).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "knit/core/errors.hpp"
#include "knit/io/json_input.hpp"
#include "knit/io/pattern.hpp"

namespace knit::io {

using nlohmann::json;

bool json_is_integer(const json& v) {
  if (v.is_number_integer()) return true;
  if (!v.is_number_float()) return false;
  const double d = v.get<double>();
  return std::isfinite(d) && std::floor(d) == d;
}

long long json_integer_saturated(const json& v) {
  constexpr long long kMax = std::numeric_limits<long long>::max();
  constexpr long long kMin = std::numeric_limits<long long>::min();
  if (v.is_number_unsigned()) {
    const auto u = v.get<unsigned long long>();
    return u > static_cast<unsigned long long>(kMax) ? kMax : static_cast<long long>(u);
  }
  if (v.is_number_integer()) return v.get<long long>();
  const double d = v.get<double>();
  // 2^63 is exact in a double; every double below it converts exactly (it has no fraction).
  if (d >= 9223372036854775808.0) return kMax;
  if (d < -9223372036854775808.0) return kMin;
  return static_cast<long long>(d);
}

namespace {

// ---- message helpers ----------------------------------------------------------------------------

std::string short_dump(const json& v) {
  std::string s = v.dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

/// How an instance value is described after "got".
std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array of " + std::to_string(v.size()) + (v.size() == 1 ? " item" : " items");
    case json::value_t::string:
      return "string " + short_dump(v);
    case json::value_t::null:
      return "null";
    default:
      return short_dump(v);  // numbers, booleans
  }
}

/// Like describe(), but a scalar is shown as its JSON text only (where its type is not the point).
std::string describe_value(const json& v) {
  return v.is_object() || v.is_array() ? describe(v) : short_dump(v);
}

std::string type_phrase(const std::string& t) {
  if (t == "object") return "an object";
  if (t == "array") return "an array";
  if (t == "integer") return "an integer";
  if (t == "null") return "null";
  return "a " + t;  // string, number, boolean
}

std::string join_or(const std::vector<std::string>& items) {
  std::string s;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i) s += (i + 1 == items.size()) ? " or " : ", ";
    s += items[i];
  }
  return s;
}

std::string join_values(const json& values) {
  std::string s;
  for (std::size_t i = 0; i < values.size(); ++i) s += (i ? ", " : "") + short_dump(values[i]);
  return s;
}

bool has_type(const json& v, const std::string& t) {
  if (t == "object") return v.is_object();
  if (t == "array") return v.is_array();
  if (t == "string") return v.is_string();
  if (t == "number") return v.is_number();
  if (t == "integer") return json_is_integer(v);
  if (t == "boolean") return v.is_boolean();
  if (t == "null") return v.is_null();
  return false;
}

/// JSON equality with numbers compared by value (1 == 1.0), as JSON Schema requires.
bool json_equal(const json& a, const json& b) {
  if (a.is_number() && b.is_number()) return a.get<double>() == b.get<double>();
  if (a.type() != b.type()) return false;
  if (a.is_array()) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!json_equal(a[i], b[i])) return false;
    return true;
  }
  if (a.is_object()) {
    if (a.size() != b.size()) return false;
    for (auto it = a.begin(); it != a.end(); ++it) {
      auto jt = b.find(it.key());
      if (jt == b.end() || !json_equal(it.value(), *jt)) return false;
    }
    return true;
  }
  return a == b;
}

std::size_t pointer_depth(const std::string& p) {
  return static_cast<std::size_t>(std::count(p.begin(), p.end(), '/'));
}

/// Length of a UTF-8 string in code points (minLength/maxLength count characters).
std::size_t utf8_length(const std::string& s) {
  std::size_t n = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++n;
  return n;
}

// ---- the schema checker (run once per schema) ---------------------------------------------------

const std::set<std::string>& annotation_keywords() {
  static const std::set<std::string> k = {
      "title",    "description", "default",          "examples",       "$schema",
      "$id",      "$comment",    "$anchor",          "format",         "deprecated",
      "readOnly", "writeOnly",   "contentMediaType", "contentEncoding"};
  return k;
}

const std::set<std::string>& value_keywords() {
  static const std::set<std::string> k = {"type",
                                          "enum",
                                          "const",
                                          "required",
                                          "minimum",
                                          "maximum",
                                          "exclusiveMinimum",
                                          "exclusiveMaximum",
                                          "multipleOf",
                                          "minLength",
                                          "maxLength",
                                          "pattern",
                                          "minItems",
                                          "maxItems",
                                          "uniqueItems",
                                          "minProperties",
                                          "maxProperties",
                                          "$ref"};
  return k;
}

}  // namespace

struct JsonSchema::Impl {
  json root;
  std::string name;
  mutable std::mutex regex_mutex;
  // Not std::regex: it recurses per subject character (a long string overflows the stack).
  mutable std::map<std::string, Pattern> regexes;

  // Internal error record: `expected_type` is set for pure type mismatches (used to merge the
  // alternatives of oneOf/anyOf into one message).
  struct Err {
    std::string pointer, message, expected_type;
    std::string at;  // where the error is located in the text ("" = pointer)
  };
  using Errs = std::vector<Err>;

  [[noreturn]] void schema_fail(const std::string& where, const std::string& what) const {
    throw std::logic_error("schema " + name + ": " + (where.empty() ? "(root)" : where) + ": " +
                           what);
  }

  const Pattern& regex(const std::string& pattern) const {
    std::lock_guard<std::mutex> lock(regex_mutex);
    auto it = regexes.find(pattern);
    if (it == regexes.end()) it = regexes.emplace(pattern, Pattern(pattern)).first;
    return it->second;
  }

  const json& resolve(const std::string& ref, const std::string& where) const {
    if (ref == "#") return root;
    if (ref.rfind("#/", 0) != 0)
      schema_fail(where, "$ref \"" + ref + "\" not supported (only \"#/$defs/...\" refs)");
    try {
      return root.at(json::json_pointer(ref.substr(1)));
    } catch (const json::exception&) {
      schema_fail(where, "$ref \"" + ref + "\" does not resolve");
    }
  }

  // Recursively checks that the schema only uses supported keywords.
  void check(const json& s, const std::string& where) const {
    if (s.is_boolean()) return;
    if (!s.is_object()) schema_fail(where, "a schema must be an object or a boolean");
    auto sub = [&](const json& v, const std::string& w) { check(v, w); };
    for (auto it = s.begin(); it != s.end(); ++it) {
      const std::string& k = it.key();
      const json& v = it.value();
      const std::string w = json_pointer_append(where, k);
      if (annotation_keywords().count(k) || k.rfind("x-", 0) == 0) continue;
      if (k == "properties" || k == "patternProperties" || k == "$defs" || k == "definitions") {
        if (!v.is_object()) schema_fail(w, "must be an object of schemas");
        for (auto jt = v.begin(); jt != v.end(); ++jt) {
          if (k == "patternProperties") regex_checked(jt.key(), w);
          sub(jt.value(), json_pointer_append(w, jt.key()));
        }
      } else if (k == "allOf" || k == "anyOf" || k == "oneOf" || k == "prefixItems") {
        if (!v.is_array() || v.empty()) schema_fail(w, "must be a non-empty array of schemas");
        for (std::size_t i = 0; i < v.size(); ++i) sub(v[i], json_pointer_append(w, i));
      } else if (k == "items") {
        if (v.is_array())
          for (std::size_t i = 0; i < v.size(); ++i) sub(v[i], json_pointer_append(w, i));
        else
          sub(v, w);
      } else if (k == "additionalProperties" || k == "additionalItems" || k == "not" || k == "if" ||
                 k == "then" || k == "else") {
        sub(v, w);
      } else if (value_keywords().count(k)) {
        if (k == "$ref") {
          if (!v.is_string()) schema_fail(w, "must be a string");
          resolve(v.get<std::string>(), w);
        } else if (k == "type") {
          const json types = v.is_array() ? v : json::array({v});
          static const std::set<std::string> known = {"object",  "array",   "string", "number",
                                                      "integer", "boolean", "null"};
          for (const auto& t : types)
            if (!t.is_string() || !known.count(t.get<std::string>()))
              schema_fail(w, "unknown type " + short_dump(t));
        } else if (k == "required") {
          if (!v.is_array()) schema_fail(w, "must be an array of strings");
          for (const auto& r : v)
            if (!r.is_string()) schema_fail(w, "must be an array of strings");
        } else if (k == "enum") {
          if (!v.is_array() || v.empty()) schema_fail(w, "must be a non-empty array");
        } else if (k == "pattern") {
          if (!v.is_string()) schema_fail(w, "must be a string");
          regex_checked(v.get<std::string>(), w);
        } else if (k != "const" && k != "uniqueItems" && !v.is_number()) {
          schema_fail(w, "must be a number");
        }
      } else {
        schema_fail(w, "unsupported keyword \"" + k +
                           "\" (the validator would ignore it; use \"x-" + k +
                           "\" for an annotation)");
      }
    }
  }

  void regex_checked(const std::string& pattern, const std::string& where) const {
    try {
      regex(pattern);
    } catch (const std::invalid_argument& e) {
      schema_fail(where, "invalid regular expression \"" + pattern + "\": " + e.what());
    }
  }

  // ---- validation ---------------------------------------------------------------------------

  void add(Errs& out, const std::string& ptr, std::string msg,
           std::string expected_type = {}) const {
    out.push_back({ptr, std::move(msg), std::move(expected_type), {}});
  }

  Errs validate(const json& s, const json& v, const std::string& ptr, int depth) const {
    Errs out;
    run(s, v, ptr, depth, out);
    return out;
  }

  void run(const json& s, const json& v, const std::string& ptr, int depth, Errs& out) const {
    if (depth > 256) {
      add(out, ptr, "schema recursion too deep");
      return;
    }
    if (s.is_boolean()) {
      if (!s.get<bool>()) add(out, ptr, "is not allowed here, got " + describe(v));
      return;
    }
    if (auto it = s.find("$ref"); it != s.end())
      run(resolve(it->get<std::string>(), ""), v, ptr, depth + 1, out);

    if (auto it = s.find("type"); it != s.end()) {
      const json types = it->is_array() ? *it : json::array({*it});
      bool ok = false;
      std::vector<std::string> phrases;
      for (const auto& t : types) {
        ok = ok || has_type(v, t.get<std::string>());
        phrases.push_back(type_phrase(t.get<std::string>()));
      }
      if (!ok) {
        const std::string expected = join_or(phrases);
        add(out, ptr, "must be " + expected + ", got " + describe(v), expected);
        return;  // the other keywords would only repeat the mismatch
      }
    }
    if (auto it = s.find("const"); it != s.end() && !json_equal(v, *it))
      add(out, ptr, "must be " + short_dump(*it) + ", got " + describe_value(v));
    if (auto it = s.find("enum"); it != s.end()) {
      const bool found =
          std::any_of(it->begin(), it->end(), [&](const json& e) { return json_equal(v, e); });
      if (!found)
        add(out, ptr, "must be one of " + join_values(*it) + ", got " + describe_value(v));
    }
    if (v.is_number()) numeric(s, v, ptr, out);
    if (v.is_string()) string(s, v, ptr, out);
    if (v.is_array()) array(s, v, ptr, depth, out);
    if (v.is_object()) object(s, v, ptr, depth, out);
    combinators(s, v, ptr, depth, out);
  }

  void numeric(const json& s, const json& v, const std::string& ptr, Errs& out) const {
    const double x = v.get<double>();
    auto bound = [&](const char* key, auto violates, const char* op) {
      if (auto it = s.find(key); it != s.end() && violates(x, it->template get<double>()))
        add(out, ptr,
            std::string("must be ") + op + " " + short_dump(*it) + ", got " + short_dump(v));
    };
    bound(
        "minimum", [](double a, double b) { return a < b; }, ">=");
    bound(
        "exclusiveMinimum", [](double a, double b) { return a <= b; }, ">");
    bound(
        "maximum", [](double a, double b) { return a > b; }, "<=");
    bound(
        "exclusiveMaximum", [](double a, double b) { return a >= b; }, "<");
    if (auto it = s.find("multipleOf"); it != s.end()) {
      const double m = it->get<double>();
      const double q = x / m;
      if (!(std::abs(q - std::round(q)) <= 1e-9 * std::max(1.0, std::abs(q))))
        add(out, ptr, "must be a multiple of " + short_dump(*it) + ", got " + short_dump(v));
    }
  }

  void string(const json& s, const json& v, const std::string& ptr, Errs& out) const {
    const std::string& str = v.get_ref<const std::string&>();
    const std::size_t n = utf8_length(str);
    if (auto it = s.find("minLength"); it != s.end() && n < it->get<std::size_t>())
      add(out, ptr,
          "must have at least " + short_dump(*it) + " characters, got " + describe_value(v));
    if (auto it = s.find("maxLength"); it != s.end() && n > it->get<std::size_t>())
      add(out, ptr,
          "must have at most " + short_dump(*it) + " characters, got " + describe_value(v));
    if (auto it = s.find("pattern"); it != s.end()) {
      const std::string& pat = it->get_ref<const std::string&>();
      if (!regex(pat).search(str))
        add(out, ptr, "must match the pattern " + short_dump(*it) + ", got " + describe_value(v));
    }
  }

  void array(const json& s, const json& v, const std::string& ptr, int depth, Errs& out) const {
    const std::size_t n = v.size();
    if (auto it = s.find("minItems"); it != s.end() && n < it->get<std::size_t>())
      add(out, ptr,
          "must have at least " + short_dump(*it) + (*it == 1 ? " item" : " items") + ", got " +
              std::to_string(n));
    if (auto it = s.find("maxItems"); it != s.end() && n > it->get<std::size_t>())
      add(out, ptr, "must have at most " + short_dump(*it) + " items, got " + std::to_string(n));
    if (auto it = s.find("uniqueItems"); it != s.end() && it->is_boolean() && it->get<bool>()) {
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
          if (json_equal(v[i], v[j])) {
            add(out, json_pointer_append(ptr, j),
                "must be unique, but equals item " + std::to_string(i) + ": " + describe(v[j]));
            i = j = n;  // report once
          }
    }
    // Tuple part: prefixItems (2020-12) or the draft-07 array form of items.
    const json* prefix = nullptr;
    const json* rest = nullptr;
    if (auto it = s.find("prefixItems"); it != s.end()) prefix = &*it;
    if (auto it = s.find("items"); it != s.end()) {
      if (it->is_array())
        prefix = &*it;
      else
        rest = &*it;
    }
    if (!rest && s.contains("additionalItems") && s.contains("items") && s["items"].is_array())
      rest = &s["additionalItems"];
    const std::size_t np = prefix ? prefix->size() : 0;
    for (std::size_t i = 0; i < n; ++i) {
      const json* item_schema = i < np ? &(*prefix)[i] : rest;
      if (item_schema) run(*item_schema, v[i], json_pointer_append(ptr, i), depth + 1, out);
    }
  }

  void object(const json& s, const json& v, const std::string& ptr, int depth, Errs& out) const {
    if (auto it = s.find("required"); it != s.end())
      for (const auto& r : *it)
        if (!v.contains(r.get<std::string>()))
          add(out, ptr, "missing required key " + short_dump(r));
    if (auto it = s.find("minProperties"); it != s.end() && v.size() < it->get<std::size_t>())
      add(out, ptr,
          "must have at least " + short_dump(*it) + " keys, got " + std::to_string(v.size()));
    if (auto it = s.find("maxProperties"); it != s.end() && v.size() > it->get<std::size_t>())
      add(out, ptr,
          "must have at most " + short_dump(*it) + " keys, got " + std::to_string(v.size()));

    const json* props = s.contains("properties") ? &s["properties"] : nullptr;
    const json* patterns = s.contains("patternProperties") ? &s["patternProperties"] : nullptr;
    const json* additional =
        s.contains("additionalProperties") ? &s["additionalProperties"] : nullptr;
    for (auto it = v.begin(); it != v.end(); ++it) {
      const std::string& key = it.key();
      const std::string child = json_pointer_append(ptr, key);
      bool matched = false;
      if (props) {
        if (auto p = props->find(key); p != props->end()) {
          matched = true;
          run(*p, it.value(), child, depth + 1, out);
        }
      }
      if (patterns) {
        for (auto p = patterns->begin(); p != patterns->end(); ++p)
          if (regex(p.key()).search(key)) {
            matched = true;
            run(p.value(), it.value(), child, depth + 1, out);
          }
      }
      if (matched || !additional) continue;
      if (additional->is_boolean()) {
        if (!additional->get<bool>()) {
          add(out, ptr, "unknown key " + short_dump(key) + allowed_keys(props, key));
          out.back().at = child;  // locate the key itself, not its object
        }
      } else {
        run(*additional, it.value(), child, depth + 1, out);
      }
    }
  }

  /// The common note (io::unknown_key_note): a close known key, the allowed ones when few.
  static std::string allowed_keys(const json* props, const std::string& key) {
    std::vector<std::string> known;
    if (props)
      for (auto it = props->begin(); it != props->end(); ++it) known.push_back(it.key());
    return unknown_key_note(key, known);
  }

  // Follows $ref chains at the top of a schema (to look at a branch's own keywords).
  const json& deref(const json* s) const {
    for (int i = 0; i < 32 && s->is_object() && s->contains("$ref"); ++i)
      s = &resolve((*s)["$ref"].get<std::string>(), "");
    return *s;
  }

  /// The value a branch requires for property `key` via const (or a one-value enum).
  const json* branch_const(const json& branch, const std::string& key) const {
    const json& b = deref(&branch);
    if (!b.is_object() || !b.contains("properties")) return nullptr;
    const auto& props = b["properties"];
    auto p = props.find(key);
    if (p == props.end()) return nullptr;
    const json& ps = deref(&*p);
    if (!ps.is_object()) return nullptr;
    if (auto c = ps.find("const"); c != ps.end()) return &*c;
    if (auto e = ps.find("enum"); e != ps.end() && e->size() == 1) return &(*e)[0];
    return nullptr;
  }

  /// A property on which every branch has a const (e.g. "type"), if any.
  std::string discriminator(const json& branches) const {
    const json& first = deref(&branches[0]);
    if (!first.is_object() || !first.contains("properties")) return "";
    for (auto it = first["properties"].begin(); it != first["properties"].end(); ++it) {
      const bool all = std::all_of(branches.begin(), branches.end(), [&](const json& b) {
        return branch_const(b, it.key()) != nullptr;
      });
      if (all) return it.key();
    }
    return "";
  }

  void report_best(const json& branches, const std::vector<Errs>& results, const json& v,
                   const std::string& ptr, Errs& out) const {
    // 1. A discriminating const.
    const std::string key = discriminator(branches);
    if (!key.empty() && v.is_object()) {
      if (auto d = v.find(key); d != v.end()) {
        for (std::size_t i = 0; i < branches.size(); ++i)
          if (json_equal(*d, *branch_const(branches[i], key))) {
            out.insert(out.end(), results[i].begin(), results[i].end());
            return;
          }
        json consts = json::array();
        for (const auto& b : branches) consts.push_back(*branch_const(b, key));
        add(out, json_pointer_append(ptr, key),
            "must be one of " + join_values(consts) + ", got " + describe_value(*d));
        return;
      }
      json consts = json::array();
      for (const auto& b : branches) consts.push_back(*branch_const(b, key));
      add(out, ptr,
          "missing required key " + short_dump(key) + " (one of " + join_values(consts) + ")");
      return;
    }
    // 2. Every branch rejects the type only: merge the expected types.
    const bool all_type = std::all_of(results.begin(), results.end(), [&](const Errs& e) {
      return e.size() == 1 && e[0].pointer == ptr && !e[0].expected_type.empty();
    });
    if (all_type) {
      std::vector<std::string> types;
      for (const auto& e : results)
        if (std::find(types.begin(), types.end(), e[0].expected_type) == types.end())
          types.push_back(e[0].expected_type);
      add(out, ptr, "must be " + join_or(types) + ", got " + describe(v), join_or(types));
      return;
    }
    // 3. The branch whose first error lies deepest (ties: fewer errors, then the first branch).
    // An unknown key counts at the key's own depth: an object with a misspelt key, against
    // "false or an object", is reported as the unknown key, not as "must be false".
    auto depth_of = [](const Err& e) { return pointer_depth(e.at.empty() ? e.pointer : e.at); };
    // A branch that rejects the value's type loses to one of its type (session 43's red team:
    // "load_paths": [] said "must be an object, got an array", where a list of at least one
    // path is allowed).
    auto wrong_type = [&](const Errs& e) {
      return e.size() == 1 && e[0].pointer == ptr && !e[0].expected_type.empty();
    };
    std::size_t best = 0;
    for (std::size_t i = 1; i < results.size(); ++i) {
      if (wrong_type(results[i]) != wrong_type(results[best])) {
        if (wrong_type(results[best])) best = i;
        continue;
      }
      const std::size_t di = depth_of(results[i].front());
      const std::size_t db = depth_of(results[best].front());
      if (di > db || (di == db && results[i].size() < results[best].size())) best = i;
    }
    out.insert(out.end(), results[best].begin(), results[best].end());
  }

  void combinators(const json& s, const json& v, const std::string& ptr, int depth,
                   Errs& out) const {
    if (auto it = s.find("allOf"); it != s.end())
      for (const auto& b : *it) run(b, v, ptr, depth + 1, out);
    for (const char* kw : {"anyOf", "oneOf"}) {
      auto it = s.find(kw);
      if (it == s.end()) continue;
      std::vector<Errs> results;
      std::vector<std::size_t> passing;
      for (std::size_t i = 0; i < it->size(); ++i) {
        results.push_back(validate((*it)[i], v, ptr, depth + 1));
        if (results.back().empty()) passing.push_back(i);
      }
      if (passing.empty())
        report_best(*it, results, v, ptr, out);
      else if (std::string(kw) == "oneOf" && passing.size() > 1)
        add(out, ptr,
            "must match exactly one alternative of oneOf, but matches #" +
                std::to_string(passing[0]) + " and #" + std::to_string(passing[1]));
    }
    if (auto it = s.find("not"); it != s.end() && validate(*it, v, ptr, depth + 1).empty())
      add(out, ptr, "must not match the schema under \"not\", got " + describe(v));
    if (auto it = s.find("if"); it != s.end()) {
      const bool cond = validate(*it, v, ptr, depth + 1).empty();
      const char* branch = cond ? "then" : "else";
      if (auto b = s.find(branch); b != s.end()) run(*b, v, ptr, depth + 1, out);
    }
  }
};

JsonSchema::JsonSchema(const nlohmann::json& schema, std::string name)
    : impl_(std::make_unique<Impl>()) {
  impl_->root = schema;
  impl_->name = std::move(name);
  impl_->check(impl_->root, "");
}

JsonSchema::JsonSchema(JsonSchema&&) noexcept = default;
JsonSchema& JsonSchema::operator=(JsonSchema&&) noexcept = default;
JsonSchema::~JsonSchema() = default;

const std::string& JsonSchema::name() const {
  return impl_->name;
}

std::vector<SchemaError> JsonSchema::errors(const nlohmann::json& instance) const {
  const auto errs = impl_->validate(impl_->root, instance, "", 0);
  std::vector<SchemaError> out;
  out.reserve(errs.size());
  for (const auto& e : errs) out.push_back({e.pointer, e.message, e.at.empty() ? e.pointer : e.at});
  return out;
}

void JsonSchema::validate(const nlohmann::json& instance, const std::string& file) const {
  const auto errs = impl_->validate(impl_->root, instance, "", 0);
  if (!errs.empty()) throw knit::InputError(file, errs.front().pointer, errs.front().message);
}

JsonSchema JsonSchema::from_file(const std::filesystem::path& file) {
  return JsonSchema(read_json_file(file), file.filename().string());
}

const JsonSchema& JsonSchema::embedded(const std::string& name) {
  static std::mutex m;
  static std::map<std::string, std::unique_ptr<JsonSchema>> cache;
  std::lock_guard<std::mutex> lock(m);
  auto it = cache.find(name);
  if (it == cache.end()) {
    const std::string& text = embedded_schema(name);
    auto schema = std::make_unique<JsonSchema>(parse_json(text, "schema " + name), name);
    it = cache.emplace(name, std::move(schema)).first;
  }
  return *it->second;
}

}  // namespace knit::io
