#include "design/optimize.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlopt.hpp>
#include <tuple>

#include "common/errors.hpp"
#include "common/sweep.hpp"
#include "common/units.hpp"
#include "design/confirm.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"

namespace swim::design {
namespace fs = std::filesystem;

bool Evaluation::feasible() const {
  return ok && std::all_of(constraints.begin(), constraints.end(), [](double g) { return g <= 0; });
}

namespace {

struct Context {
  const SearchOptions* o;
  const std::function<Evaluation(const std::vector<double>&)>* evaluate;
  SearchResult* result;
  double scale = 1;  ///< |objective| at the start (1 when it is 0 or failed)
  double worst = 0;  ///< the worst scaled objective seen (a failed evaluation's stand-in)
  std::vector<double> x;
};

// The point of scaled coordinates u in [0, 1]^n.
std::vector<double> point(const SearchOptions& o, const double* u) {
  std::vector<double> x(o.lo.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = o.lo[i] + std::clamp(u[i], 0.0, 1.0) * (o.hi[i] - o.lo[i]);
  return x;
}

// One evaluation per point: the objective asks first, the constraints reuse it.
const Evaluation& at(Context& c, const double* u) {
  const std::vector<double> x = point(*c.o, u);
  if (c.result->trajectory.empty() || x != c.x) {
    Evaluation e = (*c.evaluate)(x);
    e.x = x;
    c.x = x;
    if (c.result->trajectory.empty()) c.scale = e.ok && e.objective != 0 ? std::abs(e.objective) : 1.0;
    c.result->trajectory.push_back(std::move(e));
  }
  return c.result->trajectory.back();
}

double objective(unsigned n, const double* u, double*, void* data) {
  Context& c = *static_cast<Context*>(data);
  const Evaluation& e = at(c, u);
  // NLopt minimises: the scaled objective, negated for a maximisation; a failed run counts as
  // the worst value seen and violates every constraint
  double f = e.ok ? (c.o->maximize ? -e.objective : e.objective) / c.scale : c.worst;
  if (e.ok) c.worst = std::max(c.worst, f);
  return f;
}

double constraint(unsigned n, const double* u, double*, void* data) {
  auto* pair = static_cast<std::pair<Context*, std::size_t>*>(data);
  const Evaluation& e = at(*pair->first, u);
  return e.ok ? e.constraints[pair->second] : 1.0;
}

}  // namespace

SearchResult search(const SearchOptions& o, const std::function<Evaluation(const std::vector<double>&)>& evaluate) {
  const unsigned n = static_cast<unsigned>(o.lo.size());
  SearchResult r;
  Context c{&o, &evaluate, &r, 1.0, 0.0, {}};
  nlopt::opt opt(nlopt::LN_COBYLA, n);
  opt.set_lower_bounds(std::vector<double>(n, 0.0));
  opt.set_upper_bounds(std::vector<double>(n, 1.0));
  opt.set_min_objective(objective, &c);
  std::vector<std::pair<Context*, std::size_t>> cdata;
  cdata.reserve(o.constraints);
  for (std::size_t i = 0; i < o.constraints; ++i) cdata.emplace_back(&c, i);
  for (auto& d : cdata) opt.add_inequality_constraint(constraint, &d, 0.0);
  opt.set_maxeval(o.max_evaluations);
  opt.set_xtol_rel(o.xtol_rel);
  opt.set_initial_step(std::vector<double>(n, 0.25));
  std::vector<double> u(n);
  for (unsigned i = 0; i < n; ++i) u[i] = (o.start[i] - o.lo[i]) / (o.hi[i] - o.lo[i]);
  double f = 0;
  try {
    switch (opt.optimize(u, f)) {
      case nlopt::MAXEVAL_REACHED: r.stop_reason = "max_evaluations reached"; break;
      case nlopt::XTOL_REACHED: r.stop_reason = "tolerance reached (parameter change)"; break;
      case nlopt::FTOL_REACHED: r.stop_reason = "tolerance reached (objective change)"; break;
      default: r.stop_reason = "converged"; break;
    }
  } catch (const nlopt::roundoff_limited&) {
    r.stop_reason = "roundoff limited (the best point found is kept)";
  } catch (const std::runtime_error& e) {
    r.stop_reason = std::string("stopped: ") + e.what();
  }
  for (std::size_t k = 0; k < r.trajectory.size(); ++k) {
    const Evaluation& e = r.trajectory[k];
    if (!e.feasible()) continue;
    if (r.best < 0 || (o.maximize ? e.objective > r.trajectory[r.best].objective
                                  : e.objective < r.trajectory[r.best].objective))
      r.best = static_cast<long>(k);
  }
  return r;
}

// ---- the spec ------------------------------------------------------------------------------

json Parameter::scene_value(double v) const {
  if (integer) return static_cast<long>(std::lround(v));
  char b[32];
  std::snprintf(b, sizeof b, "%.8g", v);
  if (unit.empty()) return std::stod(b);
  return std::string(b) + " " + unit;
}

std::size_t Spec::constraint_count() const { return (min_ratio > 0 ? 1 : 0) + (std::isfinite(max_load_Pa) ? 1 : 0); }

json Spec::design(const std::vector<double>& x) const {
  json s = base;
  for (std::size_t i = 0; i < parameters.size(); ++i)
    scene::apply_override(s, parameters[i].key + "=" + parameters[i].scene_value(x[i]).dump());
  if (!name.empty()) s["name"] = name + "-design";
  return s;
}

const std::vector<std::string>& objective_names() {
  static const std::vector<std::string> n = {"mean_velocity_m_per_s", "body_lengths_per_s", "displacement_per_cycle_m"};
  return n;
}

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

void only_keys(const json& j, const std::string& where, const std::vector<std::string>& allowed) {
  for (auto it = j.begin(); it != j.end(); ++it)
    if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end())
      throw InputError((where.empty() ? "" : where + ".") + it.key(), scene::show(it.value()),
                       "unknown key; allowed: " + join(allowed));
}

// A bound in the parameter's unit: a number, or a quantity convertible to the unit of "min".
double bound(const json& v, const std::string& where, Parameter& p, bool first) {
  if (first) {
    if (v.is_number()) return v.get<double>();
    if (!v.is_string()) throw InputError(where, scene::show(v), "must be a number or a quantity string (\"0.2 um\")");
    auto [value, unit] = units::split(where, v.get<std::string>());
    p.unit = unit;
    auto [si, base] = units::to_base(where, "1 " + unit);
    p.to_si = si;
    p.si_unit = base;
    return value;
  }
  if (p.unit.empty()) {
    if (!v.is_number()) throw InputError(where, scene::show(v), "must be a number, as min is");
    return v.get<double>();
  }
  if (!v.is_string()) throw InputError(where, scene::show(v), "must be a quantity in a unit of min (" + p.unit + ")");
  return units::parse(where, v.get<std::string>(), p.unit).si;  // expressed in min's unit
}

reduced1d::Params read_design(const Spec& s, const std::vector<double>& x, const std::string& what) {
  json resolved;
  try {
    return reduced1d::read_scene(s.design(x), resolved, s.base_dir);
  } catch (const InputError& e) {
    throw InputError(e.key(), "", "at " + what + " of the parameter box: " + e.what());
  }
}

}  // namespace

