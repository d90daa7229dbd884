#include "validation/suite.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <vector>

#include "axi/scene_axi.hpp"
#include "common/errors.hpp"
#include "full3d/scene3d.hpp"
#include "validation/extrapolated_reference.hpp"
#include "validation/run_cache.hpp"
#include "validation/suite_phases.hpp"
#include "validation/verdicts.hpp"

namespace fs = std::filesystem;

namespace swim::validation {

json run_suite(const SuiteOptions& o) {
  const json suite = scene::load_file(o.suite);
  check_suite(suite, o.suite, o.data_dir, !o.scenes_checked);
  const std::string suite_dir = fs::path(o.suite).parent_path().string();
  const std::string runs_dir = o.out_dir + "/runs", cal_dir = o.out_dir + "/calibrations";
  fs::create_directories(runs_dir);
  fs::create_directories(cal_dir);
  const auto t_suite = std::chrono::steady_clock::now();
  const std::vector<json> cases = selected_cases(suite, o.only);
  if (cases.empty())
    throw InputError("--case", o.only.empty() ? "" : o.only.front(), "the scene file name or the name of a case of the suite");
  FolderKeys keys;
  RunCache cache(runs_dir, cal_dir, o.threads, keys);
  const Say say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };

  json report = {{"suite", suite.value("name", fs::path(o.suite).stem().string())},
                 {"description", suite.value("description", std::string())},
                 {"thresholds", suite["thresholds"]},
                 {"cases", json::array()}};
  report["cases_selected"] = o.only;
  for (std::size_t ci = 0; ci < cases.size(); ++ci) {
    const SuiteCase c = open_case(cases[ci], ci, cases.size(), suite_dir, o.data_dir);
    json cr = case_entry(c, o.data_dir);
    // 1. the 3D resolution study
    const std::vector<Run3d> runs = resolution_study(c, cache, say, o.run_progress, cr);
    // 2. the 3D reference, extrapolated to h -> 0; the axisymmetric reference when the case has one
    cr["reference3d"] = reference_3d(runs, orders_3d(c, suite), c.paper_max);
    const std::vector<RunAxi> aruns = axi_reference_study(c, suite, runs, cache, say, o.run_progress, cr);
    // 3. the 1D tier calibrated from 3D
    const std::string cal_file = calibrate_case(c, cache, say, cr, o.run_progress);
    // 4. every 1D model against the references
    if (const json& tg = case_targets1d(c, suite); tg.is_object()) cr["targets1d"] = tg;
    cr["models1d"] = judge_models(c, suite, cal_file, runs, aruns, cr, say);
    // 5. speed against accuracy
    cr["speed_accuracy"] = speed_accuracy(c, suite, cal_file, runs, cr, cache, say, o.run_progress);
    wall_times(c, runs, cr);
    report["cases"].push_back(cr);
  }
  report["findings"] = findings(report["cases"], suite["thresholds"]);
  // the extremes belong to the whole suite, not to a selection of its cases
  report["extremes3d"] = o.only.empty() ? extremes_3d(suite, suite_dir, o.data_dir, cache, say) : json::array();
  // every folder and calibration the report read, verified again now that the report is complete
  report["cache"] = cache.report();
  report["wall_time_s"] = seconds_since(t_suite);
  return report;
}

// ---- the suite's heavy runs as independent jobs (MPI) ---------------------------------------

