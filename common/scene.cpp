#include "common/scene.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "common/strict_json.hpp"
#include "common/units.hpp"

namespace swim::scene {
namespace {

const json& empty_object() {
  static const json e = json::object();
  return e;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s;
}

}  // namespace

std::string show(const json& value) {
  // Scalars are cut before dumping (a megabyte string is never copied twice); invalid
  // UTF-8 (only possible in values built in the program) is replaced, never thrown on.
  if (value.is_string() && value.get_ref<const std::string&>().size() > 200)
    return json(value.get_ref<const std::string&>().substr(0, 200))
               .dump(-1, ' ', false, json::error_handler_t::replace) + "... (" +
           std::to_string(value.get_ref<const std::string&>().size()) + " bytes)";
  std::string s = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > 80) s = message_text(s, 77);
  return s;
}

json load_file(const std::string& path) {
  json j = strict_json::parse_file(path, "scene");
  if (!j.is_object()) throw InputError("scene", "\"" + path + "\"", "the top level must be a JSON object");
  return j;
}

void apply_override(json& scene, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set", "\"" + assignment + "\"", "expected key.path=value, e.g. --set swimmer.length=\"0.2 um\"");
  const std::string key = assignment.substr(0, eq);
  const std::string value_text = assignment.substr(eq + 1);
  if (size_t bad = 0; !valid_utf8(assignment, &bad))
    throw InputError("--set", "\"" + assignment + "\"",
                     "is not UTF-8 text (bad byte at offset " + std::to_string(bad) + ")");
  std::vector<std::string> parts;
  for (size_t a = 0;;) {  // "a..b", ".a" and "a." have empty components
    const size_t b = key.find('.', a);
    parts.push_back(key.substr(a, b == std::string::npos ? std::string::npos : b - a));
    if (b == std::string::npos) break;
    a = b + 1;
  }
  for (const auto& part : parts)
    if (part.empty())
      throw InputError("--set", "\"" + assignment + "\"",
                       "empty component in the key path; expected key.path=value with non-empty names between the dots");
  // The value is JSON when it reads as JSON (numbers, true/false, objects), else a string
  // ("0.2 um"). JSON that is well-formed but breaks the strict rules (duplicate keys, 1e400,
  // depth) is an error, not a string.
  json value;
  try {
    value = strict_json::parse(value_text, key);
  } catch (const InputError& e) {
    const std::string m = e.what();
    if (m.find("is not valid JSON") == std::string::npos) throw;
    value = value_text;
  }
  json* node = &scene;
  std::string walked;
  for (size_t i = 0; i < parts.size(); ++i) {
    walked += (i ? "." : "") + parts[i];
    if (!node->is_object())
      throw InputError(walked, show(*node), "is not an object, so --set " + key + " cannot be applied");
    if (i + 1 == parts.size()) {
      if (value.is_null())
        node->erase(parts[i]);  // key=null removes the key: its default applies again
      else
        (*node)[parts[i]] = value;
    } else {
      if (!node->contains(parts[i])) (*node)[parts[i]] = json::object();
      node = &(*node)[parts[i]];
    }
  }
}

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (lo_open ? !(v > lo) : !(v >= lo)) return false;
  if (hi_open ? !(v < hi) : !(v <= hi)) return false;
  return true;
}

std::string Range::describe(const std::string& unit) const {
  const std::string u = unit.empty() ? "" : " " + unit;
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi)
    return std::string("must lie in ") + (lo_open ? "(" : "[") + significant(lo) + ", " + significant(hi) + (hi_open ? ")" : "]") + u;
  if (has_lo) return std::string("must be ") + (lo_open ? "> " : ">= ") + significant(lo) + u;
  if (has_hi) return std::string("must be ") + (hi_open ? "< " : "<= ") + significant(hi) + u;
  return "must be finite";
}

Reader::Reader(const json& node, std::string path, json& resolved)
    : node_(&node), path_(std::move(path)), resolved_(&resolved) {
  if (!node_->is_object()) {
    throw InputError(path_, show(*node_), "must be a JSON object");
  }
  if (!resolved_->is_object()) *resolved_ = json::object();
}

std::string Reader::path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

bool Reader::has(const std::string& key) const { return node_->contains(key); }

const json& Reader::given(const std::string& key) const { return node_->at(key); }