Spec read_spec(const std::string& path) {
  const json j = scene::load_file(path);
  only_keys(j, "", {"name", "description", "base", "set", "parameters", "objective", "goal", "constraints", "max_evaluations",
                    "tolerance", "confirm"});
  Spec s;
  s.name = j.contains("name") && j["name"].is_string() ? j["name"].get<std::string>() : fs::path(path).stem().string();
  std::tie(s.base, s.base_dir) = sweep::read_base(j, std::filesystem::path(path).parent_path().string(), "spec");
  if (j.contains("set")) {  // fixed changes of the base scene (null removes a key)
    if (!j["set"].is_object()) throw InputError("set", scene::show(j["set"]), "must map scene keys to values");
    for (auto it = j["set"].begin(); it != j["set"].end(); ++it)
      scene::apply_override(s.base, it.key() + "=" + it.value().dump());
  }
  if (!j.contains("parameters") || !j["parameters"].is_object() || j["parameters"].empty() || j["parameters"].size() > 8)
    throw InputError("parameters", j.contains("parameters") ? scene::show(j["parameters"]) : "(missing)",
                     "must map 1 to 8 scene keys to {\"min\": .., \"max\": .., \"start\": .., \"integer\": false}");
  for (auto it = j["parameters"].begin(); it != j["parameters"].end(); ++it) {
    const std::string where = "parameters." + it.key();
    const json& q = it.value();
    if (!q.is_object()) throw InputError(where, scene::show(q), "must be {\"min\": .., \"max\": ..}");
    only_keys(q, where, {"min", "max", "start", "integer"});
    if (!q.contains("min") || !q.contains("max")) throw InputError(where, scene::show(q), "needs min and max");
    Parameter p;
    p.key = it.key();
    p.lo = bound(q["min"], where + ".min", p, true);
    p.hi = bound(q["max"], where + ".max", p, false);
    if (q.contains("integer")) {
      if (!q["integer"].is_boolean()) throw InputError(where + ".integer", scene::show(q["integer"]), "must be true or false");
      p.integer = q["integer"].get<bool>();
    }
    if (!(p.lo < p.hi))
      throw InputError(where + ".max", scene::show(q["max"]),
                       "must be larger than min (" + scene::show(q["min"]) + "): the parameter box is empty");
    p.start = q.contains("start") ? bound(q["start"], where + ".start", p, false) : 0.5 * (p.lo + p.hi);
    if (p.start < p.lo || p.start > p.hi)
      throw InputError(where + ".start", scene::show(q["start"]), "must lie within [min, max]");
    s.parameters.push_back(p);
  }
  s.objective = j.value("objective", s.objective);
  if (std::find(objective_names().begin(), objective_names().end(), s.objective) == objective_names().end())
    throw InputError("objective", "\"" + s.objective + "\"", "must be one of: " + join(objective_names()));
  const std::string goal = j.value("goal", std::string("max"));
  if (goal != "max" && goal != "min") throw InputError("goal", "\"" + goal + "\"", "must be one of: max, min");
  s.maximize = goal == "max";
  if (j.contains("constraints")) {
    const json& c = j["constraints"];
    if (!c.is_object()) throw InputError("constraints", scene::show(c), "must be an object");
    only_keys(c, "constraints", {"min_directed_to_diffusive_ratio", "max_load"});
    if (c.contains("min_directed_to_diffusive_ratio")) {
      const json& v = c["min_directed_to_diffusive_ratio"];
      if (!v.is_number() || !(v.get<double>() > 0))
        throw InputError("constraints.min_directed_to_diffusive_ratio", scene::show(v), "must be a number > 0");
      s.min_ratio = v.get<double>();
    }
    if (c.contains("max_load")) {
      const json& v = c["max_load"];
      if (!v.is_string()) throw InputError("constraints.max_load", scene::show(v), "must be a pressure (\"1 Pa\")");
      s.max_load_Pa = units::parse("constraints.max_load", v.get<std::string>(), "Pa").si;
      if (!(s.max_load_Pa > 0)) throw InputError("constraints.max_load", scene::show(v), "must be > 0");
    }
  }
  if (j.contains("max_evaluations")) {
    const json& v = j["max_evaluations"];
    if (!v.is_number_integer() || v.get<long>() < 2 || v.get<long>() > 100000)
      throw InputError("max_evaluations", scene::show(v), "must be an integer in [2, 100000]");
    s.max_evaluations = v.get<int>();
  }
  if (j.contains("tolerance")) {
    const json& v = j["tolerance"];
    if (!v.is_number() || !(v.get<double>() > 0 && v.get<double>() < 1))
      throw InputError("tolerance", scene::show(v), "must be a number in (0, 1)");
    s.tolerance = v.get<double>();
  }
  s.confirm = read_confirm_section(j.contains("confirm") ? j["confirm"] : json(nullptr), "confirm");

  // Every corner, the centre and the start are valid 1D scenes; the smallest load among them
  // must meet a load constraint (the load grows monotonically with each parameter that sets it).
  const std::size_t n = s.parameters.size();
  std::vector<double> centre(n), start(n);
  for (std::size_t i = 0; i < n; ++i) {
    centre[i] = 0.5 * (s.parameters[i].lo + s.parameters[i].hi);
    start[i] = s.parameters[i].start;
  }
  double min_load = read_design(s, start, "the start").protocol.q;
  min_load = std::min(min_load, read_design(s, centre, "the centre").protocol.q);
  for (std::size_t corner = 0; corner < (std::size_t(1) << n); ++corner) {
    std::vector<double> x(n);
    std::string what = "the corner";
    for (std::size_t i = 0; i < n; ++i) {
      const bool hi = (corner >> i) & 1;
      x[i] = hi ? s.parameters[i].hi : s.parameters[i].lo;
      what += std::string(i ? "," : "") + " " + s.parameters[i].key + " = " + (hi ? "max" : "min");
    }
    min_load = std::min(min_load, read_design(s, x, what).protocol.q);
  }
  if (min_load > s.max_load_Pa) {
    char b[160];
    std::snprintf(b, sizeof b, "leaves no feasible design: the smallest actuation pressure in the parameter box is %.4g Pa",
                  min_load);
    throw InputError("constraints.max_load", scene::show(j["constraints"]["max_load"]), b);
  }
  return s;
}

