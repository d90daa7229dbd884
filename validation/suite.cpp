#include "validation/suite.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/run_record.hpp"
#include "common/run_folder.hpp"
#include "common/units.hpp"
#include "axi/run_axi.hpp"
#include "axi/scene_axi.hpp"
#include "full3d/run3d.hpp"
#include "full3d/scene3d.hpp"
#include "full3d/scene3d_keys.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"
#include "validation/calibration.hpp"
#include "validation/compare.hpp"
#include "validation/hydraulic.hpp"
#include "validation/richardson.hpp"
#include "validation/verdicts.hpp"

namespace fs = std::filesystem;

namespace swim::validation {

using scene::json;

namespace {

/// Changes whenever calibration.json gains or renames keys, or a measurement in it changes
/// method (3: the held tube on the ring forces): cached calibrations of an older format are
/// then recomputed instead of read.
constexpr int kCalibrationFormat = 3;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// ---- suite file ----------------------------------------------------------------------

const json& member(const json& j, const std::string& key, const std::string& path) {
  if (!j.is_object() || !j.contains(key)) throw InputError(path + "." + key, "(missing)", "required by a suite file");
  return j.at(key);
}

std::string find_scene(const std::string& name, const std::string& suite_dir, const std::string& data_dir) {
  for (const fs::path& p : {fs::path(name), fs::path(suite_dir) / name, fs::path(data_dir) / "scenes" / name})
    if (fs::is_regular_file(p)) return p.string();
  throw InputError("cases[].scene", "\"" + name + "\"",
                   "a scene file (tried as given, beside the suite file and in the shipped data/scenes/)");
}

/// Sets a dotted key of a scene to a JSON value, creating the objects on the way; null removes
/// the key (as `--set key=null` does).
void set_key(json& sc, const std::string& dotted, const json& value) {
  json* node = &sc;
  std::stringstream ss(dotted);
  std::string part;
  std::vector<std::string> parts;
  while (std::getline(ss, part, '.')) parts.push_back(part);
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    if (!node->contains(parts[i]) || !(*node)[parts[i]].is_object()) (*node)[parts[i]] = json::object();
    node = &(*node)[parts[i]];
  }
  if (value.is_null()) node->erase(parts.back());
  else (*node)[parts.back()] = value;
}

void apply_sets(json& sc, const json& sets) {
  if (sets.is_null()) return;
  for (const auto& [k, v] : sets.items()) set_key(sc, k, v);
}

// ---- series ----------------------------------------------------------------------------

struct Series {
  std::vector<double> t, x, u;
};

/// The centre history of a record's kept rows (times strictly increasing).
Series series_of(const record::RunRecord& rec) {
  Series s;
  const record::Series& se = rec.series;
  const std::size_t it = se.index("t_s"), ix = se.index("x_center_m"), iu = se.index("velocity_m_per_s");
  for (std::size_t k = 0; k < se.rows(); ++k) {
    const auto row = se.row(k);
    if (!s.t.empty() && !(row[it] > s.t.back())) continue;
    s.t.push_back(row[it]);
    s.x.push_back(row[ix]);
    s.u.push_back(row[iu]);
  }
  return s;
}

/// A run's per-cycle figures: from its rows, with the summary's own values where it has them,
/// computed at full precision from the rows in memory (a cached run's series.csv carries 10
/// digits), so that a fresh and a cached run report the same.
record::CycleFigures cycle_figures_of(const record::RunRecord& rec, const json& summary) {
  record::CycleFigures c = record::cycle_figures(rec);
  if (summary.contains("displacement_per_cycle_m") && summary["displacement_per_cycle_m"].is_number() &&
      summary.contains("cycle_time_s") && summary["cycle_time_s"].is_number()) {
    c.displacement_per_cycle_m = summary["displacement_per_cycle_m"].get<double>();
    c.cycle_time_s = summary["cycle_time_s"].get<double>();
    c.mean_velocity_per_cycle_m_per_s = summary["mean_velocity_per_cycle_m_per_s"].get<double>();
  }
  return c;
}

json downsample(const Series& s, double t_end, int n = 400) {
  json t = json::array(), u = json::array(), x = json::array();
  if (s.t.size() < 2) return {{"t_s", t}, {"velocity_m_per_s", u}, {"x_m", x}};
  for (int k = 0; k <= n; ++k) {
    const double tk = t_end * k / n;
    t.push_back(tk);
    u.push_back(interpolate_linear(s.t, s.u, tk));
    x.push_back(interpolate_linear(s.t, s.x, tk));
  }
  return {{"t_s", t}, {"velocity_m_per_s", u}, {"x_m", x}};
}

using record::CycleFigures;


// ---- one 3D run (cached) --------------------------------------------------------------

struct Run3d {
  json record;  ///< report entry
  Series series;
  CycleFigures cyc;
  double h = 0, wall = 0, length = 0;
  double max_displacement = std::numeric_limits<double>::quiet_NaN();  ///< m, over the run
  bool ok = false;
};

/// The part of a resolved 3D scene that determines its results: without the output settings
/// (frames, intervals), the checkpoint interval and the thread count.
json physics_of(json resolved) {
  if (resolved.contains("full3d") && resolved["full3d"].is_object()) {
    resolved["full3d"].erase("output");
    resolved["full3d"].erase("checkpoint_interval");
    resolved["full3d"].erase("threads");
  }
  return resolved;
}

/// The physics without the scene's name and description and without the 1D tier's sections:
/// two scenes that differ only in those (the paper's amplitude sweep at 0.55 R0 and its aspect
/// sweep at 0.4 um are one swimmer) share their 3D runs and calibrations.
json same_swimmer(json resolved) {
  resolved = physics_of(std::move(resolved));
  if (resolved.is_object()) {
    resolved.erase("name");
    resolved.erase("description");
    // the 1D tier's sections: a 3D run or calibration does not depend on them
    resolved.erase("model1d");
    resolved.erase("numerics1d");
  }
  return resolved;
}

/// A run folder's scene.resolved.json resolved again by the current scene reader (the 3D
/// tier's, or with axi_tier the axisymmetric tier's): keys the reader gained since the run was
/// written appear with their defaults, so a run stays found as long as its physics is what
/// the scene would resolve to today (a wall written before full3d.membrane.bending_model
/// existed resolves as the fixed k_b it had). null when the reader no longer accepts it.
json current_resolution(const json& written, bool axi_tier = false) {
  try {
    json w = written;
    // written before the wall model (no full3d.membrane.bending_model): k_b was
    // bending_constant on every mesh, bending_model "fixed_kb" today; a k_b set from
    // bending_rigidity, and the axi tier's D, came from the earlier radial-lobe measure of D
    // and are no run of today's reader (docs/full3d.md, "The wall model")
    const json* mem = w.is_object() && w.contains("full3d") && w["full3d"].is_object() && w["full3d"].contains("membrane")
                          ? &w["full3d"]["membrane"]
                          : nullptr;
    if (mem && mem->is_object() && !mem->contains("bending_model")) {
      if (axi_tier || mem->contains("bending_rigidity")) return nullptr;
      w["full3d"]["membrane"]["bending_model"] = "fixed_kb";
    }
    json again;
    if (axi_tier) axi::read_scene_axi(w, again);
    else full3d::read_scene3d(w, again);
    return again;
  } catch (const std::exception&) {
    return nullptr;
  }
}

/// The cache key of an axi run: its physics (same_swimmer) tagged with the tier, so that an
/// axi run is never taken for a 3D one.
std::string axi_key(const json& resolved) { return output::json_hash({"axi", same_swimmer(resolved)}); }

/// json_hash(same_swimmer(current_resolution(...))) of a run folder's scene.resolved.json or
/// of a calibration file's "scene" (member), "" when unreadable; with axi_tier, axi_key of the
/// axisymmetric tier's resolution. Resolving a scene again costs tens of ms and every cache
/// lookup scans every folder, so the key is kept per file and its modification time for the
/// life of the process.
std::string swimmer_key(const fs::path& file, const char* member, bool axi_tier = false) {
  static std::map<std::string, std::pair<fs::file_time_type, std::string>> memo;
  std::error_code ec;
  const auto mtime = fs::last_write_time(file, ec);
  if (ec) return {};
  std::string id = file.string();
  if (member) id.append("#").append(member);
  if (axi_tier) id.append("#axi");
  if (auto it = memo.find(id); it != memo.end() && it->second.first == mtime) return it->second.second;
  std::ifstream in(file);
  json j = json::parse(in, nullptr, false);
  std::string key;
  if (!j.is_discarded() && (!member || j.contains(member))) {
    const json again = current_resolution(member ? j[member] : j, axi_tier);
    if (!again.is_null()) key = axi_tier ? axi_key(again) : output::json_hash(same_swimmer(again));
  }
  memo[id] = {mtime, key};
  return key;
}

/// What the suite did with its cache: the results it reused, those it rejected (and why), and
/// every folder and calibration file the report reads, verified again at the end.
struct CacheLog {
  long reused = 0;
  json rejected = json::array();  ///< {"path", "reason"}
  std::vector<std::string> folders, calibrations;
  void reject(const std::string& path, const std::string& reason) {
    rejected.push_back({{"path", path}, {"reason", reason}});
  }
};

/// The files of a cached run the report reads (the series), and those that make it the run it
/// is (its resolved scene, its radius field): each must be listed in its summary.json.
const std::vector<std::string> kCachedRunFiles = {"series.csv", "radius.csv", "scene.resolved.json"};

/// Why a calibration file cannot be used, "" when it can: it carries its own checksum and it
/// matches, it is a JSON object and its status is "ok".
std::string calibration_problem(const std::string& file) {
  const fs::path p(file);
  std::string why = output::verify_folder(p.parent_path().string(), {}, p.filename().string());
  if (!why.empty()) return why;
  std::ifstream in(file);
  const json c = json::parse(in, nullptr, false);
  if (c.is_discarded() || !c.is_object()) return "calibration.json: not valid JSON";
  if (c.value("status", std::string()) != "ok")
    return "calibration.json: status " + scene::show(c.value("status", json("(none)")));
  return {};
}

/// A calibration file under `cal_dir` written in the current format for a scene whose physics,
/// resolved by the current reader, is `physics` (same_swimmer); empty when there is none. A
/// folder's name carries the hash of the physics it was written for and of its format
/// version, which tells an older format apart.
std::string cached_calibration(const std::string& cal_dir, const json& physics, CacheLog& log) {
  const std::string wanted = output::json_hash(physics);
  if (!fs::is_directory(cal_dir)) return {};
  for (const auto& e : fs::directory_iterator(cal_dir)) {
    const fs::path file = e.path() / "calibration.json";
    if (!fs::exists(file)) continue;
    if (const std::string why = calibration_problem(file.string()); !why.empty()) {
      log.reject(file.string(), why);
      continue;
    }
    std::ifstream in(file);
    const json c = json::parse(in, nullptr, false);
    if (c.is_discarded() || !c.contains("scene")) continue;
    const std::string folder = e.path().filename().string();
    const std::string written_for = output::json_hash({physics_of(c["scene"]), kCalibrationFormat});
    if (folder.size() < written_for.size() || folder.compare(folder.size() - written_for.size(), written_for.size(), written_for) != 0)
      continue;
    if (swimmer_key(file, "scene") == wanted) return file.string();
  }
  return {};
}

/// A summary written while its run was going on ("running: last checkpoint at ...").
bool is_running(const json& summary) {
  const std::string st = summary.value("status", std::string());
  return st.rfind("running", 0) == 0;
}

/// A finished run (summary status not "running") in `dir` whose files pass their checks
/// (output::verify_folder: summary.json's own checksum, every listed file's size and checksum,
/// kCachedRunFiles listed), or null. A finished run that fails them is recorded in the log as
/// rejected, with the reason, and is not used: the caller recomputes it.
json finished_summary(const std::string& dir, CacheLog& log) {
  if (!fs::exists(fs::path(dir) / "summary.json")) return nullptr;
  {
    std::ifstream in(dir + "/summary.json");
    const json s = json::parse(in, nullptr, false);
    if (!s.is_discarded() && is_running(s)) return nullptr;  // an interrupted run: resumed when its checkpoint passes
  }
  if (const std::string why = output::verify_folder(dir, kCachedRunFiles); !why.empty()) {
    log.reject(dir, why);
    return nullptr;
  }
  std::ifstream in(dir + "/summary.json");
  json s = json::parse(in, nullptr, false);
  if (s.is_discarded() || !s.contains("status") || !s["status"].is_string()) {
    log.reject(dir, "summary.json: no status");
    return nullptr;
  }
  return s;
}

/// A run that was stopped before its end and left a checkpoint to continue from.
bool interrupted_run(const std::string& dir) {
  std::ifstream in(dir + "/summary.json");
  if (!in) return false;
  const json s = json::parse(in, nullptr, false);
  return !s.is_discarded() && is_running(s) && fs::exists(full3d::checkpoint_path(dir));
}

/// frame_interval > 0: membrane frames (VTK) at that interval, for the side-view figure.
Run3d run_3d(const json& sc, const std::string& runs_dir, int threads, bool* cached, CacheLog& log,
             double frame_interval = 0, int progress = 0) {
  json s = sc;
  set_key(s, "full3d.threads", threads);
  set_key(s, "full3d.output.vtk", frame_interval > 0);
  set_key(s, "full3d.output.fluid_fields", false);
  if (frame_interval > 0) {
    char b[40];
    std::snprintf(b, sizeof b, "%.6g s", frame_interval);
    set_key(s, "full3d.output.vtk_interval", std::string(b));
  }
  json resolved;
  const full3d::Params3d p = full3d::read_scene3d(s, resolved);
  // the cache is keyed by the physics of the resolved scene; a folder under another name
  // (written with other output settings) is found by its own scene.resolved.json
  const std::string key = output::json_hash(same_swimmer(resolved));
  std::string dir = runs_dir + "/" + p.name + "-3d-" + key;
  Run3d r;
  r.h = p.h;
  r.length = p.L;
  json summary = finished_summary(dir, log);
  if (summary.is_null())
    for (const auto& e : fs::directory_iterator(runs_dir)) {
      if (e.path() == fs::path(dir) || swimmer_key(e.path() / "scene.resolved.json", nullptr) != key) continue;
      summary = finished_summary(e.path().string(), log);
      // an axi run of the same scene resolves to the same 3D physics: only a 3D run is one
      if (!summary.is_null() && summary.value("tier", std::string("3d")) != "3d") summary = nullptr;
      if (!summary.is_null()) {
        dir = e.path().string();
        break;
      }
    }
  *cached = !summary.is_null();
  // a run of this physics stopped part way (the suite was interrupted) continues from its
  // checkpoint when the checkpoint matches the scene
  bool resume = false;
  if (!*cached && interrupted_run(dir)) {
    try {
      full3d::check_resumable(p, resolved, dir);
      resume = true;
    } catch (const InputError& e) {
      log.reject(dir, std::string("interrupted run not resumed: ") + e.what());
    }
  }
  if (!*cached && !resume) {
    fs::remove_all(dir);
    output::reset_ledger(dir);  // the folder's files are this run's alone
    fs::create_directories(dir);
  }
  // a fresh run's record comes from the tier; a cached one is read back from its folder
  record::RunRecord rec;
  if (!*cached) {
    full3d::RunControl ctl;
    ctl.progress = progress;
    ctl.quiet_vtk = frame_interval <= 0;
    ctl.keep_rows = true;
    ctl.resume = resume;
    full3d::RunOutcome out = full3d::run3d(p, resolved, dir, ctl);
    summary = out.summary;
    // the record is read back from the folder, as a cached run's is: the report is the same
    // whether this process, another (an MPI rank) or an earlier invocation made the run
    rec = record::read_run(dir);
  } else {
    rec = record::read_run(dir);
    ++log.reused;
  }
  log.folders.push_back(dir);
  const std::string status = summary.value("status", std::string("unknown"));
  r.ok = status == "ok";
  r.wall = summary.value("wall_time_s", 0.0);
  r.series = series_of(rec);
  r.cyc = cycle_figures_of(rec, summary);
  r.record = {{"cell_size_m", p.h},
              {"grid", {p.nx, p.ny, p.nz}},
              {"status", status},
              {"cached", *cached},
              {"folder", dir},
              {"wall_time_s", r.wall},
              {"steps", summary.value("steps", 0L)},
              {"cycles_completed", summary.value("cycles_completed", 0)},
              {"membrane_frames", fs::exists(fs::path(dir) / "membrane.pvd")},
              {"pumped_volume_m3", summary.value("pumped_volume_m3", 0.0)},
              {"has_cycle", r.cyc.has_cycle}};
  // the wall's largest departure from axisymmetry (runs written before the wrinkle measure
  // existed have none)
  for (const char* k : {"max_wrinkle_m", "max_wrinkle_over_h"})
    if (summary.contains(k) && summary[k].is_number()) r.record[k] = summary[k];
  if (summary.contains("max_displacement_m") && summary["max_displacement_m"].is_number()) {
    r.max_displacement = summary["max_displacement_m"].get<double>();
    r.record["max_displacement_m"] = r.max_displacement;
  }
  if (r.cyc.has_cycle) {
    r.record["displacement_per_cycle_m"] = r.cyc.displacement_per_cycle_m;
    r.record["cycle_time_s"] = r.cyc.cycle_time_s;
    r.record["mean_velocity_per_cycle_m_per_s"] = r.cyc.mean_velocity_per_cycle_m_per_s;
  }
  // the first cycle of a one-cycle scene; the whole run of a multi-cycle one (Figure 14)
  const double t_end = r.series.t.empty() ? 0.0 : r.series.t.back();
  r.record["series"] = downsample(r.series, r.cyc.has_cycle && p.protocol.cycles == 1 ? r.cyc.cycle_time_s : t_end);
  return r;
}

// ---- one axi run (cached) ------------------------------------------------------------

struct RunAxi {
  json record;  ///< report entry
  CycleFigures cyc;
  double h = 0, wall = 0;
  double max_displacement = std::numeric_limits<double>::quiet_NaN();  ///< m, over the run
  bool ok = false;
};

/// One run of the axisymmetric tier, cached in runs_dir like the 3D runs: a finished run
/// whose physics (its scene resolved again by the current reader) is this scene's is reused,
/// found by its folder name or by its own scene.resolved.json; any other change reruns it.
RunAxi run_axi_cached(const json& sc, const std::string& runs_dir, int progress, bool* cached, CacheLog& log) {
  json resolved;
  const axi::ParamsAxi p = axi::read_scene_axi(sc, resolved);
  const std::string key = axi_key(resolved);
  std::string dir = runs_dir + "/" + p.name() + "-axi-" + key;
  json summary = finished_summary(dir, log);
  // the summary's own scene must still resolve to this physics
  if (!summary.is_null() && swimmer_key(fs::path(dir) / "scene.resolved.json", nullptr, true) != key) summary = nullptr;
  if (summary.is_null())
    for (const auto& e : fs::directory_iterator(runs_dir)) {
      if (e.path() == fs::path(dir) || swimmer_key(e.path() / "scene.resolved.json", nullptr, true) != key) continue;
      summary = finished_summary(e.path().string(), log);
      if (!summary.is_null() && summary.value("tier", std::string()) != "axi") summary = nullptr;
      if (!summary.is_null()) {
        dir = e.path().string();
        break;
      }
    }
  *cached = !summary.is_null();
  record::RunRecord rec;
  if (!*cached) {
    fs::remove_all(dir);
    output::reset_ledger(dir);
    fs::create_directories(dir);
    axi::RunControlAxi ctl;
    ctl.progress = progress;
    ctl.keep_rows = true;
    axi::RunOutcomeAxi out = axi::run_axi(p, resolved, dir, ctl);
    summary = out.summary;
    rec = record::read_run(dir);  // as a cached run's (run_3d)
  } else {
    rec = record::read_run(dir);
    ++log.reused;
  }
  log.folders.push_back(dir);
  RunAxi r;
  r.h = p.h;
  const std::string status = summary.value("status", std::string("unknown"));
  r.ok = status == "ok";
  r.wall = summary.value("wall_time_s", 0.0);
  r.cyc = cycle_figures_of(rec, summary);
  if (summary.contains("max_displacement_m") && summary["max_displacement_m"].is_number())
    r.max_displacement = summary["max_displacement_m"].get<double>();
  r.record = {{"cell_size_m", p.h},
              {"grid", {p.nr, p.nx}},
              {"method", p.method_name()},
              {"status", status},
              {"cached", *cached},
              {"folder", dir},
              {"wall_time_s", r.wall},
              {"steps", summary.value("steps", 0L)},
              {"cycles_completed", summary.value("cycles_completed", 0)},
              {"has_cycle", r.cyc.has_cycle}};
  if (std::isfinite(r.max_displacement)) r.record["max_displacement_m"] = r.max_displacement;
  if (r.cyc.has_cycle) {
    r.record["displacement_per_cycle_m"] = r.cyc.displacement_per_cycle_m;
    r.record["cycle_time_s"] = r.cyc.cycle_time_s;
    r.record["mean_velocity_per_cycle_m_per_s"] = r.cyc.mean_velocity_per_cycle_m_per_s;
    r.record["cycle_phase_times_s"] = r.cyc.phase_times_s;
  } else {
    r.record["no_cycle_reason"] = r.cyc.absent_because;
  }
  return r;
}

/// The calibration of `base` at `grid` (grid_key): read from cal_dir when a valid one of this
/// physics and format is there, else computed and written (`starting` called first). Returns
/// the calibration file ("" when it failed) and its content in cal_j.
std::string calibration_at(const json& base, const std::string& grid_key, const json& grid, const std::string& name,
                           int threads, const std::string& cal_dir, CacheLog& log, json& cal_j,
                           const std::function<void()>& starting) {
  std::string cal_file;
  json s = base;
  set_key(s, grid_key, grid);
  set_key(s, "full3d.threads", threads);  // as the 3D runs; not part of the key
  json resolved;
  const full3d::Params3d p = full3d::read_scene3d(s, resolved);
  // keyed by the physics of the resolved scene and the calibration file's format version
  const std::string dir = cal_dir + "/" + name + "-" + output::json_hash({physics_of(resolved), kCalibrationFormat});
  cal_file = dir + "/calibration.json";
  if (fs::exists(cal_file)) {
    // a damaged calibration is recomputed, never read
    if (const std::string why = calibration_problem(cal_file); !why.empty()) {
      log.reject(cal_file, why);
      fs::remove(cal_file);
    }
  }
  if (!fs::exists(cal_file)) {
    const std::string found = cached_calibration(cal_dir, same_swimmer(resolved), log);
    if (!found.empty()) cal_file = found;
  }
  if (fs::exists(cal_file)) {
    std::ifstream in(cal_file);
    cal_j = json::parse(in);
    ++log.reused;
    log.calibrations.push_back(cal_file);
    return cal_file;
  }
  if (starting) starting();
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const StaticCalibration c = calibrate_static(p, default_loads(p));
    const HydraulicRadii hr = measure_hydraulic_radii(p);
    cal_j = to_json(c, p, resolved);
    json hj = to_json(hr);
    hj["hydraulic_wall_time_s"] = hj["wall_time_s"];
    hj.erase("wall_time_s");
    cal_j.update(hj);
    cal_j.update(calibrate_towed(p, hr).json);
    cal_j["wall_time_s"] = seconds_since(t0);
    cal_j["status"] = "ok";
    fs::create_directories(dir);
    output::write_json(cal_file, cal_j);
    log.calibrations.push_back(cal_file);
  } catch (const NumericalError& e) {
    cal_j = {{"status", std::string("failed: ") + e.what()}};
    cal_file.clear();
  }
  return cal_file;
}