void Reader::mark(const std::string& key) {
  if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.push_back(key);
}

double Reader::quantity(const std::string& key, const std::string& si_unit, const std::string& default_text,
                        Range range) {
  mark(key);
  std::string text = default_text;
  if (has(key)) {
    const json& v = node_->at(key);
    if (!v.is_string())
      throw InputError(path(key), show(v),
                       "must be a string \"<number> <unit>\" with a unit convertible to " + si_unit +
                           (v.is_number() ? " (the unit is missing)" : ""));
    text = v.get<std::string>();
  } else if (default_text.empty()) {
    throw InputError(path(key), "(missing)", "is required: a quantity in units convertible to " + si_unit);
  }
  const auto q = units::parse(path(key), text, si_unit);
  if (!range.contains(q.si))
    throw InputError(path(key), "\"" + text + "\"", range.describe(si_unit) + " (got " + significant(q.si) + " " + si_unit + ")");
  (*resolved_)[key] = text;
  return q.si;
}

double Reader::number(const std::string& key, double default_value, Range range) {
  mark(key);
  double v = default_value;
  if (has(key)) {
    const json& j = node_->at(key);
    if (!j.is_number()) throw InputError(path(key), show(j), "must be a number (dimensionless)");
    v = j.get<double>();
  }
  if (!range.contains(v)) throw InputError(path(key), significant(v), range.describe(""));
  (*resolved_)[key] = v;
  return v;
}

