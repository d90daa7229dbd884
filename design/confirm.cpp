#include "design/confirm.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/si_format.hpp"
#include "common/run_folder.hpp"
#include "common/strict_json.hpp"
#include "axi/run_axi.hpp"
#include "axi/scene_axi.hpp"
#include "full3d/run3d.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"
#include "validation/suite_file.hpp"
#include "validation/error_estimate.hpp"

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
    if (it.key() != "grid" && it.key() != "error_estimate" && it.key() != "tier")
      throw InputError(where + "." + it.key(), scene::show(it.value()), "unknown key; allowed: tier, grid, error_estimate");
  if (section.contains("tier") &&
      !(section["tier"].is_string() && (section["tier"] == "3d" || section["tier"] == "axi")))
    throw InputError(where + ".tier", scene::show(section["tier"]),
                     "must be \"3d\" (the default: the immersed boundary) or \"axi\" (the axisymmetric reference of a "
                     "round wall, full3d.membrane.axisymmetric = true)");
  const bool axi = section.contains("tier") && section["tier"] == "axi";
  if (section.contains("error_estimate") && !section["error_estimate"].is_boolean())
    throw InputError(where + ".error_estimate", scene::show(section["error_estimate"]),
                     std::string("must be true or false (default ") + (kErrorEstimateDefault ? "true" : "false") +
                         ": each finished run also runs on a coarser grid for its own error bar)");
  if (section.contains("grid")) {
    const json& g = section["grid"];
    if (!g.is_object() || g.size() != 1 || !(g.contains("cells_across") || g.contains("cell_size")))
      throw InputError(where + ".grid", scene::show(g),
                       std::string("must be {\"cells_across\": <even integer>} or {\"cell_size\": \"<length>\"} (") +
                           (axi ? "axi.grid" : "full3d.grid") + ")");
  }
  return section;
}

std::string confirm_tier(const json& section) {
  return section.is_object() && section.contains("tier") ? section["tier"].get<std::string>() : std::string("3d");
}

std::string tier_label(const std::string& tier) { return tier == "axi" ? "axisymmetric" : "3D"; }
std::string tier_title(const std::string& tier) { return tier == "axi" ? "Axisymmetric" : "3D"; }
std::string tier_short(const std::string& tier) { return tier == "axi" ? "axi" : "3D"; }

namespace {
/// The threads a confirmation run of `tier` takes when given `threads` (axi.threads: 1 or 2).
int tier_threads(const std::string& tier, int threads) { return tier == "axi" ? std::clamp(threads, 1, 2) : threads; }
}  // namespace

bool wants_error_estimate(const json& section) {
  return section.is_object() && section.contains("error_estimate") ? section["error_estimate"].get<bool>()
                                                                   : kErrorEstimateDefault;
}

json confirm_identity(const json& section) {
  if (!section.is_object()) return section;
  json j = section;
  j.erase("error_estimate");
  return j.empty() ? json(nullptr) : j;
}

namespace {
/// The cells across of an axisymmetric run's grid (an even count: its cell size divides the
/// container's radius).
int cells_across_axi(const axi::ParamsAxi& p) { return 2 * p.nr; }

/// The coarse grid's cells across of the axisymmetric run p's estimate; throws InputError naming
/// `key` when there is none.
int coarse_cells_axi(const axi::ParamsAxi& p, const std::string& key) {
  const int n = cells_across_axi(p), c = validation::coarse_cells_across_axi(n);
  if (c == 0)
    throw InputError(key, "axi.grid.cells_across = " + std::to_string(n),
                     "the error estimate needs a coarser grid of at least 8 cells across (the axisymmetric tier's "
                     "least): confirm on 12 or more cells across, or set it false");
  return c;
}
}  // namespace

void check_error_estimate(const json& sc, const json& section, const std::string& where) {
  if (!wants_error_estimate(section)) return;
  json resolved;
  if (confirm_tier(section) == "axi")
    coarse_cells_axi(axi::read_scene_axi(sc, resolved), where + ".error_estimate");
  else
    validation::coarse_grid(sc, full3d::read_scene3d(sc, resolved), where + ".error_estimate");
}

std::string estimated_figure(const std::string& metric) {
  return metric == "mean_cycle_time_s" ? "cycle_time_s" : metric;
}