// ---- one 1D run --------------------------------------------------------------------------

struct Run1d {
  json record;
  Series series;
  CycleFigures cyc;
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

json relative(double value, double ref) {
  if (!(std::abs(ref) > 0)) return nullptr;
  return (value - ref) / std::abs(ref);
}

/// A number for the report: null when it is not finite (never NaN in a file).
json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json extrapolation_json(const Extrapolation& e) {
  return json{{"value", num(e.value)},         {"error", num(e.error)},
              {"order", num(e.order)},         {"observed_order", num(e.observed_order)},
              {"asymptotic", e.asymptotic},    {"note", e.note}};
}

std::string percent_text(double x) {
  char b[48];
  std::snprintf(b, sizeof b, "%.2g %%", 100.0 * x);
  return b;
}

/// A figure of the reference converged: asymptotic, with an observed order (three grids),
/// its relative error at most `target`.
bool figure_converged(const Extrapolation& e, double rel, double target) {
  return e.asymptotic && std::isfinite(e.observed_order) && std::isfinite(rel) && rel <= target;
}

/// The cycle time as the sum of the protocol's phases (CycleFigures::phase_times_s), each
/// extrapolated on its own (richardson_sum). Null when the runs' phases differ in number.
json phase_sum_cycle_time(const std::vector<double>& h, const std::vector<std::vector<double>>& phases, double assumed,
                          const OrderRange& orders, double target) {
  const std::size_t np = phases.front().size();
  for (const auto& p : phases)
    if (p.size() != np || np < 2) return nullptr;
  const SumExtrapolation s = richardson_sum(h, phases, assumed, orders, target);
  json list = json::array();
  for (std::size_t k = 0; k < np; ++k) {
    json j = extrapolation_json(s.parts[k]);
    j["phase"] = k == 0 ? std::string("first contraction")
                 : k + 1 == np ? std::string("recovery")
                               : "contraction " + std::to_string(k + 1);
    list.push_back(j);
  }
  return {{"value", num(s.value)},
          {"error", num(s.error)},
          {"order", nullptr},
          {"observed_order", nullptr},
          {"asymptotic", s.asymptotic},
          {"note", "sum of the protocol's " + std::to_string(np) +
                       " phases, each extrapolated on its own (error: the sum of theirs)"},
          {"phases", list},
          {"relative_error", num(s.relative_error)},
          {"converged", s.converged}};
}

/// The axisymmetric reference from its runs: each headline figure (and the largest centre
/// displacement when the paper gives it) extrapolated to h -> 0 with the reference's order
/// range over the grids that completed a cycle; each figure converged when it is asymptotic,
/// has an observed order (three grids) and its relative error is at most `target`; the
/// reference converged when every figure is. When the whole cycle's time is not converged, it
/// is taken as the sum of its phases (phase_sum_cycle_time), and the mean velocity per cycle as
/// the displacement over that time (relative errors added); the whole cycle's extrapolation is
/// kept beside it. `statement` says so with the figures reached.
json axi_reference(const std::vector<RunAxi>& runs, const OrderRange& orders, bool with_max, double target) {
  std::vector<double> h, d, T, v, hm, m;
  std::vector<std::vector<double>> phases;
  for (const auto& r : runs)
    if (r.cyc.has_cycle) {
      h.push_back(r.h);
      d.push_back(r.cyc.displacement_per_cycle_m);
      T.push_back(r.cyc.cycle_time_s);
      v.push_back(r.cyc.mean_velocity_per_cycle_m_per_s);
      phases.push_back(r.cyc.phase_times_s);
      if (std::isfinite(r.max_displacement)) {
        hm.push_back(r.h);
        m.push_back(r.max_displacement);
      }
    }
  json ref = {{"grids_used", h.size()}, {"order_range", {orders.lo, orders.hi}}, {"target_relative", target}};
  const std::string target_text = percent_text(target);
  if (h.size() < 2) {
    ref["converged"] = false;
    ref["statement"] = "not converged to " + target_text + ": fewer than two of the reference's grids completed a cycle, "
                       "so it has no extrapolated value";
    ref["note"] = "fewer than two grids completed a cycle: no extrapolated reference";
    return ref;
  }
  const double assumed = std::clamp(1.0, orders.lo, orders.hi);
  struct Fig {
    const char* key;
    const char* words;
    const std::vector<double>* hh;
    const std::vector<double>* f;
  };
  std::vector<Fig> figs = {{"displacement_per_cycle_m", "displacement per cycle", &h, &d},
                           {"cycle_time_s", "cycle time", &h, &T},
                           {"mean_velocity_per_cycle_m_per_s", "mean velocity per cycle", &h, &v}};
  if (with_max && hm.size() >= 2) figs.push_back({"max_displacement_m", "maximum displacement", &hm, &m});
  for (const Fig& f : figs) {
    const Extrapolation e = richardson(*f.hh, *f.f, assumed, orders);
    json j = extrapolation_json(e);
    const double rel = std::abs(e.value) > 0 ? std::abs(e.error / e.value) : std::numeric_limits<double>::quiet_NaN();
    j["relative_error"] = num(rel);
    j["converged"] = figure_converged(e, rel, target);
    ref[f.key] = j;
  }
  // three grids or more: the cycle time phase by phase when the whole cycle's series does not converge
  if (h.size() >= 3 && !ref["cycle_time_s"]["converged"].get<bool>()) {
    json ps = phase_sum_cycle_time(h, phases, assumed, orders, target);
    if (!ps.is_null()) {
      ps["whole_cycle"] = ref["cycle_time_s"];
      ref["cycle_time_s"] = ps;
      const json& jd = ref["displacement_per_cycle_m"];
      const double dv = jd["value"].is_number() ? jd["value"].get<double>() : std::numeric_limits<double>::quiet_NaN();
      const double rd = jd["relative_error"].is_number() ? jd["relative_error"].get<double>()
                                                         : std::numeric_limits<double>::quiet_NaN();
      const double tv = ps["value"].get<double>(), rt = ps["relative_error"].is_number()
                                                            ? ps["relative_error"].get<double>()
                                                            : std::numeric_limits<double>::quiet_NaN();
      const double vv = dv / tv, rv = rd + rt;
      json jv = {{"value", num(vv)},
                 {"error", num(std::abs(vv) * rv)},
                 {"order", nullptr},
                 {"observed_order", nullptr},
                 {"asymptotic", jd["asymptotic"].get<bool>() && ps["asymptotic"].get<bool>()},
                 {"note", "extrapolated displacement per cycle / cycle time from its phases (relative errors added)"},
                 {"relative_error", num(rv)},
                 {"converged", jd["converged"].get<bool>() && ps["converged"].get<bool>() && std::isfinite(rv) &&
                                   rv <= target},
                 {"direct", ref["mean_velocity_per_cycle_m_per_s"]}};
      ref["mean_velocity_per_cycle_m_per_s"] = jv;
    }
  }
  bool all = true;
  std::string parts;
  for (const Fig& f : figs) {
    const json& j = ref[f.key];
    const bool ok = j["converged"].get<bool>();
    all = all && ok;
    std::string why;
    if (j.contains("phases")) why = " (the sum of its phases)";
    else if (j.contains("direct")) why = " (displacement over the phases' cycle time)";
    else if (!j["asymptotic"].get<bool>()) why = " (not in the asymptotic range)";
    else if (j["observed_order"].is_null()) why = " (two grids: no observed order)";
    const bool has_rel = j["relative_error"].is_number();
    parts += std::string(parts.empty() ? "" : ", ") + f.words + " ± " +
             (has_rel ? percent_text(j["relative_error"].get<double>()) : std::string("—")) + why;
  }
  ref["converged"] = all;
  ref["statement"] = std::string(all ? "converged to " : "not converged to ") + target_text + ": " + parts;
  return ref;
}

/// The 3D extrapolation against the axisymmetric reference, figure by figure: both values
/// with their errors, the difference, e_3d + e_ref, agree / disagree (verdicts.hpp), the 3D
/// series' observed order, and the finest 3D grid's relative error against the reference.
json compare_3d_with_reference(const json& ref3d, const json& ref, const std::vector<const Run3d*>& runs) {
  json out = json::object();
  const Run3d* finest = nullptr;
  for (const Run3d* r : runs)
    if (!finest || r->h < finest->h) finest = r;
  for (const char* key : {"displacement_per_cycle_m", "cycle_time_s", "mean_velocity_per_cycle_m_per_s", "max_displacement_m"}) {
    const bool in3d = ref3d.contains(key) && ref3d[key].is_object(), inref = ref.contains(key) && ref[key].is_object();
    if (!inref) continue;
    auto get = [](const json& j, const char* k) {
      return j.contains(k) && j[k].is_number() ? j[k].get<double>() : std::numeric_limits<double>::quiet_NaN();
    };
    const double a = in3d ? get(ref3d[key], "value") : std::numeric_limits<double>::quiet_NaN();
    const double ea = in3d ? std::abs(get(ref3d[key], "error")) : std::numeric_limits<double>::quiet_NaN();
    const double b = get(ref[key], "value"), eb = std::abs(get(ref[key], "error"));
    json c = {{"value_3d", num(a)},
              {"error_3d", num(ea)},
              {"order_3d", in3d ? ref3d[key]["order"] : json(nullptr)},
              {"observed_order_3d", in3d ? ref3d[key]["observed_order"] : json(nullptr)},
              {"asymptotic_3d", in3d ? ref3d[key]["asymptotic"] : json(nullptr)},
              {"value_reference", num(b)},
              {"error_reference", num(eb)},
              {"difference", num(a - b)},
              {"combined_uncertainty", num(ea + eb)},
              {"verdict", agreement_verdict(a, ea, b, eb)}};
    if (!in3d) c["note"] = "fewer than two 3D grids completed a cycle: no 3D extrapolation";
    double f = std::numeric_limits<double>::quiet_NaN();
    if (finest) {
      const std::string k = key;
      f = k == "displacement_per_cycle_m" ? finest->cyc.displacement_per_cycle_m
          : k == "cycle_time_s"           ? finest->cyc.cycle_time_s
          : k == "mean_velocity_per_cycle_m_per_s" ? finest->cyc.mean_velocity_per_cycle_m_per_s
                                                   : finest->max_displacement;
      c["finest_3d_cell_size_m"] = finest->h;
    }
    c["finest_3d_value"] = num(f);
    c["finest_3d_relative_error"] = std::abs(b) > 0 ? num((f - b) / std::abs(b)) : json(nullptr);
    out[key] = c;
  }
  return out;
}

/// The reference's order range: its `order_range`, else the axi method's own (the fitted
/// method is a sharp-interface one, the immersed boundary first order at best).
OrderRange reference_orders(const json& ref, const axi::ParamsAxi& p) {
  if (ref.contains("order_range")) return parse_order_range(ref["order_range"], "reference.order_range");
  return p.method == axi::AxiMethod::Fitted ? kSharpInterfaceOrders : kImmersedBoundaryOrders;
}

/// The scene of one reference grid: the case's scene (after its own set), the reference's
/// set, the grid.
json reference_scene(const json& base, const json& ref, const json& grid) {
  json s = base;
  apply_sets(s, ref.value("set", json()));
  set_key(s, ref.value("grid_key", std::string("axi.grid.cells_across")), grid);
  return s;
}

/// A case's `reference` read strictly (InputError naming the key, the value and what is
/// allowed).
void check_reference(const json& ref, const std::string& at) {
  if (!ref.is_object())
    throw InputError(at, scene::show(ref),
                     "an object {\"tier\": \"axi\", \"grid_key\": \"axi.grid.cells_across\", \"grids\": [64, 128, 256], "
                     "\"order_range\": ..., \"set\": {...}}: the converged reference of the case");
  for (const auto& [k, v] : ref.items())
    if (k != "tier" && k != "grid_key" && k != "grids" && k != "order_range" && k != "set")
      throw InputError(at + "." + k, scene::show(v), "not a key of a reference: tier, grid_key, grids, order_range, set");
  const json& tier = member(ref, "tier", at);
  if (tier != "axi")
    throw InputError(at + ".tier", scene::show(tier),
                     "\"axi\" (the axisymmetric tier, --tier axi, the converged reference of round-wall scenes)");
  if (ref.contains("grid_key")) {
    const json& k = ref["grid_key"];
    if (!k.is_string() || k.get<std::string>().rfind("axi.grid", 0) != 0)
      throw InputError(at + ".grid_key", scene::show(k),
                       "a dotted key of the axi tier's grid: \"axi.grid.cells_across\" (default), \"axi.grid.cell_size\" "
                       "or \"axi.grid\"");
  }
  const json& g = member(ref, "grids", at);
  bool distinct = g.is_array() && g.size() >= 3;
  for (std::size_t i = 0; distinct && i < g.size(); ++i)
    for (std::size_t j = 0; j < i; ++j) distinct = distinct && g[i] != g[j];
  if (!distinct)
    throw InputError(at + ".grids", scene::show(g),
                     "three or more distinct grid values (an observed order needs three grids), coarse to fine");
  if (ref.contains("order_range")) parse_order_range(ref["order_range"], at + ".order_range");
  if (ref.contains("set") && !ref["set"].is_object())
    throw InputError(at + ".set", scene::show(ref["set"]), "an object {\"dotted.key\": value} applied to the axi runs");
}

}  // namespace