long Reader::integer(const std::string& key, long default_value, long lo, long hi) {
  mark(key);
  long v = default_value;
  if (has(key)) {
    const json& j = node_->at(key);
    if (!j.is_number_integer() ||
        (j.is_number_unsigned() && j.get<json::number_unsigned_t>() > static_cast<json::number_unsigned_t>(hi)))
      throw InputError(path(key), show(j), "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    v = j.get<long>();
  }
  if (v < lo || v > hi)
    throw InputError(path(key), std::to_string(v), "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  (*resolved_)[key] = v;
  return v;
}

bool Reader::boolean(const std::string& key, bool default_value) {
  mark(key);
  bool v = default_value;
  if (has(key)) {
    const json& j = node_->at(key);
    if (!j.is_boolean()) throw InputError(path(key), show(j), "must be true or false");
    v = j.get<bool>();
  }
  (*resolved_)[key] = v;
  return v;
}

std::string Reader::choice(const std::string& key, const std::string& default_value,
                           const std::vector<std::string>& allowed) {
  mark(key);
  std::string v = default_value;
  if (has(key)) {
    const json& j = node_->at(key);
    if (!j.is_string()) throw InputError(path(key), show(j), "must be one of: " + join(allowed));
    v = j.get<std::string>();
  }
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end())
    throw InputError(path(key), "\"" + v + "\"", "must be one of: " + join(allowed));
  (*resolved_)[key] = v;
  return v;
}

std::string Reader::text(const std::string& key, const std::string& default_value) {
  mark(key);
  std::string v = default_value;
  if (has(key)) {
    const json& j = node_->at(key);
    if (!j.is_string()) throw InputError(path(key), show(j), "must be a string");
    v = j.get<std::string>();
  }
  (*resolved_)[key] = v;
  return v;
}

Reader Reader::child(const std::string& key) {
  mark(key);
  const json& n = has(key) ? node_->at(key) : empty_object();
  if (!n.is_object()) throw InputError(path(key), show(n), "must be a JSON object");
  json& r = (*resolved_)[key];
  if (!r.is_object()) r = json::object();
  return Reader(n, path(key), r);
}

void Reader::pass_through(const std::string& key) {
  mark(key);
  if (has(key)) (*resolved_)[key] = node_->at(key);
}

namespace {
/// The range of a schema kind's "@<range>" suffix: "positive", "non_negative", or an interval
/// "(a,b)", "[a,b]", "(a,b]", "[a,b)"; none: any finite value.
Range schema_range(const std::string& spec, const std::string& key) {
  if (spec.empty()) return {};
  if (spec == "positive") return Range::positive();
  if (spec == "non_negative") return Range::non_negative();
  const size_t comma = spec.find(',');
  if (spec.size() < 5 || comma == std::string::npos || (spec.front() != '(' && spec.front() != '[') ||
      (spec.back() != ')' && spec.back() != ']'))
    throw std::logic_error("internal: bad range '" + spec + "' in the section schema of " + key);
  Range r;
  r.lo = std::stod(spec.substr(1, comma - 1));
  r.hi = std::stod(spec.substr(comma + 1, spec.size() - comma - 2));
  r.lo_open = spec.front() == '(';
  r.hi_open = spec.back() == ')';
  return r;
}
}  // namespace

void check_section(const json& node, const std::string& path, const json& schema) {
  if (!node.is_object()) throw InputError(path, show(node), "must be a JSON object");
  std::vector<std::string> keys;
  for (auto it = schema.begin(); it != schema.end(); ++it) keys.push_back(it.key());
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = path + "." + it.key();
    if (!schema.contains(it.key()))
      throw InputError(key, show(it.value()), "unknown key; allowed here: " + join(keys));
    const json& kind = schema.at(it.key());
    const json& v = it.value();
    if (kind.is_object()) {
      check_section(v, key, kind);
      continue;
    }
    const std::string spec = kind.get<std::string>();
    const size_t at = spec.find('@');
    const std::string k = spec.substr(0, at);
    const Range range = schema_range(at == std::string::npos ? "" : spec.substr(at + 1), key);
    if (k.rfind("quantity:", 0) == 0) {
      const std::string unit = k.substr(9);
      if (!v.is_string())
        throw InputError(key, show(v), "must be a string \"<number> <unit>\" with a unit convertible to " + unit);
      const auto q = units::parse(key, v.get<std::string>(), unit);
      if (!range.contains(q.si))
        throw InputError(key, show(v), range.describe(unit) + " (got " + significant(q.si) + " " + unit + ")");
    } else if (k == "number") {
      if (!v.is_number()) throw InputError(key, show(v), "must be a number (dimensionless)");
      if (!range.contains(v.get<double>())) throw InputError(key, show(v), range.describe(""));
    } else if (k == "integer" || k == "integer_or_auto") {
      if (k == "integer_or_auto" && v.is_string() && v.get<std::string>() == "auto") continue;
      if (!v.is_number_integer())
        throw InputError(key, show(v), k == "integer" ? "must be an integer" : "must be an integer or \"auto\"");
      if (!range.contains(v.get<double>())) throw InputError(key, show(v), range.describe(""));
    } else if (k == "boolean") {
      if (!v.is_boolean()) throw InputError(key, show(v), "must be true or false");
    } else if (k == "text") {
      if (!v.is_string()) throw InputError(key, show(v), "must be a string");
    } else if (k.rfind("choice:", 0) == 0) {
      std::vector<std::string> allowed;
      for (size_t a = 7;;) {
        const size_t b = k.find('|', a);
        allowed.push_back(k.substr(a, b == std::string::npos ? std::string::npos : b - a));
        if (b == std::string::npos) break;
        a = b + 1;
      }
      if (!v.is_string() || std::find(allowed.begin(), allowed.end(), v.get<std::string>()) == allowed.end())
        throw InputError(key, show(v), "must be one of: " + join(allowed));
    } else {
      throw std::logic_error("internal: unknown kind '" + k + "' in the section schema of " + key);
    }
  }
}

void check_name(const std::string& name) {
  const auto ok = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' || c == '+';
  };
  if (name.empty() || name.size() > 100 || name[0] == '.' || name[0] == '-' ||
      !std::all_of(name.begin(), name.end(), ok))
    throw InputError("name", "\"" + name + "\"",
                     "must be 1 to 100 characters of letters, digits, '.', '_', '-' and '+', not starting with '.' "
                     "or '-' (it names the output folder under out/)");
}

OutputLimits read_output(Reader& top) {
  OutputLimits o;
  Reader r = top.child("output");
  o.max_bytes = r.integer("max_bytes", o.max_bytes, 1000, 1000000000000000L);
  r.finish();
  return o;
}

OutputLimits output_limits(const json& scene) {
  json resolved = json::object();
  Reader top(scene, "", resolved);
  return read_output(top);
}

void Reader::finish() const {
  for (auto it = node_->begin(); it != node_->end(); ++it) {
    if (std::find(known_.begin(), known_.end(), it.key()) == known_.end())
      throw InputError(path(it.key()), show(it.value()),
                       "unknown key" + std::string(known_.empty() ? "" : "; allowed here: " + join(known_)));
  }
}

}  // namespace swim::scene
