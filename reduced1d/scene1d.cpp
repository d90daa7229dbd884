#include "reduced1d/scene1d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"
#include "common/units.hpp"

namespace swim::reduced1d {

using scene::json;
using scene::Range;
using scene::Reader;

namespace {

std::string fmt(double v, const char* unit) {
  char b[48];
  std::snprintf(b, sizeof b, "%.6g %s", v, unit);
  return b;
}

/// Exactly one of `keys` may be given; returns the one present, or `fallback`.
std::string one_of(const Reader& r, const std::vector<std::string>& keys, const std::string& fallback) {
  std::string found;
  for (const auto& k : keys) {
    if (!r.has(k)) continue;
    if (!found.empty())
      throw InputError(r.path(k), "(given together with " + found + ")", "give only one of: " + [&] {
        std::string s;
        for (size_t i = 0; i < keys.size(); ++i) s += (i ? ", " : "") + keys[i];
        return s;
      }());
    found = k;
  }
  return found.empty() ? fallback : found;
}

}  // namespace

double c1_from_spring_constant(double k_s, double R0) { return 2.0 * k_s / (std::sqrt(3.0) * R0 * R0); }

double c1_from_calibration(const std::string& key, const std::string& path, const std::string& scene_dir) {
  namespace fs = std::filesystem;
  fs::path p(path);
  if (p.is_relative() && !fs::exists(p)) p = fs::path(scene_dir) / path;
  std::ifstream in(p);
  if (!in) throw InputError(key, "\"" + path + "\"", "calibration file not found (relative paths are tried from the "
                                                     "working directory, then from the scene's directory)");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw InputError(key, "\"" + path + "\"", std::string("calibration file is not valid JSON: ") + e.what());
  }
  if (!j.is_object() || !j.contains("C1_Pa_per_m") || !j["C1_Pa_per_m"].is_number())
    throw InputError(key, "\"" + path + "\"", "calibration file must hold a number \"C1_Pa_per_m\"");
  const double c1 = j["C1_Pa_per_m"].get<double>();
  if (!(c1 > 0) || !std::isfinite(c1)) throw InputError(key, "\"" + path + "\"", "C1_Pa_per_m must be > 0");
  return c1;
}

