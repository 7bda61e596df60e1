// JSON input: reading files with precise parse errors, and validation against JSON Schemas
// (a subset of draft 2020-12) embedded into the binary at build time.
//
//   nlohmann::json c = knit::io::load_and_validate(path, "case");   // schemas/case.schema.json
//
// Errors are knit::InputError(file, json_pointer, message), one line each:
//   case.json: invalid JSON at line 3, column 14: syntax error ... (pointer "")
//   case.json: /geometry/thickness: must be > 0, got -1 (line 7)
//   case.json: /boundary_conditions/2/edge: must be one of "u0", "u1", "v0", "v1", got "u2"
//   case.json: /material: unknown key "Young" (allowed: "E", "nu") (line 9)
//   case.json: /geometry: unknown key "thicknes" (did you mean "thickness"?) (line 5)
// (load_and_validate adds the line; JsonSchema::validate, which has no text, does not).
//
// Supported keywords: type (string or array; "integer" = number with no fraction), enum,
// const, properties, required, additionalProperties (bool or schema), patternProperties,
// minProperties, maxProperties, items (schema, or the draft-07 array form), prefixItems,
// minItems, maxItems, uniqueItems, minimum, maximum, exclusiveMinimum, exclusiveMaximum,
// multipleOf, minLength, maxLength, pattern (ECMAScript, unanchored search), allOf, anyOf,
// oneOf, not, if/then/else, $ref to "#", "#/$defs/..." or "#/definitions/..." (other keywords
// next to $ref apply too), boolean schemas. Annotations are ignored: title, description,
// default, examples, $schema, $id, $comment, $anchor, format, deprecated, readOnly, writeOnly,
// and any key starting with "x-" (use e.g. "x-unit": "mm"). Any other keyword makes the SCHEMA
// invalid (std::logic_error when it is loaded), so a schema never silently means less than
// its author thought.
//
// oneOf/anyOf with no matching branch report the most relevant branch: the one whose `const`
// on a property (a discriminator such as "type") matches the instance; with a discriminator
// that matches no branch, "must be one of <the consts>"; otherwise the branch whose first
// error lies deepest. If every branch fails only on its type, the types are merged ("must be
// a number or an object, got ...").
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "knit/core/errors.hpp"

namespace knit::io {

// ---- reading ---------------------------------------------------------------------------------

/// Deepest nesting of arrays/objects accepted in a JSON input (ours need < 10). Deeper text
/// is refused before it is parsed, so nothing recursive ever sees it.
inline constexpr std::size_t kMaxJsonDepth = 256;

/// Parses a JSON file: a regular file of at most kMaxJsonInputBytes (knit/io/input_file.hpp).
/// Throws knit::InputError(file, "", "file not found" / "not a regular file (a FIFO)...") or
/// (file, "", "invalid JSON at line L, column C: <what>").
nlohmann::json read_json_file(const std::filesystem::path& file);
/// Parses JSON text; `source` names it in errors. Besides syntax errors (line, column), these
/// are InputErrors too: nesting deeper than kMaxJsonDepth (line, column), a number outside the
/// range of a double such as 1e400 (its JSON pointer, line and column), a duplicate key.
nlohmann::json parse_json(std::string_view text, const std::string& source);

/// A path written inside an input file: absolute as is, relative ones are taken relative to the
/// directory of that input file (so a case runs the same from any working directory).
std::filesystem::path resolve_input_path(const std::filesystem::path& input_file,
                                         const std::string& value);

// ---- JSON pointers (RFC 6901) ------------------------------------------------------------------

/// Escapes one reference token: "~" -> "~0", "/" -> "~1".
std::string json_pointer_escape(std::string_view token);
/// parent + "/" + escaped token.
std::string json_pointer_append(const std::string& parent, std::string_view token);
std::string json_pointer_append(const std::string& parent, std::size_t index);

// ---- embedded schemas --------------------------------------------------------------------------

/// Text of schemas/<name>.schema.json (or schemas/<name>.json) as embedded at build time.
/// Throws std::out_of_range naming the available schemas if there is none.
const std::string& embedded_schema(const std::string& name);
/// Names of all embedded schemas, sorted.
std::vector<std::string> embedded_schema_names();

// ---- validation --------------------------------------------------------------------------------

struct SchemaError {
  std::string pointer;  ///< JSON pointer into the instance ("" = the whole document)
  std::string message;  ///< what is expected and what was found
  /// Pointer of the value the error is about: = pointer, except for an unknown key, where it
  /// is the key's own pointer (used to find the line in the input text).
  std::string at;
};

class JsonSchema {
 public:
  /// `name` appears in schema-definition errors. Checks the schema itself (supported
  /// keywords, resolvable $refs, regexes); throws std::logic_error if it is not usable.
  JsonSchema(const nlohmann::json& schema, std::string name);
  /// The embedded schema `name` (parsed and checked once, then cached).
  static const JsonSchema& embedded(const std::string& name);
  /// Reads a schema from a file (tests, tools).
  static JsonSchema from_file(const std::filesystem::path& file);
  JsonSchema(JsonSchema&&) noexcept;
  JsonSchema& operator=(JsonSchema&&) noexcept;
  ~JsonSchema();