json plan_runs(const SuiteOptions& o) {
  json suite = scene::load_file(o.suite);
  check_suite(suite, o.suite, o.data_dir, !o.scenes_checked);
  const std::string suite_dir = fs::path(o.suite).parent_path().string();
  const std::string runs_dir = fs::absolute(o.out_dir + "/runs").string();
  const std::string cal_dir = fs::absolute(o.out_dir + "/calibrations").string();
  fs::create_directories(runs_dir);
  fs::create_directories(cal_dir);
  json jobs = json::array();
  std::string key;  // the cache key of the run being planned (its folder)
  auto cost3d = [&](json s) {
    set_key(s, "full3d.threads", 1);
    json resolved;
    const full3d::Params3d p = full3d::read_scene3d(s, resolved);
    key = run_key_3d(resolved);
    return double(p.nx) * p.ny * p.nz * ((p.duration > 0 ? p.duration : p.time_limit) / p.dt);
  };
  // two jobs of one physics share a folder: the second waits for the first and reuses it
  std::map<std::string, std::size_t> first_of;
  auto add = [&](json job, double cost, json after = json::array()) {
    if (auto it = first_of.find(key); !key.empty() && it != first_of.end()) after.push_back(it->second);
    if (!key.empty()) first_of.emplace(key, jobs.size());
    key.clear();
    const json& sc = job.contains("scene") ? job["scene"] : job["base"];
    std::string label = job["type"].get<std::string>() + " run of " + sc.value("name", std::string("a scene"));
    if (job.contains("grid")) label = "calibration of " + job["name"].get<std::string>() + " at " + job["grid"].dump();
    else if (sc.contains("full3d") && sc["full3d"].contains("grid")) label += " at " + sc["full3d"]["grid"].dump();
    jobs.push_back({{"job", std::move(job)}, {"cost", cost}, {"after", std::move(after)}, {"label", label}});
    return jobs.size() - 1;
  };
  for (const json& cs : selected_cases(suite, o.only)) {
    const std::string scene_path = find_scene(cs["scene"], suite_dir, o.data_dir);
    json base = scene::load_file(scene_path);
    apply_sets(base, cs.value("set", json()));
    const std::string name = base.value("name", fs::path(scene_path).stem().string());
    const std::string grid_key = cs.value("grid_key", std::string("full3d.grid.cells_across"));
    const json& grids = cs["grids"];
    json grid_jobs = json::array();
    for (std::size_t g = 0; g < grids.size(); ++g) {
      json s = base;
      set_key(s, grid_key, grids[g]);
      json job = {{"type", "3d"}, {"scene", s}, {"runs_dir", runs_dir}, {"threads", o.threads}};
      json after = json::array();
      // the finest grid writes membrane frames at an interval taken from the grid before it
      if (g + 1 == grids.size() && g > 0) {
        job["frames_from"] = jobs[grid_jobs.back().get<std::size_t>()]["job"]["scene"];
        after.push_back(grid_jobs.back());
      }
      grid_jobs.push_back(add(job, cost3d(s), after));
    }
    if (cs.contains("reference")) {
      const json& rs = cs["reference"];
      std::vector<std::pair<json, std::string>> scenes;  // its grids, then its checks' runs
      const std::string ref_key = rs.value("grid_key", std::string("axi.grid.cells_across"));
      auto at = [&](const json& g) {
        return ref_key == "axi.grid.cells_across" && g.is_number() ? g.dump() + " cells across" : ref_key + " = " + g.dump();
      };
      for (const json& g : rs["grids"]) scenes.emplace_back(reference_scene(base, rs, g), " at " + at(g));
      const std::string coarsest = at(rs["grids"][coarsest_reference_grid(base, rs)]);
      if (json s = tolerance_check_scene(base, rs); !s.is_null())
        scenes.emplace_back(std::move(s), " at " + coarsest + ", its time-step check");
      if (json s = spacing_check_scene(base, rs); !s.is_null())
        scenes.emplace_back(std::move(s), " at " + coarsest + ", its wall-spacing check");
      for (const auto& [s, where] : scenes) {
        json resolved;
        const axi::ParamsAxi p = axi::read_scene_axi(s, resolved);
        key = run_key_axi(resolved);
        // the cost of a simulated second grows about as h^-2.5 on the measured series (h^-2
        // nodes, steps from h^-0.5 to h^-1 under the error control)
        const std::size_t j = add({{"type", "axi"}, {"scene", s}, {"runs_dir", runs_dir}},
                                  std::pow(double(p.nr) * p.nx, 1.25) * (p.time_limit / p.dt_max));
        jobs[j]["label"] = jobs[j]["label"].get<std::string>() + where;
      }
    }
    const std::size_t cg = std::size_t(cs.value("calibration_grid", long(grids.size()) - 1));
    {
      json s = base;
      set_key(s, grid_key, grids[cg]);
      const double cost = cost3d(s);
      key = "calibration " + key;
      add({{"type", "calibration"}, {"base", base}, {"grid_key", grid_key}, {"grid", grids[cg]}, {"name", name},
           {"threads", o.threads}, {"cal_dir", cal_dir}},
          cost);
    }
    // the time-step variants run when the case has a reference to judge them by: after its grids
    const json& variants = cs.contains("time_variants3d") ? cs["time_variants3d"] : json::array();
    for (const json& v : variants) {
      json s = base;
      set_key(s, grid_key, grids[cg]);
      apply_sets(s, v.value("set", json()));
      add({{"type", "3d"}, {"scene", s}, {"runs_dir", runs_dir}, {"threads", o.threads},
           {"unless_no_reference", {{"grids", grid_jobs.size()}, {"has_axi_reference", cs.contains("reference")}}},
           {"grid_scenes", [&] {
              json a = json::array();
              for (const auto& i : grid_jobs) a.push_back(jobs[i.get<std::size_t>()]["job"]["scene"]);
              return a;
            }()}},
          cost3d(s), grid_jobs);
    }
  }
  const json& ex = suite.contains("extremes3d") && o.only.empty() ? suite["extremes3d"] : json::array();
  for (const json& e : ex) {
    json s = scene::load_file(find_scene(e["scene"], suite_dir, o.data_dir));
    apply_sets(s, e.value("set", json()));
    double cost = 0;
    try {
      cost = cost3d(s);
    } catch (const InputError&) {
      continue;  // a scene the 3D tier refuses: the suite reports it, nothing to run
    }
    add({{"type", "3d"}, {"scene", s}, {"runs_dir", runs_dir}, {"threads", o.threads}}, cost);
  }
  return jobs;
}