Params read_scene(const json& scene, json& resolved, const std::string& scene_dir) {
  Params p;
  resolved = json::object();
  Reader top(scene, "", resolved);
  p.name = top.text("name", "unnamed");
  top.text("description", "");

  {
    Reader s = top.child("swimmer");
    p.geometry.R0 = s.quantity("radius", "m", "0.125 um", Range::positive());
    p.geometry.L = s.quantity("length", "m", "0.4 um", Range::positive());
    s.finish();
  }
  const double R0 = p.geometry.R0, L = p.geometry.L;
  {
    Reader f = top.child("fluid");
    p.fluid.mu = f.quantity("viscosity", "Pa*s", "1.2e-3 Pa*s", Range::positive());
    p.fluid.rho = f.quantity("density", "kg/m^3", "1000 kg/m^3", Range::positive());
    f.finish();
  }
  {
    Reader w = top.child("wall");
    const std::string stiff = one_of(w, {"C1", "spring_constant", "calibration"}, "spring_constant");
    if (stiff == "C1") {
      p.wall.C1 = w.quantity("C1", "Pa/m", "", Range::positive());
    } else if (stiff == "spring_constant") {
      p.wall.C1 = c1_from_spring_constant(w.quantity("spring_constant", "N/m", "5.5e-8 N/m", Range::positive()), R0);
    } else {
      const std::string file = w.text("calibration", "");
      p.wall.C1 = c1_from_calibration(w.path("calibration"), file, scene_dir);
    }
    const std::string mass = one_of(w, {"mass_per_area", "mass_per_length"}, "mass_per_length");
    if (mass == "mass_per_area")
      p.wall.m = w.quantity("mass_per_area", "kg/m^2", "", Range::positive());
    else  // notes section 1: mass per unit length m_l = 2 pi R0 m
      p.wall.m = w.quantity("mass_per_length", "kg/m", "2.25e-3 ug/um", Range::positive()) / (2.0 * M_PI * R0);
    w.finish();
  }

  double R_f = 0;
  {
    Reader w = top.child("wave");
    const std::string kind = w.choice("kind", "force_driven", {"step", "sine", "force_driven"});
    p.wave = kind == "step" ? WaveKind::Step : kind == "sine" ? WaveKind::Sine : WaveKind::ForceDriven;
    if (one_of(w, {"contracted_ratio", "contracted_radius"}, "contracted_ratio") == "contracted_radius") {
      R_f = w.quantity("contracted_radius", "m", "", Range::positive());
      if (!(R_f < R0))
        throw InputError(w.path("contracted_radius"), fmt(R_f, "m"),
                         "must be below the reference radius swimmer.radius = " + fmt(R0, "m"));
    } else {
      R_f = R0 * w.number("contracted_ratio", 0.55, Range::open(0.0, 1.0));
    }
    if (p.wave == WaveKind::Step) {
      p.step.R_min = R_f;
      p.step.speed = w.quantity("speed", "m/s", "10 um/s", Range::positive());
      p.step.width = w.quantity("width", "m", "0.01 um", Range::positive());
      if (!(p.step.width <= 0.25 * L))
        throw InputError(w.path("width"), fmt(p.step.width, "m"), "must be at most a quarter of swimmer.length = " + fmt(L, "m"));
    } else if (p.wave == WaveKind::Sine) {
      p.sine.amplitude = R0 - R_f;
      p.sine.speed = w.quantity("speed", "m/s", "10 um/s", Range::positive());
      p.sine.wavelength = w.quantity("wavelength", "m", fmt(L, "m"), Range::positive());
    }
    w.finish();
  }

  const bool forced = p.wave == WaveKind::ForceDriven;
  if (!forced && top.has("protocol"))
    throw InputError("protocol", scene::show(scene.at("protocol")), "is only used when wave.kind = \"force_driven\"");
  if (forced) {
    Reader r = top.child("protocol");
    p.protocol.R_f = R_f;
    const double area = 2.0 * M_PI * R0 * L;
    const double q_needed = p.wall.C1 * (R0 - R_f);  // static load that holds the wall at R_f
    const std::string act = one_of(r, {"pressure", "total_force", "load_factor"}, "total_force");
    if (act == "pressure")
      p.protocol.q = r.quantity("pressure", "Pa", "", Range::positive());
    else if (act == "load_factor")  // actuation as a multiple of the static load, for sweeps
      p.protocol.q = q_needed * r.number("load_factor", 1.5, Range::open(1.02, 1e6));
    else  // Section 3: F_ext spread evenly over the wall, F_ext / N_n per node of equal area
      p.protocol.q = r.quantity("total_force", "N", "0.1 pN", Range::positive()) / area;
    p.protocol.segments = static_cast<int>(r.integer("segments", 6, 2, 1000));
    p.protocol.first_ratio = r.number("first_segment_ratio", 1.0 / 3.0, Range::open(0.0, 1.0e3));
    p.protocol.delta = R0 * r.number("tolerance_ratio", 0.02, Range::open(0.0, 0.2));
    p.protocol.energy_tol = r.number("energy_tolerance", 1e-3, Range::open(0.0, 1.0));
    p.protocol.cycles = static_cast<int>(r.integer("cycles", 1, 1, 100000));
    r.finish();
    if (!(p.protocol.q > 1.02 * q_needed))
      throw InputError(r.path(act), fmt(p.protocol.q, "Pa") + " (as pressure)",
                       "cannot contract the wall to the contracted radius: the static load C1 (R0 - R_f) = " +
                           fmt(q_needed, "Pa") + " must be exceeded by at least 2%; raise the actuation or "
                           "wave.contracted_ratio");
    if (!(p.protocol.delta < 0.5 * (R0 - R_f)) || !(p.protocol.delta < 0.5 * R_f))
      throw InputError(r.path("tolerance_ratio"), fmt(p.protocol.delta / R0, ""),
                       "the tolerance delta must be below half of both R0 - R_f and R_f");
  }

  {
    Reader m = top.child("model1d");
    p.swimmer.closure = m.choice("closure", "tube_law", {"tube_law", "flow"}) == "flow" ? Closure::Flow : Closure::TubeLaw;
    p.swimmer.balance =
        m.choice("balance", "per_area", {"per_area", "per_length"}) == "per_length" ? Balance::PerLength : Balance::PerArea;
    p.swimmer.thrust = m.boolean("thrust", true);
    p.swimmer.drag = m.choice("external_drag", "none", {"none", "resistive_force"}) == "resistive_force"
                         ? ExternalDrag::ResistiveForce
                         : ExternalDrag::None;
    p.wall.inertia = m.boolean("wall_inertia", false);
    if (p.wall.inertia && !forced)
      throw InputError(m.path("wall_inertia"), "true", "wall inertia only applies to wave.kind = \"force_driven\" "
                                                       "(a prescribed wave fixes R(z,t))");
    m.finish();
  }
  {
    Reader n = top.child("numerics1d");
    p.numerics.cells = static_cast<int>(n.integer("cells", 200, 4, 100000));
    p.numerics.rtol = n.number("rtol", 1e-6, Range::closed(1e-12, 1e-2));
    p.numerics.atol_scale = n.number("atol_scale", 1e-6, Range::closed(1e-14, 1e-2));
    p.numerics.max_steps = n.integer("max_steps", 2000000, 100, 1000000000);
    n.finish();
    if (forced) {  // every protocol segment must span at least one cell
      const double other = L / (p.protocol.first_ratio + p.protocol.segments - 1);
      const double shortest = std::min(other, other * p.protocol.first_ratio);
      const int needed = static_cast<int>(std::ceil(L / shortest - 1e-9));
      if (p.numerics.cells < needed)
        throw InputError(n.path("cells"), std::to_string(p.numerics.cells),
                         "too few cells to resolve the shortest protocol segment (length " + fmt(shortest, "m") +
                             "); need at least " + std::to_string(needed));
    }
  }
  {
    Reader t = top.child("time");
    const json& tn = scene.contains("time") ? scene["time"] : json::object();
    // duration: a quantity, or "auto" (prescribed: wave transit time; force-driven: until
    // protocol.cycles cycles are complete)
    if (tn.is_object() && tn.contains("duration") && tn["duration"] == "auto") {
      t.text("duration", "auto");
      p.duration = 0;
    } else if (tn.is_object() && tn.contains("duration")) {
      p.duration = t.quantity("duration", "s", "", Range::positive());
    } else {
      t.text("duration", "auto");
      p.duration = 0;
    }
    double transit = 0;
    if (p.wave == WaveKind::Step) transit = L / p.step.speed;
    if (p.wave == WaveKind::Sine) transit = p.sine.wavelength / p.sine.speed;
    const double span = p.duration > 0 ? p.duration : transit;
    const std::string def = span > 0 ? fmt(span / 200.0, "s") : "0.5 ms";
    p.numerics.output_interval = t.quantity("output_interval", "s", def, Range::positive());
    if (span > 0 && p.numerics.output_interval > span)
      throw InputError(t.path("output_interval"), fmt(p.numerics.output_interval, "s"),
                       "must not exceed the run duration " + fmt(span, "s"));
    t.finish();
  }
  top.pass_through("full3d");
  top.finish();
  return p;
}

}  // namespace swim::reduced1d