  const std::string& name() const;
  /// All violations, in document order (empty = valid).
  std::vector<SchemaError> errors(const nlohmann::json& instance) const;
  /// Throws knit::InputError(file, pointer, message) for the first violation.
  void validate(const nlohmann::json& instance, const std::string& file) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The known key closest to a misspelt `key` (Levenshtein distance, case-insensitive, at most
/// max(1, min(2, |key| / 3))), or "" when none is that close: the "did you mean" of the schema
/// reader and of the hand-written readers (the case loader).
std::string closest_key(const std::string& key, const std::vector<std::string>& known);

/// What follows "unknown key" in every reader's message, one wording for all of them (the
/// schema reader, the case, material, design and rod readers): ` (did you mean "x"? allowed:
/// "a", "b")`. The suggestion is closest_key's; the allowed keys are listed when there are at
/// most kMaxListedKeys of them. "" when there is neither.
inline constexpr std::size_t kMaxListedKeys = 16;
std::string unknown_key_note(const std::string& key, const std::vector<std::string>& known);

/// The first member of the object `j` whose key is not in `allowed`, as the hand-written
/// readers report it (the case, material, design, rod and cell readers and the fit options):
/// the key, its JSON pointer under `pointer`, escaped as RFC 6901 says ("a/b" -> "a~1b", so
/// the pointer names the member and its line can be found), and unknown_key_note. nullopt
/// when every key is allowed (or `j` is not an object). One loop for every reader (session 27:
/// four readers appended the raw key, "/material/x/y" for the key "x/y"). The case, material,
/// design and fit-option readers name the member's pointer; the rod and cell readers word it
/// as their schemas do (the object's pointer, the key quoted).
/// JSON Schema's "integer": a number with no fraction, 2 as well as 2.0 (draft 2020-12, section
/// 6.1.1 of the validation vocabulary). The schema validator and every hand-written reader of an
/// integer use this one predicate (session 38: the readers refused "steps": 2.0, which the
/// schemas accept).
bool json_is_integer(const nlohmann::json& j);
/// The value of a json_is_integer number as a long long, saturated at the type's limits
/// (18446744073709551615 and 1e300 give LLONG_MAX), so that a range check on the result
/// refuses what lies beyond and never narrows silently (get<int>() of 4294967297 gave 1: issue
/// 14). Precondition: json_is_integer(j).
long long json_integer_saturated(const nlohmann::json& j);

struct UnknownKey {
  std::string key;
  std::string pointer;
  std::string note;
};
std::optional<UnknownKey> find_unknown_key(const nlohmann::json& j, const std::string& pointer,
                                           const std::vector<std::string>& allowed);

/// `message` + " (line N)", N the line of the first of `pointers` found in the JSON `text`
/// (json_pointer_lines); `message` unchanged when none is found, when it already names a line,
/// or when the document is on one line (a generated file gains nothing from "(line 1)").
std::string with_line(std::string_view text, const std::vector<std::string>& pointers,
                      std::string message);

/// For a reader of the JSON file `file` whose text is `text`: `e` with the line of its pointer
/// added (with_line), or nullopt when `e` names another file, no pointer, or no line is found
/// (rethrow `e` as it is then). Used as `catch (const InputError& e) { if (auto l =
/// error_with_line(e, text, file)) throw *l; throw; }` by the case and design loaders.
std::optional<knit::InputError> error_with_line(const knit::InputError& e, std::string_view text,
                                                const std::string& file);

/// Line (1-based) where each value starts in JSON text, by JSON pointer ("" = the root). For
/// object members, the line of the key. The text must be valid JSON.
std::map<std::string, int> json_pointer_lines(std::string_view text);

/// read_json_file + validation against the embedded schema `schema_name`. A validation error
/// is InputError(path, pointer, message + " (line N)").
nlohmann::json load_and_validate(const std::filesystem::path& path, const std::string& schema_name);
/// The same with a schema object (tests, tools).
nlohmann::json load_and_validate(const std::filesystem::path& path, const JsonSchema& schema);

}  // namespace knit::io