Evaluation evaluate_1d(const Spec& s, const std::vector<double>& x) {
  Evaluation e;
  json resolved;
  reduced1d::Params p;
  try {  // a point inside the box whose scene the 1D reader refuses (a rule between keys)
    p = reduced1d::read_scene(s.design(x), resolved, s.base_dir);
  } catch (const InputError& err) {
    e.ok = false;
    e.message = std::string("refused by the 1D tier: ") + err.what();
    e.constraints.assign(s.constraint_count(), 1.0);
    return e;
  }
  const auto out = reduced1d::run_designs({p}, 1);
  e.ok = out[0].ok;
  e.message = out[0].message;
  const reduced1d::Metrics& m = out[0].metrics;
  e.objective = e.ok ? reduced1d::metric_value(m, s.objective) : 0.0;
  if (e.ok && s.objective == "displacement_per_cycle_m" && !m.has_cycle) {
    e.ok = false;
    e.message = "no cycle completed";
  }
  if (s.min_ratio > 0) e.constraints.push_back((s.min_ratio - m.directed_to_diffusive) / s.min_ratio);
  if (std::isfinite(s.max_load_Pa)) e.constraints.push_back((p.protocol.q - s.max_load_Pa) / s.max_load_Pa);
  return e;
}

}  // namespace swim::design