PlanClock::PlanClock(const json& plan, int ranks) : ranks_(std::max(1, ranks)) {
  for (const json& j : plan) {
    kind_.push_back(j["job"]["type"].get<std::string>());
    cost_.push_back(j["cost"].get<double>());
  }
  start_.assign(kind_.size(), -1.0);
  done_.assign(kind_.size(), false);
}

void PlanClock::started(std::size_t job, double t) { start_.at(job) = t; }

void PlanClock::finished(std::size_t job, double t, bool computed) {
  done_.at(job) = true;
  if (!computed || start_[job] < 0 || !(cost_[job] > 0)) return;
  auto it = std::find_if(timed_.begin(), timed_.end(), [&](const auto& e) { return e.first == kind_[job]; });
  if (it == timed_.end()) it = timed_.insert(timed_.end(), {kind_[job], {0.0, 0.0}});
  it->second[0] += std::max(0.0, t - start_[job]);
  it->second[1] += cost_[job];
}

const std::array<double, 2>* PlanClock::rate(const std::string& kind) const {
  for (const auto& [k, v] : timed_)
    if (k == kind) return &v;
  return nullptr;
}

PlanClock::Left PlanClock::left(double t) const {
  Left l;
  double work = 0, longest = 0;
  std::vector<std::string> kinds;
  for (std::size_t i = 0; i < kind_.size(); ++i) {
    if (done_[i]) continue;
    const auto* r = rate(kind_[i]);
    if (!r) {
      ++l.untimed;
      if (std::find(kinds.begin(), kinds.end(), kind_[i]) == kinds.end()) kinds.push_back(kind_[i]);
      continue;
    }
    double est = cost_[i] * (*r)[0] / (*r)[1];
    if (start_[i] >= 0) est = std::max(0.0, est - (t - start_[i]));
    work += est;
    longest = std::max(longest, est);
  }
  l.seconds = std::max(work / ranks_, longest);
  for (const auto& k : kinds) l.untimed_kinds += (l.untimed_kinds.empty() ? "" : ", ") + k;
  return l;
}

std::string PlanClock::describe(const Left& l) {
  auto span = [](double s) {
    char b[64];
    if (s < 90) std::snprintf(b, sizeof b, "%.0f s", s);
    else if (s < 600) std::snprintf(b, sizeof b, "%.1f min", s / 60);
    else if (s < 5400) std::snprintf(b, sizeof b, "%.0f min", s / 60);
    else std::snprintf(b, sizeof b, "%.1f h", s / 3600);
    return std::string(b);
  };
  if (l.untimed == 0) return l.seconds < 1 ? "less than 1 s left" : "about " + span(l.seconds) + " left";
  const std::string rest = std::to_string(l.untimed) + " run(s) (" + l.untimed_kinds + ") not yet timed";
  if (l.seconds > 0) return "about " + span(l.seconds) + " left and " + rest;
  return "time left not yet known: " + rest;
}

json run_planned(const json& job) {
  // a rank runs many jobs: the keys of the folders it has read serve all of them
  static FolderKeys keys;
  const std::string type = job.at("type").get<std::string>();
  const int progress = job.value("progress", 0);
  if (type == "3d") {
    RunCache cache(job["runs_dir"], "", job["threads"], keys);  // this job's view; the report's pass has its own
    double frames = 0;
    if (job.contains("frames_from")) {
      const Run3d prev = cache.run_3d(job["frames_from"]);  // finished before this job
      if (prev.cyc.has_cycle) frames = prev.cyc.cycle_time_s / 12.0;
    }
    if (job.contains("grid_scenes")) {
      // a time-step variant is run only for a case with a reference (two grids with a cycle, or the axi one)
      int with_cycle = 0;
      for (const json& g : job["grid_scenes"]) with_cycle += cache.run_3d(g).cyc.has_cycle;
      if (with_cycle < 2 && !job["unless_no_reference"].value("has_axi_reference", false))
        return {{"status", "not needed: the case has no reference"}};
    }
    const Run3d r = cache.run_3d(job["scene"], frames, progress);
    return {{"status", r.record.value("status", std::string("unknown"))}, {"cached", r.cached}};
  }
  if (type == "axi") {
    RunCache cache(job["runs_dir"], "", 1, keys);
    const RunAxi r = cache.run_axi(job["scene"], progress);
    return {{"status", r.record.value("status", std::string("unknown"))}, {"cached", r.cached}};
  }
  if (type == "calibration") {
    RunCache cache("", job["cal_dir"], job["threads"], keys);
    json cal;
    bool computed = false;
    const std::string file = cache.calibration(job["base"], job["grid_key"], job["grid"], job["name"], cal,
                                               [&] { computed = true; }, progress);
    return {{"status", cal.value("status", std::string("unknown"))}, {"file", file}, {"cached", !computed}};
  }
  throw std::logic_error("unknown validation job " + type);
}

}  // namespace swim::validation