json confirm_scene(json sc, const json& section, int threads) {
  if (confirm_tier(section) == "axi") {
    if (section.contains("grid")) sc["axi"]["grid"] = section["grid"];
    sc["axi"]["threads"] = tier_threads("axi", threads);
    return sc;
  }
  if (section.contains("grid")) sc["full3d"]["grid"] = section["grid"];
  sc["full3d"]["threads"] = threads;
  sc["full3d"]["output"]["vtk"] = false;
  sc["full3d"]["output"]["fluid_fields"] = false;
  return sc;
}

void check_confirm_scene(const json& sc, const json& section) {
  json resolved;
  if (confirm_tier(section) == "axi")
    axi::read_scene_axi(sc, resolved);
  else
    full3d::read_scene3d(sc, resolved);
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
  return {{"summary", c.summary},       {"folder", c.folder},
          {"reused", c.reused},         {"ok", c.ok},
          {"cell_size_m", c.cell_size_m}, {"coarse_run", c.coarse_run},
          {"coarse_reused", c.coarse_reused}, {"coarse_wall_time_s", c.coarse_wall_time_s}};
}

Confirmed confirmed_from_json(const json& j) {
  Confirmed c;
  c.summary = j.at("summary");
  c.folder = j.at("folder").get<std::string>();
  c.reused = j.at("reused").get<bool>();
  c.ok = j.at("ok").get<bool>();
  c.cell_size_m = j.at("cell_size_m").get<double>();
  c.coarse_run = j.at("coarse_run").get<bool>();
  c.coarse_reused = j.at("coarse_reused").get<bool>();
  c.coarse_wall_time_s = j.at("coarse_wall_time_s").get<double>();
  return c;
}

std::string confirm_label(const Candidate& c) { return "design-" + std::to_string(c.design); }