namespace {

std::string key_list(std::initializer_list<const char*> keys) {
  std::string s;
  for (const char* k : keys) s += std::string(s.empty() ? "" : ", ") + k;
  return s;
}

/// `j` must be an object whose keys are all in `allowed` (InputError naming the first other key).
void only_keys(const json& j, const std::string& at, const std::string& what, std::initializer_list<const char*> allowed) {
  if (!j.is_object()) throw InputError(at, scene::show(j), "an object: " + what + " (keys " + key_list(allowed) + ")");
  for (const auto& [k, v] : j.items()) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || k == a;
    if (!ok) throw InputError(at + "." + k, scene::show(v), "not a key of " + what + ": " + key_list(allowed));
  }
}

void optional_text(const json& j, const char* key, const std::string& at) {
  if (j.contains(key) && !j[key].is_string()) throw InputError(at + "." + key, scene::show(j[key]), "a text");
}

/// A `set`: an object {"dotted.key": value}, every key a dotted path with non-empty components.
/// The values are checked by the tier's reader on the scene they are applied to.
void check_set(const json& set, const std::string& at) {
  if (!set.is_object()) throw InputError(at, scene::show(set), "an object {\"dotted.key\": value} applied to the scene");
  for (const auto& [k, v] : set.items()) {
    bool ok = !k.empty() && k.front() != '.' && k.back() != '.' && k.find("..") == std::string::npos;
    if (!ok) throw InputError(at + "." + k, scene::show(v), "a dotted scene key with non-empty components (\"wall.C1\")");
  }
}

