#include "full3d/scene3d.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <tuple>

#include "common/errors.hpp"
#include "common/scene_shared.hpp"
#include "full3d/buckling_estimate.hpp"
#include "full3d/fft.hpp"

namespace swim::full3d {

using scene::json;
using scene::Range;
using scene::Reader;

using scene::multiple_of;

namespace {

std::string fmt(double v, const char* unit) { return scene::format_quantity(v, unit); }

/// The seed's amplitude with seed_mode = "auto" when none is given: 1 % of R0, above the 1e-3 R0
/// from which the chosen mode grows rather than the grid's own (docs/full3d.md, "Wall wrinkling").
constexpr double kAutoSeedAmplitude = 0.01;

}  // namespace

double Params3d::c1_estimate() const { return scene::c1_from_spring_constant(membrane.ks, R0); }

GridBoundary Params3d::grid_boundary() const {
  return container == "box" ? GridBoundary::PeriodicBox : GridBoundary::SquareDuct;  // cylinder: inside a duct
}

Eigen::Vector3d Params3d::axis_start() const {
  return Eigen::Vector3d(0.5 * (nx * h - L), 0.5 * ny * h, 0.5 * nz * h);
}

ProtocolParams effective_protocol(const Params3d& p, const CylinderMesh& mesh) {
  ProtocolParams q = p.protocol;
  q.end_energy = p.recovery_end == "dead_band"
                     ? uniform_contraction_energy(mesh, p.membrane, mesh.radius - p.protocol.delta)
                     : 0.0;
  return q;
}

CylinderMesh make_round_mesh(const Params3d& p) {
  return make_cylinder_for_grid(p.R0, p.L, p.h, p.axis_start(), p.spacing_factor, p.ring_nodes_multiple);
}

CylinderMesh make_mesh(const Params3d& p) {
  CylinderMesh mesh = make_round_mesh(p);
  seed_ring_modes(mesh, {{p.seed_mode, p.seed_amplitude}, {p.secondary_seed_mode, p.secondary_seed_amplitude}});
  return mesh;
}

double reference_rigidity_per_kb(double R0, double L, double a_ref, BendingForm form) {
  static std::mutex lock;
  static std::map<std::tuple<double, double, double, int>, double> cache;
  const auto key = std::make_tuple(R0, L, a_ref, int(form));
  {
    const std::lock_guard<std::mutex> g(lock);
    const auto it = cache.find(key);
    if (it != cache.end()) return it->second;
  }
  const double v =
      bending_rigidity_per_kb(make_cylinder_for_grid(R0, L, 2.0 * a_ref, Eigen::Vector3d::Zero(), 1.0), form);
  const std::lock_guard<std::mutex> g(lock);
  cache[key] = v;
  return v;
}

Params3d read_scene3d(const json& scene, json& resolved, bool prescribed_waves) {
  Params3d p;
  resolved = json::object();
  Reader top(scene, "", resolved);
  // the 3D wall is the spring network
  scene::SharedScene s = scene::SharedScene::read(top, [&](const scene::Body&, const scene::WallSpec& w) {
    if (!w.network())
      throw InputError("wall." + w.stiffness, scene::show(scene.at("wall").at(w.stiffness)),
                       "the 3D tier models the wall as a spring network and needs its spring constant: give "
                       "wall.spring_constant (N/m) or wall.stretching_modulus (N/m) instead; C1 and calibration "
                       "are 1D lumped stiffnesses");
    p.membrane.ks = w.value;
    p.mass_per_area = w.mass_per_area;
  });
  p.name = s.name;
  p.R0 = s.body.R0;
  p.L = s.body.L;
  p.fluid.mu = s.body.mu;
  p.fluid.rho = s.body.rho;
  const double R0 = p.R0, L = p.L;
  p.container = s.container.kind;
  p.container_radius = s.container.radius;
  p.period = s.container.period;
  p.wave = s.wave;
  if (p.wave.kind == "recorded")
    throw InputError("wave.kind", "\"recorded\"",
                     "a recorded wave (wave.radius_file) is replayed by the 1D tier only: run --tier 1d; the 3D tier "
                     "runs \"force_driven\", the axisymmetric tier \"force_driven\", \"step\" and \"sine\"");
  if (p.wave.prescribed() && !prescribed_waves)
    throw InputError("wave.kind", "\"" + p.wave.kind + "\"",
                     "the 3D tier drives the wall by forces only (prescribed kinematics are not implemented): "
                     "use \"force_driven\" or run --tier 1d or --tier axi");
  p.protocol.R_f = p.wave.R_f;
  s.read_protocol(top, p.c1_estimate());
  if (s.force_driven()) s.protocol.assign_to(p.protocol);
  top.pass_through("model1d");
  top.pass_through("numerics1d");
  top.pass_through("axi");  // the axisymmetric tier's numerics (axi/scene_axi.hpp)
  s.read_time(top);
  p.duration = s.time.duration;
  p.output_interval = s.time.output_interval;
  p.protocol.repeat_until_duration = p.duration > 0;

  {
    Reader f = top.child("full3d");
    const double width = 2.0 * p.container_radius;
    {
      Reader g = f.child("grid");
      if (scene::one_of(g, {"cells_across", "cell_size"}, "cells_across") == "cell_size") {
        p.h = g.quantity("cell_size", "m", "", Range::positive());
        if (!multiple_of(width, p.h))
          throw InputError(g.path("cell_size"), fmt(p.h, "m"),
                           "must divide the container width 2 * container.radius = " + fmt(width, "m"));
      } else {
        p.h = width / g.integer("cells_across", 32, 4, 4096);
      }
      if (!multiple_of(p.period, p.h))
        throw InputError("container.period", fmt(p.period, "m"),
                         "must be a multiple of the cell size " + fmt(p.h, "m"));
      // cylinder: the fictitious square domain is at least one cell wider than the cylinder on
      // each side (paper, Remark 1: collocation points between the cylinder and the duct walls),
      // padded to a size the cross-section transforms handle fast (fft_friendly_size; the
      // masked cells carry u = 0 exactly, so the padding changes nothing but the cost)
      const int across = int(std::lround(width / p.h));
      p.ny = p.nz = p.container == "cylinder" ? fft_friendly_size(across + 2) : across;
      p.nx = int(std::lround(p.period / p.h));
      g.finish();
    }
    p.dt = f.quantity("dt", "s", "1 ms", Range::positive());
    // full3d.scheme is read below (its place in the resolved scene); the adaptive section
    // reads the Chebyshev stage bound only for that scheme
    const bool chebyshev = f.has("scheme") && f.given("scheme") == "chebyshev";
    {
      Reader a = f.child("adaptive");
      AdaptiveStep& q = p.adaptive;
      q.enabled = a.boolean("enabled", false);
      q.cfl = a.number("cfl", 0.25, Range::open(0.0, 2.0));
      q.tolerance = a.number("tolerance", 1e-3, Range::open(0.0, 1.0));
      q.dt_max = a.quantity("dt_max", "s", "16 ms", Range::positive());
      q.dt_min = a.quantity("dt_min", "s", "1 us", Range::positive());
      q.event_dt = a.quantity("event_dt", "s", "0.25 ms", Range::positive());
      q.stability_fraction = a.number("stability_fraction", 0.5, Range::open(0.0, 1.0));
      if (chebyshev)
        q.max_stages = int(a.integer("max_stages", 8, 1, 32));
      else if (a.has("max_stages"))
        throw InputError(a.path("max_stages"), scene::show(a.given("max_stages")), "only with full3d.scheme = chebyshev (the stages of its steps)");
      if (!(q.dt_min <= q.event_dt && q.event_dt <= q.dt_max))
        throw InputError(a.path("event_dt"), fmt(q.event_dt, "s"),
                         "must lie between full3d.adaptive.dt_min = " + fmt(q.dt_min, "s") +
                             " and full3d.adaptive.dt_max = " + fmt(q.dt_max, "s"));
      a.finish();
    }
    {
      const std::string scheme = f.choice("scheme", "forward_euler", {"forward_euler", "midpoint", "chebyshev"});
      p.scheme = scheme == "midpoint"    ? IbScheme::Midpoint
                 : scheme == "chebyshev" ? IbScheme::Chebyshev
                                         : IbScheme::ForwardEuler;
      p.wall_stabilization =
          wall_stabilization_from(f.choice("wall_stabilization", "none", {"none", "bending"}));
      p.stabilization_factor = f.number("stabilization_factor", 1.0, Range::closed(0.1, 100.0));
      p.memory_limit_gib = f.number("memory_limit_gib", 4.0, Range::closed(0.125, 1024.0));
      if (p.wall_stabilization != WallStabilization::None && p.scheme != IbScheme::ForwardEuler)
        throw InputError("full3d.wall_stabilization", to_string(p.wall_stabilization),
                         "only with full3d.scheme = forward_euler (the stabilised update is a forward-Euler step); "
                         "set full3d.wall_stabilization = \"none\" or full3d.scheme = forward_euler");
    }
    {
      Reader m = f.child("membrane");
      p.bending_model = m.choice("bending_model", "rigidity", {"rigidity", "fixed_kb"}) == "fixed_kb"
                            ? Params3d::BendingModel::FixedKb
                            : Params3d::BendingModel::Rigidity;
      const bool fixed_kb = p.bending_model == Params3d::BendingModel::FixedKb;
      if (m.has("bending_rigidity")) {
        p.bending_rigidity = m.quantity("bending_rigidity", "J", "", Range::positive());
        if (m.has("bending_constant"))
          throw InputError(m.path("bending_rigidity"), fmt(p.bending_rigidity, "J"),
                           "give either full3d.membrane.bending_constant (eq. 8's k_b, N) or "
                           "full3d.membrane.bending_rigidity (the wall's rigidity D, J), not both");
        if (fixed_kb)
          throw InputError(m.path("bending_rigidity"), fmt(p.bending_rigidity, "J"),
                           "a wall given by its bending rigidity cannot also have the fixed k_b of "
                           "full3d.membrane.bending_model = \"fixed_kb\" (the paper's literal eq. 8): "
                           "remove one of full3d.membrane.bending_rigidity and full3d.membrane.bending_model");
        if (m.has("reference_edge"))
          throw InputError(m.path("reference_edge"), fmt(m.quantity("reference_edge", "m", "", Range::positive()), "m"),
                           "maps full3d.membrane.bending_constant to the rigidity D; not used with "
                           "full3d.membrane.bending_rigidity (remove one of the two)");
        p.bending_source = "full3d.membrane.bending_rigidity";
      } else {
        p.membrane.kb = m.quantity("bending_constant", "N", "1e-15 N", Range::non_negative());
        if (fixed_kb) {
          if (m.has("reference_edge"))
            throw InputError(m.path("reference_edge"), fmt(m.quantity("reference_edge", "m", "", Range::positive()), "m"),
                             "maps full3d.membrane.bending_constant to the rigidity D; not used with "
                             "full3d.membrane.bending_model = \"fixed_kb\" (remove one of the two)");
        } else {
          p.reference_edge = m.quantity("reference_edge", "m", fmt(kDefaultReferenceEdge, "m"), Range::positive());
          if (!(p.reference_edge >= 0.01 * R0 && p.reference_edge <= R0))
            throw InputError(m.path("reference_edge"), fmt(p.reference_edge, "m"),
                             "between 0.01 swimmer.radius and swimmer.radius (" + fmt(0.01 * R0, "m") + " to " +
                                 fmt(R0, "m") + ")");
        }
      }
      if (m.has("seed_mode") && m.given("seed_mode").is_string()) {
        p.seed_auto = m.choice("seed_mode", "auto", {"auto"}) == "auto";  // resolved below, once D is known
      } else {
        p.seed_mode = int(m.integer("seed_mode", 0, 0, 64));
        if (p.seed_mode == 1)
          throw InputError(m.path("seed_mode"), "1",
                           "0 (no seed), a lobe number >= 2 (m = 1 is a sideways shift of the ring, not a lobe) or "
                           "\"auto\"");
      }
      p.seed_amplitude = m.number("seed_amplitude", p.seed_auto ? kAutoSeedAmplitude : 0.0, Range::closed(0.0, 0.1));
      if (p.seed_amplitude > 0.0 && p.seed_mode == 0 && !p.seed_auto)
        throw InputError(m.path("seed_amplitude"), fmt(p.seed_amplitude, ""),
                         "a seed needs its lobe number: give full3d.membrane.seed_mode >= 2 as well");
      p.secondary_seed_mode = int(m.integer("secondary_seed_mode", 0, 0, 64));
      if (p.secondary_seed_mode == 1)
        throw InputError(m.path("secondary_seed_mode"), "1",
                         "0 (no secondary seed) or a lobe number >= 2 (m = 1 is a sideways shift of the ring)");
      p.secondary_seed_amplitude = m.number("secondary_seed_amplitude", 0.0, Range::closed(0.0, 0.1));
      if ((p.secondary_seed_amplitude > 0.0) != (p.secondary_seed_mode > 0))
        throw InputError(p.secondary_seed_mode > 0 ? m.path("secondary_seed_mode") : m.path("secondary_seed_amplitude"),
                         p.secondary_seed_mode > 0 ? std::to_string(p.secondary_seed_mode)
                                                   : fmt(p.secondary_seed_amplitude, ""),
                         "a secondary seed needs both its lobe number (full3d.membrane.secondary_seed_mode >= 2) "
                         "and its amplitude (full3d.membrane.secondary_seed_amplitude > 0)");
      if (p.secondary_seed_mode > 0 && p.secondary_seed_mode == p.seed_mode)
        throw InputError(m.path("secondary_seed_mode"), std::to_string(p.secondary_seed_mode),
                         "a lobe number other than full3d.membrane.seed_mode's (" + std::to_string(p.seed_mode) + ")");
      p.membrane.bending = m.choice("bending_form", "reference_angle", {"reference_angle", "printed"}) == "printed"
                               ? BendingForm::Printed
                               : BendingForm::ReferenceAngle;
      p.spacing_factor = m.number("spacing_factor", 0.6, Range::open(0.0, 1.0));
      p.ring_nodes_multiple = int(m.integer("ring_nodes_multiple", 1, 1, 64));
      p.axisymmetric_wall = m.boolean("axisymmetric", false);
      m.finish();
    }
    p.wall_inertia = f.boolean("wall_inertia", false);
    p.navier_stokes = f.boolean("navier_stokes", false);
    p.recovery_end = f.choice("recovery_end", "dead_band", {"energy", "dead_band", "shape"});
    p.protocol.shape_end = p.recovery_end == "shape";
    p.dry = f.boolean("dry", false);
    p.dry_damping = f.quantity("dry_damping", "kg/(m^2*s)", "1e4 kg/(m^2*s)", Range::non_negative());
    p.max_cfl = f.number("max_cfl", 0.5, Range::open(0.0, 2.0));
    if (p.adaptive.enabled && !(p.adaptive.cfl < p.max_cfl))
      throw InputError("full3d.adaptive.cfl", fmt(p.adaptive.cfl, ""),
                       "must be below the CFL guard full3d.max_cfl = " + fmt(p.max_cfl, ""));
    p.energy_growth = f.number("energy_growth_limit", 50.0, Range::open(1.0, 1e12));
    p.time_limit = f.quantity("time_limit", "s", "2 s", Range::positive());
    {
      Reader o = f.child("output");
      p.vtk = o.boolean("vtk", true);
      p.vtk_interval = o.quantity("vtk_interval", "s", fmt(p.output_interval, "s"), Range::positive());
      p.fluid_fields = o.boolean("fluid_fields", false);
      // every fluid frame falls on a membrane frame: the default is the membrane's interval
      // rounded up to a whole multiple of it that is at least 10 output intervals, and a given
      // interval must be a whole multiple of vtk_interval
      const double k_default = std::max(1.0, std::ceil(10.0 * p.output_interval / p.vtk_interval - 1e-9));
      p.fluid_interval =
          o.quantity("fluid_interval", "s", fmt(k_default * p.vtk_interval, "s"), Range::positive());
      const double k = p.fluid_interval / p.vtk_interval;
      if (!(k >= 1.0 - 1e-9) || std::abs(k - std::round(k)) > 1e-6 * k)
        throw InputError(o.path("fluid_interval"), fmt(p.fluid_interval, "s"),
                         "a whole multiple of full3d.output.vtk_interval (" + fmt(p.vtk_interval, "s") +
                             "), so that every fluid frame has a membrane frame at the same time");
      o.finish();
    }
    p.checkpoint_interval =
        f.quantity("checkpoint_interval", "s", fmt(10.0 * p.output_interval, "s"), Range::positive());
    p.threads = static_cast<int>(f.integer("threads", 1, 1, 256));
    f.finish();
  }
  scene::read_output(top);
  top.finish();

  // Consistency (before anything is written).
  if (p.dry && p.dry_damping == 0.0 && p.duration <= 0)
    throw InputError("full3d.dry_damping", "0 kg/(m^2*s)",
                     "an undamped dry swimmer never recovers (the energy criterion is never met): give a positive "
                     "damping or a time.duration");
  if (p.dry && p.adaptive.enabled)
    throw InputError("full3d.adaptive.enabled", "true",
                     "the adaptive step controls the fluid-coupled run; the dry swimmer uses the fixed full3d.dt");
  if (p.scheme == IbScheme::Chebyshev) {
    // the stage count follows the adaptive step's estimate of the coupling's stiffest rate
    if (!p.adaptive.enabled)
      throw InputError("full3d.scheme", "chebyshev",
                       "the Chebyshev stages are chosen by the adaptive step (full3d.adaptive.enabled = true); "
                       "with a fixed full3d.dt use forward_euler or midpoint");
    if (p.wall_inertia)
      throw InputError("full3d.scheme", "chebyshev",
                       "not with full3d.wall_inertia = true (the lagged node inertia has its own explicit limit); "
                       "use forward_euler or midpoint");
  }
  if (p.dry && !(p.mass_per_area > 0))
    throw InputError("wall.mass_per_area", "", "the dry swimmer needs a positive wall mass");
  if (!(R0 + 2.0 * p.h < p.container_radius))
    throw InputError("container.radius", fmt(p.container_radius, "m"),
                     "the swimmer must fit: swimmer.radius + 2 h (kernel support) = " + fmt(R0 + 2.0 * p.h, "m") +
                         " must be below the container radius (h = " + fmt(p.h, "m") + ")");
  if (!(L + 4.0 * p.h < p.nx * p.h))
    throw InputError("container.period", fmt(p.period, "m"),
                     "must exceed swimmer.length + 4 h = " + fmt(L + 4.0 * p.h, "m") +
                         " so that the swimmer's ends do not interact through the periodic boundary");
  if (p.nx * double(p.ny) * p.nz > 2.0e8)
    throw InputError("full3d.grid", std::to_string(p.nx) + "x" + std::to_string(p.ny) + "x" + std::to_string(p.nz),
                     "more than 2e8 cells; use a coarser grid");
  const double edge_bound = p.spacing_factor * 0.5 * p.h;
  if (!(edge_bound > 1e-3 * R0))
    throw InputError("full3d.membrane.spacing_factor", fmt(p.spacing_factor, ""), "gives a node spacing below 1e-3 R0");
  const CylinderMesh mesh = make_mesh(p);
  if (!(max_edge_length(mesh, mesh.X0) < 0.5 * p.h))
    throw InputError("full3d.membrane.spacing_factor", fmt(p.spacing_factor, ""),
                     "the mesh spacing must be below h/2 (no-leak rule)");
  if (mesh.nodes() > 2000000)
    throw InputError("full3d.grid", "", "the membrane would have more than 2e6 nodes; use a coarser grid");
  Protocol3d check(p.protocol, mesh, 1.0);  // every segment must hold a ring
  // The wall's bending rigidity D and eq. (8)'s k_b on this mesh (D / k_b scales with the edge
  // length; measured on the unseeded mesh, the seed being an imperfection of the same wall)
  const double per_kb_run = bending_rigidity_per_kb(
      p.seed_amplitude > 0.0 || p.secondary_seed_amplitude > 0.0 ? make_round_mesh(p) : mesh,
      p.membrane.bending);
  if (p.bending_model == Params3d::BendingModel::FixedKb) {
    p.bending_rigidity = p.membrane.kb * per_kb_run;
    p.bending_source = "full3d.membrane.bending_constant " + fmt(p.membrane.kb, "N") +
                       " fixed on every mesh (bending_model fixed_kb; n_theta " + std::to_string(mesh.n_theta) + ")";
  } else {
    if (!(p.bending_rigidity > 0.0)) {
      p.bending_rigidity = p.membrane.kb * reference_rigidity_per_kb(p.R0, p.L, p.reference_edge, p.membrane.bending);
      p.bending_source = "full3d.membrane.bending_constant " + fmt(p.membrane.kb, "N") + " at reference_edge " +
                         fmt(p.reference_edge, "m");
    }
    p.membrane.kb = p.bending_rigidity / per_kb_run;
  }
  if (p.seed_auto) {
    p.seed_mode = auto_seed_mode(p);
    if (p.seed_mode == 0) p.seed_amplitude = 0.0;
    if (!(2 * p.seed_mode < mesh.n_theta))
      throw InputError("full3d.membrane.seed_mode", "\"auto\"",
                       "the buckling estimate's mode " + std::to_string(p.seed_mode) + " needs more than " +
                           std::to_string(2 * p.seed_mode) + " nodes per ring; this grid has " +
                           std::to_string(mesh.n_theta) + " (refine full3d.grid.cells_across or give a lobe number)");
    if (p.secondary_seed_mode > 0 && p.secondary_seed_mode == p.seed_mode)
      throw InputError("full3d.membrane.secondary_seed_mode", std::to_string(p.secondary_seed_mode),
                       "a lobe number other than the one full3d.membrane.seed_mode = \"auto\" resolves to (" +
                           std::to_string(p.seed_mode) + ")");
  }
  return p;
}

std::vector<ContractionStage> scene_contraction_buckling(const Params3d& p) {
  const double Y = 2.0 * p.membrane.ks / std::sqrt(3.0);  // the equilateral network's 2D Young's modulus
  return contraction_buckling(p.L, p.protocol.segments, p.protocol.first_ratio, p.protocol.R_f, p.protocol.q * p.R0,
                              p.bending_rigidity, Y, p.fluid.mu);
}

int auto_seed_mode(const Params3d& p) {
  if (p.axisymmetric_wall || p.dry || !(p.protocol.q > 0.0)) return 0;
  int mode = 0;
  double rate = 0.0;
  for (const auto& s : scene_contraction_buckling(p))
    if (s.mode > 0 && s.growth_rate > rate) rate = s.growth_rate, mode = s.mode;
  return mode;
}

}  // namespace swim::full3d