namespace {
// The run in `dir`: the finished one reused, an interrupted one continued when `resumable()`
// (the tier's check of the checkpoint against the scene) accepts it, else run afresh into the
// cleared folder; run(resume) runs it.
template <class Resumable, class Run>
json reuse_resume_or_run(const fs::path& dir, bool& reused, Resumable resumable, Run run) {
  json s = finished_summary(dir);
  reused = !s.is_null() && !running(s);
  if (reused) return s;
  bool resume = false;
  if (running(s)) {
    try {
      resume = resumable();
    } catch (const InputError&) {
    }
  }
  if (!resume) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  return run(resume);
}

// The 3D run of (p, resolved) in `dir` (reuse_resume_or_run).
json run_or_reuse(const full3d::Params3d& p, const json& resolved, const fs::path& dir, int progress, bool& reused) {
  return reuse_resume_or_run(
      dir, reused,
      [&] {
        if (!fs::exists(full3d::checkpoint_path(dir.string()))) return false;
        full3d::check_resumable(p, resolved, dir.string());
        return true;
      },
      [&](bool resume) {
        full3d::RunControl ctl;
        ctl.progress = progress;
        ctl.quiet_vtk = true;
        ctl.resume = resume;
        return full3d::run3d(p, resolved, dir.string(), ctl).summary;
      });
}

// The axisymmetric run of (p, resolved) in `dir` (reuse_resume_or_run).
json run_or_reuse_axi(const axi::ParamsAxi& p, const json& resolved, const fs::path& dir, int progress, bool& reused) {
  return reuse_resume_or_run(
      dir, reused,
      [&] {
        axi::check_resumable_axi(p, resolved, dir.string());
        return true;
      },
      [&](bool resume) {
        axi::RunControlAxi ctl;
        ctl.progress = progress;
        ctl.resume = resume;
        return axi::run_axi(p, resolved, dir.string(), ctl).summary;
      });
}

// The error estimate of the finished run c (validation/error_estimate.hpp): its coarse run in
// c.folder/error_estimate/coarse, then the estimate of the headline figures and `figure`.
// An extra run of an error estimate (the coarse run, or an axisymmetric run's wall check) in
// `dir`, by `run` (which sets `reused`): its summary when it finished with its per-cycle
// figures; otherwise {"status": "failed: <what>: ..."}, its files taken off the run's list (they
// are not the run's, as with swim run). An earlier invocation's run, reused, is listed by the run.
json estimate_run(Confirmed& c, const std::string& dir, const std::string& what, const bool& reused,
                  const std::function<json()>& run) {
  json s;
  try {
    s = run();
  } catch (const std::exception& e) {
    s = {{"status", std::string("failed: ") + e.what()}};
  }
  c.coarse_run = true;
  const std::string status = s.value("status", std::string("unknown"));
  if (status != "ok") {
    output::reset_ledger(dir);
    return {{"status", "failed: " + what + ": " + status}};
  }
  if (!s["displacement_per_cycle_m"].is_number()) {
    output::reset_ledger(dir);
    return {{"status", "failed: " + what + ": no cycle completed (" +
                           s.value("per_cycle_absent_because", std::string("no per-cycle figures")) + ")"}};
  }
  if (reused) output::adopt_listed(dir);
  return s;
}

json estimate_error(Confirmed& c, const json& sc, const full3d::Params3d& p, const std::string& figure, int progress) {
  validation::CoarseGrid g;
  try {
    g = validation::coarse_grid(sc, p, "confirm.error_estimate");
  } catch (const InputError& e) {
    return {{"status", std::string("failed: no coarse grid: ") + e.what()}};
  }
  const std::string dir = validation::coarse_folder(c.folder);
  double wall = 0;
  const json s = estimate_run(c, dir, "the coarse run (" + std::to_string(g.cells) + " cells across)", c.coarse_reused, [&] {
    json r = run_or_reuse(g.p, g.resolved, dir, progress, c.coarse_reused);
    wall = r.value("wall_time_s", 0.0);
    return r;
  });
  c.coarse_wall_time_s = wall;
  if (s.value("status", std::string()) != "ok") return s;
  return validation::error_estimate_json(c.summary, s, g.cells, p.h, g.p.h, {figure});
}

// The same for a finished axisymmetric run: its coarse run (coarse_cells_axi) in
// c.folder/error_estimate/coarse, the estimate at the sharp interface's orders; then its wall
// check, the run again on its own grid with its rings at half the spacing
// (axi.spacing_factor x 0.5) in c.folder/error_estimate/wall, whose change of each figure,
// taken at order 1 (change / (1 - 0.5)), is the wall's resolution error at this grid: it widens
// each figure's interval on both sides (what the two grids cannot see, docs/design-loop.md).
json estimate_error_axi(Confirmed& c, const json& sc, const axi::ParamsAxi& p, const std::string& figure, int progress) {
  int cells = 0;
  try {
    cells = coarse_cells_axi(p, "confirm.error_estimate");
  } catch (const InputError& e) {
    return {{"status", std::string("failed: no coarse grid: ") + e.what()}};
  }
  // one extra run of the estimate on `scene` (its cell size in *h when asked); the wall time of a
  // run this invocation made goes to the estimate's
  auto extra_run = [&](const json& scene, const std::string& dir, const std::string& what, bool& reused,
                       double* h) -> json {
    return estimate_run(c, dir, what, reused, [&] {
      json resolved;
      const axi::ParamsAxi pv = axi::read_scene_axi(scene, resolved);
      if (h) *h = pv.h;
      json r = run_or_reuse_axi(pv, resolved, dir, progress, reused);
      if (!reused) c.coarse_wall_time_s += r.value("wall_time_s", 0.0);
      return r;
    });
  };
  c.coarse_wall_time_s = 0;
  json coarse_scene = sc;
  coarse_scene["axi"]["grid"] = {{"cells_across", cells}};
  double h_coarse = 0;
  const json s = extra_run(coarse_scene, validation::coarse_folder(c.folder),
                           "the coarse run (" + std::to_string(cells) + " cells across)", c.coarse_reused, &h_coarse);
  if (s.value("status", std::string()) != "ok") return s;
  json e = validation::sharp_interface_error_estimate_json(c.summary, s, cells, p.h, h_coarse, {figure});
  if (e.value("status", std::string()) != "ok") return e;

  constexpr double kWallCheckFactor = 0.5;
  json wall_scene = sc;
  wall_scene["axi"]["spacing_factor"] = kWallCheckFactor * p.spacing_factor;
  bool wall_reused = false;
  const json w = extra_run(wall_scene, (fs::path(c.folder) / "error_estimate" / "wall").string(),
                           "the wall check (axi.spacing_factor " + std::to_string(kWallCheckFactor * p.spacing_factor) +
                               ")",
                           wall_reused, nullptr);
  c.coarse_reused = c.coarse_reused && wall_reused;
  json check = {{"spacing_factor", kWallCheckFactor * p.spacing_factor},
                {"folder", "error_estimate/wall"},
                {"method", "the run again on its grid with its rings at half the spacing; each figure's wall "
                           "resolution error = |change| / (1 - 0.5) (order 1), added to both ends of its interval and "
                           "to its error"}};
  if (w.value("status", std::string()) != "ok") {
    check["status"] = w["status"];
    e["wall_check"] = check;
    return e;
  }
  check["status"] = "ok";
  for (auto it = e.begin(); it != e.end(); ++it) {
    json& f = it.value();
    if (!f.is_object() || !f.contains("fine") || !w.contains(it.key()) || !w[it.key()].is_number()) continue;
    const double ew = std::abs(w[it.key()].get<double>() - f["fine"].get<double>()) / (1.0 - kWallCheckFactor);
    f["wall_check"] = w[it.key()];
    f["wall_resolution_error"] = ew;
    f["interval_low"] = f["interval_low"].get<double>() - ew;
    f["interval_high"] = f["interval_high"].get<double>() + ew;
    f["error"] = f["error"].get<double>() + ew;
  }
  e["wall_check"] = check;
  return e;
}

// The estimate of the finished run c, by `estimate` (the run's tier's), added to its
// summary.json; an estimate the summary holds already is kept and its coarse run counted as
// reused.
void add_error_estimate(Confirmed& c, const std::string& figure, const std::function<json()>& estimate) {
  const json* have = c.summary.contains("error_estimate") ? &c.summary["error_estimate"] : nullptr;
  const bool complete = have && (have->value("status", std::string()) != "ok" || have->contains(figure));
  if (complete) {  // an earlier invocation's estimate: its coarse run (and an axisymmetric run's wall check), reused
    const json cs = finished_summary(validation::coarse_folder(c.folder));
    const json ws = finished_summary(fs::path(c.folder) / "error_estimate" / "wall");
    c.coarse_run = c.coarse_reused = !cs.is_null();
    c.coarse_wall_time_s = (cs.is_null() ? 0.0 : cs.value("wall_time_s", 0.0)) + (ws.is_null() ? 0.0 : ws.value("wall_time_s", 0.0));
    return;
  }
  if (!c.ok || !c.summary["displacement_per_cycle_m"].is_number()) return;
  const json e = estimate();
  if (!output::amend_summary(c.folder, [&](json& j) { j["error_estimate"] = e; }))
    throw OutputError((fs::path(c.folder) / "summary.json").string(), "could not be read back to add the error estimate");
  c.summary["error_estimate"] = e;
}
}  // namespace

