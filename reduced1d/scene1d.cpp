#include "reduced1d/scene1d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/scene_shared.hpp"
#include "common/units.hpp"
#include "reduced1d/outer_flow.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/recorded_wave.hpp"
#include "reduced1d/tube_law.hpp"

namespace swim::reduced1d {

using scene::json;
using scene::Range;
using scene::Reader;

namespace {
std::string fmt(double v, const char* unit) { return scene::format_quantity(v, unit); }
}  // namespace


namespace {
json load_calibration(const std::string& key, const std::string& path, const std::string& scene_dir) {
  namespace fs = std::filesystem;
  fs::path p(path);
  if (p.is_relative() && !fs::exists(p)) p = fs::path(scene_dir) / path;
  std::error_code ec;
  if (fs::exists(p, ec) && !fs::is_regular_file(p, ec))
    throw InputError(key, "\"" + path + "\"", "a calibration file (calibration.json written by swim calibrate); this is "
                                              "a directory or another kind of file");
  std::ifstream in(p, std::ios::binary);
  if (!in) throw InputError(key, "\"" + path + "\"", "calibration file not found (relative paths are tried from the "
                                                     "working directory, then from the scene's directory)");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  // a file that carries its own checksum (swim calibrate writes one) must still match it
  if (text.find("\"self_fnv1a64\"") != std::string::npos &&
      output::check_own_checksum(text) == output::OwnChecksum::Mismatch)
    throw InputError(key, "\"" + path + "\"", "the calibration file was changed after it was written (its own "
                                              "FNV-1a 64 checksum, self_fnv1a64, does not match); calibrate again");
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {  // syntax, and numbers beyond a double (out_of_range)
    throw InputError(key, "\"" + path + "\"", std::string("calibration file is not valid JSON: ") + e.what());
  }
  // a failed calibration may hold some of its figures; none of them is used
  if (j.is_object() && j.contains("status") && !(j["status"].is_string() && j["status"].get<std::string>() == "ok"))
    throw InputError(key, "\"" + path + "\"", "a calibration whose status is \"ok\"; this one's status is " +
                                              scene::show(j["status"]));
  return j;
}
}  // namespace

std::pair<double, double> hydraulic_offsets_from_calibration(const std::string& key, const std::string& path,
                                                             const std::string& scene_dir) {
  const json j = load_calibration(key, path, scene_dir);
  double v[2];
  const char* names[2] = {"hydraulic_offset_inner_m", "hydraulic_offset_outer_m"};
  for (int k = 0; k < 2; ++k) {
    if (!j.is_object() || !j.contains(names[k]) || !j[names[k]].is_number())
      throw InputError(key, "\"" + path + "\"", std::string("calibration file must hold a number \"") + names[k] + "\"");
    v[k] = j[names[k]].get<double>();
    if (!(v[k] >= 0) || !std::isfinite(v[k]))
      throw InputError(key, "\"" + path + "\"", std::string(names[k]) + " must be >= 0");
  }
  return {v[0], v[1]};
}

double axial_bending_from_calibration(const std::string& key, const std::string& path, const std::string& scene_dir) {
  const json j = load_calibration(key, path, scene_dir);
  if (!j.is_object() || !j.contains("axial_bending_rigidity_J") || !j["axial_bending_rigidity_J"].is_number())
    throw InputError(key, "\"" + path + "\"",
                     "calibration file must hold a number \"axial_bending_rigidity_J\" (written by swim calibrate: "
                     "the wall's stiffness under static loads along the axis) for model1d.axial_bending.source = "
                     "\"calibration\"");
  const double D = j["axial_bending_rigidity_J"].get<double>();
  if (!(D > 0) || !std::isfinite(D)) throw InputError(key, "\"" + path + "\"", "axial_bending_rigidity_J must be > 0");
  return D;
}

double c1_from_calibration(const std::string& key, const std::string& path, const std::string& scene_dir) {
  const json j = load_calibration(key, path, scene_dir);
  if (!j.is_object() || !j.contains("C1_Pa_per_m") || !j["C1_Pa_per_m"].is_number())
    throw InputError(key, "\"" + path + "\"", "calibration file must hold a number \"C1_Pa_per_m\"");
  const double c1 = j["C1_Pa_per_m"].get<double>();
  if (!(c1 > 0) || !std::isfinite(c1)) throw InputError(key, "\"" + path + "\"", "C1_Pa_per_m must be > 0");
  return c1;
}

std::shared_ptr<const TubeLaw> tube_law_from_calibration(const std::string& key, const std::string& path,
                                                         const std::string& scene_dir, const std::string& branch,
                                                         double R0) {
  const json j = load_calibration(key, path, scene_dir);
  const std::string where = "tube_law." + branch;
  auto bad = [&](const std::string& what) { return InputError(key, "\"" + path + "\"", what); };
  if (!j.is_object() || !j.contains("tube_law") || !j["tube_law"].is_object() || !j["tube_law"].contains(branch) ||
      !j["tube_law"][branch].is_object())
    throw bad("calibration file must hold the tube law \"" + where +
              "\" (written by swim calibrate --tube-law) for wall.law = \"calibrated_" + branch + "\"");
  const json& b = j["tube_law"][branch];
  auto numbers = [&](const std::string& name) {
    if (!b.contains(name) || !b[name].is_array())
      throw bad("calibration file must hold an array \"" + where + "." + name + "\"");
    std::vector<double> out;
    for (const auto& v : b[name]) {
      if (!v.is_number()) throw bad("\"" + where + "." + name + "\" must hold numbers only");
      out.push_back(v.get<double>());
    }
    return out;
  };
  std::vector<double> R = numbers("knots_radius_m"), w = numbers("knots_wall_pressure_Pa");
  if (!R.empty() && !(std::abs(R.back() / R0 - 1.0) <= 1e-9))
    throw bad("the tube law was calibrated for a tube of radius " + fmt(R.back(), "m") +
              "; this scene's swimmer.radius is " + fmt(R0, "m") + " (calibrate the scene's own tube)");
  if (!R.empty()) R.back() = R0;  // the undeformed knot is the scene's R0
  try {
    return std::make_shared<const TubeLaw>(R0, std::move(R), std::move(w));
  } catch (const InputError& e) {
    throw bad(std::string("the tube law \"") + where + "\" is not a valid monotone law: " + e.what());
  }
}

Params read_scene(const json& scene, json& resolved, const std::string& scene_dir) {
  Params p;
  resolved = json::object();
  Reader top(scene, "", resolved);
  // the 1D wall: its stiffness C1 from the network or the calibration file, and the file's tube law
  scene::SharedScene s = scene::SharedScene::read(top, [&](const scene::Body& body, const scene::WallSpec& w) {
    const double R0 = body.R0;
    if (w.stiffness == "C1")
      p.wall.C1 = w.value;
    else if (w.network())
      p.wall.C1 = scene::c1_from_spring_constant(w.value, R0);
    else
      p.wall.C1 = c1_from_calibration("wall.calibration", w.calibration, scene_dir);
    p.wall.m = w.mass_per_area;
    if (w.law != "linear") {
      if (w.stiffness != "calibration")
        throw InputError("wall.law", "\"" + w.law + "\"",
                         "a calibrated tube law is read from the calibration file: give wall.calibration (a "
                         "calibration.json written by swim calibrate --tube-law) instead of wall." + w.stiffness +
                         ", or use wall.law = \"linear\"");
      p.wall.law = tube_law_from_calibration("wall.calibration", w.calibration, scene_dir,
                                             w.law == "calibrated_round" ? "round" : "buckled", R0);
    }
  });
  p.name = s.name;
  p.geometry.R0 = s.body.R0;
  p.geometry.L = s.body.L;
  p.fluid.mu = s.body.mu;
  p.fluid.rho = s.body.rho;
  p.fluid.temperature = s.body.temperature;
  const double R0 = p.geometry.R0, L = p.geometry.L;
  {
    const scene::ContainerSpec& c = s.container;
    p.container.shape = c.kind == "cylinder" ? ContainerShape::Cylinder
                       : c.kind == "box"    ? ContainerShape::Box
                                            : ContainerShape::Duct;
    p.container.radius = c.radius;
    p.container.period = c.period;
    p.container.radius_eff = c.kind == "duct" ? outer::duct_equivalent_radius(c.radius) : c.radius;
  }
  const std::string& calibration = s.wall.calibration;

  double R_f = s.wave.R_f;
  {
    scene::WaveSpec& w = s.wave;
    p.wave = w.kind == "step"       ? WaveKind::Step
             : w.kind == "sine"     ? WaveKind::Sine
             : w.kind == "recorded" ? WaveKind::Recorded
                                    : WaveKind::ForceDriven;
    if (p.wave == WaveKind::Recorded) {
      // the record is read (and checked) with the scene, before anything is written; its span
      // is the period, its smallest radius stands for the contracted radius
      p.recorded = read_radius_file("wave.radius_file", w.radius_file, scene_dir, L);
      w.period = p.recorded->period();
      R_f = std::min(p.recorded->min_radius(), R0);
    } else if (p.wave == WaveKind::Step) {
      p.step.R_min = R_f;
      p.step.speed = w.speed;
      p.step.width = w.width;
    } else if (p.wave == WaveKind::Sine) {
      p.sine.amplitude = R0 - R_f;
      p.sine.speed = w.speed;
      p.sine.wavelength = w.wavelength;
    }
  }

  const bool forced = s.force_driven();
  s.read_protocol(top, p.wall.C1, forced && p.wall.law ? -(*p.wall.law)(R_f) : 0.0);
  if (forced) {
    p.protocol.R_f = R_f;
    s.protocol.assign_to(p.protocol);
  }

  {
    Reader m = top.child("model1d");
    p.swimmer.model = m.choice("model", "force_free", {"force_free", "paper"}) == "paper" ? SwimmerModel::Paper
                                                                                       : SwimmerModel::ForceFree;
    if (p.swimmer.model == SwimmerModel::ForceFree) {
      p.swimmer.outer = m.choice("outer_flow", "confined", {"confined", "unbounded"}) == "unbounded"
                            ? OuterFlow::Unbounded
                            : OuterFlow::Confined;
      Reader ho = m.child("hydraulic_offsets");
      if (ho.choice("source", "scene", {"scene", "calibration"}) == "calibration") {
        if (calibration.empty())
          throw InputError(ho.path("source"), "\"calibration\"",
                           "needs wall.calibration (the calibration file that holds the measured offsets)");
        const auto off = hydraulic_offsets_from_calibration("wall.calibration", calibration, scene_dir);
        p.swimmer.a_in = off.first;
        p.swimmer.a_out = off.second;
      } else {
        p.swimmer.a_in = ho.quantity("inner", "m", "0 m", Range::non_negative());
        p.swimmer.a_out = ho.quantity("outer", "m", "0 m", Range::non_negative());
      }
      ho.finish();
      if (!(p.swimmer.a_in < 0.5 * R_f))
        throw InputError("model1d.hydraulic_offsets.inner", fmt(p.swimmer.a_in, "m"),
                         "must be below half the contracted radius (" + fmt(0.5 * R_f, "m") +
                             ") so that the lumen stays open");
      if (p.swimmer.outer == OuterFlow::Confined && p.container.shape == ContainerShape::Box)
        throw InputError(m.path("outer_flow"), "\"confined\"",
                         "container.kind = \"box\" (a periodic box, 3D only) has no wall: use container.kind = "
                         "\"cylinder\" or \"duct\", or model1d.outer_flow = \"unbounded\"");
      if (p.swimmer.outer == OuterFlow::Confined && !(R0 + p.swimmer.a_out < 0.99 * p.container.radius_eff))
        throw InputError("container.radius", fmt(p.container.radius, "m"),
                         "the tube's outer hydraulic radius swimmer.radius + model1d.hydraulic_offsets.outer = " +
                             fmt(R0 + p.swimmer.a_out, "m") + " must stay below the container radius seen by the 1D "
                             "tier (" + fmt(p.container.radius_eff, "m") + ")");
    } else {
      Reader q = m.child("paper");
      p.swimmer.closure = q.choice("closure", "tube_law", {"tube_law", "flow"}) == "flow" ? Closure::Flow : Closure::TubeLaw;
      p.swimmer.balance = q.choice("balance", "per_area", {"per_area", "per_length"}) == "per_length"
                              ? Balance::PerLength
                              : Balance::PerArea;
      p.swimmer.thrust = q.boolean("thrust", true);
      p.swimmer.drag = q.choice("external_drag", "none", {"none", "resistive_force"}) == "resistive_force"
                           ? ExternalDrag::ResistiveForce
                           : ExternalDrag::None;
      q.finish();
    }
    if (p.wall.law && (p.swimmer.model != SwimmerModel::ForceFree || !forced))
      throw InputError("wall.law", "\"" + std::string(scene.at("wall").at("law").get<std::string>()) + "\"",
                       "a calibrated tube law is available for the force-free model (model1d.model = "
                       "\"force_free\") with wave.kind = \"force_driven\"; use wall.law = \"linear\" here");
    p.wall.inertia = m.boolean("wall_inertia", false);
    if (p.wall.inertia && p.swimmer.model == SwimmerModel::ForceFree && p.swimmer.outer == OuterFlow::Confined)
      throw InputError(m.path("wall_inertia"), "true",
                       "wall inertia is available with model1d.outer_flow = \"unbounded\" and model1d.model = "
                       "\"paper\"; the confined force-free model runs without it (at Re ~ 1e-6 the wall's inertia "
                       "is negligible: its time scale 2 pi sqrt(m / C1) is below 0.1 ms)");
    // default on for the force-free force-driven wave (docs/outer-flow-1d.md, 3b)
    if (const std::string ends = m.choice("end_effects", "none", {"none", "open_ends", "junction"}); ends != "none") {
      if (p.swimmer.model != SwimmerModel::ForceFree || p.swimmer.outer != OuterFlow::Confined)
        throw InputError(m.path("end_effects"), "\"" + ends + "\"",
                         "the open ends' flow is modelled for the confined force-free model (model1d.model = "
                         "\"force_free\", model1d.outer_flow = \"confined\"); use \"none\" here");
      if (forced && ends != "junction")
        throw InputError(m.path("end_effects"), "\"" + ends + "\"",
                         "with wave.kind = \"force_driven\" the open ends are modelled by the calibrated junction; "
                         "use \"junction\" or \"none\" here");
      if (ends == "open_ends") {
        p.swimmer.end_lumen = outer::kOpenEnds.lumen;
        p.swimmer.end_annulus = outer::kOpenEnds.annulus;
      } else {
        p.swimmer.end_junction = true;
      }
    }
    p.swimmer.short_wave_traction = m.boolean("short_wave_traction", p.swimmer.model == SwimmerModel::ForceFree && forced);
    if (p.swimmer.short_wave_traction && p.swimmer.model != SwimmerModel::ForceFree)
      throw InputError(m.path("short_wave_traction"), "true",
                       "the short-wave wall traction belongs to the force-free model (model1d.model = \"force_free\")");
    if (p.swimmer.short_wave_traction && !forced)
      throw InputError(m.path("short_wave_traction"), "true",
                       "the short-wave wall traction only applies to wave.kind = \"force_driven\" (a prescribed wave "
                       "fixes R(z,t), and the normal stress then does not change the swimmer's velocity)");
    if (m.has("short_wave_traction_end")) {
      const double beta = m.number("short_wave_traction_end", 0.0, Range::closed(0.0, 1.0));
      if (!p.swimmer.short_wave_traction && beta != 0.0) {
        char b[32];
        std::snprintf(b, sizeof b, "%.6g", beta);
        throw InputError(m.path("short_wave_traction_end"), b,
                         "the end condition of the short-wave wall traction needs model1d.short_wave_traction = true");
      }
      p.swimmer.traction_end = beta;
    }
    if (p.wall.inertia && !forced)
      throw InputError(m.path("wall_inertia"), "true", "wall inertia only applies to wave.kind = \"force_driven\" "
                                                       "(a prescribed wave fixes R(z,t))");
    if (m.has("recovery_end")) {  // (not echoed when absent: the paper's energy rule)
      const std::string e = m.choice("recovery_end", "energy", {"energy", "dead_band", "shape"});
      if (!forced)
        throw InputError(m.path("recovery_end"), "\"" + e + "\"",
                         "the recovery's end belongs to the force-driven protocol (wave.kind = \"force_driven\"); a "
                         "prescribed wave has no recovery phase");
      for (RecoveryEnd r : {RecoveryEnd::Energy, RecoveryEnd::DeadBand, RecoveryEnd::Shape})
        if (e == recovery_end_name(r)) p.protocol.recovery_end = r;
    }
    if (m.has("axial_bending")) {  // (not echoed when absent: scenes without it resolve as before)
      Reader ab = m.child("axial_bending");
      const std::string src = ab.choice("source", "none", {"none", "scene", "calibration"});
      if (src == "calibration") {
        if (calibration.empty())
          throw InputError(ab.path("source"), "\"calibration\"",
                           "needs wall.calibration (the calibration file that holds the measured "
                           "axial_bending_rigidity_J)");
        p.wall.D_axial = axial_bending_from_calibration("wall.calibration", calibration, scene_dir);
      } else if (src == "scene") {
        p.wall.D_axial = ab.quantity("rigidity", "J", "", Range::positive());
      }
      ab.finish();
      if (src != "none" && (p.swimmer.model != SwimmerModel::ForceFree || !forced))
        throw InputError(ab.path("source"), "\"" + src + "\"",
                         "the wall's axial bending belongs to the force-free model (model1d.model = \"force_free\") "
                         "with wave.kind = \"force_driven\" (a prescribed wave fixes R(z,t)); use \"none\" here");
    }
    m.finish();
  }
  {
    Reader n = top.child("numerics1d");
    // the shortest protocol segment and the cells it needs to span one (force-driven wave)
    const double seg_other = forced ? L / (p.protocol.first_ratio + p.protocol.segments - 1) : L;
    const double shortest = std::min(seg_other, seg_other * (forced ? p.protocol.first_ratio : 1.0));
    const int needed = static_cast<int>(std::ceil(L / shortest - 1e-9));
    // With the short-wave traction the cell-scale motion is damped and N = 50 is as accurate
    // as N = 400 without it (docs/outer-flow-1d.md, 3b): 50 cells, and at least 4 per
    // protocol segment; 200 otherwise.
    const int cells_default = p.swimmer.short_wave_traction ? std::max(50, 4 * needed) : 200;
    p.numerics.cells = static_cast<int>(n.integer("cells", cells_default, 4, 100000));
    // The time integration's tolerance against the grid's own error: on the screening grids (up
    // to 100 cells, whose error is 0.7 % at the median on 50) 1e-4 keeps the integration's error
    // a tenth to a fortieth of the grid's at half the steps; finer grids get 1e-6
    // (docs/performance-1d.md, "The tolerance against the grid's error").
    p.numerics.rtol = n.number("rtol", p.numerics.cells <= kScreeningCells ? 1e-4 : 1e-6, Range::closed(1e-12, 1e-2));
    p.numerics.atol_scale = n.number("atol_scale", 1e-6, Range::closed(1e-14, 1e-2));
    p.numerics.max_steps = n.integer("max_steps", 2000000, 100, 1000000000);
    // A second thread evaluates the output samples of a force-driven run (docs/performance-1d.md,
    // "The output samples on a second thread"); a screen runs its designs one per thread instead.
    p.numerics.threads = static_cast<int>(n.integer("threads", 1, 1, 2));
    // The open ends (docs/reduced1d.md, "The open ends' half cells") of the force-driven wave
    // without the axial bending or the calibrated junction, whose ends are their own: at the
    // static radius of the end's actuation, its half cell a drainage layer (the default) or a
    // lumen linear in R; or, with the short-wave traction, the end cell continued to the mouth.
    const bool static_ends = forced && !p.swimmer.end_junction && !(p.wall.D_axial > 0);
    // A static end needs a static radius under the actuation: at or below the collapse radius
    // (q near or above C1 R0, or above the calibrated law's load there) it has none, and a run
    // would stop at t = 0. The short-wave traction's wall then takes the end cell continued to
    // the mouth instead, the same limit, which needs no static end (docs/reduced1d.md, "The open
    // ends' half cells").
    const bool no_static_end =
        static_ends && detail::wall_law(p).static_radius(p.protocol.q) < detail::collapse_radius(p);
    const char* end_default =
        !static_ends ? "linear" : no_static_end && p.swimmer.short_wave_traction ? "continued" : "drainage";
    const std::string open_end = n.choice("open_end", end_default, {"drainage", "linear", "continued"});
    if (open_end == "drainage" && !static_ends)
      throw InputError(n.path("open_end"), "\"drainage\"",
                       "the drainage layer is the half cell of an open end held at its actuation's static radius: "
                       "wave.kind = \"force_driven\" without model1d.axial_bending or model1d.end_effects = "
                       "\"junction\"; use \"linear\" here");
    if (open_end == "continued" && !(static_ends && p.swimmer.short_wave_traction))
      throw InputError(n.path("open_end"), "\"continued\"",
                       "an end continued from its cell is an open end of the short-wave traction's wall: "
                       "wave.kind = \"force_driven\" with model1d.short_wave_traction = true, without "
                       "model1d.axial_bending (whose ends follow the wall already) or model1d.end_effects = "
                       "\"junction\"; use \"drainage\" or \"linear\" here");
    p.numerics.open_end = open_end == "drainage"    ? OpenEnd::Drainage
                          : open_end == "continued" ? OpenEnd::Continued
                                                    : OpenEnd::Linear;
    n.finish();
    if (forced) {  // every protocol segment must span at least one cell
      if (p.numerics.cells < needed)
        throw InputError(n.path("cells"), std::to_string(p.numerics.cells),
                         "too few cells to resolve the shortest protocol segment (length " + fmt(shortest, "m") +
                             "); need at least " + std::to_string(needed));
    }
  }
  s.read_time(top);
  p.duration = s.time.duration;
  p.numerics.output_interval = s.time.output_interval;
  top.pass_through("full3d");
  top.pass_through("axi");  // the axisymmetric tier's numerics (axi/scene_axi.hpp)
  scene::read_output(top);
  top.finish();
  return p;
}

}  // namespace swim::reduced1d