/// A list of numbers accepted by `ok`, at least one.
template <class Ok>
void number_list(const json& j, const std::string& at, Ok ok, const std::string& allowed) {
  bool good = j.is_array() && !j.empty();
  for (const auto& v : good ? j : json::array()) good = good && v.is_number() && ok(v);
  if (!good) throw InputError(at, scene::show(j), allowed);
}

/// The scene (after its sets) read by the 3D tier's reader; a refusal names `at`.
void check_3d(const json& s, const std::string& at, const std::string& what) {
  try {
    json resolved;
    full3d::read_scene3d(s, resolved);
  } catch (const InputError& e) {
    throw InputError(at, what, std::string("a scene the 3D tier runs; it refuses this one: ") + e.what());
  }
}

/// A calibration file for the 1D reads of calibrated models before the calibration exists: the
/// 3D spring network's C1 and zero offsets, in the system's temporary folder, removed after.
class StandInCalibration {
 public:
  explicit StandInCalibration(double c1) {
    std::string tmpl = (fs::temp_directory_path() / "swim-suite-check-XXXXXX").string();
    const int fd = ::mkstemp(tmpl.data());
    if (fd < 0) throw OutputError("a temporary calibration file", std::strerror(errno));
    ::close(fd);
    path_ = tmpl;
    std::ofstream(path_) << json{{"C1_Pa_per_m", c1}, {"hydraulic_offset_inner_m", 0.0},
                                 {"hydraulic_offset_outer_m", 0.0}, {"status", "ok"}}.dump();
  }
  ~StandInCalibration() {
    std::error_code ec;
    fs::remove(path_, ec);
  }
  StandInCalibration(const StandInCalibration&) = delete;
  StandInCalibration& operator=(const StandInCalibration&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// A 1D model's scene as the suite runs it (model_scene), read by the 1D tier's reader; a
/// refusal names `at`.
void check_1d(const json& base, const json& model, const std::string& cal, const std::string& scene_dir,
              const std::string& at, const std::string& what) {
  const json s = model_scene(base, model, cal);
  try {
    json resolved;
    reduced1d::read_scene(s, resolved, scene_dir);
  } catch (const InputError& e) {
    throw InputError(at, what, std::string("a scene the 1D tier runs; it refuses this one: ") + e.what());
  }
}

}  // namespace

json model_scene(json s, const json& model, const std::string& cal) {
  apply_sets(s, model.value("set", json()));
  if (model.value("calibrated", false)) {
    if (s.contains("wall") && s["wall"].is_object()) {
      s["wall"].erase("spring_constant");
      s["wall"].erase("C1");
    }
    set_key(s, "wall.calibration", cal);
  }
  return s;
}

json load_suite(const std::string& path, const std::string& data_dir) {
  const json s = scene::load_file(path);
  check_suite(s, path, data_dir, true);
  return s;
}

void check_suite(const json& s, const std::string& path, const std::string& data_dir, bool scenes) {
  if (!s.is_object()) throw InputError("suite", path, "a JSON object with \"cases\" and \"models1d\"");
  only_keys(s, "suite", "a suite file",
            {"name", "description", "order_range", "thresholds", "cells1d", "rtol1d", "cases", "models1d",
             "reference_target_relative", "extremes3d"});
  optional_text(s, "name", "suite");
  optional_text(s, "description", "suite");
  const json& cases = member(s, "cases", "suite");
  if (!cases.is_array() || cases.empty()) throw InputError("suite.cases", scene::show(cases), "a non-empty array");
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string at = "suite.cases[" + std::to_string(i) + "]";
    only_keys(cases[i], at, "a case",
              {"scene", "grid_key", "grids", "calibration_grid", "time_variants3d", "set", "paper", "group",
               "sweep_value", "order_range", "reference"});
    const json& sc = member(cases[i], "scene", at);
    if (!sc.is_string() || sc.get<std::string>().empty())
      throw InputError(at + ".scene", scene::show(sc), "a scene file name (text)");
    optional_text(cases[i], "group", at);
    if (cases[i].contains("grid_key")) {
      const json& k = cases[i]["grid_key"];
      if (!k.is_string() || k.get<std::string>().rfind("full3d.grid", 0) != 0)
        throw InputError(at + ".grid_key", scene::show(k),
                         "a dotted key of the 3D grid: \"full3d.grid.cells_across\" (default), \"full3d.grid\" or "
                         "another key under full3d.grid");
    }
    if (cases[i].contains("set")) check_set(cases[i]["set"], at + ".set");
    if (cases[i].contains("paper")) {
      const json& pp = cases[i]["paper"];
      only_keys(pp, at + ".paper", "the paper's values",
                {"source", "max_displacement_m", "displacement_per_cycle_m", "cycle_time_s",
                 "mean_velocity_per_cycle_m_per_s"});
      for (const auto& [k, v] : pp.items())
        if (k == "source" ? !v.is_string() : !(v.is_number() && std::isfinite(v.get<double>())))
          throw InputError(at + ".paper." + k, scene::show(v), k == "source" ? "a text" : "a number (SI units)");
    }
    const json& g = member(cases[i], "grids", at);
    if (!g.is_array() || g.size() < 2) throw InputError(at + ".grids", scene::show(g), "two or more grid values");
    if (cases[i].contains("calibration_grid")) {
      const json& c = cases[i]["calibration_grid"];
      if (!c.is_number_integer() || c.get<long>() < 0 || c.get<long>() >= long(g.size()))
        throw InputError(at + ".calibration_grid", scene::show(c),
                         "an index into grids, 0 to " + std::to_string(g.size() - 1));
    }
    if (cases[i].contains("order_range")) parse_order_range(cases[i]["order_range"], at + ".order_range");
    if (cases[i].contains("reference")) check_reference(cases[i]["reference"], at + ".reference");
    if (cases[i].contains("time_variants3d")) {
      const json& v = cases[i]["time_variants3d"];
      bool ok = v.is_array();
      for (const auto& e : ok ? v : json::array())
        ok = ok && e.is_object() && e.size() == 2 && e.contains("label") && e["label"].is_string() && e.contains("set") &&
             e["set"].is_object();
      if (!ok)
        throw InputError(at + ".time_variants3d", scene::show(v),
                         "an array of {\"label\": text, \"set\": {\"dotted.key\": value}} (3D time-step variants)");
      for (std::size_t k = 0; k < v.size(); ++k)
        check_set(v[k]["set"], at + ".time_variants3d[" + std::to_string(k) + "].set");
    }
  }
  if (s.contains("order_range")) parse_order_range(s["order_range"], "suite.order_range");
  if (s.contains("reference_target_relative")) {
    const json& t = s["reference_target_relative"];
    if (!t.is_number() || !(t.get<double>() > 0 && t.get<double>() < 1))
      throw InputError("suite.reference_target_relative", scene::show(t),
                       "a number between 0 and 1 (exclusive): the relative error below which a reference counts as "
                       "converged (default 0.01)");
  }
  if (s.contains("cells1d"))
    number_list(
        s["cells1d"], "suite.cells1d",
        [](const json& v) { return v.is_number_integer() && v.get<long>() >= 4 && v.get<long>() <= 100000; },
        "a non-empty array of cell counts of the 1D speed/accuracy runs, integers from 4 to 100000");
  if (s.contains("rtol1d"))
    number_list(
        s["rtol1d"], "suite.rtol1d", [](const json& v) { return v.get<double>() >= 1e-14 && v.get<double>() < 1; },
        "a non-empty array of relative tolerances of the 1D speed/accuracy runs, from 1e-14 to below 1");
  if (s.contains("extremes3d")) {
    const json& ex = s["extremes3d"];
    bool ok = ex.is_array();
    for (const auto& e : ok ? ex : json::array()) {
      ok = ok && e.is_object() && e.contains("label") && e["label"].is_string() && e.contains("scene") &&
           e["scene"].is_string() && e.contains("expect") &&
           (e["expect"] == "ok" || e["expect"] == "failed" || e["expect"] == "rejected") &&
           (!e.contains("set") || e["set"].is_object()) && (!e.contains("cause") || e["cause"].is_string());
      if (ok)
        for (const auto& [k, v] : e.items())
          ok = ok && (k == "label" || k == "scene" || k == "expect" || k == "set" || k == "cause");
    }
    if (!ok)
      throw InputError("suite.extremes3d", scene::show(ex),
                       "an array of {\"label\": text, \"scene\": file, \"set\": {...}, \"expect\": \"ok\" | "
                       "\"failed\" | \"rejected\", \"cause\": text in the message}");
    for (std::size_t k = 0; k < ex.size(); ++k)
      if (ex[k].contains("set")) check_set(ex[k]["set"], "suite.extremes3d[" + std::to_string(k) + "].set");
  }
  const json& models = member(s, "models1d", "suite");
  if (!models.is_array() || models.empty()) throw InputError("suite.models1d", scene::show(models), "a non-empty array");
  for (std::size_t i = 0; i < models.size(); ++i) {
    const std::string at = "suite.models1d[" + std::to_string(i) + "]";
    only_keys(models[i], at, "a 1D model", {"label", "calibrated", "set"});
    const json& l = member(models[i], "label", at);
    if (!l.is_string() || l.get<std::string>().empty()) throw InputError(at + ".label", scene::show(l), "a non-empty text");
    if (models[i].contains("calibrated") && !models[i]["calibrated"].is_boolean())
      throw InputError(at + ".calibrated", scene::show(models[i]["calibrated"]), "true or false");
    if (models[i].contains("set")) check_set(models[i]["set"], at + ".set");
  }
  const json& th = member(s, "thresholds", "suite");
  only_keys(th, "suite.thresholds", "the thresholds",
            {"displacement_per_cycle_relative", "cycle_time_relative", "mean_velocity_per_cycle_relative",
             "velocity_phase_correlation"});
  for (const char* k : {"displacement_per_cycle_relative", "cycle_time_relative", "mean_velocity_per_cycle_relative"}) {
    const json& v = member(th, k, "suite.thresholds");
    if (!v.is_number() || !(v.get<double>() > 0 && v.get<double>() <= 10))
      throw InputError(std::string("suite.thresholds.") + k, scene::show(v),
                       "a relative error above 0 and at most 10 (0.1: 10 %)");
  }
  {
    const json& v = member(th, "velocity_phase_correlation", "suite.thresholds");
    if (!v.is_number() || !(v.get<double>() > -1 && v.get<double>() <= 1))
      throw InputError("suite.thresholds.velocity_phase_correlation", scene::show(v),
                       "a correlation above -1 and at most 1");
  }
  if (!scenes) return;
  // every case's scene, on every grid, with its time-step variants, and every 1D model on it:
  // read by the tiers' own readers here, before anything runs or is written
  const std::string suite_dir = fs::path(path).parent_path().string();
  auto scene_file = [&](const json& name, const std::string& at) {
    const std::string n = name.get<std::string>();
    for (const fs::path& q : {fs::path(n), fs::path(suite_dir) / n,
                              data_dir.empty() ? fs::path() : fs::path(data_dir) / "scenes" / n})
      if (!q.empty() && fs::is_regular_file(q)) return q.string();
    throw InputError(at, scene::show(name), "a scene file (tried as given, beside the suite file and in the shipped data/scenes/)");
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string at = "suite.cases[" + std::to_string(i) + "]";
    const std::string scene_path = scene_file(cases[i]["scene"], at + ".scene");
    const std::string scene_dir = fs::path(scene_path).parent_path().string();
    json base;
    try {
      base = scene::load_file(scene_path);
    } catch (const InputError& e) {
      throw InputError(at + ".scene", scene::show(cases[i]["scene"]), std::string("a readable scene: ") + e.what());
    }
    apply_sets(base, cases[i].value("set", json()));
    const std::string grid_key = cases[i].value("grid_key", std::string("full3d.grid.cells_across"));
    const json& grids = cases[i]["grids"];
    // the 3D reader builds the membrane mesh (up to seconds on a fine grid): the scene and its
    // time-step variants are read at the first (coarsest) grid; the other grids' 3D sections
    // are checked against the ranges the reader accepts (scene::check_section)
    json s0 = base;
    set_key(s0, grid_key, grids[0]);
    check_3d(s0, at + ".grids[0]", grid_key + " = " + grids[0].dump());
    for (std::size_t g = 1; g < grids.size(); ++g) {
      json sg = base;
      set_key(sg, grid_key, grids[g]);
      try {
        if (sg.contains("full3d")) scene::check_section(sg["full3d"], "full3d", full3d::section_keys());
      } catch (const InputError& e) {
        throw InputError(at + ".grids[" + std::to_string(g) + "]", grid_key + " = " + grids[g].dump(),
                         std::string("a scene the 3D tier runs; it refuses this one: ") + e.what());
      }
    }
    json resolved0;
    const double c1 = full3d::read_scene3d(s0, resolved0).c1_estimate();
    if (cases[i].contains("time_variants3d"))
      for (std::size_t k = 0; k < cases[i]["time_variants3d"].size(); ++k) {
        json sv = s0;
        apply_sets(sv, cases[i]["time_variants3d"][k]["set"]);
        check_3d(sv, at + ".time_variants3d[" + std::to_string(k) + "].set", scene::show(cases[i]["time_variants3d"][k]["set"]));
      }
    const StandInCalibration cal(c1 > 0 && std::isfinite(c1) ? c1 : 1.0);
    for (std::size_t m = 0; m < models.size(); ++m) {
      const std::string mat = "suite.models1d[" + std::to_string(m) + "]";
      const std::string what = "the model on " + cases[i]["scene"].get<std::string>();
      check_1d(base, models[m], cal.path(), scene_dir, mat, what);
      if (m == 0) {
        for (const json& cells : s.value("cells1d", json::array())) {
          json sc = base;
          set_key(sc, "numerics1d.cells", cells);
          check_1d(sc, models[m], cal.path(), scene_dir, "suite.cells1d", cells.dump());
        }
        for (const json& rtol : s.value("rtol1d", json::array())) {
          json sc = base;
          set_key(sc, "numerics1d.rtol", rtol);
          check_1d(sc, models[m], cal.path(), scene_dir, "suite.rtol1d", rtol.dump());
        }
      }
    }
  }
  // the extremes' scenes exist and are scenes (their outcome, a refusal included, is what they
  // report: a scene the reader refuses is recorded as "rejected", never a stop of the suite)
  if (s.contains("extremes3d"))
    for (std::size_t k = 0; k < s["extremes3d"].size(); ++k) {
      const std::string at = "suite.extremes3d[" + std::to_string(k) + "].scene";
      try {
        scene::load_file(scene_file(s["extremes3d"][k]["scene"], at));
      } catch (const InputError& e) {
        if (e.key() == at) throw;
        throw InputError(at, scene::show(s["extremes3d"][k]["scene"]), std::string("a readable scene: ") + e.what());
      }
    }
  // the scene of every case with a reference must be one the axi tier runs, on every grid:
  // refused here, before anything runs
  for (std::size_t i = 0; i < cases.size(); ++i) {
    if (!cases[i].contains("reference")) continue;
    const std::string at = "suite.cases[" + std::to_string(i) + "].reference";
    const json& ref = cases[i]["reference"];
    const std::string scene_name = cases[i]["scene"].get<std::string>();
    json base = scene::load_file(scene_file(cases[i]["scene"], "suite.cases[" + std::to_string(i) + "].scene"));
    apply_sets(base, cases[i].value("set", json()));
    for (const json& g : ref["grids"]) {
      try {
        json resolved;
        axi::read_scene_axi(reference_scene(base, ref, g), resolved);
      } catch (const InputError& e) {
        throw InputError(at, scene_name + " at " + ref.value("grid_key", std::string("axi.grid.cells_across")) + " = " +
                                 g.dump(),
                         std::string("a scene the axisymmetric tier (--tier axi) runs; it refuses this one: ") + e.what());
      }
    }
  }
}