namespace {
// A confirmation run's record before it runs: its folder in runs_dir, the label and the hash of
// its resolved physics (`physics`, the thread count left out: it does not change the results),
// and its cell size.
Confirmed confirmation_in(const std::string& runs_dir, const std::string& label, const json& physics, double h) {
  Confirmed c;
  c.folder = (fs::path(runs_dir) / (label + "-" + output::json_hash(physics).substr(0, 12))).string();
  c.cell_size_m = h;
  return c;
}
}  // namespace

Confirmed run_confirmed(const json& sc, const std::string& runs_dir, const std::string& label, int progress,
                        bool error_estimate, const std::string& metric, const std::string& tier) {
  json resolved;
  Confirmed c;
  // the estimate of a finished run with its per-cycle figures (as swim run --error-estimate
  // gives one); an estimate the summary holds already is kept
  const std::string figure = estimated_figure(metric);
  if (tier == "axi") {
    const axi::ParamsAxi p = axi::read_scene_axi(sc, resolved);
    json physics = resolved;
    if (physics.contains("axi")) physics["axi"].erase("threads");
    physics["confirm_tier"] = "axi";  // never the folder of the same design's 3D run
    c = confirmation_in(runs_dir, label, physics, p.h);
    c.summary = run_or_reuse_axi(p, resolved, c.folder, progress, c.reused);
    c.ok = c.summary.value("status", std::string()) == "ok";
    if (error_estimate) add_error_estimate(c, figure, [&] { return estimate_error_axi(c, sc, p, figure, progress); });
    return c;
  }
  const full3d::Params3d p = full3d::read_scene3d(sc, resolved);
  json physics = resolved;
  physics["full3d"].erase("threads");
  c = confirmation_in(runs_dir, label, physics, p.h);
  c.summary = run_or_reuse(p, resolved, c.folder, progress, c.reused);
  c.ok = c.summary.value("status", std::string()) == "ok";
  if (error_estimate) add_error_estimate(c, figure, [&] { return estimate_error(c, sc, p, figure, progress); });
  return c;
}

