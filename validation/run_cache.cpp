#include "validation/run_cache.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "axi/run_axi.hpp"
#include "axi/scene_axi.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/progress.hpp"
#include "common/run_folder.hpp"
#include "common/strict_json.hpp"
#include "full3d/run3d.hpp"
#include "full3d/scene3d.hpp"
#include "validation/calibration.hpp"
#include "validation/compare.hpp"
#include "validation/hydraulic.hpp"
#include "validation/suite_file.hpp"

namespace fs = std::filesystem;

namespace swim::validation {

namespace {

/// Changes whenever calibration.json gains or renames keys, or a measurement in it changes
/// method (3: the held tube on the ring forces; 4: the axial stiffness C(k) and
/// axial_bending_rigidity_J): cached calibrations of an older format are
/// then recomputed instead of read.
constexpr int kCalibrationFormat = 5;

/// The files of a cached run the report reads (the series), and those that make it the run it
/// is (its resolved scene, its radius field): each must be listed in its summary.json.
const std::vector<std::string> kCachedRunFiles = {"series.csv", "radius.csv", "scene.resolved.json"};

/// A JSON file read back by the strict reader (a key given twice, a number out of range are
/// refused as in a scene); discarded (is_discarded()) when it is missing or refused.
json read_back(const fs::path& file, const std::string& what) {
  try {
    return strict_json::parse_file(file.string(), what);
  } catch (const InputError&) {
    return json(json::value_t::discarded);
  }
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

/// The part of a resolved scene that determines its results: without the output settings
/// (frames, intervals), the checkpoint intervals, the thread count and the fluid solver's memory
/// limit (how many factors it keeps, not what they solve).
json physics_of(json resolved) {
  if (resolved.contains("full3d") && resolved["full3d"].is_object()) {
    resolved["full3d"].erase("output");
    resolved["full3d"].erase("checkpoint_interval");
    resolved["full3d"].erase("threads");
    resolved["full3d"].erase("memory_limit_gib");
  }
  if (resolved.contains("axi") && resolved["axi"].is_object()) {
    resolved["axi"].erase("checkpoint_interval");
    resolved["axi"].erase("threads");
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
/// the scene would resolve to today. null when the reader no longer accepts it.
///
/// A wall written before full3d.membrane.bending_model existed: on the 3D tier, a fixed k_b
/// (no bending_rigidity) resolves as the "fixed_kb" it was; a k_b set from a stated
/// bending_rigidity came from the earlier radial-lobe measure of D (about twice the wall's D),
/// so that run is not today's. On the axisymmetric tier a stated bending_rigidity was used as
/// it is today (D itself); without one, D came from that measure, and the run is not today's
/// (docs/full3d.md, "The wall model").
json current_resolution(const json& written, bool axi_tier) {
  try {
    json w = written;
    json* mem = w.is_object() && w.contains("full3d") && w["full3d"].is_object() &&
                        w["full3d"].contains("membrane") && w["full3d"]["membrane"].is_object()
                    ? &w["full3d"]["membrane"]
                    : nullptr;
    const bool stated = mem && mem->contains("bending_rigidity");
    if (!mem || !mem->contains("bending_model")) {
      if (axi_tier && !stated) return nullptr;
      if (!axi_tier && stated) return nullptr;
      if (!axi_tier) w["full3d"]["membrane"]["bending_model"] = "fixed_kb";
    }
    json again;
    if (axi_tier) axi::read_scene_axi(w, again);
    else full3d::read_scene3d(w, again);
    return again;
  } catch (const std::exception&) {
    return nullptr;
  }
}

/// Why a calibration file cannot be used, "" when it can: it carries its own checksum and it
/// matches, it is a JSON object and its status is "ok".
std::string calibration_problem(const std::string& file) {
  const fs::path p(file);
  std::string why = output::verify_folder(p.parent_path().string(), {}, p.filename().string());
  if (!why.empty()) return why;
  const json c = read_back(file, "calibration.json");
  if (c.is_discarded() || !c.is_object()) return "calibration.json: not valid JSON";
  if (c.value("status", std::string()) != "ok")
    return "calibration.json: status " + scene::show(c.value("status", json("(none)")));
  return {};
}

/// A summary written while its run was going on ("running: last checkpoint at ...").
bool is_running(const json& summary) {
  const std::string st = summary.value("status", std::string());
  return st.rfind("running", 0) == 0;
}

/// A run that was stopped before its end and left a checkpoint to continue from.
bool interrupted_run(const std::string& dir) {
  const json s = read_back(fs::path(dir) / "summary.json", "summary.json");
  return !s.is_discarded() && is_running(s) && fs::exists(full3d::checkpoint_path(dir));
}

/// The report entry both tiers' runs share: the cell size, the outcome, where the run is, its
/// cost, and its per-cycle figures when it completed a cycle.
json run_entry(double h, const std::string& status, bool cached, const std::string& dir, double wall,
               const json& summary, const record::CycleFigures& cyc) {
  json j = {{"cell_size_m", h},
            {"status", status},
            {"cached", cached},
            {"folder", dir},
            {"wall_time_s", wall},
            {"steps", summary.value("steps", 0L)},
            {"cycles_completed", summary.value("cycles_completed", 0)},
            {"has_cycle", cyc.has_cycle}};
  if (cyc.has_cycle) {
    j["displacement_per_cycle_m"] = cyc.displacement_per_cycle_m;
    j["cycle_time_s"] = cyc.cycle_time_s;
    j["mean_velocity_per_cycle_m_per_s"] = cyc.mean_velocity_per_cycle_m_per_s;
    // the protocol's phases (each segment's contraction, then the recovery): what each took and
    // what the centre moved over it
    if (!cyc.phase_times_s.empty()) j["cycle_phase_times_s"] = cyc.phase_times_s;
    if (!cyc.phase_displacements_m.empty()) j["cycle_phase_displacements_m"] = cyc.phase_displacements_m;
  }
  return j;
}

}  // namespace

// ---- series ----------------------------------------------------------------------------

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

json downsample(const Series& s, double t_end, int n) {
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

// ---- keys --------------------------------------------------------------------------------

std::string run_key_3d(const json& resolved) { return output::json_hash(same_swimmer(resolved)); }

std::string run_key_axi(const json& resolved) { return output::json_hash({"axi", same_swimmer(resolved)}); }

std::string FolderKeys::of(const fs::path& file, const char* member, bool axi_tier) {
  std::error_code ec;
  const auto mtime = fs::last_write_time(file, ec);
  if (ec) return {};
  std::string id = file.string();
  if (member) id.append("#").append(member);
  if (axi_tier) id.append("#axi");
  if (auto it = keys_.find(id); it != keys_.end() && it->second.first == mtime) return it->second.second;
  const json j = read_back(file, file.filename().string());
  std::string key;
  if (!j.is_discarded() && (!member || j.contains(member))) {
    const json again = current_resolution(member ? j[member] : j, axi_tier);
    if (!again.is_null()) key = axi_tier ? run_key_axi(again) : run_key_3d(again);
  }
  keys_[id] = {mtime, key};
  return key;
}

// ---- the cache ---------------------------------------------------------------------------

RunCache::RunCache(std::string runs_dir, std::string cal_dir, int threads, FolderKeys& keys)
    : runs_dir_(std::move(runs_dir)), cal_dir_(std::move(cal_dir)), threads_(threads), keys_(keys) {}

void RunCache::reject(const std::string& path, const std::string& reason) {
  rejected_.push_back({{"path", path}, {"reason", reason}});
}

bool RunCache::resumes(const std::string& dir, const std::function<void()>& check) {
  if (!interrupted_run(dir)) return false;
  try {
    check();
    return true;
  } catch (const InputError& e) {
    reject(dir, std::string("interrupted run not resumed: ") + e.what());
    return false;
  }
}

/// A finished run (summary status not "running") in `dir` whose files pass their checks
/// (output::verify_folder: summary.json's own checksum, every listed file's size and checksum,
/// kCachedRunFiles listed), or null. A finished run that fails them is recorded as rejected,
/// with the reason, and is not used: the caller recomputes it.
json RunCache::finished_summary(const std::string& dir) {
  const fs::path file = fs::path(dir) / "summary.json";
  if (!fs::exists(file)) return nullptr;
  {
    const json s = read_back(file, "summary.json");
    if (!s.is_discarded() && is_running(s)) return nullptr;  // an interrupted run: resumed when its checkpoint passes
  }
  if (const std::string why = output::verify_folder(dir, kCachedRunFiles); !why.empty()) {
    reject(dir, why);
    return nullptr;
  }
  json s = read_back(file, "summary.json");
  if (s.is_discarded() || !s.contains("status") || !s["status"].is_string()) {
    reject(dir, "summary.json: no status");
    return nullptr;
  }
  return s;
}

json RunCache::find_finished(std::string& dir, const std::string& key, bool axi_tier) {
  json summary = finished_summary(dir);
  // an axi run's own scene must still resolve to this physics (a 3D run's folder name says it)
  if (axi_tier && !summary.is_null() && keys_.of(fs::path(dir) / "scene.resolved.json", nullptr, true) != key)
    summary = nullptr;
  if (!summary.is_null()) return summary;
  for (const auto& e : fs::directory_iterator(runs_dir_)) {
    if (e.path() == fs::path(dir) || keys_.of(e.path() / "scene.resolved.json", nullptr, axi_tier) != key) continue;
    summary = finished_summary(e.path().string());
    // an axi run of the same scene resolves to the same 3D physics: only a run of this tier is
    // one (folders written before the summary named its tier are 3D runs)
    if (!summary.is_null() && summary.value("tier", std::string(axi_tier ? "" : "3d")) != (axi_tier ? "axi" : "3d"))
      summary = nullptr;
    if (!summary.is_null()) {
      dir = e.path().string();
      return summary;
    }
  }
  return nullptr;
}

/// A calibration file under the calibrations folder written in the current format for a scene
/// whose physics, resolved by the current reader, is `physics` (same_swimmer); empty when
/// there is none. A folder's name carries the hash of the physics it was written for and of
/// its format version, which tells an older format apart.
std::string RunCache::cached_calibration(const json& physics) {
  const std::string wanted = output::json_hash(physics);
  if (!fs::is_directory(cal_dir_)) return {};
  for (const auto& e : fs::directory_iterator(cal_dir_)) {
    const fs::path file = e.path() / "calibration.json";
    if (!fs::exists(file)) continue;
    if (const std::string why = calibration_problem(file.string()); !why.empty()) {
      reject(file.string(), why);
      continue;
    }
    const json c = read_back(file, "calibration.json");
    if (c.is_discarded() || !c.contains("scene")) continue;
    const std::string folder = e.path().filename().string();
    const std::string written_for = output::json_hash({physics_of(c["scene"]), kCalibrationFormat});
    if (folder.size() < written_for.size() ||
        folder.compare(folder.size() - written_for.size(), written_for.size(), written_for) != 0)
      continue;
    if (keys_.of(file, "scene") == wanted) return file.string();
  }
  return {};
}

Run3d RunCache::run_3d(const json& sc, double frame_interval, int progress) {
  json s = sc;
  set_key(s, "full3d.threads", threads_);
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
  const std::string key = run_key_3d(resolved);
  std::string dir = runs_dir_ + "/" + p.name + "-3d-" + key;
  Run3d r;
  r.h = p.h;
  r.length = p.L;
  json summary = find_finished(dir, key, false);
  r.cached = !summary.is_null();
  // a run of this physics stopped part way (the suite was interrupted) continues from its
  // checkpoint when the checkpoint matches the scene
  const bool resume = !r.cached && resumes(dir, [&] { full3d::check_resumable(p, resolved, dir); });
  if (!r.cached && !resume) {
    fs::remove_all(dir);
    output::reset_ledger(dir);  // the folder's files are this run's alone
    fs::create_directories(dir);
  }
  if (!r.cached) {
    full3d::RunControl ctl;
    ctl.progress = progress;
    ctl.quiet_vtk = frame_interval <= 0;
    ctl.keep_rows = true;
    ctl.resume = resume;
    summary = full3d::run3d(p, resolved, dir, ctl).summary;
  } else {
    ++reused_;
  }
  // a fresh run's record is read back from the folder, as a cached run's is: the report is the
  // same whether this process, another (an MPI rank) or an earlier invocation made the run
  const record::RunRecord rec = record::read_run(dir);
  folders_.push_back(dir);
  const std::string status = summary.value("status", std::string("unknown"));
  r.ok = status == "ok";
  r.wall = summary.value("wall_time_s", 0.0);
  r.series = series_of(rec);
  r.cyc = cycle_figures_of(rec, summary);
  r.record = run_entry(p.h, status, r.cached, dir, r.wall, summary, r.cyc);
  r.record["grid"] = {p.nx, p.ny, p.nz};
  r.record["membrane_frames"] = fs::exists(fs::path(dir) / "membrane.pvd");
  r.record["pumped_volume_m3"] = summary.value("pumped_volume_m3", 0.0);
  // the wall's largest departure from axisymmetry (runs written before the wrinkle measure
  // existed have none)
  for (const char* k : {"max_wrinkle_m", "max_wrinkle_over_h", "max_wrinkle_mode"})
    if (summary.contains(k) && summary[k].is_number()) r.record[k] = summary[k];
  // the lobe numbers the wall showed above half a cell, in order (two or more: they changed)
  if (summary.contains("wrinkle_modes_over_half_cell") && summary["wrinkle_modes_over_half_cell"].is_array())
    r.record["wrinkle_modes_over_half_cell"] = summary["wrinkle_modes_over_half_cell"];
  // the lobes seeded in the wall's stress-free shape, and the secondary seed's (0: none)
  if (summary.contains("derived") && summary["derived"].is_object())
    for (const char* k : {"seed_mode", "secondary_seed_mode"})
      if (summary["derived"].contains(k) && summary["derived"][k].is_number()) r.record[k] = summary["derived"][k];
  if (summary.contains("max_displacement_m") && summary["max_displacement_m"].is_number()) {
    r.max_displacement = summary["max_displacement_m"].get<double>();
    r.record["max_displacement_m"] = r.max_displacement;
  }
  // the first cycle of a one-cycle scene; the whole run of a multi-cycle one (Figure 14)
  const double t_end = r.series.t.empty() ? 0.0 : r.series.t.back();
  r.record["series"] = downsample(r.series, r.cyc.has_cycle && p.protocol.cycles == 1 ? r.cyc.cycle_time_s : t_end);
  return r;
}

RunAxi RunCache::run_axi(const json& scene, int progress) {
  // the cache's threads, as the 3D runs' (the second factors the systems; 1 in an MPI rank)
  json sc = scene;
  set_key(sc, "axi.threads", std::min(threads_, 2));
  json resolved;
  const axi::ParamsAxi p = axi::read_scene_axi(sc, resolved);
  const std::string key = run_key_axi(resolved);
  std::string dir = runs_dir_ + "/" + p.name() + "-axi-" + key;
  json summary = find_finished(dir, key, true);
  RunAxi r;
  r.cached = !summary.is_null();
  // an interrupted run of this physics continues from its checkpoint (as run_3d's)
  const bool resume = !r.cached && resumes(dir, [&] { axi::check_resumable_axi(p, resolved, dir); });
  if (!r.cached) {
    if (!resume) {
      fs::remove_all(dir);
      output::reset_ledger(dir);
      fs::create_directories(dir);
    }
    axi::RunControlAxi ctl;
    ctl.progress = progress;
    ctl.keep_rows = true;
    ctl.resume = resume;
    summary = axi::run_axi(p, resolved, dir, ctl).summary;
  } else {
    ++reused_;
  }
  const record::RunRecord rec = record::read_run(dir);  // as a cached run's (run_3d)
  folders_.push_back(dir);
  r.h = p.h;
  const std::string status = summary.value("status", std::string("unknown"));
  r.ok = status == "ok";
  r.wall = summary.value("wall_time_s", 0.0);
  r.series = series_of(rec);
  r.cyc = cycle_figures_of(rec, summary);
  if (summary.contains("max_displacement_m") && summary["max_displacement_m"].is_number())
    r.max_displacement = summary["max_displacement_m"].get<double>();
  r.record = run_entry(p.h, status, r.cached, dir, r.wall, summary, r.cyc);
  r.record["grid"] = {p.nr, p.nx};
  r.record["method"] = p.method_name();
  if (std::isfinite(r.max_displacement)) r.record["max_displacement_m"] = r.max_displacement;
  if (!r.cyc.has_cycle) r.record["no_cycle_reason"] = r.cyc.absent_because;
  // as run_3d's: the first cycle of a one-cycle scene, the whole run of a multi-cycle one (the
  // reference of the report's U(t) comparisons, drawn beside 3D's)
  const double t_end = r.series.t.empty() ? 0.0 : r.series.t.back();
  r.record["series"] = downsample(r.series, r.cyc.has_cycle && p.base.protocol.cycles == 1 ? r.cyc.cycle_time_s : t_end);
  return r;
}

std::string RunCache::calibration(const json& base, const std::string& grid_key, const json& grid,
                                  const std::string& name, json& cal_j, const std::function<void()>& starting,
                                  int progress) {
  json s = base;
  set_key(s, grid_key, grid);
  set_key(s, "full3d.threads", threads_);  // as the 3D runs; not part of the key
  json resolved;
  const full3d::Params3d p = full3d::read_scene3d(s, resolved);
  // keyed by the physics of the resolved scene and the calibration file's format version
  const std::string dir = cal_dir_ + "/" + name + "-" + output::json_hash({physics_of(resolved), kCalibrationFormat});
  std::string cal_file = dir + "/calibration.json";
  if (fs::exists(cal_file)) {
    // a damaged calibration is recomputed, never read
    if (const std::string why = calibration_problem(cal_file); !why.empty()) {
      reject(cal_file, why);
      fs::remove(cal_file);
    }
  }
  if (!fs::exists(cal_file)) {
    const std::string found = cached_calibration(same_swimmer(resolved));
    if (!found.empty()) cal_file = found;
  }
  if (fs::exists(cal_file)) {
    cal_j = strict_json::parse_file(cal_file, "calibration.json");
    ++reused_;
    calibrations_.push_back(cal_file);
    return cal_file;
  }
  if (starting) starting();
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<double> loads = default_loads(p);
    const std::size_t steps = loads.size() + 2;  // the loads, the hydraulic radii, the towed tube
    Progress bar("calibration " + p.name, double(steps), progress);
    const StaticCalibration c = calibrate_static(p, loads, [&](std::size_t done) {
      bar.step(done, steps, "load " + std::to_string(done) + "/" + std::to_string(loads.size()));
    });
    cal_j = to_json(c, p, resolved);
    cal_j.update(try_measure_axial_stiffness(p).entries());  // the wall's stiffness along the axis, as swim calibrate
    const HydraulicRadii hr = measure_hydraulic_radii(p);
    bar.step(loads.size() + 1, steps, "hydraulic radii");
    json hj = to_json(hr);
    hj["hydraulic_wall_time_s"] = hj["wall_time_s"];
    hj.erase("wall_time_s");
    cal_j.update(hj);
    cal_j.update(calibrate_towed(p, hr).json);
    bar.step(steps, steps, "towed tube");
    bar.done();
    cal_j["wall_time_s"] = seconds_since(t0);
    cal_j["status"] = "ok";
    fs::create_directories(dir);
    output::write_json(cal_file, cal_j);
    calibrations_.push_back(cal_file);
  } catch (const NumericalError& e) {
    cal_j = {{"status", std::string("failed: ") + e.what()}};
    cal_file.clear();
  }
  return cal_file;
}

json RunCache::report() const {
  json unverified = json::array();
  for (const std::string& d : folders_)
    if (const std::string why = output::verify_folder(d, kCachedRunFiles); !why.empty())
      unverified.push_back({{"path", d}, {"reason", why}});
  for (const std::string& f : calibrations_)
    if (const std::string why = calibration_problem(f); !why.empty()) unverified.push_back({{"path", f}, {"reason", why}});
  return {{"reused", reused_},
          {"rejected", rejected_.size()},
          {"rejections", rejected_},
          {"verified", unverified.empty()},
          {"unverified", unverified}};
}

}  // namespace swim::validation
