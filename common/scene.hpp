// Scenes: one JSON file that says what to simulate. Every dimensional value is a string
// "<number> <unit>"; the readers below convert it once to SI and record every value they
// used -- the given one or the default -- into a resolved scene that is echoed into each
// output folder (and is itself a valid scene).
//
// Errors are swim::InputError naming the full key path, the value and what is allowed.
#pragma once

#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace swim::scene {

using json = nlohmann::ordered_json;

/// Read a scene file. Syntax errors and a missing file are InputErrors naming the file.
json load_file(const std::string& path);

/// Apply "key.path=value" to a scene. The value is read as JSON when it parses as JSON
/// (numbers, true/false, objects), else as a string ("0.2 um"). "key=null" removes the key. Intermediate objects are
/// created; a path through a non-object is an InputError.
void apply_override(json& scene, const std::string& assignment);

/// Value bounds for numbers and quantities (SI).
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Range non_negative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
  static Range open(double a, double b) { return {a, b, true, true}; }
  static Range closed(double a, double b) { return {a, b, false, false}; }
  bool contains(double v) const;
  std::string describe(const std::string& unit) const;
};

/// A cursor over one object of a scene. Each accessor reads one key (or its default),
/// validates it and writes the value used into the resolved scene; finish() rejects every
/// key that no accessor asked for.
class Reader {
 public:
  /// `node` must outlive the reader; `resolved` receives the values used (an object).
  Reader(const json& node, std::string path, json& resolved);

  /// A quantity "<number> <unit>" converted to `si_unit`. Empty default = required.
  double quantity(const std::string& key, const std::string& si_unit, const std::string& default_text,
                  Range range = {});
  double number(const std::string& key, double default_value, Range range = {});
  long integer(const std::string& key, long default_value, long lo, long hi);
  bool boolean(const std::string& key, bool default_value);
  std::string choice(const std::string& key, const std::string& default_value,
                     const std::vector<std::string>& allowed);
  std::string text(const std::string& key, const std::string& default_value);
  /// A sub-object (an empty one when absent). Finish the child before finishing the parent.
  Reader child(const std::string& key);
  /// Accept the key as is (echoed unchanged, not validated here), e.g. another tier's section.
  void pass_through(const std::string& key);

  bool has(const std::string& key) const;
  /// The value given for a key that `has` (as written in the scene), for messages and tests.
  const json& given(const std::string& key) const;
  /// Full dotted path of a key of this object, for messages.
  std::string path(const std::string& key) const;
  /// Throw InputError for the first key present in the scene that was not read.
  void finish() const;

 private:
  const json* node_;
  std::string path_;
  json* resolved_;
  std::vector<std::string> known_;
  void mark(const std::string& key);
};

/// JSON value as short text for messages.
std::string show(const json& value);

/// The keys and value kinds of a section another tier reads, so that a tier that only
/// passes the section through still rejects a malformed one (the resolved scene must run on
/// both tiers). `schema` is an object: key -> nested object (a sub-section) or a kind
/// string: "quantity:<SI unit>", "number", "integer", "integer_or_auto" (an integer or the
/// string "auto"), "boolean", "text" or
/// "choice:<a>|<b>|...". A quantity, number or integer may end in "@<range>": "@positive",
/// "@non_negative", or an interval "@(a,b)", "@[a,b]", "@(a,b]", "@[a,b)" (SI values), the
/// range the owning tier's reader accepts. Values are checked for kind, unit, choice and range.
/// Throws InputError naming the full key (`path`.key).
void check_section(const json& node, const std::string& path, const json& schema);

/// A scene `name` becomes a folder name under out/: 1 to 100 characters of letters,
/// digits, '.', '_', '-' and '+', not starting with '.' or '-'. Throws InputError("name").
void check_name(const std::string& name);

/// The `output` section, read by both tiers: limits on what a run may write.
struct OutputLimits {
  long long max_bytes = 1000000000;  ///< output.max_bytes: refuse runs whose estimated output is larger
};
/// Reads (and finishes) the `output` section of `top`.
OutputLimits read_output(Reader& top);
/// The `output` section of a scene, read on its own (the tiers read it with the rest).
OutputLimits output_limits(const json& scene);

}  // namespace swim::scene
