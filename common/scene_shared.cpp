#include "common/scene_shared.hpp"

#include <cmath>
#include <cstdio>

#include "common/errors.hpp"

namespace swim::scene {

std::string one_of(const Reader& r, const std::vector<std::string>& keys, const std::string& fallback) {
  std::string found;
  for (const auto& k : keys) {
    if (!r.has(k)) continue;
    if (!found.empty()) {
      std::string s;
      for (size_t i = 0; i < keys.size(); ++i) s += (i ? ", " : "") + keys[i];
      throw InputError(r.path(k), "(given together with " + found + ")", "give only one of: " + s);
    }
    found = k;
  }
  return found.empty() ? fallback : found;
}

std::string format_quantity(double v, const char* unit) {
  char b[48];
  std::snprintf(b, sizeof b, "%.6g %s", v, unit);
  return b;
}

bool multiple_of(double a, double h) {
  const double n = std::round(a / h);
  return n >= 1 && std::abs(a - n * h) <= 1e-9 * a;
}

namespace {

/// The least tube radius and length the tiers model [m]: they solve continuum Stokes flow in
/// the lumen and around the wall, which needs several molecular diameters (water's is about
/// 0.3 nm). Below it a typed unit (1e-15 m for 1e-6 m) would run for hours or write the output
/// limit's gigabyte before failing.
constexpr double kLeastContinuumLength = 1e-9;

double continuum_length(Reader& s, const char* key, const char* fallback) {
  const double v = s.quantity(key, "m", fallback, Range::positive());
  if (v < kLeastContinuumLength)
    throw InputError(s.path(key), format_quantity(v, "m"),
                     "at least 1 nm: the tiers solve continuum Stokes flow in the lumen and around the wall, which "
                     "needs a tube several molecular diameters across (water's is about 0.3 nm)");
  return v;
}

Body read_body(Reader& top) {
  Body b;
  {
    Reader s = top.child("swimmer");
    b.R0 = continuum_length(s, "radius", "0.125 um");
    b.L = continuum_length(s, "length", "0.4 um");
    s.finish();
  }
  {
    Reader f = top.child("fluid");
    b.mu = f.quantity("viscosity", "Pa*s", "1.2e-3 Pa*s", Range::positive());
    b.rho = f.quantity("density", "kg/m^3", "1000 kg/m^3", Range::positive());
    b.temperature = f.quantity("temperature", "K", "310 K", Range::open(0.0, 1e4));
    f.finish();
  }
  return b;
}

ContainerSpec read_container(Reader& top, double R0, double L) {
  ContainerSpec c;
  Reader r = top.child("container");
  c.kind = r.choice("kind", "duct", {"duct", "cylinder", "box"});
  c.radius = r.quantity("radius", "m", "0.25 um", Range::positive());
  c.period = r.quantity("period", "m", "2 um", Range::positive());
  r.finish();
  if (!(c.radius > R0))
    throw InputError(r.path("radius"), format_quantity(c.radius, "m"),
                     "must exceed swimmer.radius = " + format_quantity(R0, "m") + " (the swimmer must fit)");
  if (!(c.period > L))
    throw InputError(r.path("period"), format_quantity(c.period, "m"),
                     "must exceed swimmer.length = " + format_quantity(L, "m") + " (one swimmer per period)");
  return c;
}

WallSpec read_wall(Reader& top, double R0) {
  WallSpec w;
  Reader r = top.child("wall");
  w.stiffness = one_of(r, {"C1", "spring_constant", "stretching_modulus", "calibration"}, "spring_constant");
  if (w.stiffness == "C1")
    w.value = r.quantity("C1", "Pa/m", "", Range::positive());
  else if (w.stiffness == "spring_constant")
    w.value = r.quantity("spring_constant", "N/m", "5.5e-8 N/m", Range::positive());
  else if (w.stiffness == "stretching_modulus")  // the network's 2D Young's modulus Y = 2 k_s / sqrt(3)
    w.value = std::sqrt(3.0) / 2.0 * r.quantity("stretching_modulus", "N/m", "", Range::positive());
  else
    w.calibration = r.text("calibration", "");
  if (r.has("law")) w.law = r.choice("law", "linear", {"linear", "calibrated_round", "calibrated_buckled"});
  if (one_of(r, {"mass_per_area", "mass_per_length"}, "mass_per_length") == "mass_per_area")
    w.mass_per_area = r.quantity("mass_per_area", "kg/m^2", "", Range::positive());
  else  // source-equations.md §1: mass per unit length m_l = 2 pi R0 m
    w.mass_per_area = r.quantity("mass_per_length", "kg/m", "2.25e-3 ug/um", Range::positive()) / (2.0 * M_PI * R0);
  r.finish();
  return w;
}

double read_contracted_radius(Reader& w, double R0) {
  if (one_of(w, {"contracted_ratio", "contracted_radius"}, "contracted_ratio") == "contracted_radius") {
    const double R_f = w.quantity("contracted_radius", "m", "", Range::positive());
    if (!(R_f < R0))
      throw InputError(w.path("contracted_radius"), format_quantity(R_f, "m"),
                       "must be below the reference radius swimmer.radius = " + format_quantity(R0, "m"));
    return R_f;
  }
  return R0 * w.number("contracted_ratio", 0.55, Range::open(0.0, 1.0));
}

WaveSpec read_wave(Reader& top, double R0, double L) {
  WaveSpec s;
  Reader w = top.child("wave");
  s.kind = w.choice("kind", "force_driven", {"step", "sine", "force_driven", "recorded"});
  if (s.kind == "recorded") {
    // the record sets the radius: a contracted radius, speed, width or wavelength has no meaning
    for (const char* k : {"contracted_ratio", "contracted_radius", "speed", "width", "wavelength"})
      if (w.has(k))
        throw InputError(w.path(k), show(w.given(k)),
                         "is not used with wave.kind = \"recorded\" (the radius comes from wave.radius_file)");
    if (!w.has("radius_file"))
      throw InputError(w.path("radius_file"), "(missing)",
                       "wave.kind = \"recorded\" needs wave.radius_file: the path of a radius.csv (t_s, z_m, "
                       "radius_m) written by swim run");
    s.radius_file = w.text("radius_file", "");
    w.finish();
    return s;
  }
  if (w.has("radius_file"))
    throw InputError(w.path("radius_file"), show(w.given("radius_file")),
                     "is only used with wave.kind = \"recorded\"");
  s.R_f = read_contracted_radius(w, R0);
  if (s.kind == "step") {
    s.speed = w.quantity("speed", "m/s", "10 um/s", Range::positive());
    s.width = w.quantity("width", "m", "0.01 um", Range::positive());
    if (!(s.width <= 0.25 * L))
      throw InputError(w.path("width"), format_quantity(s.width, "m"),
                       "must be at most a quarter of swimmer.length = " + format_quantity(L, "m"));
  } else if (s.kind == "sine") {
    s.speed = w.quantity("speed", "m/s", "10 um/s", Range::positive());
    s.wavelength = w.quantity("wavelength", "m", format_quantity(L, "m"), Range::positive());
  }
  w.finish();
  return s;
}

ProtocolSpec read_protocol_section(Reader& top, double R0, double L, double R_f, double C1, double static_load) {
  ProtocolSpec p;
  Reader r = top.child("protocol");
  const double area = 2.0 * M_PI * R0 * L;
  // static load that holds the wall at R_f (a nonlinear law's own, when given)
  const double q_needed = static_load > 0 ? static_load : C1 * (R0 - R_f);
  const std::string act = one_of(r, {"pressure", "total_force", "load_factor"}, "total_force");
  if (act == "pressure")
    p.q = r.quantity("pressure", "Pa", "", Range::positive());
  else if (act == "load_factor")  // actuation as a multiple of the static load, for sweeps
    p.q = q_needed * r.number("load_factor", 1.5, Range::open(1.02, 1e6));
  else  // Section 3: F_ext spread evenly over the wall, F_ext / N_n per node of equal area
    p.q = r.quantity("total_force", "N", "0.1 pN", Range::positive()) / area;
  p.segments = static_cast<int>(r.integer("segments", 6, 2, 1000));
  p.first_ratio = r.number("first_segment_ratio", 1.0 / 3.0, Range::open(0.0, 1.0e3));
  p.delta = R0 * r.number("tolerance_ratio", 0.02, Range::open(0.0, 0.2));
  p.energy_tol = r.number("energy_tolerance", 1e-3, Range::open(0.0, 1.0));
  p.cycles = static_cast<int>(r.integer("cycles", 1, 1, 100000));
  r.finish();
  if (!(p.q > 1.02 * q_needed))
    throw InputError(r.path(act), format_quantity(p.q, "Pa") + " (as pressure)",
                     std::string("cannot contract the wall to the contracted radius: the static load ") +
                         (static_load > 0 ? "of the calibrated tube law at R_f" : "C1 (R0 - R_f)") + " = " +
                         format_quantity(q_needed, "Pa") +
                         " must be exceeded by at least 2%; raise the actuation, use protocol.load_factor, or "
                         "raise wave.contracted_ratio");
  if (!(p.delta < 0.5 * (R0 - R_f)) || !(p.delta < 0.5 * R_f))
    throw InputError(r.path("tolerance_ratio"), format_quantity(p.delta / R0, ""),
                     "the tolerance delta must be below half of both R0 - R_f and R_f");
  return p;
}

}  // namespace

double WaveSpec::transit(double L) const {
  if (kind == "step") return L / speed;
  if (kind == "sine") return wavelength / speed;
  if (kind == "recorded") return period;
  return 0.0;
}

SharedScene SharedScene::read(Reader& top, const WallRule& wall_rule) {
  SharedScene s;
  s.name = top.text("name", "unnamed");
  check_name(s.name);
  top.text("description", "");
  s.body = read_body(top);
  s.container = read_container(top, s.body.R0, s.body.L);
  s.wall = read_wall(top, s.body.R0);
  if (wall_rule) wall_rule(s.body, s.wall);
  s.wave = read_wave(top, s.body.R0, s.body.L);
  return s;
}

void SharedScene::read_protocol(Reader& top, double C1, double static_load) {
  if (wave.prescribed()) {
    if (top.has("protocol"))
      throw InputError(top.path("protocol"), show(top.given("protocol")),
                       "is only used when wave.kind = \"force_driven\"");
    return;
  }
  protocol = read_protocol_section(top, body.R0, body.L, wave.R_f, C1, static_load);
}

void SharedScene::read_time(Reader& top) {
  Reader t = top.child("time");
  // duration: a quantity, or "auto" (a prescribed wave: its transit time; a force-driven wave:
  // until protocol.cycles cycles are complete)
  if (t.has("duration") && t.given("duration") != "auto") {
    time.duration = t.quantity("duration", "s", "", Range::positive());
  } else {
    t.text("duration", "auto");
    time.duration = 0;
  }
  const double span = time.duration > 0 ? time.duration : wave.transit(body.L);
  const std::string def = span > 0 ? format_quantity(span / 200.0, "s") : "0.5 ms";
  time.output_interval = t.quantity("output_interval", "s", def, Range::positive());
  if (span > 0 && time.output_interval > span)
    throw InputError(t.path("output_interval"), format_quantity(time.output_interval, "s"),
                     "must not exceed the run duration " + format_quantity(span, "s"));
  t.finish();
}

double c1_from_spring_constant(double k_s, double R0) { return 2.0 * k_s / (std::sqrt(3.0) * R0 * R0); }

}  // namespace swim::scene
