#include "design/confirm.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "common/run_folder.hpp"
#include "common/strict_json.hpp"
#include "full3d/run3d.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/screen.hpp"

namespace swim::design {
namespace fs = std::filesystem;

const std::vector<std::string>& metrics_in_3d() {
  static const std::vector<std::string> m = {
      "displacement_m",       "mean_velocity_m_per_s", "body_lengths_per_s",       "pumped_volume_m3",
      "max_velocity_m_per_s", "final_velocity_m_per_s", "mean_cycle_time_s",       "displacement_per_cycle_m",
      "mean_velocity_per_cycle_m_per_s"};
  return m;
}

void check_metric_in_3d(const std::string& metric, const std::string& key) {
  for (const auto& m : metrics_in_3d())
    if (m == metric) return;
  std::string allowed;
  for (const auto& m : metrics_in_3d()) allowed += (allowed.empty() ? "" : ", ") + m;
  throw InputError(key, "\"" + metric + "\"", "is not reported by the 3D tier, so it cannot be confirmed; one of: " + allowed);
}

json read_confirm_section(const json& section, const std::string& where) {
  if (section.is_null()) return json::object();
  if (!section.is_object()) throw InputError(where, scene::show(section), "must be an object {\"grid\": {...}}");
  for (auto it = section.begin(); it != section.end(); ++it)
    if (it.key() != "grid") throw InputError(where + "." + it.key(), scene::show(it.value()), "unknown key; allowed: grid");
  if (section.contains("grid")) {
    const json& g = section["grid"];
    if (!g.is_object() || g.size() != 1 || !(g.contains("cells_across") || g.contains("cell_size")))
      throw InputError(where + ".grid", scene::show(g),
                       "must be {\"cells_across\": <even integer>} or {\"cell_size\": \"<length>\"} (full3d.grid)");
  }
  return section;
}

json confirm_scene(json sc, const json& section, int threads) {
  if (section.contains("grid")) sc["full3d"]["grid"] = section["grid"];
  sc["full3d"]["threads"] = threads;
  sc["full3d"]["output"]["vtk"] = false;
  sc["full3d"]["output"]["fluid_fields"] = false;
  return sc;
}

namespace {
json finished_summary(const fs::path& dir) {
  std::ifstream in(dir / "summary.json");
  if (!in) return nullptr;
  json s = json::parse(in, nullptr, false);
  if (s.is_discarded() || !s.contains("status") || !s["status"].is_string()) return nullptr;
  return s;
}
bool running(const json& s) { return !s.is_null() && s["status"].get<std::string>().rfind("running", 0) == 0; }
json number_or_null(double v, bool present) { return present && std::isfinite(v) ? json(v) : json(nullptr); }
}  // namespace

json confirmed_to_json(const Confirmed& c) {
  return {{"summary", c.summary}, {"folder", c.folder}, {"reused", c.reused}, {"ok", c.ok}, {"cell_size_m", c.cell_size_m}};
}

Confirmed confirmed_from_json(const json& j) {
  Confirmed c;
  c.summary = j.at("summary");
  c.folder = j.at("folder").get<std::string>();
  c.reused = j.at("reused").get<bool>();
  c.ok = j.at("ok").get<bool>();
  c.cell_size_m = j.at("cell_size_m").get<double>();
  return c;
}

std::string confirm_label(const Candidate& c) { return "design-" + std::to_string(c.design); }

Confirmed run_confirmed(const json& sc, const std::string& runs_dir, const std::string& label, int progress) {
  json resolved;
  const full3d::Params3d p = full3d::read_scene3d(sc, resolved);
  json physics = resolved;
  physics["full3d"].erase("threads");  // the thread count does not change the run's results
  const fs::path dir = fs::path(runs_dir) / (label + "-" + output::json_hash(physics).substr(0, 12));
  Confirmed c;
  c.folder = dir.string();
  c.cell_size_m = p.h;
  json s = finished_summary(dir);
  if (!s.is_null() && !running(s)) {
    c.summary = s;
    c.reused = true;
  } else {
    bool resume = false;
    if (running(s) && fs::exists(full3d::checkpoint_path(dir.string()))) {
      try {
        full3d::check_resumable(p, resolved, dir.string());
        resume = true;
      } catch (const InputError&) {
      }
    }
    if (!resume) {
      fs::remove_all(dir);
      fs::create_directories(dir);
    }
    full3d::RunControl ctl;
    ctl.progress = progress;
    ctl.quiet_vtk = true;
    ctl.resume = resume;
    c.summary = full3d::run3d(p, resolved, dir.string(), ctl).summary;
  }
  c.ok = c.summary.value("status", std::string()) == "ok";
  return c;
}

json figures_1d(const reduced1d::Metrics& m, const std::string& metric) {
  return {{metric, reduced1d::metric_value(m, metric)},
          {"displacement_per_cycle_m", number_or_null(m.displacement_per_cycle_m, m.has_cycle)},
          {"cycle_time_s", number_or_null(m.mean_cycle_time_s, m.has_cycle)},
          {"mean_velocity_m_per_s", m.mean_velocity_m_per_s}};
}

json figures_3d(const json& s, const std::string& metric) {
  auto get = [&](const char* k) { return s.contains(k) && s[k].is_number() ? s[k] : json(nullptr); };
  json f = {{"displacement_per_cycle_m", get("displacement_per_cycle_m")},
            {"cycle_time_s", get("cycle_time_s")},
            {"mean_velocity_m_per_s", get("mean_velocity_m_per_s")}};
  if (metric == "mean_cycle_time_s") {
    double sum = 0;
    const json& t = s.contains("cycle_times_s") ? s["cycle_times_s"] : json::array();
    for (const auto& v : t) sum += v.get<double>();
    f[metric] = t.empty() ? json(nullptr) : json(sum / double(t.size()));
  } else {
    f[metric] = get(metric.c_str());
  }
  return f;
}

double error_bar_3d(const json& s, const std::string& figure) {
  if (s.contains("error_bars") && s["error_bars"].is_object() && s["error_bars"].contains(figure) &&
      s["error_bars"][figure].is_number())
    return std::abs(s["error_bars"][figure].get<double>());
  return 0.0;
}

json relative_differences(const json& fig1d, const json& fig3d) {
  json d = json::object();
  for (auto it = fig1d.begin(); it != fig1d.end(); ++it) {
    const json& b = fig3d.contains(it.key()) ? fig3d[it.key()] : json(nullptr);
    const bool both = it.value().is_number() && b.is_number() && b.get<double>() != 0.0;
    d[it.key()] = both ? json((b.get<double>() - it.value().get<double>()) / std::abs(b.get<double>())) : json(nullptr);
  }
  return d;
}

json agreement_json(const RankAgreement& a, const std::vector<std::string>& labels) {
  json mis = json::array();
  for (const auto& [i, j] : a.misranked) mis.push_back({labels[i], labels[j]});
  return {{"designs", a.n},
          {"kendall_tau", a.kendall_tau},
          {"kendall_tau_ci_95", {a.kendall_ci.lo, a.kendall_ci.hi}},
          {"spearman_rho", a.spearman_rho},
          {"spearman_rho_ci_95", {a.spearman_ci.lo, a.spearman_ci.hi}},
          {"method",
           "Kendall tau-b and Spearman rho on mid-ranks; 95 % intervals by Fisher z = atanh(r) with the "
           "variances 0.437/(n-4) (tau) and 1.06/(n-3) (rho) of Fieller, Hartley & Pearson (1957); at |r| = 1 "
           "the interval runs from the far end of that of the nearest attainable value (one adjacent pair swapped) to 1; a pair whose 3D values lie within their error bars is tied"},
          {"concordant_pairs", a.concordant},
          {"discordant_pairs", a.discordant},
          {"pairs_tied_in_1d", a.tied_x},
          {"pairs_tied_in_3d", a.tied_y},
          {"pairs_tied_by_3d_error_bars", a.tied_by_error_bars},
          {"misranked_pairs", mis}};
}

}  // namespace swim::design

