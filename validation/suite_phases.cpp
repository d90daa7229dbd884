#include "validation/suite_phases.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "axi/scene_axi.hpp"
#include "common/errors.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"
#include "validation/compare.hpp"
#include "validation/extrapolated_reference.hpp"
#include "validation/suite_file.hpp"
#include "validation/verdicts.hpp"

namespace fs = std::filesystem;

namespace swim::validation {

namespace {

/// One 1D run as the report sees it (never cached: seconds at most).
struct Run1d {
  json record;
  Series series;
  record::CycleFigures cyc;
  double wall = 0;
  bool ok = false;
};

Run1d run_1d(const json& sc, const std::string& label, const std::string& scene_dir) {
  json resolved;
  Run1d r;
  r.record = {{"label", label}};
  try {
    const reduced1d::Params p = reduced1d::read_scene(sc, resolved, scene_dir);
    const auto t0 = std::chrono::steady_clock::now();
    reduced1d::SolveOptions so;
    so.keep_samples = false;
    so.keep_record_rows = true;
    const reduced1d::Result res = reduced1d::solve(p, so);
    r.wall = seconds_since(t0);
    const reduced1d::Metrics m = reduced1d::metrics(p, res);
    r.series = series_of(res.record);
    r.ok = !res.failure.has_value();
    r.cyc.has_cycle = m.has_cycle;
    if (m.has_cycle) {
      r.cyc.displacement_per_cycle_m = m.displacement_per_cycle_m;
      r.cyc.cycle_time_s = m.mean_cycle_time_s;
      r.cyc.mean_velocity_per_cycle_m_per_s = m.mean_velocity_per_cycle_m_per_s;
    }
    r.record["status"] = r.ok ? "ok" : std::string("failed: ") + res.failure->what();
    r.record["wall_time_s"] = r.wall;
    r.record["cells"] = p.numerics.cells;
    r.record["has_cycle"] = m.has_cycle;
    r.record["pumped_volume_m3"] = m.pumped_volume_m3;
    if (m.has_cycle) {
      r.record["displacement_per_cycle_m"] = m.displacement_per_cycle_m;
      r.record["cycle_time_s"] = m.mean_cycle_time_s;
      r.record["mean_velocity_per_cycle_m_per_s"] = m.mean_velocity_per_cycle_m_per_s;
      // the protocol's phases, as the reference runs' (run_cache.cpp, run_entry)
      const record::CycleFigures cf = record::cycle_figures(res.record);
      if (!cf.phase_times_s.empty()) r.record["cycle_phase_times_s"] = cf.phase_times_s;
      if (!cf.phase_displacements_m.empty()) r.record["cycle_phase_displacements_m"] = cf.phase_displacements_m;
    } else {
      r.record["no_cycle_reason"] = m.no_cycle_reason;
    }
    r.record["plausible"] = m.implausible.empty();
    r.record["series"] = downsample(r.series, m.has_cycle && p.protocol.cycles == 1 ? m.mean_cycle_time_s : m.t_end_s);
  } catch (const InputError& e) {
    r.record["status"] = std::string("not run: ") + e.what();
  } catch (const NumericalError& e) {
    r.record["status"] = std::string("failed: ") + e.what();
  }
  return r;
}

/// The grid error of a 1D model's figures on case c: the model's scene again on twice its
/// cells, each figure's error estimated as 2 |v_N - v_2N| (a first-order series; a second-order
/// one would give 4/3 of the change), in the figure's unit. `status` says why there is none.
json grid_error_1d(const json& scene, const Run1d& r, const std::string& label, const std::string& scene_dir) {
  const long cells = r.record.value("cells", 0L);
  json e = {{"cells", cells}, {"refined_cells", 2 * cells},
            {"rule", "2 |v_N - v_2N|: the figure on twice the cells, read as a first-order series"}};
  json s = scene;
  set_key(s, "numerics1d.cells", 2 * cells);
  const Run1d f = run_1d(s, label, scene_dir);
  if (!f.cyc.has_cycle) {
    e["status"] = "no error estimate: on " + std::to_string(2 * cells) + " cells the model " +
                  (f.ok ? "completed no cycle" : f.record.value("status", std::string("failed")));
    return e;
  }
  e["status"] = "ok";
  e["displacement_per_cycle_m"] = 2.0 * std::abs(r.cyc.displacement_per_cycle_m - f.cyc.displacement_per_cycle_m);
  e["cycle_time_s"] = 2.0 * std::abs(r.cyc.cycle_time_s - f.cyc.cycle_time_s);
  e["mean_velocity_per_cycle_m_per_s"] =
      2.0 * std::abs(r.cyc.mean_velocity_per_cycle_m_per_s - f.cyc.mean_velocity_per_cycle_m_per_s);
  return e;
}

json relative(double value, double ref) {
  if (!(std::abs(ref) > 0)) return nullptr;
  return (value - ref) / std::abs(ref);
}

/// A 1D model's scene for this case (model_scene), with the calibration file when the model is
/// a calibrated one.
json model_scene_of(const SuiteCase& c, const json& model, const std::string& cal_file) {
  return model_scene(c.base, model, model.value("calibrated", false) ? fs::absolute(cal_file).string() : "");
}

/// The scene of the case at its calibration grid.
json at_calibration_grid(const SuiteCase& c) {
  json s = c.base;
  set_key(s, c.grid_key, c.grids[c.calibration_grid]);
  return s;
}

/// The runs of a grid series (coarse to fine) as U(t) references.
template <class Run>
std::vector<VelocityRun> velocity_runs(const std::vector<Run>& runs) {
  std::vector<VelocityRun> v;
  for (const Run& r : runs) v.push_back({&r.series, r.cyc.has_cycle, r.cyc.cycle_time_s, r.h});
  return v;
}

}  // namespace

json velocity_vs_runs(const Series& s, double cycle_time_s, const std::vector<VelocityRun>& runs) {
  // the runs that completed a cycle, coarse to fine: the finest of them is the reference
  std::vector<const VelocityRun*> done;
  for (const VelocityRun& r : runs)
    if (r.has_cycle && r.cycle_time_s > 0 && r.series->t.size() > 1) done.push_back(&r);
  if (done.empty() || s.t.size() < 2 || !(cycle_time_s > 0)) return json::object();
  const VelocityRun& finest = *done.back();
  const SeriesComparison ph =
      compare_series(s.t, s.u, cycle_time_s, finest.series->t, finest.series->u, finest.cycle_time_s, true);
  const SeriesComparison ab =
      compare_series(s.t, s.u, cycle_time_s, finest.series->t, finest.series->u, finest.cycle_time_s, false);
  json v = {{"phase_l2_relative", ph.l2_relative},
            {"phase_correlation", ph.correlation},
            {"time_l2_relative", ab.l2_relative},
            {"time_correlation", ab.correlation},
            {"reference_cell_size_m", finest.h}};
  // the uncertainty of the correlation: its spread against the (up to) three finest grids
  // that completed a cycle, as the spread of a reference that is not asymptotic
  std::vector<double> corr;
  for (auto it = done.rbegin(); it != done.rend() && corr.size() < 3; ++it)
    corr.push_back(
        compare_series(s.t, s.u, cycle_time_s, (*it)->series->t, (*it)->series->u, (*it)->cycle_time_s, true).correlation);
  if (corr.size() >= 2) {
    const double spread = *std::max_element(corr.begin(), corr.end()) - *std::min_element(corr.begin(), corr.end());
    v["phase_correlation_grid_spread"] = spread;
    v["phase_correlation_grids"] = corr.size();
  }
  return v;
}

SuiteCase open_case(const json& spec, std::size_t index, std::size_t count, const std::string& suite_dir,
                    const std::string& data_dir) {
  SuiteCase c;
  c.spec = spec;
  c.scene_path = find_scene(spec["scene"], suite_dir, data_dir);
  c.scene_dir = fs::path(c.scene_path).parent_path().string();
  c.base = scene::load_file(c.scene_path);
  apply_sets(c.base, spec.value("set", json()));
  c.name = c.base.value("name", fs::path(c.scene_path).stem().string());
  c.grid_key = spec.value("grid_key", std::string("full3d.grid.cells_across"));
  c.grids = spec["grids"];
  c.calibration_grid = std::size_t(spec.value("calibration_grid", long(c.grids.size()) - 1));
  c.paper_max = spec.contains("paper") && spec["paper"].is_object() && spec["paper"].contains("max_displacement_m") &&
                spec["paper"]["max_displacement_m"].is_number();
  c.tag = "case " + std::to_string(index + 1) + "/" + std::to_string(count) + " (" + c.name + ")";
  return c;
}

const json& case_targets1d(const SuiteCase& c, const json& suite) {
  static const json none;
  if (c.spec.contains("targets1d")) return c.spec["targets1d"];
  return suite.contains("targets1d") ? suite["targets1d"] : none;
}

json case_entry(const SuiteCase& c, const std::string& data_dir) {
  // shipped scenes are named relative to the source tree, so that reports compare across machines
  const fs::path rel = fs::path(c.scene_path).lexically_relative(fs::path(data_dir).parent_path());
  const std::string scene_name = !rel.empty() && *rel.begin() != ".." ? rel.string() : c.scene_path;
  json cr = {{"name", c.name}, {"scene", scene_name}, {"group", c.spec.value("group", json())},
             {"grid_key", c.grid_key}, {"paper", c.spec.value("paper", json())}};
  cr["description"] = c.base.value("description", std::string());
  cr["sweep_value"] = c.spec.value("sweep_value", json());
  return cr;
}

std::vector<Run3d> resolution_study(const SuiteCase& c, RunCache& cache, const Say& say, int progress, json& cr) {
  std::vector<Run3d> runs;
  json runs_j = json::array();
  // the relative cost of each grid's run: its cells per time step (the simulated span is the
  // same physics on every grid); a fixed step costs 1/dt steps, an adaptive one follows h
  std::vector<double> cost;
  for (const json& grid : c.grids) {
    json s = c.base, resolved;
    set_key(s, c.grid_key, grid);
    const full3d::Params3d p = full3d::read_scene3d(s, resolved);
    cost.push_back(double(p.nx) * p.ny * p.nz / (p.adaptive.enabled ? p.h : p.dt));
  }
  double done_wall = 0;
  for (std::size_t g = 0; g < c.grids.size(); ++g) {
    json s = c.base;
    set_key(s, c.grid_key, c.grids[g]);
    // the time left in the stage, estimated from the last run that ran here
    std::string left;
    if (g > 0 && !runs.back().cached && runs.back().wall > 0) {
      double est = 0;
      for (std::size_t k = g; k < c.grids.size(); ++k) est += runs.back().wall * cost[k] / cost[g - 1];
      left = ", about " + std::to_string(long(std::ceil(est))) + " s left in this stage (so far " +
             std::to_string(long(std::ceil(done_wall))) + " s)";
    }
    say(c.tag + ": 3D grid " + std::to_string(g + 1) + "/" + std::to_string(c.grids.size()) + " (" + c.grid_key +
        " = " + c.grids[g].dump() + left + ")");
    // the finest grid writes membrane frames, about 12 per cycle of the grid before it
    double frames = 0;
    if (g + 1 == c.grids.size() && g > 0 && runs.back().cyc.has_cycle) frames = runs.back().cyc.cycle_time_s / 12.0;
    Run3d r = cache.run_3d(s, frames, progress);
    done_wall += r.cached ? 0.0 : r.wall;
    cr["length_m"] = r.length;
    r.record["grid_value"] = c.grids[g];
    runs_j.push_back(r.record);
    runs.push_back(std::move(r));
  }
  cr["runs3d"] = runs_j;
  return runs;
}

OrderRange orders_3d(const SuiteCase& c, const json& suite) {
  return c.spec.contains("order_range") ? parse_order_range(c.spec["order_range"], "order_range")
         : suite.contains("order_range") ? parse_order_range(suite["order_range"], "order_range")
                                         : kImmersedBoundaryOrders;
}

std::vector<RunAxi> axi_reference_study(const SuiteCase& c, const json& suite, const std::vector<Run3d>& runs,
                                        RunCache& cache, const Say& say, int progress, json& cr) {
  if (!c.spec.contains("reference")) return {};
  const json& rs = c.spec["reference"];
  const json& rgrids = rs["grids"];
  const std::string rkey = rs.value("grid_key", std::string("axi.grid.cells_across"));
  const double target = suite.value("reference_target_relative", 0.01);
  json axi_runs = json::array();
  std::vector<RunAxi> aruns;
  OrderRange rorders = kSharpInterfaceOrders;
  std::string method;
  double done_wall = 0;
  std::vector<double> rh;  // the cell size of each reference grid
  for (const json& g : rgrids) {
    json resolved;
    rh.push_back(axi::read_scene_axi(reference_scene(c.base, rs, g), resolved).h);
  }
  for (std::size_t g = 0; g < rgrids.size(); ++g) {
    const json s = reference_scene(c.base, rs, rgrids[g]);
    json resolved;
    const axi::ParamsAxi p = axi::read_scene_axi(s, resolved);
    rorders = reference_orders(rs, p);
    method = p.method_name();
    // the time left in the stage, estimated from the last run that ran here: a 2D grid's
    // cost grows as h^-3 (cells as h^-2, steps as h^-1)
    std::string left;
    if (g > 0 && !aruns.back().record.value("cached", true) && aruns.back().wall > 0) {
      double est = 0;
      for (std::size_t k = g; k < rgrids.size(); ++k) est += aruns.back().wall * std::pow(aruns.back().h / rh[k], 3.0);
      left = ", about " + std::to_string(long(std::ceil(est))) + " s left in this stage (so far " +
             std::to_string(long(std::ceil(done_wall))) + " s)";
    }
    say(c.tag + ": axi reference grid " + std::to_string(g + 1) + "/" + std::to_string(rgrids.size()) + " (" + rkey +
        " = " + rgrids[g].dump() + ", " + method + ", h = " + std::to_string(p.h * 1e9).substr(0, 5) + " nm" + left +
        ")");
    RunAxi r = cache.run_axi(s, progress);
    done_wall += r.cached ? 0.0 : r.wall;
    r.record["grid_value"] = rgrids[g];
    axi_runs.push_back(r.record);
    aruns.push_back(std::move(r));
  }
  // the time integration's and the wall's shares of the error: the coarsest grid again at a
  // tighter step tolerance, and again with its rings closer
  auto check = [&](const json& scene, const char* key, const std::string& what,
                   json (*judge)(const RunAxi&, const RunAxi&, double)) -> json {
    if (scene.is_null()) return nullptr;
    const std::size_t g0 = coarsest_reference_grid(c.base, rs);
    say(c.tag + ": axi reference " + what + " (" + rkey + " = " + rgrids[g0].dump() + ", " + key + " " +
        rs[key].dump() + ")");
    RunAxi r = cache.run_axi(scene, progress);
    r.record["grid_value"] = rgrids[g0];
    json j = judge(aruns[g0], r, rs[key].get<double>());
    j["grid_value"] = rgrids[g0];
    j["run"] = r.record;
    return j;
  };
  const json time_check = check(tolerance_check_scene(c.base, rs), "tolerance_check", "time check", axi_time_check);
  const json wall_check = check(spacing_check_scene(c.base, rs), "spacing_check", "wall check", axi_wall_check);
  cr["reference"] = axi_reference(aruns, rorders, c.paper_max, target, time_check, wall_check);
  cr["reference"]["tier"] = "axi";
  cr["reference"]["method"] = method;
  cr["reference"]["grid_key"] = rkey;
  cr["reference"]["grids"] = rgrids;
  cr["reference"]["set"] = rs.value("set", json::object());
  cr["reference"]["runs"] = axi_runs;
  // 3D against the converged reference, figure by figure
  std::vector<const Run3d*> done3d;
  for (const auto& r : runs)
    if (r.cyc.has_cycle) done3d.push_back(&r);
  cr["comparison_3d_vs_reference"] = compare_3d_with_reference(cr["reference3d"], cr["reference"], done3d);
  // U(t) of the finest 3D run against the finest axi run (informative: no verdict)
  if (!runs.empty() && runs.back().cyc.has_cycle)
    if (json v = velocity_vs_runs(runs.back().series, runs.back().cyc.cycle_time_s, velocity_runs(aruns)); !v.empty()) {
      v["cell_size_m"] = runs.back().h;
      cr["velocity_3d_vs_reference"] = v;
    }
  return aruns;
}

std::string calibrate_case(const SuiteCase& c, RunCache& cache, const Say& say, json& cr, int progress) {
  const std::size_t cg = c.calibration_grid;
  json cal_j;
  const std::string cal_file = cache.calibration(c.base, c.grid_key, c.grids[cg], c.name, cal_j,
                                                 [&] { say(c.tag + ": calibration at grid " + std::to_string(cg + 1)); }, progress);
  cr["calibration"] = {{"grid_index", cg}, {"grid_value", c.grids[cg]}, {"file", cal_file}};
  for (const char* k : {"C1_Pa_per_m", "C1_stderr_Pa_per_m", "C1_spring_network_Pa_per_m", "hydraulic_offset_inner_m",
                        "hydraulic_offset_inner_uncertainty_m", "hydraulic_offset_outer_m",
                        "hydraulic_offset_outer_uncertainty_m", "hydraulic_offset_outer_from_drag_m",
                        "hydraulic_offset_outer_from_drag_uncertainty_m", "towed_drag_coefficient_N_s_per_m", "axial_bending_rigidity_J",
                        "status", "wall_time_s"})
    if (cal_j.contains(k)) cr["calibration"][k] = cal_j[k];
  return cal_file;
}

json judge_models(const SuiteCase& c, const json& suite, const std::string& cal_file, const std::vector<Run3d>& runs,
                  const std::vector<RunAxi>& aruns, const json& cr, const Say& say) {
  const Run3d& finest = runs.back();
  const Run3d& at_cal = runs[c.calibration_grid];
  json models_j = json::array();
  for (const json& m : suite["models1d"]) {
    const std::string label = m["label"];
    const bool calibrated = m.value("calibrated", false);
    const bool first = models_j.empty();  // the suite's default 1D model
    Run1d r;
    json scene;
    if (calibrated && cal_file.empty()) {
      r.record = {{"label", label}, {"status", "not run: the calibration failed"}};
    } else {
      say(c.tag + ": 1D " + label);
      scene = model_scene_of(c, m, cal_file);
      r = run_1d(scene, label, c.scene_dir);
    }
    json entry = r.record;
    entry["calibrated"] = calibrated;
    // the error bar of the default model's figures in the trend claims (verdicts.cpp)
    if (first && r.cyc.has_cycle) {
      say(c.tag + ": 1D " + label + " on twice its cells (its grid error)");
      entry["grid_error"] = grid_error_1d(scene, r, label, c.scene_dir);
    }
    if (r.cyc.has_cycle) {
      json vs_cal = json::object();
      // against the case's reference: the axisymmetric one when the case has it, else the
      // 3D extrapolation (verdicts.hpp)
      compare_with_reference(entry, cr);
      if (at_cal.cyc.has_cycle) {
        vs_cal["displacement_per_cycle"] = relative(r.cyc.displacement_per_cycle_m, at_cal.cyc.displacement_per_cycle_m);
        vs_cal["cycle_time"] = relative(r.cyc.cycle_time_s, at_cal.cyc.cycle_time_s);
        vs_cal["mean_velocity_per_cycle"] =
            relative(r.cyc.mean_velocity_per_cycle_m_per_s, at_cal.cyc.mean_velocity_per_cycle_m_per_s);
      }
      entry["relative_error_vs_calibration_grid"] = vs_cal;
      // U(t) against the finest 3D run (informative when the case has an axi reference) and
      // against the finest axi run; the verdict takes the axi one when the case has it
      // (judged_velocity, verdicts.hpp)
      if (finest.cyc.has_cycle && r.series.t.size() > 1 && finest.series.t.size() > 1)
        entry["velocity_vs_finest3d"] = velocity_vs_runs(r.series, r.cyc.cycle_time_s, velocity_runs(runs));
      if (cr.contains("reference")) {
        json v = velocity_vs_runs(r.series, r.cyc.cycle_time_s, velocity_runs(aruns));
        // no axi run completed a cycle: no verdict, rather than one taken against 3D
        if (v.empty()) v["note"] = "no axisymmetric run completed a cycle";
        entry["velocity_vs_reference"] = v;
      }
      if (!judged_velocity(entry).empty()) entry["velocity_judged_against"] = judged_velocity_name(entry);
      // pass, fail or inconclusive against the reference's error bar (verdicts.hpp)
      if (const json v = model_verdicts(entry, suite["thresholds"]); !v.empty()) entry["verdicts"] = v;
      // the 1D tier's design targets for this case, judged by the same rules (case_targets1d)
      if (const json& tg = case_targets1d(c, suite); tg.is_object())
        if (const json v = model_verdicts(entry, tg); !v.empty()) entry["target_verdicts"] = v;
      if (at_cal.record.value("pumped_volume_m3", 0.0) != 0.0)
        entry["pumped_volume_relative_vs_calibration_grid"] =
            relative(r.record.value("pumped_volume_m3", 0.0), at_cal.record["pumped_volume_m3"].get<double>());
    }
    models_j.push_back(entry);
  }
  return models_j;
}

json speed_accuracy(const SuiteCase& c, const json& suite, const std::string& cal_file, const std::vector<Run3d>& runs,
                    const json& cr, RunCache& cache, const Say& say, int progress) {
  json trade = json::array();
  // the error of each point against the case's judged reference (the axisymmetric one when
  // the case has it)
  const json& jref = judged_reference(cr);
  const bool have_jref = jref.contains("displacement_per_cycle_m") && jref["displacement_per_cycle_m"].is_object() &&
                         jref["displacement_per_cycle_m"]["value"].is_number() &&
                         std::abs(jref["displacement_per_cycle_m"]["value"].get<double>()) > 0;
  if (!have_jref) return trade;
  const double d_ref = jref["displacement_per_cycle_m"]["value"].get<double>();
  auto point = [&](const char* tier, const std::string& axis, const std::string& resolution, double wall, double d) {
    trade.push_back({{"tier", tier},
                     {"axis", axis},
                     {"resolution", resolution},
                     {"wall_time_s", wall},
                     {"displacement_per_cycle_error", std::abs(d - d_ref) / std::abs(d_ref)}});
  };
  const json& m0 = suite["models1d"][0];
  auto model0 = [&](const std::string& key, const json& value) -> std::optional<Run1d> {
    if (m0.value("calibrated", false) && cal_file.empty()) return std::nullopt;
    json s = model_scene_of(c, m0, cal_file);
    set_key(s, key, value);
    return run_1d(s, m0["label"], c.scene_dir);
  };
  for (long cells : suite.value("cells1d", std::vector<long>{50, 100, 200, 400}))
    if (const auto r = model0("numerics1d.cells", cells); r && r->cyc.has_cycle)
      point("1d", "cells", "N = " + std::to_string(cells), r->wall, r->cyc.displacement_per_cycle_m);
  for (double rtol : suite.value("rtol1d", std::vector<double>{1e-4, 1e-6, 1e-8})) {
    char label[40];
    std::snprintf(label, sizeof label, "rtol = %.0e", rtol);
    if (const auto r = model0("numerics1d.rtol", rtol); r && r->cyc.has_cycle)
      point("1d", "rtol", label, r->wall, r->cyc.displacement_per_cycle_m);
  }
  for (const auto& r : runs)
    if (r.cyc.has_cycle)
      point("3d", "h", "h = " + std::to_string(r.h * 1e9).substr(0, 5) + " nm", r.wall, r.cyc.displacement_per_cycle_m);
  const json& variants = c.spec.contains("time_variants3d") ? c.spec["time_variants3d"] : json::array();
  for (std::size_t v = 0; v < variants.size(); ++v) {
    json s = at_calibration_grid(c);
    apply_sets(s, variants[v].value("set", json()));
    const std::string label = variants[v].value("label", "variant " + std::to_string(v + 1));
    say(c.tag + ": 3D time-step variant " + std::to_string(v + 1) + "/" + std::to_string(variants.size()) + " (" +
        label + ")");
    const Run3d r = cache.run_3d(s, 0, progress);
    if (r.cyc.has_cycle) point("3d", "time step", label, r.wall, r.cyc.displacement_per_cycle_m);
    else  // a step beyond the stability limit: the outcome is reported, not a point
      trade.push_back({{"tier", "3d"}, {"axis", "time step"}, {"resolution", label}, {"wall_time_s", r.wall},
                       {"status", r.record.value("status", std::string("unknown"))}});
  }
  return trade;
}

void wall_times(const SuiteCase& c, const std::vector<Run3d>& runs, json& cr) {
  // read before cr gains keys (an ordered object's members move as it grows)
  const json& models_j = cr["models1d"];
  double w3 = 0, w1 = 0;
  for (const auto& r : runs) w3 += r.wall;
  for (const auto& m : models_j) w1 += m.value("wall_time_s", 0.0);
  const double w1_first = models_j.empty() ? 0.0 : models_j[0].value("wall_time_s", 0.0);
  const bool cycle_1d = !models_j.empty() && models_j[0].value("has_cycle", false);
  cr["wall_time_3d_s"] = w3;
  cr["wall_time_1d_s"] = w1;
  // the cost of one cycle in each tier: a run that stopped before its cycle (a time limit, a
  // failure) has no such cost, so there is no ratio
  const Run3d& at_cal = runs[c.calibration_grid];
  if (at_cal.cyc.has_cycle && cycle_1d && at_cal.wall > 0 && w1_first > 0)
    cr["wall_time_ratio_3d_over_1d"] = at_cal.wall / w1_first;
}

json extremes_3d(const json& suite, const std::string& suite_dir, const std::string& data_dir, RunCache& cache,
                 const Say& say) {
  json extremes = json::array();
  const json& ex = suite.contains("extremes3d") ? suite["extremes3d"] : json::array();
  for (std::size_t k = 0; k < ex.size(); ++k) {
    const json& e = ex[k];
    json s = scene::load_file(find_scene(e["scene"], suite_dir, data_dir));
    apply_sets(s, e.value("set", json()));
    const std::string label = e["label"];
    say("extremes " + std::to_string(k + 1) + "/" + std::to_string(ex.size()) + ": " + label);
    json entry = {{"label", label}, {"scene", e["scene"]}, {"set", e.value("set", json::object())},
                  {"expected", e["expect"]}, {"expected_cause", e.value("cause", std::string())}};
    std::string kind, text;
    try {
      const Run3d r = cache.run_3d(s);
      const std::string status = r.record.value("status", std::string("unknown"));
      kind = status == "ok" ? "ok" : "failed";
      text = status;
      entry["wall_time_s"] = r.wall;
      entry["steps"] = r.record.value("steps", 0L);
      if (r.cyc.has_cycle) {
        entry["displacement_per_cycle_m"] = r.cyc.displacement_per_cycle_m;
        entry["cycle_time_s"] = r.cyc.cycle_time_s;
      }
    } catch (const InputError& err) {
      kind = "rejected";
      text = err.what();
    }
    entry["outcome"] = kind;
    entry["message"] = text;
    const std::string cause = e.value("cause", std::string());
    entry["as_expected"] = kind == e["expect"].get<std::string>() && (cause.empty() || text.find(cause) != std::string::npos);
    extremes.push_back(entry);
  }
  return extremes;
}

}  // namespace swim::validation