json figures_1d(const reduced1d::Metrics& m, const std::string& metric) {
  return {{metric, reduced1d::metric_value(m, metric)},
          {"displacement_per_cycle_m", number_or_null(m.displacement_per_cycle_m, m.has_cycle)},
          {"cycle_time_s", number_or_null(m.mean_cycle_time_s, m.has_cycle)},
          {"mean_velocity_m_per_s", m.mean_velocity_m_per_s}};
}

void match_recovery_end(Candidate& c, const std::string& scene_dir) {
  const json s = validation::with_recovery_end_3d(c.scene);
  json resolved;
  const reduced1d::Params p = reduced1d::read_scene(s, resolved, scene_dir);
  if (p.wave != reduced1d::WaveKind::ForceDriven) return;
  c.recovery_end_1d = reduced1d::recovery_end_name(p.protocol.recovery_end);
  // the design states its own rule, or the 3D rule is the sweep's (the 1D default) already
  if (s == c.scene || p.protocol.recovery_end == reduced1d::RecoveryEnd::Energy) return;
  const reduced1d::DesignOutcome o = reduced1d::run_design(p);
  if (!o.ok)
    throw NumericalError("design " + std::to_string(c.design) + " in 1D with the 3D run's recovery end (" +
                             c.recovery_end_1d + "): " + o.message,
                         "state model1d.recovery_end in the design scene to keep the sweep's rule");
  c.metrics_sweep = c.metrics;
  c.metrics = o.metrics;
}