namespace swim::design {

json confirm_candidates(const std::vector<Candidate>& cands, const ConfirmOptions& o,
                        const std::function<void(std::size_t, const Confirmed&)>& on_done) {
  fs::create_directories(o.runs_dir);
  json designs = json::array();
  std::vector<double> x, y, yerr;
  std::vector<std::size_t> used;  // candidates in the agreement
  std::vector<std::string> labels, failures;
  double wall = 0;
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const Candidate& c = cands[i];
    const std::string label = "design " + std::to_string(c.design);
    const json sc = confirm_scene(c.scene, o.section, o.threads);
    Confirmed r = o.run ? o.run(i, sc, confirm_label(c)) : run_confirmed(sc, o.runs_dir, confirm_label(c), o.progress);
    if (on_done) on_done(i, r);
    const json f1 = figures_1d(c.metrics, o.metric), f3 = figures_3d(r.summary, o.metric);
    const std::string status = r.summary.value("status", std::string("unknown"));
    if (!r.reused) wall += r.summary.value("wall_time_s", 0.0);
    json d = {{"design", c.design},
              {"values", c.values},
              {"selected_as", c.selected_as},
              {"rank_in_sweep_1d", c.rank_in_sweep},
              {"status_3d", status},
              {"folder_3d", fs::relative(r.folder, fs::path(o.runs_dir).parent_path()).generic_string()},
              {"reused_3d", r.reused},
              {"wall_time_3d_s", r.summary.value("wall_time_s", 0.0)},
              {"cell_size_3d_m", r.cell_size_m},
              {"figures_1d", f1},
              {"figures_3d", f3},
              {"error_bar_3d", error_bar_3d(r.summary, o.metric)},
              {"relative_difference_3d_vs_1d", relative_differences(f1, f3)}};
    designs.push_back(d);
    if (!r.ok) {
      failures.push_back(label + ": " + status);
      continue;
    }
    if (!f3[o.metric].is_number()) {
      failures.push_back(label + ": the 3D run reports no " + o.metric + " (no completed cycle)");
      continue;
    }
    // ranks count the best as 1: a maximised metric is ranked on its negative
    const double sgn = o.maximize ? -1.0 : 1.0;
    x.push_back(sgn * f1[o.metric].get<double>());
    y.push_back(sgn * f3[o.metric].get<double>());
    yerr.push_back(error_bar_3d(r.summary, o.metric));
    used.push_back(i);
    labels.push_back(label);
  }
  json report = {{"status", failures.empty() ? std::string("ok") : "failed: " + failures.front() +
                                                                       (failures.size() > 1 ? " (and " + std::to_string(failures.size() - 1) + " more)" : "")},
                 {"metric", o.metric},
                 {"goal", o.maximize ? "max" : "min"},
                 {"grid_3d", o.section.contains("grid") ? o.section["grid"] : json("the design scene's full3d.grid")},
                 {"threads_3d", o.threads},
                 {"designs_confirmed", cands.size()},
                 {"designs_failed_3d", failures.size()},
                 {"failures_3d", failures},
                 {"wall_time_3d_s", wall}};
  if (used.size() >= 2) {
    const std::vector<double> r1 = mid_ranks(x), r3 = mid_ranks(y);
    for (std::size_t k = 0; k < used.size(); ++k) {
      designs[used[k]]["rank_1d"] = r1[k];
      designs[used[k]]["rank_3d"] = r3[k];
    }
    const RankAgreement a = rank_agreement(x, y, yerr);
    report["agreement"] = agreement_json(a, labels);
    // a design is misranked when it takes part in a misranked pair
    std::vector<std::string> mis;
    for (const auto& [i, j] : a.misranked)
      for (std::size_t k : {i, j})
        if (std::find(mis.begin(), mis.end(), labels[k]) == mis.end()) mis.push_back(labels[k]);
    report["misranked_designs"] = mis;
    report["agreement_absent_because"] = nullptr;
  } else {
    report["agreement"] = nullptr;
    report["misranked_designs"] = json::array();
    report["agreement_absent_because"] = "fewer than two designs have a finished 3D run with the metric";
  }
  report["designs"] = designs;
  return report;
}

