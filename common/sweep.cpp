#include "common/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <tuple>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "common/units.hpp"

namespace swim::sweep {
namespace {

constexpr std::size_t kMaxDesigns = 1000000;

/// SI value of a numeric or quantity scene value, for the CSV and plots.
std::pair<double, std::string> si_of(const std::string& key, const json& v) {
  if (v.is_number()) return {v.get<double>(), ""};
  return units::to_base(key, v.get<std::string>());
}

Axis read_axis(const std::string& key, const json& spec) {
  const std::string where = "vary." + key;
  Axis a;
  a.key = key;
  if (spec.is_array()) {
    a.values.assign(spec.begin(), spec.end());
  } else if (spec.is_object() && spec.contains("values")) {
    if (!spec["values"].is_array() || spec["values"].empty())
      throw InputError(where + ".values", scene::show(spec["values"]), "must be a non-empty list of scene values");
    for (auto it = spec.begin(); it != spec.end(); ++it)
      if (it.key() != "values") throw InputError(where + "." + it.key(), scene::show(it.value()), "unknown key; allowed: values");
    a.values.assign(spec["values"].begin(), spec["values"].end());
  } else if (spec.is_object() && spec.contains("from")) {
    for (auto it = spec.begin(); it != spec.end(); ++it)
      if (it.key() != "from" && it.key() != "to" && it.key() != "count" && it.key() != "spacing")
        throw InputError(where + "." + it.key(), scene::show(it.value()), "unknown key; allowed: from, to, count, spacing");
    if (!spec.contains("to")) throw InputError(where + ".to", "(missing)", "a range needs from, to and count");
    if (!spec.contains("count") || !spec["count"].is_number_integer() || spec["count"].get<long>() < 1 ||
        spec["count"].get<long>() > 100000)
      throw InputError(where + ".count", spec.contains("count") ? scene::show(spec["count"]) : "(missing)",
                       "must be an integer in [1, 100000]");
    const long n = spec["count"].get<long>();
    if (spec.contains("spacing") && !spec["spacing"].is_string())
      throw InputError(where + ".spacing", scene::show(spec["spacing"]), "must be one of: \"linear\", \"log\"");
    const std::string spacing = spec.value("spacing", std::string("linear"));
    if (spacing != "linear" && spacing != "log")
      throw InputError(where + ".spacing", "\"" + spacing + "\"", "must be one of: linear, log");
    double from = 0, to = 0;
    std::string unit;
    const json &f = spec["from"], &t = spec["to"];
    if (f.is_number() && t.is_number()) {
      from = f.get<double>();
      to = t.get<double>();
    } else if (f.is_string() && t.is_string()) {
      auto [v, u] = units::split(where + ".from", f.get<std::string>());
      from = v;
      unit = u;
      to = units::parse(where + ".to", t.get<std::string>(), unit).si;  // "to" expressed in from's unit
    } else {
      throw InputError(where, scene::show(spec), "from and to must both be numbers or both be quantity strings");
    }
    if (spacing == "log" && !(from > 0 && to > 0))
      throw InputError(where + ".from", scene::show(f), "log spacing needs positive from and to");
    // every value of the range a normal double (no overflow to inf, no NaN, no subnormal)
    auto normal = [](double v) { return v == 0 || std::isnormal(v); };
    if (!normal(from) || !normal(to))
      throw InputError(where, scene::show(spec),
                       "from and to must be finite numbers of normal size (0, or between 2.2e-308 and 1.8e308 in "
                       "magnitude)");
    for (long i = 0; i < n; ++i) {
      const double s = n == 1 ? 0.0 : double(i) / double(n - 1);
      const double v = spacing == "log" ? from * std::pow(to / from, s) : from + (to - from) * s;
      // The values go into scenes and printouts as written: rounded to 8 significant digits,
      // so that 0.35 + 0.1 reads 0.45 (not 0.44999999999999996) in designs.csv and screen.json.
      const std::string text = significant(v, 8);
      const double rounded = std::strtod(text.c_str(), nullptr);
      if (!std::isfinite(v) || !normal(rounded))
        throw InputError(where, scene::show(spec),
                         "a range whose every value is a finite number of normal size; value " + std::to_string(i) +
                             " is " + text);
      if (unit.empty())
        a.values.push_back(rounded);
      else
        a.values.push_back(text + " " + unit);
    }
  } else {
    throw InputError(where, scene::show(spec),
                     "must be a list of values, {\"values\": [...]} or {\"from\": .., \"to\": .., \"count\": n}");
  }
  if (a.values.empty()) throw InputError(where, scene::show(spec), "gives no values");
  // Quantities and numbers map to SI; anything else (choices such as "step", null,
  // booleans) is categorical and is represented by its position in the list.
  bool categorical = false;
  for (const auto& v : a.values) {
    if (v.is_number()) continue;
    if (!v.is_string()) {
      categorical = true;
      break;
    }
    try {
      units::split(where, v.get<std::string>());
    } catch (const InputError&) {
      categorical = true;
      break;
    }
  }
  for (size_t i = 0; i < a.values.size(); ++i) {
    if (categorical) {
      a.si.push_back(static_cast<double>(i));
      a.si_unit = "index";
    } else {
      auto [s, u] = si_of(where, a.values[i]);
      a.si.push_back(s);
      a.si_unit = u;
    }
  }
  return a;
}

}  // namespace

size_t Sweep::count() const {
  size_t n = 1;
  for (const auto& a : axes) n *= a.values.size();  // read_sweep refuses a product above kMaxDesigns
  return n;
}

std::vector<size_t> Sweep::indices(size_t index) const {
  std::vector<size_t> idx(axes.size());
  for (size_t k = axes.size(); k-- > 0;) {
    idx[k] = index % axes[k].values.size();
    index /= axes[k].values.size();
  }
  return idx;
}

json Sweep::design(size_t index) const {
  json s = base;
  const auto idx = indices(index);
  for (size_t k = 0; k < axes.size(); ++k) scene::apply_override(s, axes[k].key + "=" + axes[k].values[idx[k]].dump());
  return s;
}

std::pair<json, std::string> read_base(const json& file, const std::string& dir_name, const std::string& what) {
  namespace fs = std::filesystem;
  const fs::path dir(dir_name);
  if (!file.contains("base")) throw InputError("base", "(missing)", "a " + what + " needs a base scene (path or object)");
  const json& base = file["base"];
  std::pair<json, std::string> r;
  if (base.is_string()) {
    fs::path b = dir / base.get<std::string>();
    if (!fs::exists(b)) b = base.get<std::string>();
    r = {scene::load_file(b.string()), b.parent_path().string()};
  } else if (base.is_object()) {
    r = {base, dir.string()};
  } else {
    throw InputError("base", scene::show(base), "must be a scene file path or an inline scene object");
  }
  if (r.second.empty()) r.second = ".";
  return r;
}

Sweep read_sweep(const std::string& path, const std::vector<std::string>& metrics) {
  namespace fs = std::filesystem;
  return parse_sweep(scene::load_file(path), fs::path(path).parent_path().string(), fs::path(path).stem().string(),
                     metrics);
}

Sweep parse_sweep(const json& j, const std::string& dir_name, const std::string& stem,
                  const std::vector<std::string>& metrics) {
  namespace fs = std::filesystem;
  Sweep sw;
  if (!j.is_object()) throw InputError("sweep", scene::show(j), "a JSON object with base, vary, metric and goal");
  for (const char* k : {"name", "description", "metric", "goal"})
    if (j.contains(k) && !j[k].is_string()) throw InputError(k, scene::show(j[k]), "a text");
  if (j.contains("name")) scene::check_name(j["name"].get<std::string>());
  sw.name = j.contains("name") ? j["name"].get<std::string>() : stem;
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.key() != "base" && it.key() != "vary" && it.key() != "metric" && it.key() != "goal" &&
        it.key() != "name" && it.key() != "description" && it.key() != "confirm")
      throw InputError(it.key(), scene::show(it.value()),
                       "unknown key; allowed: name, description, base, vary, metric, goal, confirm");
  if (j.contains("confirm")) sw.confirm = j["confirm"];  // checked by swim screen --confirm
  std::tie(sw.base, sw.base_dir) = read_base(j, dir_name, "sweep");
  if (!j.contains("vary") || !j["vary"].is_object() || j["vary"].empty())
    throw InputError("vary", j.contains("vary") ? scene::show(j["vary"]) : "(missing)",
                     "must be an object mapping scene keys to value lists or ranges");
  std::size_t designs = 1;
  std::string names;
  for (auto it = j["vary"].begin(); it != j["vary"].end(); ++it) {
    const std::string& k = it.key();
    if (k.empty() || k.front() == '.' || k.back() == '.' || k.find("..") != std::string::npos)
      throw InputError("vary." + k, scene::show(it.value()),
                       "a dotted scene key with non-empty components, as swim run --set takes (\"swimmer.length\")");
    sw.axes.push_back(read_axis(it.key(), it.value()));
    names += (names.empty() ? "" : " x ") + it.key() + " (" + std::to_string(sw.axes.back().values.size()) + ")";
    // the product checked as it grows: it never wraps
    designs = designs > kMaxDesigns / sw.axes.back().values.size() ? kMaxDesigns + 1 : designs * sw.axes.back().values.size();
    if (designs > kMaxDesigns)
      throw InputError("vary", names + (std::next(it) == j["vary"].end() ? "" : " x ..."),
                       "at most " + std::to_string(kMaxDesigns) + " designs (the product of the axes' value counts)");
  }
  sw.metric = j.value("metric", std::string("mean_velocity_m_per_s"));
  if (std::find(metrics.begin(), metrics.end(), sw.metric) == metrics.end()) {
    std::string allowed;
    for (const auto& m : metrics) allowed += (allowed.empty() ? "" : ", ") + m;
    throw InputError("metric", "\"" + sw.metric + "\"", "must be one of: " + allowed);
  }
  const std::string goal = j.value("goal", std::string("max"));
  if (goal != "max" && goal != "min") throw InputError("goal", "\"" + goal + "\"", "must be one of: max, min");
  sw.maximize = goal == "max";
  return sw;
}

}  // namespace swim::sweep
