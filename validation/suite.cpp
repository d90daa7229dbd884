#include "validation/suite.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/run_record.hpp"
#include "common/run_folder.hpp"
#include "common/units.hpp"
#include "full3d/run3d.hpp"
#include "full3d/scene3d.hpp"
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

/// A run folder's scene.resolved.json resolved again by the current scene reader: keys the
/// reader gained since the run was written appear with their defaults, so a run stays found
/// as long as its physics is what the scene would resolve to today. null when the reader
/// no longer accepts it.
json current_resolution(const json& written) {
  try {
    json again;
    full3d::read_scene3d(written, again);
    return again;
  } catch (const std::exception&) {
    return nullptr;
  }
}

/// json_hash(same_swimmer(current_resolution(...))) of a run folder's scene.resolved.json or
/// of a calibration file's "scene" (member), "" when unreadable. Resolving a scene again costs
/// tens of ms and every cache lookup scans every folder, so the key is kept per file and its
/// modification time for the life of the process.
std::string swimmer_key(const fs::path& file, const char* member) {
  static std::map<std::string, std::pair<fs::file_time_type, std::string>> memo;
  std::error_code ec;
  const auto mtime = fs::last_write_time(file, ec);
  if (ec) return {};
  std::string id = file.string();
  if (member) id.append("#").append(member);
  if (auto it = memo.find(id); it != memo.end() && it->second.first == mtime) return it->second.second;
  std::ifstream in(file);
  json j = json::parse(in, nullptr, false);
  std::string key;
  if (!j.is_discarded() && (!member || j.contains(member)))
    key = output::json_hash(same_swimmer(current_resolution(member ? j[member] : j)));
  memo[id] = {mtime, key};
  return key;
}