namespace {
std::string fig(const json& v, const std::string& key) {
  if (!v.is_number()) return "–";
  const std::string unit = reduced1d::metric_unit(key == "cycle_time_s" ? "mean_cycle_time_s" : key);
  char b[48];
  if (unit == "m" || unit == "m/s" || unit == "s" || unit == "m^3") return si(v.get<double>(), unit);
  std::snprintf(b, sizeof b, "%.4g%s%s", v.get<double>(), unit.empty() ? "" : " ", unit.c_str());
  return b;
}
std::string pct(const json& v) {
  if (!v.is_number()) return "–";
  char b[32];
  std::snprintf(b, sizeof b, "%+.1f %%", 100.0 * v.get<double>());
  return b;
}
/// A figure of the report for Markdown: `digits` significant digits, "–" when it is not a number.
std::string num(const json& v, int digits = 3) { return v.is_number() ? significant(v.get<double>(), digits) : "–"; }
}  // namespace

std::string confirm_markdown(const json& r, const std::string& title) {
  const std::string m = r["metric"].get<std::string>();
  std::string s = "# " + title + "\n\n";
  s += "Metric: `" + m + "` (" + r["goal"].get<std::string>() + "); 3D grid: `" + r["grid_3d"].dump() + "`; status: " +
       r["status"].get<std::string>() + ".\n\n";
  if (r["agreement"].is_object()) {
    const json& a = r["agreement"];
    s += "| rank agreement over " + std::to_string(a["designs"].get<int>()) + " designs | value | 95 % interval |\n|---|---|---|\n";
    s += "| Kendall τ-b | " + num(a["kendall_tau"]) + " | [" + num(a["kendall_tau_ci_95"][0]) + ", " + num(a["kendall_tau_ci_95"][1]) + "] |\n";
    s += "| Spearman ρ | " + num(a["spearman_rho"]) + " | [" + num(a["spearman_rho_ci_95"][0]) + ", " + num(a["spearman_rho_ci_95"][1]) + "] |\n\n";
    s += "Method: " + a["method"].get<std::string>() + ".\n\n";
    std::string mis;
    for (const auto& p : a["misranked_pairs"]) mis += (mis.empty() ? "" : "; ") + p[0].get<std::string>() + " / " + p[1].get<std::string>();
    s += "Misranked pairs (1D orders them one way, 3D the other): " + (mis.empty() ? std::string("none") : mis) + ".\n\n";
  } else {
    s += "No rank agreement: " + r["agreement_absent_because"].get<std::string>() + ".\n\n";
  }
  s += "| design | values | selected as | rank 1D (sweep) | rank 1D / 3D (confirmed) | " + m + " 1D | 3D | Δ | displacement per cycle 1D | 3D | cycle time 1D | 3D | mean velocity 1D | 3D | 3D status |\n";
  s += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& d : r["designs"]) {
    const json &f1 = d["figures_1d"], &f3 = d["figures_3d"], &rel = d["relative_difference_3d_vs_1d"];
    s += "| " + std::to_string(d["design"].get<int>()) + " | " + d["values"].get<std::string>() + " | " +
         d["selected_as"].get<std::string>() + " | " + std::to_string(d["rank_in_sweep_1d"].get<long>()) + " | " +
         num(d.value("rank_1d", json(nullptr)), 6) + " / " + num(d.value("rank_3d", json(nullptr)), 6) + " | " +
         fig(f1[m], m) + " | " + fig(f3[m], m) + " | " + pct(rel[m]) + " | " + fig(f1["displacement_per_cycle_m"], "displacement_per_cycle_m") +
         " | " + fig(f3["displacement_per_cycle_m"], "displacement_per_cycle_m") + " | " + fig(f1["cycle_time_s"], "cycle_time_s") +
         " | " + fig(f3["cycle_time_s"], "cycle_time_s") + " | " + fig(f1["mean_velocity_m_per_s"], "mean_velocity_m_per_s") + " | " +
         fig(f3["mean_velocity_m_per_s"], "mean_velocity_m_per_s") + " | " + d["status_3d"].get<std::string>() + " |\n";
  }
  s += "\nΔ = (3D − 1D) / |3D|. Ranks: 1 = best by the metric; equal values share their mean rank.\n";
  return s;
}

}  // namespace swim::design
