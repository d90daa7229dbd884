#include "common/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "common/errors.hpp"
#include "common/units.hpp"

namespace swim::scene {
namespace {

const json& empty_object() {
  static const json e = json::object();
  return e;
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s;
}

}  // namespace

std::string show(const json& value) {
  std::string s = value.dump();
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s;
}

json load_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("scene", "\"" + path + "\"", "file cannot be opened; give an existing JSON scene file");
  try {
    json j = json::parse(in, nullptr, true, /*ignore_comments=*/false);
    if (!j.is_object()) throw InputError("scene", "\"" + path + "\"", "the top level must be a JSON object");
    return j;
  } catch (const json::parse_error& e) {
    throw InputError("scene", "\"" + path + "\"", std::string("is not valid JSON: ") + e.what());
  }
}

void apply_override(json& scene, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set", "\"" + assignment + "\"", "expected key.path=value, e.g. --set swimmer.length=\"0.2 um\"");
  const std::string key = assignment.substr(0, eq);
  const std::string value_text = assignment.substr(eq + 1);
  json value;
  try {
    value = json::parse(value_text);
  } catch (const json::parse_error&) {
    value = value_text;
  }
  json* node = &scene;
  std::stringstream ss(key);
  std::string part, walked;
  std::vector<std::string> parts;
  while (std::getline(ss, part, '.')) parts.push_back(part);
  for (size_t i = 0; i < parts.size(); ++i) {
    if (parts[i].empty()) throw InputError("--set", "\"" + assignment + "\"", "empty component in key path");
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
    return std::string("must lie in ") + (lo_open ? "(" : "[") + fmt(lo) + ", " + fmt(hi) + (hi_open ? ")" : "]") + u;
  if (has_lo) return std::string("must be ") + (lo_open ? "> " : ">= ") + fmt(lo) + u;
  if (has_hi) return std::string("must be ") + (hi_open ? "< " : "<= ") + fmt(hi) + u;
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
    throw InputError(path(key), "\"" + text + "\"", range.describe(si_unit) + " (got " + fmt(q.si) + " " + si_unit + ")");
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
  if (!range.contains(v)) throw InputError(path(key), fmt(v), range.describe(""));
  (*resolved_)[key] = v;
  return v;
}

long Reader::integer(const std::string& key, long default_value, long lo, long hi) {
  mark(key);
  long v = default_value;
  if (has(key)) {
    const json& j = node_->at(key);
    if (!j.is_number_integer())
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

void Reader::finish() const {
  for (auto it = node_->begin(); it != node_->end(); ++it) {
    if (std::find(known_.begin(), known_.end(), it.key()) == known_.end())
      throw InputError(path(it.key()), show(it.value()),
                       "unknown key" + std::string(known_.empty() ? "" : "; allowed here: " + join(known_)));
  }
}

}  // namespace swim::scene