/// A calibration file under `cal_dir` written in the current format for a scene whose physics,
/// resolved by the current reader, is `physics` (same_swimmer); empty when there is none. A
/// folder's name carries the hash of the physics it was written for and of its format
/// version, which tells an older format apart.
std::string cached_calibration(const std::string& cal_dir, const json& physics) {
  const std::string wanted = output::json_hash(physics);
  if (!fs::is_directory(cal_dir)) return {};
  for (const auto& e : fs::directory_iterator(cal_dir)) {
    const fs::path file = e.path() / "calibration.json";
    std::ifstream in(file);
    if (!in) continue;
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

/// A finished run (summary status not "running") in `dir`, or null.
json finished_summary(const std::string& dir) {
  std::ifstream in(dir + "/summary.json");
  if (!in) return nullptr;
  json s = json::parse(in, nullptr, false);
  if (s.is_discarded() || !s.contains("status") || !s["status"].is_string() || is_running(s)) return nullptr;
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
Run3d run_3d(const json& sc, const std::string& runs_dir, int threads, bool* cached, double frame_interval = 0) {
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
  json summary = finished_summary(dir);
  if (summary.is_null())
    for (const auto& e : fs::directory_iterator(runs_dir)) {
      if (swimmer_key(e.path() / "scene.resolved.json", nullptr) != key) continue;
      summary = finished_summary(e.path().string());
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
    } catch (const InputError&) {
    }
  }
  if (!*cached && !resume) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  // a fresh run's record comes from the tier; a cached one is read back from its folder
  record::RunRecord rec;
  if (!*cached) {
    full3d::RunControl ctl;
    ctl.progress = 0;
    ctl.quiet_vtk = frame_interval <= 0;
    ctl.keep_rows = true;
    ctl.resume = resume;
    full3d::RunOutcome out = full3d::run3d(p, resolved, dir, ctl);
    summary = out.summary;
    // a resumed run holds only this process's rows in memory: the whole run is in its folder
    rec = resume ? record::read_run(dir) : std::move(out.record);
  } else {
    rec = record::read_run(dir);
  }
  const std::string status = summary.value("status", std::string("unknown"));
  r.ok = status == "ok";
  r.wall = summary.value("wall_time_s", 0.0);
  r.series = series_of(rec);
  r.cyc = record::cycle_figures(rec);
  // the run's own per-cycle figures, computed at full precision from the rows in memory (a
  // cached run's series.csv carries 10 digits): a fresh and a cached run report the same
  if (summary.contains("displacement_per_cycle_m") && summary["displacement_per_cycle_m"].is_number() &&
      summary.contains("cycle_time_s") && summary["cycle_time_s"].is_number()) {
    r.cyc.displacement_per_cycle_m = summary["displacement_per_cycle_m"].get<double>();
    r.cyc.cycle_time_s = summary["cycle_time_s"].get<double>();
    r.cyc.mean_velocity_per_cycle_m_per_s = summary["mean_velocity_per_cycle_m_per_s"].get<double>();
  }
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

}  // namespace

json load_suite(const std::string& path) {
  const json s = scene::load_file(path);
  if (!s.is_object()) throw InputError("suite", path, "a JSON object with \"cases\" and \"models1d\"");
  const json& cases = member(s, "cases", "suite");
  if (!cases.is_array() || cases.empty()) throw InputError("suite.cases", scene::show(cases), "a non-empty array");
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string at = "suite.cases[" + std::to_string(i) + "]";
    member(cases[i], "scene", at);
    const json& g = member(cases[i], "grids", at);
    if (!g.is_array() || g.size() < 2) throw InputError(at + ".grids", scene::show(g), "two or more grid values");
    if (cases[i].contains("calibration_grid")) {
      const json& c = cases[i]["calibration_grid"];
      if (!c.is_number_integer() || c.get<long>() < 0 || c.get<long>() >= long(g.size()))
        throw InputError(at + ".calibration_grid", scene::show(c),
                         "an index into grids, 0 to " + std::to_string(g.size() - 1));
    }
    if (cases[i].contains("order_range")) parse_order_range(cases[i]["order_range"], at + ".order_range");
    if (cases[i].contains("time_variants3d")) {
      const json& v = cases[i]["time_variants3d"];
      bool ok = v.is_array();
      for (const auto& e : ok ? v : json::array()) ok = ok && e.is_object() && e.contains("label") && e["label"].is_string() &&
                                                        e.contains("set") && e["set"].is_object();
      if (!ok)
        throw InputError(at + ".time_variants3d", scene::show(v),
                         "an array of {\"label\": text, \"set\": {\"dotted.key\": value}} (3D time-step variants)");
    }
  }
  if (s.contains("order_range")) parse_order_range(s["order_range"], "suite.order_range");
  if (s.contains("extremes3d")) {
    const json& ex = s["extremes3d"];
    bool ok = ex.is_array();
    for (const auto& e : ok ? ex : json::array())
      ok = ok && e.is_object() && e.contains("label") && e["label"].is_string() && e.contains("scene") &&
           e["scene"].is_string() && e.contains("expect") &&
           (e["expect"] == "ok" || e["expect"] == "failed" || e["expect"] == "rejected") &&
           (!e.contains("set") || e["set"].is_object()) && (!e.contains("cause") || e["cause"].is_string());
    if (!ok)
      throw InputError("suite.extremes3d", scene::show(ex),
                       "an array of {\"label\": text, \"scene\": file, \"set\": {...}, \"expect\": \"ok\" | "
                       "\"failed\" | \"rejected\", \"cause\": text in the message}");
  }
  const json& models = member(s, "models1d", "suite");
  if (!models.is_array() || models.empty()) throw InputError("suite.models1d", scene::show(models), "a non-empty array");
  for (std::size_t i = 0; i < models.size(); ++i) member(models[i], "label", "suite.models1d[" + std::to_string(i) + "]");
  const json& th = member(s, "thresholds", "suite");
  for (const char* k : {"displacement_per_cycle_relative", "cycle_time_relative", "mean_velocity_per_cycle_relative",
                        "velocity_phase_correlation"})
    if (!member(th, k, "suite.thresholds").is_number()) throw InputError(std::string("suite.thresholds.") + k, scene::show(th[k]), "a number");
  return s;
}

json run_suite(const SuiteOptions& o) {
  const json suite = load_suite(o.suite);
  const std::string suite_dir = fs::path(o.suite).parent_path().string();
  const json& th = suite["thresholds"];
  const std::string runs_dir = o.out_dir + "/runs", cal_dir = o.out_dir + "/calibrations";
  fs::create_directories(runs_dir);
  fs::create_directories(cal_dir);
  auto say = [&](const std::string& s) {
    if (o.progress) o.progress(s);
  };
  const auto t_suite = std::chrono::steady_clock::now();

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
      Run3d r = run_3d(s, runs_dir, o.threads, &cached, frames);
      cr["length_m"] = r.length;
      r.record["grid_value"] = grids[g];
      runs_j.push_back(r.record);
      runs.push_back(std::move(r));
    }
    cr["runs3d"] = runs_j;

    // 2. the extrapolated reference over the grids that completed a cycle
    std::vector<double> hs, fd, fT;
    for (const auto& r : runs)
      if (r.cyc.has_cycle) {
        hs.push_back(r.h);
        fd.push_back(r.cyc.displacement_per_cycle_m);
        fT.push_back(r.cyc.cycle_time_s);
      }
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
      auto ej = [](const Extrapolation& e) {
        return json{{"value", e.value},
                    {"error", e.error},
                    {"order", e.order},
                    {"observed_order", std::isfinite(e.observed_order) ? json(e.observed_order) : json(nullptr)},
                    {"asymptotic", e.asymptotic},
                    {"note", e.note}};
      };
      ref = {{"grids_used", hs.size()},
             {"order_range", {orders.lo, orders.hi}},
             {"displacement_per_cycle_m", ej(ed)},
             {"cycle_time_s", ej(eT)},
             {"mean_velocity_per_cycle_m_per_s", ej(ev)}};
    } else {
      ref = {{"grids_used", hs.size()}, {"note", "fewer than two grids completed a cycle: no extrapolated reference"}};
    }
    cr["reference3d"] = ref;

    // 3. calibration at the chosen grid
    const std::size_t cg = std::size_t(cs.value("calibration_grid", long(grids.size()) - 1));
    json cal_j;
    std::string cal_file;
    {
      json s = base;
      set_key(s, grid_key, grids[cg]);
      set_key(s, "full3d.threads", o.threads);  // as the 3D runs; not part of the key
      json resolved;
      const full3d::Params3d p = full3d::read_scene3d(s, resolved);
      // keyed by the physics of the resolved scene and the calibration file's format version
      const std::string dir = cal_dir + "/" + name + "-" + output::json_hash({physics_of(resolved), kCalibrationFormat});
      cal_file = dir + "/calibration.json";
      if (!fs::exists(cal_file)) {
        const std::string found = cached_calibration(cal_dir, same_swimmer(resolved));
        if (!found.empty()) cal_file = found;
      }
      if (fs::exists(cal_file)) {
        std::ifstream in(cal_file);
        cal_j = json::parse(in);
      } else {
        say(tag + ": calibration at grid " + std::to_string(cg + 1));
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
          fs::create_directories(dir);
          output::write_json(cal_file, cal_j);
        } catch (const NumericalError& e) {
          cal_j = {{"status", std::string("failed: ") + e.what()}};
          cal_file.clear();
        }
      }
    }
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
      json s = base;
      apply_sets(s, m.value("set", json()));
      const bool calibrated = m.value("calibrated", false);
      json entry;
      Run1d r;
      if (calibrated && cal_file.empty()) {
        r.record = {{"label", label}, {"status", "not run: the calibration failed"}};
      } else {
        if (calibrated) {
          if (s.contains("wall")) {
            s["wall"].erase("spring_constant");
            s["wall"].erase("C1");
          }
          set_key(s, "wall.calibration", fs::absolute(cal_file).string());
        }
        say(tag + ": 1D " + label);
        r = run_1d(s, label, scene_dir);
      }
      entry = r.record;
      entry["calibrated"] = calibrated;
      if (r.cyc.has_cycle) {
        json vs_ref = json::object(), vs_cal = json::object();
        if (have_ref) {
          vs_ref["displacement_per_cycle"] = relative(r.cyc.displacement_per_cycle_m, ed.value);
          vs_ref["cycle_time"] = relative(r.cyc.cycle_time_s, eT.value);
          vs_ref["mean_velocity_per_cycle"] = relative(r.cyc.mean_velocity_per_cycle_m_per_s, ev.value);
        }
        if (at_cal.cyc.has_cycle) {
          vs_cal["displacement_per_cycle"] = relative(r.cyc.displacement_per_cycle_m, at_cal.cyc.displacement_per_cycle_m);
          vs_cal["cycle_time"] = relative(r.cyc.cycle_time_s, at_cal.cyc.cycle_time_s);
          vs_cal["mean_velocity_per_cycle"] =
              relative(r.cyc.mean_velocity_per_cycle_m_per_s, at_cal.cyc.mean_velocity_per_cycle_m_per_s);
        }
        entry["relative_error_vs_reference"] = vs_ref;
        // the reference's error relative to its value: the width of the verdicts' interval
        json ref_err = json::object();
        if (have_ref)
          for (const auto& [k, e] : {std::pair<const char*, const Extrapolation*>{"displacement_per_cycle", &ed},
                                     {"cycle_time", &eT},
                                     {"mean_velocity_per_cycle", &ev}})
            ref_err[k] = std::abs(e->value) > 0 && std::isfinite(e->error / e->value) ? json(std::abs(e->error / e->value))
                                                                                       : json(nullptr);
        entry["reference_error_relative"] = ref_err;
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
    if (have_ref) {
      const json& m0 = suite["models1d"][0];
      auto point = [&](const char* tier, const std::string& axis, const std::string& resolution, double wall,
                       double d) {
        trade.push_back({{"tier", tier},
                         {"axis", axis},
                         {"resolution", resolution},
                         {"wall_time_s", wall},
                         {"displacement_per_cycle_error", std::abs(d - ed.value) / std::abs(ed.value)}});
      };
      auto model0 = [&](const std::string& key, const json& value) -> std::optional<Run1d> {
        json s = base;
        apply_sets(s, m0.value("set", json()));
        if (m0.value("calibrated", false)) {
          if (cal_file.empty()) return std::nullopt;
          if (s.contains("wall")) s["wall"].erase("spring_constant");
          set_key(s, "wall.calibration", fs::absolute(cal_file).string());
        }
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
        const Run3d r = run_3d(s, runs_dir, o.threads, &cached);
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
      const Run3d r = run_3d(s, runs_dir, o.threads, &cached);
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
  report["wall_time_s"] = seconds_since(t_suite);
  return report;
}

}  // namespace swim::validation