// ---- the suite's heavy runs as independent jobs (MPI: validation/suite.hpp) ---------------

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
    key = output::json_hash(same_swimmer(resolved));
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
  for (const json& cs : suite["cases"]) {
    const std::string stem = fs::path(cs["scene"].get<std::string>()).stem().string();
    bool take = o.only.empty();
    for (const auto& n : o.only) take = take || n == stem || n == stem + ".json";
    if (!take) continue;
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
      for (const json& g : rs["grids"]) {
        const json s = reference_scene(base, rs, g);
        json resolved;
        const axi::ParamsAxi p = axi::read_scene_axi(s, resolved);
        key = axi_key(resolved);
        add({{"type", "axi"}, {"scene", s}, {"runs_dir", runs_dir}},
            double(p.nr) * p.nx * (p.time_limit / p.dt_max));
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

json run_planned(const json& job) {
  CacheLog log;  // this process's view; the report's pass builds its own
  const std::string type = job.at("type").get<std::string>();
  bool cached = false;
  if (type == "3d") {
    const std::string runs_dir = job["runs_dir"];
    const int threads = job["threads"];
    double frames = 0;
    if (job.contains("frames_from")) {
      const Run3d prev = run_3d(job["frames_from"], runs_dir, threads, &cached, log);  // finished before this job
      if (prev.cyc.has_cycle) frames = prev.cyc.cycle_time_s / 12.0;
    }
    if (job.contains("grid_scenes")) {
      // a time-step variant is run only for a case with a reference (two grids with a cycle, or the axi one)
      int with_cycle = 0;
      for (const json& g : job["grid_scenes"]) with_cycle += run_3d(g, runs_dir, threads, &cached, log).cyc.has_cycle;
      if (with_cycle < 2 && !job["unless_no_reference"].value("has_axi_reference", false))
        return {{"status", "not needed: the case has no reference"}};
    }
    const Run3d r = run_3d(job["scene"], runs_dir, threads, &cached, log, frames);
    return {{"status", r.record.value("status", std::string("unknown"))}, {"cached", cached}};
  }
  if (type == "axi") {
    const RunAxi r = run_axi_cached(job["scene"], job["runs_dir"], 0, &cached, log);
    return {{"status", r.record.value("status", std::string("unknown"))}, {"cached", cached}};
  }
  if (type == "calibration") {
    json cal;
    const std::string file = calibration_at(job["base"], job["grid_key"], job["grid"], job["name"], job["threads"],
                                            job["cal_dir"], log, cal, {});
    return {{"status", cal.value("status", std::string("unknown"))}, {"file", file}};
  }
  throw std::logic_error("unknown validation job " + type);
}

json run_suite(const SuiteOptions& o) {
  json suite = scene::load_file(o.suite);
  check_suite(suite, o.suite, o.data_dir, !o.scenes_checked);
  const std::string suite_dir = fs::path(o.suite).parent_path().string();
  const json& th = suite["thresholds"];
  const std::string runs_dir = o.out_dir + "/runs", cal_dir = o.out_dir + "/calibrations";
  fs::create_directories(runs_dir);
  fs::create_directories(cal_dir);
  auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  const auto t_suite = std::chrono::steady_clock::now();
  CacheLog log;

  json report = {{"suite", suite.value("name", fs::path(o.suite).stem().string())},
                 {"description", suite.value("description", std::string())},
                 {"thresholds", th},
                 {"cases", json::array()}};
  json cases = json::array();
  for (const json& cs : suite["cases"]) {
    const std::string stem = fs::path(cs["scene"].get<std::string>()).stem().string();
    bool take = o.only.empty();
    for (const auto& n : o.only) take = take || n == stem || n == stem + ".json";
    if (take) cases.push_back(cs);
  }
  if (cases.empty())
    throw InputError("--case", o.only.empty() ? "" : o.only.front(), "the scene file name of a case of the suite");
  report["cases_selected"] = o.only;
  for (std::size_t ci = 0; ci < cases.size(); ++ci) {
    const json& cs = cases[ci];
    const std::string scene_path = find_scene(cs["scene"], suite_dir, o.data_dir);
    const std::string scene_dir = fs::path(scene_path).parent_path().string();
    json base = scene::load_file(scene_path);
    apply_sets(base, cs.value("set", json()));
    const std::string name = base.value("name", fs::path(scene_path).stem().string());
    const std::string grid_key = cs.value("grid_key", std::string("full3d.grid.cells_across"));
    const std::string tag = "case " + std::to_string(ci + 1) + "/" + std::to_string(cases.size()) + " (" + name + ")";
    // shipped scenes are named relative to the source tree, so that reports compare across machines
    const fs::path rel = fs::path(scene_path).lexically_relative(fs::path(o.data_dir).parent_path());
    const std::string scene_name = !rel.empty() && *rel.begin() != ".." ? rel.string() : scene_path;
    json cr = {{"name", name}, {"scene", scene_name}, {"group", cs.value("group", json())},
               {"grid_key", grid_key}, {"paper", cs.value("paper", json())}};
    cr["description"] = base.value("description", std::string());
    cr["sweep_value"] = cs.value("sweep_value", json());

    // 1. the 3D resolution study
    std::vector<Run3d> runs;
    json runs_j = json::array();
    const json& grids = cs["grids"];
    for (std::size_t g = 0; g < grids.size(); ++g) {
      json s = base;
      set_key(s, grid_key, grids[g]);
      say(tag + ": 3D grid " + std::to_string(g + 1) + "/" + std::to_string(grids.size()) + " (" + grid_key + " = " +
          grids[g].dump() + ")");
      bool cached = false;
      // the finest grid writes membrane frames, about 12 per cycle of the grid before it
      double frames = 0;
      if (g + 1 == grids.size() && g > 0 && runs.back().cyc.has_cycle) frames = runs.back().cyc.cycle_time_s / 12.0;
      Run3d r = run_3d(s, runs_dir, o.threads, &cached, log, frames, o.run_progress);
      cr["length_m"] = r.length;
      r.record["grid_value"] = grids[g];
      runs_j.push_back(r.record);
      runs.push_back(std::move(r));
    }
    cr["runs3d"] = runs_j;

    // 2. the extrapolated reference over the grids that completed a cycle
    std::vector<double> hs, fd, fT, hm, fm;
    for (const auto& r : runs)
      if (r.cyc.has_cycle) {
        hs.push_back(r.h);
        fd.push_back(r.cyc.displacement_per_cycle_m);
        fT.push_back(r.cyc.cycle_time_s);
        if (std::isfinite(r.max_displacement)) {
          hm.push_back(r.h);
          fm.push_back(r.max_displacement);
        }
      }
    const bool paper_max = cs.contains("paper") && cs["paper"].is_object() &&
                           cs["paper"].contains("max_displacement_m") && cs["paper"]["max_displacement_m"].is_number();
    Extrapolation em;
    const bool have_max = paper_max && hm.size() >= 2;
    json ref = json::object();
    Extrapolation ed, eT, ev;
    const bool have_ref = hs.size() >= 2;
    // the observed orders the 3D scheme can show: the case's, else the suite's, else the
    // immersed boundary's
    const OrderRange orders = cs.contains("order_range")      ? parse_order_range(cs["order_range"], "order_range")
                              : suite.contains("order_range") ? parse_order_range(suite["order_range"], "order_range")
                                                              : kImmersedBoundaryOrders;
    if (have_ref) {
      // two grids: first order, or the range's nearest end when first order lies outside it
      const double assumed = std::clamp(1.0, orders.lo, orders.hi);
      ed = richardson(hs, fd, assumed, orders);
      eT = richardson(hs, fT, assumed, orders);
      // the mean velocity of the reference is its displacement over its cycle time; the
      // relative errors add (bounds, as everywhere in the verdicts: verdicts.hpp)
      ev.value = ed.value / eT.value;
      ev.error = std::abs(ev.value) * (std::abs(ed.error / ed.value) + std::abs(eT.error / eT.value));
      ev.asymptotic = ed.asymptotic && eT.asymptotic;
      ev.note = "extrapolated displacement per cycle / extrapolated cycle time (relative errors added)";
      ref = {{"grids_used", hs.size()},
             {"order_range", {orders.lo, orders.hi}},
             {"displacement_per_cycle_m", extrapolation_json(ed)},
             {"cycle_time_s", extrapolation_json(eT)},
             {"mean_velocity_per_cycle_m_per_s", extrapolation_json(ev)}};
      // the largest centre displacement over the run, where the paper gives it
      if (have_max) {
        em = richardson(hm, fm, assumed, orders);
        ref["max_displacement_m"] = extrapolation_json(em);
      }
    } else {
      ref = {{"grids_used", hs.size()}, {"note", "fewer than two grids completed a cycle: no extrapolated reference"}};
    }
    cr["reference3d"] = ref;

    // 2b. the converged reference: the case's scene on the axi tier at each reference grid,
    // extrapolated with the reference's order range
    if (cs.contains("reference")) {
      const json& rs = cs["reference"];
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
        rh.push_back(axi::read_scene_axi(reference_scene(base, rs, g), resolved).h);
      }
      for (std::size_t g = 0; g < rgrids.size(); ++g) {
        const json s = reference_scene(base, rs, rgrids[g]);
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
        say(tag + ": axi reference grid " + std::to_string(g + 1) + "/" + std::to_string(rgrids.size()) + " (" + rkey +
            " = " + rgrids[g].dump() + ", " + method + ", h = " + std::to_string(p.h * 1e9).substr(0, 5) + " nm" + left +
            ")");
        bool cached = false;
        RunAxi r = run_axi_cached(s, runs_dir, o.run_progress, &cached, log);
        done_wall += cached ? 0.0 : r.wall;
        r.record["grid_value"] = rgrids[g];
        axi_runs.push_back(r.record);
        aruns.push_back(std::move(r));
      }
      cr["reference"] = axi_reference(aruns, rorders, paper_max, target);
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
    }

    // 3. calibration at the chosen grid
    const std::size_t cg = std::size_t(cs.value("calibration_grid", long(grids.size()) - 1));
    json cal_j;
    const std::string cal_file = calibration_at(base, grid_key, grids[cg], name, o.threads, cal_dir, log, cal_j,
                                                [&] { say(tag + ": calibration at grid " + std::to_string(cg + 1)); });
    cr["calibration"] = {{"grid_index", cg}, {"grid_value", grids[cg]}, {"file", cal_file}};
    for (const char* k : {"C1_Pa_per_m", "C1_stderr_Pa_per_m", "C1_spring_network_Pa_per_m", "hydraulic_offset_inner_m",
                          "hydraulic_offset_inner_uncertainty_m", "hydraulic_offset_outer_m",
                          "hydraulic_offset_outer_uncertainty_m", "hydraulic_offset_outer_from_drag_m",
                          "hydraulic_offset_outer_from_drag_uncertainty_m", "towed_drag_coefficient_N_s_per_m", "status",
                          "wall_time_s"})
      if (cal_j.contains(k)) cr["calibration"][k] = cal_j[k];

    // 4. every 1D model
    const Run3d& finest = runs.back();
    const Run3d& at_cal = runs[cg];
    json models_j = json::array();
    for (const json& m : suite["models1d"]) {
      const std::string label = m["label"];
      const bool calibrated = m.value("calibrated", false);
      json entry;
      Run1d r;
      if (calibrated && cal_file.empty()) {
        r.record = {{"label", label}, {"status", "not run: the calibration failed"}};
      } else {
        say(tag + ": 1D " + label);
        r = run_1d(model_scene(base, m, calibrated ? fs::absolute(cal_file).string() : ""), label, scene_dir);
      }
      entry = r.record;
      entry["calibrated"] = calibrated;
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
        if (finest.cyc.has_cycle && r.series.t.size() > 1 && finest.series.t.size() > 1) {
          const SeriesComparison ph = compare_series(r.series.t, r.series.u, r.cyc.cycle_time_s, finest.series.t,
                                                     finest.series.u, finest.cyc.cycle_time_s, true);
          const SeriesComparison ab = compare_series(r.series.t, r.series.u, r.cyc.cycle_time_s, finest.series.t,
                                                     finest.series.u, finest.cyc.cycle_time_s, false);
          entry["velocity_vs_finest3d"] = {{"phase_l2_relative", ph.l2_relative},
                                          {"phase_correlation", ph.correlation},
                                          {"time_l2_relative", ab.l2_relative},
                                          {"time_correlation", ab.correlation}};
          // the uncertainty of the correlation: its spread against the (up to) three finest
          // grids that completed a cycle, as the spread of a reference that is not asymptotic
          std::vector<double> corr;
          for (auto it = runs.rbegin(); it != runs.rend() && corr.size() < 3; ++it)
            if (it->cyc.has_cycle && it->series.t.size() > 1)
              corr.push_back(compare_series(r.series.t, r.series.u, r.cyc.cycle_time_s, it->series.t, it->series.u,
                                            it->cyc.cycle_time_s, true)
                                 .correlation);
          if (corr.size() >= 2) {
            const double spread = *std::max_element(corr.begin(), corr.end()) - *std::min_element(corr.begin(), corr.end());
            entry["velocity_vs_finest3d"]["phase_correlation_grid_spread"] = spread;
            entry["velocity_vs_finest3d"]["phase_correlation_grids"] = corr.size();
          }
        }
        // pass, fail or inconclusive against the reference's error bar (verdicts.hpp)
        if (const json v = model_verdicts(entry, th); !v.empty()) entry["verdicts"] = v;
        if (at_cal.record.value("pumped_volume_m3", 0.0) != 0.0)
          entry["pumped_volume_relative_vs_calibration_grid"] =
              relative(r.record.value("pumped_volume_m3", 0.0), at_cal.record["pumped_volume_m3"].get<double>());
      }
      models_j.push_back(entry);
    }
    cr["models1d"] = models_j;

    // 5. speed/accuracy: the first 1D model over cell counts and integrator tolerances, 3D
    // over the grids and the case's time-step variants (at the calibration grid)
    json trade = json::array();
    // the error of each point against the case's judged reference (the axisymmetric one when
    // the case has it)
    const json& jref = judged_reference(cr);
    const bool have_jref = jref.contains("displacement_per_cycle_m") && jref["displacement_per_cycle_m"].is_object() &&
                           jref["displacement_per_cycle_m"]["value"].is_number() &&
                           std::abs(jref["displacement_per_cycle_m"]["value"].get<double>()) > 0;
    const double d_ref = have_jref ? jref["displacement_per_cycle_m"]["value"].get<double>() : 0.0;
    if (have_jref) {
      const json& m0 = suite["models1d"][0];
      auto point = [&](const char* tier, const std::string& axis, const std::string& resolution, double wall,
                       double d) {
        trade.push_back({{"tier", tier},
                         {"axis", axis},
                         {"resolution", resolution},
                         {"wall_time_s", wall},
                         {"displacement_per_cycle_error", std::abs(d - d_ref) / std::abs(d_ref)}});
      };
      auto model0 = [&](const std::string& key, const json& value) -> std::optional<Run1d> {
        const bool calibrated = m0.value("calibrated", false);
        if (calibrated && cal_file.empty()) return std::nullopt;
        json s = model_scene(base, m0, calibrated ? fs::absolute(cal_file).string() : "");
        set_key(s, key, value);
        return run_1d(s, m0["label"], scene_dir);
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
          point("3d", "h", "h = " + std::to_string(r.h * 1e9).substr(0, 5) + " nm", r.wall,
                r.cyc.displacement_per_cycle_m);
      const json& variants = cs.contains("time_variants3d") ? cs["time_variants3d"] : json::array();
      for (std::size_t v = 0; v < variants.size(); ++v) {
        json s = base;
        set_key(s, grid_key, grids[cg]);
        apply_sets(s, variants[v].value("set", json()));
        const std::string label = variants[v].value("label", "variant " + std::to_string(v + 1));
        say(tag + ": 3D time-step variant " + std::to_string(v + 1) + "/" + std::to_string(variants.size()) + " (" +
            label + ")");
        bool cached = false;
        const Run3d r = run_3d(s, runs_dir, o.threads, &cached, log, 0, o.run_progress);
        if (r.cyc.has_cycle) point("3d", "time step", label, r.wall, r.cyc.displacement_per_cycle_m);
        else  // a step beyond the stability limit: the outcome is reported, not a point
          trade.push_back({{"tier", "3d"}, {"axis", "time step"}, {"resolution", label}, {"wall_time_s", r.wall},
                           {"status", r.record.value("status", std::string("unknown"))}});
      }
    }
    cr["speed_accuracy"] = trade;
    double w3 = 0, w1 = 0;
    for (const auto& r : runs) w3 += r.wall;
    for (const auto& m : models_j) w1 += m.value("wall_time_s", 0.0);
    cr["wall_time_3d_s"] = w3;
    cr["wall_time_1d_s"] = w1;
    if (at_cal.wall > 0 && !models_j.empty() && models_j[0].value("wall_time_s", 0.0) > 0)
      cr["wall_time_ratio_3d_over_1d"] = at_cal.wall / models_j[0]["wall_time_s"].get<double>();
    report["cases"].push_back(cr);
  }
  report["findings"] = findings(report["cases"], th);

  // 3D at the extremes: each case's outcome against the one the suite states for it
  json extremes = json::array();
  const json& ex = suite.contains("extremes3d") && o.only.empty() ? suite["extremes3d"] : json::array();
  for (std::size_t k = 0; k < ex.size(); ++k) {
    const json& e = ex[k];
    json s = scene::load_file(find_scene(e["scene"], suite_dir, o.data_dir));
    apply_sets(s, e.value("set", json()));
    const std::string label = e["label"];
    say("extremes " + std::to_string(k + 1) + "/" + std::to_string(ex.size()) + ": " + label);
    json entry = {{"label", label}, {"scene", e["scene"]}, {"set", e.value("set", json::object())},
                  {"expected", e["expect"]}, {"expected_cause", e.value("cause", std::string())}};
    std::string kind, text;
    try {
      bool cached = false;
      const Run3d r = run_3d(s, runs_dir, o.threads, &cached, log);
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
  report["extremes3d"] = extremes;
  // every folder and calibration the report read, verified again now that the report is complete
  json unverified = json::array();
  for (const std::string& d : log.folders)
    if (const std::string why = output::verify_folder(d, kCachedRunFiles); !why.empty())
      unverified.push_back({{"path", d}, {"reason", why}});
  for (const std::string& f : log.calibrations)
    if (const std::string why = calibration_problem(f); !why.empty()) unverified.push_back({{"path", f}, {"reason", why}});
  report["cache"] = {{"reused", log.reused},
                     {"rejected", log.rejected.size()},
                     {"rejections", log.rejected},
                     {"verified", unverified.empty()},
                     {"unverified", unverified}};
  report["wall_time_s"] = seconds_since(t_suite);
  return report;
}

}  // namespace swim::validation
