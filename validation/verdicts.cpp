#include "validation/verdicts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>
#include <vector>

#include "common/errors.hpp"
#include "common/si_format.hpp"

namespace swim::validation {

using scene::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A number for the report: null when it is not finite (never NaN in a file).
json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

std::string fmt(const char* f, double x) {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

std::string percent(double x) { return fmt("%.3g %%", 100 * x); }

std::string show(double x, const std::string& unit) { return unit.empty() ? fmt("%.3g", x) : si(x, unit); }

/// A case's 3D reference value with its error; `missing` says why there is none.
struct Valued {
  double value = kNaN, error = kNaN;
  std::string missing;
};

Valued reference_of(const json& c, const std::string& key) {
  Valued v;
  const json& ref = judged_reference(c);
  if (ref.contains(key) && ref[key].is_object() && ref[key].contains("value") && ref[key]["value"].is_number() &&
      ref[key].contains("error") && ref[key]["error"].is_number()) {
    v.value = ref[key]["value"].get<double>();
    v.error = std::abs(ref[key]["error"].get<double>());
    if (std::isfinite(v.value) && std::isfinite(v.error)) return v;
  }
  v.value = v.error = kNaN;
  if (c.contains("reference") && c["reference"].is_object()) {
    v.missing = "the axisymmetric reference has no value with an error bar (fewer than two of its grids completed a cycle)";
    return v;
  }
  bool one = false;
  if (c.contains("runs3d"))
    for (const auto& r : c["runs3d"]) one = one || (r.contains(key) && r[key].is_number());
  v.missing = one ? "fewer than two grids completed a cycle: a value without an error bar" : "no 3D value";
  return v;
}

/// The suite's default 1D model's (the first of models1d) value of `key` on case c, with the
/// error of its grid: 2 |v_N - v_2N| from its run on twice the cells (`grid_error`, written by
/// the suite's 1D phase). Without that estimate the value has no error bar and is missing.
Valued default_model_of(const json& c, const std::string& key) {
  Valued v;
  const json& models = c.contains("models1d") ? c["models1d"] : json::array();
  if (models.empty() || !models[0].is_object()) {
    v.missing = "no 1D model";
    return v;
  }
  const json& m = models[0];
  const std::string label = m.value("label", std::string());
  if (m.value("status", std::string()) == "ok" && m.contains(key) && m[key].is_number() &&
      std::isfinite(m[key].get<double>())) {
    const json& g = m.contains("grid_error") ? m["grid_error"] : json();
    if (g.is_object() && g.value("status", std::string()) == "ok" && g.contains(key) && g[key].is_number()) {
      v.value = m[key].get<double>();
      v.error = g[key].get<double>();
      return v;
    }
    v.value = v.error = kNaN;
    v.missing = "the default 1D model (" + label + ") has a value without an error bar: " +
                (g.is_object() ? g.value("status", std::string("no grid error")) : std::string("no grid error"));
    return v;
  }
  v.value = v.error = kNaN;
  v.missing = "the default 1D model (" + label + ") has no value: " + m.value("status", std::string("no cycle"));
  return v;
}

const char* kTrendRule =
    "each difference the claim rests on is compared with the combined uncertainty of its two values, "
    "|a − b| > e_a + e_b (their error bars do not overlap): reproduced when every difference exceeds it in the "
    "claimed direction, refuted when one exceeds it in the opposite direction, inconclusive otherwise";

const char* kSettleSuffix = ": finer grids or the converged reference";

struct Point {
  const json* c = nullptr;
  Valued v;
  std::string name() const { return (*c)["name"].get<std::string>(); }
};

/// The reference values of the cases of a claim, with the evidence; `missing` gets the first
/// case without a value (or without an error bar).
/// one_d: the suite's default 1D model's values instead of the reference's.
std::vector<Point> points(const std::vector<const json*>& cases, const std::string& key, const char* sweep_name,
                          json& ev, std::string& missing, bool one_d = false) {
  std::vector<Point> p;
  for (const json* c : cases) {
    Point q{c, one_d ? default_model_of(*c, key) : reference_of(*c, key)};
    const json& models = c->contains("models1d") ? (*c)["models1d"] : json::array();
    const std::string source =
        one_d ? "1D: " + (models.empty() ? std::string() : models[0].value("label", std::string()))
              : judged_reference_name(*c);
    json e = {{"case", (*c)["name"]}, {sweep_name, (*c)["sweep_value"]}, {"quantity", key},
              {"value", num(q.v.value)}, {"error", num(q.v.error)}, {"reference", source}};
    if (!q.v.missing.empty()) {
      e["note"] = q.v.missing;
      if (missing.empty()) missing = q.name() + ": " + q.v.missing;
    }
    ev.push_back(e);
    p.push_back(q);
  }
  return p;
}

/// "a exceeds b" against the combined uncertainty: +1 beyond it, -1 beyond it the other way,
/// 0 within it (then what would settle it goes to `undecided`).
int exceeds(const Point& a, const Point& b, const std::string& unit, json& comps, std::vector<std::string>& undecided) {
  const double d = a.v.value - b.v.value, u = a.v.error + b.v.error;
  const int o = d > u ? 1 : -d > u ? -1 : 0;
  comps.push_back({{"expected_larger", a.name()},
                   {"expected_smaller", b.name()},
                   {"difference", num(d)},
                   {"combined_uncertainty", num(u)},
                   {"outcome", o > 0 ? "supports" : o < 0 ? "contradicts" : "within the uncertainty"}});
  if (o == 0)
    undecided.push_back(d == 0 ? a.name() + " and " + b.name() + " are equal: no error bar separates them"
                               : "needs error bars below " + show(std::abs(d) / 2, unit) + " on both " + a.name() +
                                     " and " + b.name() + " (now ± " + show(a.v.error, unit) + " and ± " +
                                     show(b.v.error, unit) + ")");
  return o;
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

json finding(const std::string& claim, const std::string& rule, const json& ev) {
  return json{{"claim", claim}, {"status", "not assessed"}, {"rule", rule}, {"evidence", ev}};
}

/// The points that have a value, and what the others lack ("CASE: reason", joined).
std::vector<Point> present(const std::vector<Point>& p, std::vector<std::string>& lacking) {
  std::vector<Point> q;
  for (const Point& x : p)
    if (x.v.missing.empty()) q.push_back(x);
    else lacking.push_back(x.name() + " (" + x.v.missing + ")");
  return q;
}

/// A claim that values[a] > values[b] for each (a, b) that pairs_of(n) gives on n points in
/// sweep order. Cases without a value leave the claim on the others: pairs_of then runs on the
/// points that have one (a monotone trend holds across a gap as between neighbours), a
/// contradiction among them refutes the claim, and otherwise it is at best inconclusive, to be
/// settled by the missing values. first_required: the claim is about the sweep's first case
/// (the shortest swimmer), so without its value it is not assessed.
template <class PairsOf>
json trend(const std::string& claim, const std::vector<Point>& all, const std::string& missing, const json& ev,
           const PairsOf& pairs_of, const std::string& unit, const std::string& settle_suffix = kSettleSuffix,
           bool first_required = false) {
  json f = finding(claim, kTrendRule, ev);
  if (all.size() < 2) {
    f["reason"] = "the suite has fewer than two cases for it";
    return f;
  }
  std::vector<std::string> lacking;
  const std::vector<Point> p = present(all, lacking);
  if (p.size() < 2 || (first_required && !all.front().v.missing.empty())) {
    f["reason"] = missing;
    return f;
  }
  json comps = json::array();
  std::vector<std::string> undecided;
  bool all_support = true, against = false;
  for (const auto& [a, b] : pairs_of(p.size())) {
    const int o = exceeds(p[a], p[b], unit, comps, undecided);
    all_support = all_support && o > 0;
    against = against || o < 0;
  }
  f["comparisons"] = comps;
  f["status"] = against ? "refuted" : all_support && lacking.empty() ? "reproduced" : "inconclusive";
  if (!lacking.empty()) f["missing"] = join(lacking, "; ");
  if (f["status"] == "inconclusive") {
    if (!lacking.empty()) undecided.insert(undecided.begin(), "values for " + join(lacking, "; "));
    f["to_settle"] = join(undecided, "; ") + settle_suffix;
  }
  return f;
}

/// Combined status of a claim over cases: refuted > not assessed > inconclusive > reproduced.
std::string combine(const std::vector<std::string>& st) {
  if (st.empty()) return "not assessed";
  for (const char* s : {"refuted", "not assessed", "inconclusive"})
    if (std::find(st.begin(), st.end(), s) != st.end()) return s;
  return "reproduced";
}

}  // namespace

OrderRange parse_order_range(const json& v, const std::string& key) {
  if (v.is_string()) {
    if (v == "immersed_boundary") return kImmersedBoundaryOrders;
    if (v == "sharp_interface") return kSharpInterfaceOrders;
  } else if (v.is_array() && v.size() == 2 && v[0].is_number() && v[1].is_number()) {
    const OrderRange r{v[0].get<double>(), v[1].get<double>()};
    if (r.lo > 0 && r.hi > r.lo && r.hi <= kOrderSearchMax) return r;
  }
  throw InputError(key, scene::show(v),
                   "\"immersed_boundary\" (orders " + kImmersedBoundaryOrders.text() + "), \"sharp_interface\" (" +
                       kSharpInterfaceOrders.text() + ") or [lo, hi] with 0 < lo < hi <= 20: the observed orders the "
                       "3D scheme can show");
}

std::string tolerance_verdict(double rel, double rel_error, double tolerance) {
  if (!std::isfinite(rel) || !std::isfinite(rel_error)) return "not assessed";
  const double d = std::abs(rel), e = std::abs(rel_error);
  if (d + e <= tolerance) return "pass";
  if (d - e > tolerance) return "fail";
  return "inconclusive";
}

std::string agreement_verdict(double a, double ea, double b, double eb) {
  if (!std::isfinite(a) || !std::isfinite(ea) || !std::isfinite(b) || !std::isfinite(eb)) return "not assessed";
  const double e = std::abs(ea) + std::abs(eb);
  if (std::abs(a - b) > e) return "disagree";
  return e <= kAgreementResolution * std::abs(b) ? "agree" : "inconclusive";
}

const json& judged_reference(const json& c) {
  static const json empty = json::object();
  if (c.is_object() && c.contains("reference") && c["reference"].is_object()) return c["reference"];
  if (c.is_object() && c.contains("reference3d") && c["reference3d"].is_object()) return c["reference3d"];
  return empty;
}

std::string judged_reference_name(const json& c) {
  return c.is_object() && c.contains("reference") && c["reference"].is_object() ? "axisymmetric reference"
                                                                                 : "3D reference";
}

void compare_with_reference(json& entry, const json& c) {
  const json& ref = judged_reference(c);
  json rel = json::object(), err = json::object();
  for (const auto& [k, fig] : {std::pair<const char*, const char*>{"displacement_per_cycle", "displacement_per_cycle_m"},
                               {"cycle_time", "cycle_time_s"},
                               {"mean_velocity_per_cycle", "mean_velocity_per_cycle_m_per_s"}}) {
    if (!ref.contains(fig) || !ref[fig].is_object() || !ref[fig].contains("value") || !ref[fig]["value"].is_number())
      continue;
    const double r = ref[fig]["value"].get<double>();
    const double e = ref[fig].contains("error") && ref[fig]["error"].is_number() ? ref[fig]["error"].get<double>() : kNaN;
    const double x = entry.contains(fig) && entry[fig].is_number() ? entry[fig].get<double>() : kNaN;
    rel[k] = std::abs(r) > 0 ? num((x - r) / std::abs(r)) : json(nullptr);
    err[k] = std::abs(r) > 0 ? num(std::abs(e / r)) : json(nullptr);
  }
  entry["relative_error_vs_reference"] = rel;
  entry["reference_error_relative"] = err;
  entry["judged_against"] = judged_reference_name(c);
}

std::string correlation_verdict(double corr, double error, double threshold) {
  if (!std::isfinite(corr) || !std::isfinite(error)) return "not assessed";
  const double e = std::abs(error);
  if (corr - e >= threshold) return "pass";
  if (corr + e < threshold) return "fail";
  return "inconclusive";
}

const json& judged_velocity(const json& entry) {
  static const json empty = json::object();
  for (const char* k : {"velocity_vs_reference", "velocity_vs_finest3d"})
    if (entry.is_object() && entry.contains(k) && entry[k].is_object()) return entry[k];
  return empty;
}

std::string judged_velocity_name(const json& entry) {
  return entry.is_object() && entry.contains("velocity_vs_reference") && entry["velocity_vs_reference"].is_object()
             ? "finest axisymmetric run"
             : "finest 3D run";
}

json model_verdicts(const json& entry, const json& th) {
  json v = json::object();
  auto number = [](const json& j, const char* k) {
    return j.is_object() && j.contains(k) && j[k].is_number() ? j[k].get<double>() : kNaN;
  };
  const json& rel = entry.contains("relative_error_vs_reference") ? entry["relative_error_vs_reference"] : json::object();
  const json& err = entry.contains("reference_error_relative") ? entry["reference_error_relative"] : json::object();
  for (const auto& [k, t] : {std::pair<const char*, const char*>{"displacement_per_cycle", "displacement_per_cycle_relative"},
                             {"cycle_time", "cycle_time_relative"},
                             {"mean_velocity_per_cycle", "mean_velocity_per_cycle_relative"}})
    if (rel.is_object() && rel.contains(k)) v[k] = tolerance_verdict(number(rel, k), number(err, k), th.at(t).get<double>());
  // against the finest axisymmetric run when the case has one, else the finest 3D run
  const json& u = judged_velocity(entry);
  if (u.contains("phase_correlation_grid_spread"))
    v["velocity_phase_correlation"] =
        correlation_verdict(number(u, "phase_correlation"), number(u, "phase_correlation_grid_spread"),
                            th.at("velocity_phase_correlation").get<double>());
  return v;
}

json findings(const json& cases, const json& th) {
  auto group = [&](const std::string& g) {
    std::vector<const json*> v;
    for (const auto& c : cases)
      if (c.value("group", json()) == g && c.value("sweep_value", json()).is_number()) v.push_back(&c);
    std::sort(v.begin(), v.end(), [](const json* a, const json* b) { return (*a)["sweep_value"] < (*b)["sweep_value"]; });
    return v;
  };
  json out = json::array();
  const std::string kd = "displacement_per_cycle_m", kv = "mean_velocity_per_cycle_m_per_s";
  const auto aspect = group("aspect"), amplitude = group("amplitude");

  // The paper's trends, on the reference (the converged answer) and then on the suite's default
  // 1D model with the same rule (each 1D value carries its own grid error, default_model_of).
  const auto trends = [&](bool one_d) {
    const std::string on = one_d ? " (1D tier, the suite's default 1D model)" : "";
    const std::string settle_suffix = one_d ? ": a finer 1D grid (numerics1d.cells)" : kSettleSuffix;
    // a trend claimed pairwise, "the value at i exceeds the value at j" for each pair (i, j)
    // the rule gives on the sweep's n points
    using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;
    const auto pairwise = [&](const std::string& claim, const auto& sweep, const std::string& key, const char* axis,
                              const char* unit, const auto& pairs_of, bool first_required = false) {
      json ev = json::array();
      std::string missing;
      const auto p = points(sweep, key, axis, ev, missing, one_d);
      out.push_back(trend(claim + on, p, missing, ev, pairs_of, unit, settle_suffix, first_required));
    };
    // distance per cycle grows with L: each L against the next
    pairwise("distance per cycle grows with the swimmer length L", aspect, kd, "L_um", "m", [](std::size_t n) {
      Pairs q;
      for (std::size_t i = 0; i + 1 < n; ++i) q.emplace_back(i + 1, i);
      return q;
    });
    // ... and with the amplitude: the sweep value is R_f / R0, the deformation grows as it falls
    pairwise("distance per cycle grows with the deformation amplitude", amplitude, kd, "R_f_over_R0", "m",
             [](std::size_t n) {
               Pairs q;
               for (std::size_t i = 0; i + 1 < n; ++i) q.emplace_back(i, i + 1);
               return q;
             });
    // the shortest swimmer against every other
    pairwise("mean velocity per cycle is largest for the shortest swimmer", aspect, kv, "L_um", "m/s",
             [](std::size_t n) {
               Pairs q;
               for (std::size_t j = 1; j < n; ++j) q.emplace_back(0, j);
               return q;
             },
             true);
    // largest at about 50 % deformation (R_f / R0 within 0.1 of 0.5): some case there exceeds
    // every case away from it
    {
      json ev = json::array();
      std::string missing;
      const auto all = points(amplitude, kv, "R_f_over_R0", ev, missing, one_d);
      std::vector<std::string> lacking;
      const auto p = present(all, lacking);
      bool lacking_at = false;  // a case at about 50 % without a value: the claim cannot be refuted
      for (const Point& x : all)
        lacking_at = lacking_at || (!x.v.missing.empty() && std::abs((*x.c)["sweep_value"].get<double>() - 0.5) <= 0.1);
      json f = finding("mean velocity per cycle is largest at about 50 % deformation (R_f/R0 within 0.1 of 0.5)" + on,
                       std::string(kTrendRule) + "; a case at about 50 % must exceed every case away from it", ev);
      std::vector<std::size_t> at, away;
      for (std::size_t i = 0; i < p.size(); ++i)
        (std::abs((*p[i].c)["sweep_value"].get<double>() - 0.5) <= 0.1 ? at : away).push_back(i);
      if (all.size() < 2) f["reason"] = "the suite has fewer than two cases for it";
      else if (p.size() < 2) f["reason"] = missing;
      else if (at.empty()) f["reason"] = lacking_at ? missing : "the sweep has no case at about 50 % deformation";
      else if (away.empty()) f["reason"] = "the sweep has no case away from 50 % deformation";
      else {
        json comps = json::array();
        std::vector<std::string> undecided;
        std::vector<std::vector<int>> o(at.size(), std::vector<int>(away.size()));
        for (std::size_t i = 0; i < at.size(); ++i)
          for (std::size_t j = 0; j < away.size(); ++j) o[i][j] = exceeds(p[at[i]], p[away[j]], "m/s", comps, undecided);
        bool reproduced = false, refuted = false;
        for (std::size_t i = 0; i < at.size(); ++i)
          reproduced = reproduced || std::all_of(o[i].begin(), o[i].end(), [](int x) { return x > 0; });
        for (std::size_t j = 0; j < away.size(); ++j) {
          bool beats_all = true;
          for (std::size_t i = 0; i < at.size(); ++i) beats_all = beats_all && o[i][j] < 0;
          refuted = refuted || beats_all;
        }
        refuted = refuted && !lacking_at;
        reproduced = reproduced && lacking.empty();
        f["comparisons"] = comps;
        f["status"] = reproduced ? "reproduced" : refuted ? "refuted" : "inconclusive";
        if (!lacking.empty()) f["missing"] = join(lacking, "; ");
        if (!reproduced && !refuted) {
          if (!lacking.empty()) undecided.insert(undecided.begin(), "values for " + join(lacking, "; "));
          f["to_settle"] = join(undecided, "; ") + settle_suffix;
        }
      }
      out.push_back(f);
    }
  };
  trends(false);
  trends(true);
  // 1D against 3D up to 50 % deformation (R_f / R0 >= 0.5), one finding per figure, judged on
  // the suite's default 1D model (the first); every model is evidence
  {
    struct Figure {
      const char* key;
      const char* what;
      const char* threshold_key;
      bool correlation;
    };
    for (const Figure& fig : {Figure{"displacement_per_cycle", "displacement per cycle", "displacement_per_cycle_relative", false},
                              Figure{"cycle_time", "cycle time", "cycle_time_relative", false},
                              Figure{"mean_velocity_per_cycle", "mean velocity per cycle", "mean_velocity_per_cycle_relative", false},
                              Figure{"velocity_phase_correlation", "U(t) against the cycle phase", "velocity_phase_correlation", true}}) {
      const double tol = th.at(fig.threshold_key).get<double>();
      const std::string claim =
          std::string("1D agrees with 3D up to 50 % deformation: ") + fig.what +
          (fig.correlation ? " (correlation at least " + fmt("%g", tol) +
                                 " with the finest run of the case's reference, axisymmetric when it has one, else 3D;"
                           : " (within " + fmt("%g", 100 * tol) + " % of the 3D reference,") +
          " the suite's default 1D model)";
      const std::string rule =
          fig.correlation
              ? "pass when the correlation minus its uncertainty (its spread over the reference run's three finest "
                "grids) reaches the threshold, "
                "fail when the correlation plus its uncertainty stays below it, inconclusive otherwise"
              : "pass when |1D − ref| / |ref| plus the reference's relative error e_ref is within the tolerance (the "
                "whole interval inside the band), fail when |1D − ref| / |ref| − e_ref exceeds it, inconclusive "
                "otherwise (a difference within the reference's error bar cannot fail)";
      json ev = json::array();
      std::vector<std::string> st, settle, reasons;
      for (const json* c : amplitude) {
        if ((*c)["sweep_value"].get<double>() < 0.5) continue;
        const std::string name = (*c)["name"];
        const json& models = c->contains("models1d") ? (*c)["models1d"] : json::array();
        for (std::size_t k = 0; k < models.size(); ++k) {
          const json& md = models[k];
          const bool has = md.contains("verdicts") && md["verdicts"].contains(fig.key);
          json e = {{"case", name}, {"model", md.value("label", std::string())}, {"default_model", k == 0},
                    {"verdict", has ? md["verdicts"][fig.key] : json("not assessed")}};
          double x = kNaN, err = kNaN;
          if (fig.correlation) {
            const json& v = judged_velocity(md);
            if (v.contains("phase_correlation") && v["phase_correlation"].is_number()) x = v["phase_correlation"];
            if (v.contains("phase_correlation_grid_spread") && v["phase_correlation_grid_spread"].is_number())
              err = v["phase_correlation_grid_spread"];
            e["correlation"] = num(x);
            e["correlation_error"] = num(err);
            e["threshold"] = tol;
            if (!v.empty()) e["reference"] = judged_velocity_name(md);
          } else {
            const json& r = md.contains("relative_error_vs_reference") ? md["relative_error_vs_reference"] : json::object();
            const json& re = md.contains("reference_error_relative") ? md["reference_error_relative"] : json::object();
            if (r.contains(fig.key) && r[fig.key].is_number()) x = r[fig.key];
            if (re.contains(fig.key) && re[fig.key].is_number()) err = re[fig.key];
            e["relative_difference"] = num(x);
            e["reference_error_relative"] = num(err);
            e["tolerance"] = tol;
          }
          ev.push_back(e);
          if (k != 0) continue;
          const std::string v = has ? md["verdicts"][fig.key].get<std::string>() : "not assessed";
          st.push_back(v == "pass" ? "reproduced" : v == "fail" ? "refuted" : v == "inconclusive" ? "inconclusive"
                                                                                                   : "not assessed");
          if (v == "inconclusive") {
            const double need = fig.correlation ? std::abs(x - tol) : std::abs(std::abs(x) - tol);
            settle.push_back(fig.correlation
                                 ? "needs the correlation's grid spread below " + fmt("%.2g", need) + " on " + name +
                                       " (now " + fmt("%.2g", err) + ")"
                                 : "needs the 3D reference's error below " + percent(need) + " of it on " + name +
                                       " (now " + percent(err) + ")");
          } else if (!has) {
            reasons.push_back(name + ": the default 1D model has no verdict (" + md.value("status", std::string("no cycle")) + ")");
          }
        }
        if (models.empty()) {
          st.push_back("not assessed");
          reasons.push_back(name + ": no 1D model");
        }
      }
      json f = finding(claim, rule, ev);
      f["status"] = combine(st);
      if (st.empty()) f["reason"] = "the suite has no amplitude case with R_f/R0 >= 0.5";
      else if (f["status"] == "not assessed") f["reason"] = join(reasons, "; ");
      else if (f["status"] == "inconclusive") f["to_settle"] = join(settle, "; ") + kSettleSuffix;
      out.push_back(f);
    }
  }
  // the optimal swimmer's speed against the paper's 1.5 body lengths/s
  {
    const double paper = 1.5, tol = 0.2, lo = paper * (1 - tol), hi = paper * (1 + tol);
    json ev = json::array();
    std::vector<std::string> st, settle, reasons;
    for (const json* c : group("optimal")) {
      const Valued v = reference_of(*c, kv);
      const double L = c->contains("length_m") && (*c)["length_m"].is_number() ? (*c)["length_m"].get<double>() : kNaN;
      const double bl = v.value / L, e = v.error / L;
      const std::string name = (*c)["name"];
      ev.push_back({{"case", name}, {"quantity", "body_lengths_per_s"}, {"value", num(bl)}, {"error", num(e)},
                    {"paper", paper}, {"band", {lo, hi}}});
      if (!std::isfinite(bl) || !std::isfinite(e)) {
        st.push_back("not assessed");
        reasons.push_back(name + ": " + (v.missing.empty() ? "no swimmer length" : v.missing));
      } else if (bl - e >= lo && bl + e <= hi) {
        st.push_back("reproduced");
      } else if (bl + e < lo || bl - e > hi) {
        st.push_back("refuted");
      } else {
        st.push_back("inconclusive");
        const double need = bl < lo ? lo - bl : bl > hi ? bl - hi : std::min(bl - lo, hi - bl);
        settle.push_back("needs an error bar below " + fmt("%.2g", need) + " body lengths/s on " + name + " (now ± " +
                         fmt("%.2g", e) + ")");
      }
    }
    json f = finding("the optimal swimmer makes 1.5 body lengths/s (within 20 %)",
                     "reproduced when the whole interval value ± error lies inside [1.2, 1.8] body lengths/s, refuted "
                     "when it lies wholly outside, inconclusive otherwise",
                     ev);
    f["status"] = combine(st);
    if (st.empty()) f["reason"] = "the suite has no case for it";
    else if (f["status"] == "not assessed") f["reason"] = join(reasons, "; ");
    else if (f["status"] == "inconclusive") f["to_settle"] = join(settle, "; ") + kSettleSuffix;
    out.push_back(f);
  }
  return out;
}

}  // namespace swim::validation
