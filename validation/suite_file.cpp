#include "validation/suite_file.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>
#include <utility>

#include <unistd.h>

#include "axi/scene_axi.hpp"
#include "common/errors.hpp"
#include "full3d/scene3d.hpp"
#include "full3d/scene3d_keys.hpp"
#include "full3d/world3d.hpp"
#include "reduced1d/scene1d.hpp"
#include "validation/richardson.hpp"
#include "validation/verdicts.hpp"

namespace fs = std::filesystem;

namespace swim::validation {

namespace {

const json& member(const json& j, const std::string& key, const std::string& path) {
  if (!j.is_object() || !j.contains(key)) throw InputError(path + "." + key, "(missing)", "required by a suite file");
  return j.at(key);
}

/// A case's `reference` read strictly (InputError naming the key, the value and what is
/// allowed).
void check_reference(const json& ref, const std::string& at) {
  if (!ref.is_object())
    throw InputError(at, scene::show(ref),
                     "an object {\"tier\": \"axi\", \"grid_key\": \"axi.grid.cells_across\", \"grids\": [64, 128, 256], "
                     "\"order_range\": ..., \"set\": {...}}: the converged reference of the case");
  for (const auto& [k, v] : ref.items())
    if (k != "tier" && k != "grid_key" && k != "grids" && k != "order_range" && k != "set" && k != "tolerance_check" &&
        k != "spacing_check")
      throw InputError(at + "." + k, scene::show(v),
                       "not a key of a reference: tier, grid_key, grids, order_range, set, tolerance_check, spacing_check");
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
  // the checks' factors: one run each on the coarsest grid, a parameter times the factor
  for (const auto& [key, what] :
       {std::pair{"tolerance_check", "the factor on axi.tolerance of the run that measures the time integration's "
                                     "error on the coarsest grid (0.25: four times tighter)"},
        std::pair{"spacing_check", "the factor on axi.spacing_factor of the run that measures the wall's "
                                   "resolution error on the coarsest grid (0.5: twice the rings)"}})
    if (ref.contains(key)) {
      const json& f = ref[key];
      if (!f.is_number() || !(f.get<double>() > 0 && f.get<double>() < 1))
        throw InputError(at + "." + key, scene::show(f), std::string("a number between 0 and 1 (exclusive): ") + what);
    }
}

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
    full3d::check_fluid_memory(full3d::read_scene3d(s, resolved));
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
    // (the axial rigidity: the paper's wall, 1.0e-24 J, for a model that reads it)
    std::ofstream(path_) << json{{"C1_Pa_per_m", c1}, {"hydraulic_offset_inner_m", 0.0},
                                 {"hydraulic_offset_outer_m", 0.0}, {"axial_bending_rigidity_J", 1.009e-24},
                                 {"status", "ok"}}.dump();
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

// The four figures' limits of a verdict (the suite's thresholds, the 1D tier's targets), each
// required: three relative errors in (0, 10] and a correlation in (-1, 1].
void check_thresholds(const json& th, const std::string& at) {
  only_keys(th, at, "the limits of the verdicts",
            {"displacement_per_cycle_relative", "cycle_time_relative", "mean_velocity_per_cycle_relative",
             "velocity_phase_correlation"});
  for (const char* k : {"displacement_per_cycle_relative", "cycle_time_relative", "mean_velocity_per_cycle_relative"}) {
    const json& v = member(th, k, at);
    if (!v.is_number() || !(v.get<double>() > 0 && v.get<double>() <= 10))
      throw InputError(at + "." + k, scene::show(v), "a relative error above 0 and at most 10 (0.1: 10 %)");
  }
  const json& v = member(th, "velocity_phase_correlation", at);
  if (!v.is_number() || !(v.get<double>() > -1 && v.get<double>() <= 1))
    throw InputError(at + ".velocity_phase_correlation", scene::show(v), "a correlation above -1 and at most 1");
}

}  // namespace

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

bool case_selected_by(const json& cs, const std::string& name) {
  const std::string stem = fs::path(cs["scene"].get<std::string>()).stem().string();
  if (name == stem || name == stem + ".json") return true;
  const json* set = cs.contains("set") && cs["set"].is_object() ? &cs["set"] : nullptr;
  return set && set->contains("name") && (*set)["name"].is_string() && (*set)["name"].get<std::string>() == name;
}

std::vector<json> selected_cases(const json& suite, const std::vector<std::string>& only) {
  std::vector<json> cases;
  for (const json& cs : suite["cases"]) {
    bool take = only.empty();
    for (const auto& n : only) take = take || case_selected_by(cs, n);
    if (take) cases.push_back(cs);
  }
  return cases;
}

/// The scene of one reference grid: the case's scene (after its own set), the reference's
/// set, the grid.
json reference_scene(const json& base, const json& ref, const json& grid) {
  json s = base;
  apply_sets(s, ref.value("set", json()));
  set_key(s, ref.value("grid_key", std::string("axi.grid.cells_across")), grid);
  return s;
}

std::size_t coarsest_reference_grid(const json& base, const json& ref) {
  std::size_t best = 0;
  double h = 0;
  for (std::size_t g = 0; g < ref["grids"].size(); ++g) {
    json resolved;
    const double hg = axi::read_scene_axi(reference_scene(base, ref, ref["grids"][g]), resolved).h;
    if (hg > h) h = hg, best = g;
  }
  return best;
}

namespace {

/// The coarsest reference grid's scene with one axi parameter at the check's factor (the
/// reference's `key`) times the value that grid resolves to; null without the key.
json check_scene(const json& base, const json& ref, const char* key, const char* parameter,
                 double axi::ParamsAxi::*value) {
  if (!ref.contains(key)) return nullptr;
  json s = reference_scene(base, ref, ref["grids"][coarsest_reference_grid(base, ref)]);
  json resolved;
  const axi::ParamsAxi p = axi::read_scene_axi(s, resolved);
  set_key(s, parameter, ref[key].get<double>() * (p.*value));
  return s;
}

}  // namespace

json tolerance_check_scene(const json& base, const json& ref) {
  return check_scene(base, ref, "tolerance_check", "axi.tolerance", &axi::ParamsAxi::tolerance);
}

json spacing_check_scene(const json& base, const json& ref) {
  return check_scene(base, ref, "spacing_check", "axi.spacing_factor", &axi::ParamsAxi::spacing_factor);
}

std::string recovery_end_3d(const json& s) {
  if (s.contains("full3d") && s["full3d"].is_object() && s["full3d"].contains("recovery_end") &&
      s["full3d"]["recovery_end"].is_string())
    return s["full3d"]["recovery_end"].get<std::string>();
  return kRecoveryEndDefault3d;
}

json with_recovery_end_3d(json s) {
  const json wave = s.value("wave", json::object());
  const bool forced = !wave.is_object() || wave.value("kind", std::string("force_driven")) == "force_driven";
  const bool own = s.contains("model1d") && s["model1d"].is_object() && s["model1d"].contains("recovery_end");
  if (forced && !own) set_key(s, "model1d.recovery_end", recovery_end_3d(s));
  return s;
}

json model_scene(json s, const json& model, const std::string& cal) {
  apply_sets(s, model.value("set", json()));
  // A force-driven cycle ends by the reference's rule: the case's full3d.recovery_end, which the
  // 3D and axisymmetric runs read (the 3D tier's default when the case does not set it), unless
  // the model states its own.
  s = with_recovery_end_3d(std::move(s));
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
            {"name", "description", "order_range", "thresholds", "targets1d", "cells1d", "rtol1d", "cases",
             "models1d", "reference_target_relative", "extremes3d"});
  optional_text(s, "name", "suite");
  optional_text(s, "description", "suite");
  const json& cases = member(s, "cases", "suite");
  if (!cases.is_array() || cases.empty()) throw InputError("suite.cases", scene::show(cases), "a non-empty array");
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string at = "suite.cases[" + std::to_string(i) + "]";
    only_keys(cases[i], at, "a case",
              {"scene", "grid_key", "grids", "calibration_grid", "time_variants3d", "set", "paper", "group",
               "sweep_value", "order_range", "reference", "targets1d"});
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
    if (cases[i].contains("targets1d")) check_thresholds(cases[i]["targets1d"], at + ".targets1d");
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
  check_thresholds(member(s, "thresholds", "suite"), "suite.thresholds");
  if (s.contains("targets1d")) check_thresholds(s["targets1d"], "suite.targets1d");
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
    // the last grid (the finest in a suite's ascending series) read in full too: its fluid
    // grid against the memory limit before any run starts
    if (grids.size() > 1) {
      json sl = base;
      set_key(sl, grid_key, grids.back());
      check_3d(sl, at + ".grids[" + std::to_string(grids.size() - 1) + "]", grid_key + " = " + grids.back().dump());
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
    // the checks' scenes: the coarsest grid at its tighter step tolerance, and with its rings closer
    for (const auto& [key, what, scene_of] : {std::tuple{"tolerance_check", "time check", &tolerance_check_scene},
                                              std::tuple{"spacing_check", "wall check", &spacing_check_scene}})
      if (ref.contains(key)) {
        try {
          json resolved;
          axi::read_scene_axi(scene_of(base, ref), resolved);
        } catch (const InputError& e) {
          throw InputError(at + "." + key, scene::show(ref[key]),
                           std::string("a factor whose ") + what + " the axisymmetric tier runs; it refuses it: " + e.what());
        }
      }
  }
}

// ---- the suite's heavy runs as independent jobs (MPI: validation/suite.hpp) ---------------

}  // namespace swim::validation