json figures_confirming(const json& s, const std::string& metric) {
  // a run that did not finish has only partial figures (its mean velocity up to the failure):
  // none of them is the design's
  const bool finished = s.value("status", std::string()) == "ok";
  auto get = [&](const char* k) { return finished && s.contains(k) && s[k].is_number() ? s[k] : json(nullptr); };
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

json error_bar_of(const json& s, const std::string& figure) {
  const std::string k = estimated_figure(figure);
  if (!s.contains("error_estimate") || !s["error_estimate"].is_object()) return nullptr;
  const json& e = s["error_estimate"];
  if (e.value("status", std::string()) != "ok" || !e.contains(k) || !e[k].is_object()) return nullptr;
  const json& f = e[k];
  for (const char* b : {"fine", "interval_low", "interval_high"})
    if (!f.contains(b) || !f[b].is_number()) return nullptr;
  const double v = f["fine"].get<double>();
  return std::max(std::abs(v - f["interval_low"].get<double>()), std::abs(v - f["interval_high"].get<double>()));
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

json agreement_json(const RankAgreement& a, const std::vector<std::string>& labels, const std::string& tier) {
  json mis = json::array();
  for (const auto& [i, j] : a.misranked) mis.push_back({labels[i], labels[j]});
  const std::string L = tier_label(tier), T = "_" + tier;
  return {{"designs", a.n},
          {"kendall_tau", a.kendall_defined ? json(a.kendall_tau) : json(nullptr)},
          {"kendall_tau_ci_95", a.kendall_defined ? json({a.kendall_ci.lo, a.kendall_ci.hi}) : json(nullptr)},
          {"kendall_tau_absent_because",
           a.kendall_defined ? json(nullptr)
                             : json("every pair is tied in 1D or in " + L + " (" + L +
                                    " ties counting those within the error bars): tau-b is 0/0, the " + L +
                                    " tier does not order these designs beyond its own error")},
          {"spearman_rho", a.spearman_rho},
          {"spearman_rho_ci_95", {a.spearman_ci.lo, a.spearman_ci.hi}},
          {"method",
           std::string("Kendall tau-b and Spearman rho on mid-ranks; 95 % intervals by Fisher z = atanh(r) with the "
                       "variances 0.437/(n-4) (tau) and 1.06/(n-3) (rho) of Fieller, Hartley & Pearson (1957); at |r| = 1 "
                       "the interval runs from the far end of that of the nearest attainable value (one adjacent pair "
                       "swapped) to 1") +
               "; a pair whose " + L + " values lie within their error bars is tied"},
          {"concordant_pairs", a.concordant},
          {"discordant_pairs", a.discordant},
          {"pairs_tied_in_1d", a.tied_x},
          {"pairs_tied_in" + T, a.tied_y},
          {"pairs_tied_by" + T + "_error_bars", a.tied_by_error_bars},
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
  const bool estimate = wants_error_estimate(o.section);
  // the confirming tier names its keys and texts: "figures_3d" or "figures_axi", "3D" or "axisymmetric"
  const std::string tier = confirm_tier(o.section), T = "_" + tier, L = tier_label(tier);
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const Candidate& c = cands[i];
    const std::string label = "design " + std::to_string(c.design);
    const json sc = confirm_scene(c.scene, o.section, o.threads);
    Confirmed r = o.run ? o.run(i, sc, confirm_label(c))
                        : run_confirmed(sc, o.runs_dir, confirm_label(c), o.progress, estimate, o.metric, tier);
    if (on_done) on_done(i, r);
    const json f1 = figures_1d(c.metrics, o.metric), f3 = figures_confirming(r.summary, o.metric);
    const std::string status = r.summary.value("status", std::string("unknown"));
    if (!r.reused) wall += r.summary.value("wall_time_s", 0.0);
    if (r.coarse_run && !r.coarse_reused) wall += r.coarse_wall_time_s;
    // the error bar of the metric, and why there is none
    const json bar = estimate ? error_bar_of(r.summary, o.metric) : json(nullptr);
    json bar_absent = nullptr;
    if (!estimate) {
      bar_absent = "confirm.error_estimate is false";
    } else if (bar.is_null()) {
      const json& e = r.summary.contains("error_estimate") ? r.summary["error_estimate"] : json(nullptr);
      bar_absent = e.is_object() && e.contains("status") && e["status"] != "ok"
                       ? json(e["status"])
                       : json("no error estimate: the " + L + " run did not finish with its per-cycle figures");
    }
    json d = {{"design", c.design},
              {"values", c.values},
              {"selected_as", c.selected_as},
              {"rank_in_sweep_1d", c.rank_in_sweep},
              {"status" + T, status},
              {"folder" + T, fs::relative(r.folder, fs::path(o.runs_dir).parent_path()).generic_string()},
              {"reused" + T, r.reused},
              {"wall_time" + T + "_s", r.summary.value("wall_time_s", 0.0)},
              {"cell_size" + T + "_m", r.cell_size_m},
              {"figures_1d", f1},
              {"recovery_end_1d", c.recovery_end_1d.empty() ? json(nullptr) : json(c.recovery_end_1d)},
              {"figures_1d_sweep", c.metrics_sweep ? figures_1d(*c.metrics_sweep, o.metric) : json(nullptr)},
              {"figures" + T, f3},
              {"error_bar" + T, bar},
              {"error_bar" + T + "_absent_because", bar_absent},
              {"coarse_wall_time" + T + "_s", r.coarse_run ? json(r.coarse_wall_time_s) : json(nullptr)},
              {"relative_difference" + T + "_vs_1d", relative_differences(f1, f3)}};
    if (estimate && r.summary.contains("error_estimate") && r.summary["error_estimate"].is_object()) {
      const json& e = r.summary["error_estimate"];
      const std::string k = estimated_figure(o.metric);
      d["error_estimate" + T] = e.contains(k) ? json{{"figure", k},
                                                    {"coarse_cells_across", e["coarse_cells_across"]},
                                                    {"coarse_cell_size_m", e["coarse_cell_size_m"]},
                                                    {"estimate", e[k]}}
                                             : json{{"status", e.value("status", std::string("unknown"))}};
    } else {
      d["error_estimate" + T] = nullptr;
    }
    designs.push_back(d);
    if (!r.ok) {
      failures.push_back(label + ": " + status);
      continue;
    }
    if (!f3[o.metric].is_number()) {
      failures.push_back(label + ": the " + L + " run reports no " + o.metric + " (no completed cycle)");
      continue;
    }
    // ranks count the best as 1: a maximised metric is ranked on its negative
    const double sgn = o.maximize ? -1.0 : 1.0;
    x.push_back(sgn * f1[o.metric].get<double>());
    y.push_back(sgn * f3[o.metric].get<double>());
    yerr.push_back(bar.is_number() ? bar.get<double>() : 0.0);
    used.push_back(i);
    labels.push_back(label);
  }
  json report = {{"status", failures.empty() ? std::string("ok") : "failed: " + failures.front() +
                                                                       (failures.size() > 1 ? " (and " + std::to_string(failures.size() - 1) + " more)" : "")},
                 {"metric", o.metric},
                 {"goal", o.maximize ? "max" : "min"},
                 {"tier", tier},
                 {"grid" + T, o.section.contains("grid") ? o.section["grid"]
                                                          : json(tier == "axi" ? "the design scene's axi.grid"
                                                                               : "the design scene's full3d.grid")},
                 {"threads" + T, tier_threads(tier, o.threads)},
                 {"error_estimate" + T, estimate},
                 {"designs_with_error_bar" + T, 0},
                 {"designs_confirmed", cands.size()},
                 {"designs_failed" + T, failures.size()},
                 {"failures" + T, failures},
                 {"wall_time" + T + "_s", wall}};
  if (used.size() >= 2) {
    const std::vector<double> r1 = mid_ranks(x), r3 = mid_ranks(y);
    for (std::size_t k = 0; k < used.size(); ++k) {
      designs[used[k]]["rank_1d"] = r1[k];
      designs[used[k]]["rank" + T] = r3[k];
    }
    const RankAgreement a = rank_agreement(x, y, yerr);
    report["agreement"] = agreement_json(a, labels, tier);
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
    report["agreement_absent_because"] = "fewer than two designs have a finished " + L + " run with the metric";
  }
  std::size_t with_bar = 0;
  for (const auto& d : designs) with_bar += d["error_bar" + T].is_number();
  report["designs_with_error_bar" + T] = with_bar;
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
  const std::string tier = r.value("tier", std::string("3d")), T = "_" + tier, L = tier_label(tier);
  // error bars (their column, the ties they make) on the 3D tier, and on the axisymmetric tier
  // where its runs estimated their error
  const bool bars = tier != "axi" || r.value("error_estimate" + T, false);
  std::string s = "# " + title + "\n\n";
  s += "Metric: `" + m + "` (" + r["goal"].get<std::string>() + "); " + L + " grid: `" + r["grid" + T].dump() + "`; status: " +
       r["status"].get<std::string>() + ".\n\n";
  if (r["agreement"].is_object()) {
    const json& a = r["agreement"];
    s += "| rank agreement over " + std::to_string(a["designs"].get<int>()) + " designs | value | 95 % interval |\n|---|---|---|\n";
    if (a["kendall_tau"].is_number())
      s += "| Kendall τ-b | " + num(a["kendall_tau"]) + " | [" + num(a["kendall_tau_ci_95"][0]) + ", " + num(a["kendall_tau_ci_95"][1]) + "] |\n";
    else
      s += "| Kendall τ-b | – (" + a["kendall_tau_absent_because"].get<std::string>() + ") | – |\n";
    s += "| Spearman ρ | " + num(a["spearman_rho"]) + " | [" + num(a["spearman_rho_ci_95"][0]) + ", " + num(a["spearman_rho_ci_95"][1]) + "] |\n\n";
    s += "Method: " + a["method"].get<std::string>() + ".\n\n";
    std::string mis;
    for (const auto& p : a["misranked_pairs"]) mis += (mis.empty() ? "" : "; ") + p[0].get<std::string>() + " / " + p[1].get<std::string>();
    s += "Misranked pairs (1D orders them one way, " + L + " the other" +
         (bars ? " beyond the " + L + " error bars" : std::string()) + "): " +
         (mis.empty() ? std::string("none") : mis) + ".\n\n";
    if (bars)
      s += "Pairs tied " + (tier == "axi" ? std::string("on the axisymmetric tier") : "in " + L) + " by their error bars (" + L +
           " values apart by no more than the sum of their error bars): " +
           std::to_string(a["pairs_tied_by" + T + "_error_bars"].get<int>()) + " of " +
           std::to_string(a["designs"].get<int>() * (a["designs"].get<int>() - 1) / 2) + ".\n\n";
  } else {
    s += "No rank agreement: " + r["agreement_absent_because"].get<std::string>() + ".\n\n";
  }
  if (r.value("error_estimate_3d", false))
    s += "3D error bars: each finished 3D run also ran on a coarser grid (`swim run --error-estimate`); the error bar is "
         "the largest distance from the run's value to the interval of its extrapolations to h → 0 at the orders 0.5 "
         "to 2 (" + std::to_string(r["designs_with_error_bar_3d"].get<int>()) + " of " +
         std::to_string(r["designs"].size()) + " designs have one).\n\n";
  if (r.value("error_estimate_axi", false))
    s += "Axisymmetric error bars: each finished axisymmetric run also ran on a coarser grid (about 3/4 of its cells "
         "across) and on its own grid with its rings at half the spacing; the error bar is the largest distance from "
         "the run's value to the interval of its extrapolations to h → 0 at the orders 1 to 3.5 of the fitted method, "
         "a sharp interface of second order, widened on both sides by twice the wall check's change (" +
         std::to_string(r["designs_with_error_bar_axi"].get<int>()) + " of " + std::to_string(r["designs"].size()) +
         " designs have one).\n\n";

  s += "| design | values | selected as | rank 1D (sweep) | rank 1D / " + L + " (confirmed) | " + m + " 1D | " + L + " | " +
       (bars ? L + " error bar | " : std::string()) + "Δ | displacement per cycle 1D | " + L + " | cycle time 1D | " + L +
       " | mean velocity 1D | " + L + " | " + L + " status |\n";
  s += std::string("|---|---|---|---|---|---|---|") + (bars ? "---|" : "") + "---|---|---|---|---|---|---|---|\n";
  for (const auto& d : r["designs"]) {
    const json &f1 = d["figures_1d"], &f3 = d["figures" + T], &rel = d["relative_difference" + T + "_vs_1d"];
    const json& bar = d["error_bar" + T];
    s += "| " + std::to_string(d["design"].get<int>()) + " | " + d["values"].get<std::string>() + " | " +
         d["selected_as"].get<std::string>() + " | " + std::to_string(d["rank_in_sweep_1d"].get<long>()) + " | " +
         num(d.value("rank_1d", json(nullptr)), 6) + " / " + num(d.value("rank" + T, json(nullptr)), 6) + " | " +
         fig(f1[m], m) + " | " + fig(f3[m], m) + " | " +
         (bars ? (bar.is_number() ? "± " + fig(bar, m) : std::string("–")) + " | " : std::string()) + pct(rel[m]) +
         " | " + fig(f1["displacement_per_cycle_m"], "displacement_per_cycle_m") +
         " | " + fig(f3["displacement_per_cycle_m"], "displacement_per_cycle_m") + " | " + fig(f1["cycle_time_s"], "cycle_time_s") +
         " | " + fig(f3["cycle_time_s"], "cycle_time_s") + " | " + fig(f1["mean_velocity_m_per_s"], "mean_velocity_m_per_s") + " | " +
         fig(f3["mean_velocity_m_per_s"], "mean_velocity_m_per_s") + " | " + d["status" + T].get<std::string>() + " |\n";
  }
  s += "\nΔ = (" + tier_short(tier) + " − 1D) / |" + tier_short(tier) +
       "|. Ranks: 1 = best by the metric; equal values share their mean rank.\n";
  // the recovery end of the 1D figures, and the sweep's own figures where it changed them
  std::string rules, changed;
  for (const auto& d : r["designs"]) {
    if (!d.contains("recovery_end_1d") || !d["recovery_end_1d"].is_string()) continue;
    const std::string rule = d["recovery_end_1d"].get<std::string>();
    if (rules.find("`" + rule + "`") == std::string::npos) rules += (rules.empty() ? "" : ", ") + ("`" + rule + "`");
    if (d["figures_1d_sweep"].is_object())
      changed += (changed.empty() ? "" : "; ") + std::string("design ") + std::to_string(d["design"].get<int>()) + ": " +
                 fig(d["figures_1d_sweep"][m], m) + ", cycle " + fig(d["figures_1d_sweep"]["cycle_time_s"], "cycle_time_s");
  }
  if (!rules.empty())
    s += "\nThe 1D cycles end by the recovery rule of their " + L + " runs (" + rules +
         ", model1d.recovery_end), so that both tiers' cycle times measure the same cycle." +
         (changed.empty() ? std::string() : " The sweep's own figures (its rule) were: " + changed + ".") + "\n";
  return s;
}

}  // namespace swim::design
