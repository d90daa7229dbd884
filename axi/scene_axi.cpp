#include "axi/scene_axi.hpp"

#include <cmath>
#include <numbers>

#include "common/errors.hpp"
#include "common/scene_shared.hpp"
#include "axi/wall_axi.hpp"
#include "full3d/membrane.hpp"

namespace swim::axi {

using scene::json;
using scene::Range;
using scene::Reader;

using scene::multiple_of;

namespace {

std::string fmt(double v, const char* unit) { return scene::format_quantity(v, unit); }

const json& section_or_empty(const json& sc, const char* key) {
  static const json empty = json::object();
  return sc.is_object() && sc.contains(key) ? sc.at(key) : empty;
}

}  // namespace

const json& section_keys() {
  static const json keys = {{"axi",
                             {{"method", "choice:fitted|immersed_boundary"},
                              {"mesh", "choice:quadrilaterals|triangles"},
                              {"remesh_angle", "quantity:rad@(0,0.3490658503988659)"},
                              {"gap_size", "number@[1,8]"},
                              {"remesh_interval", "quantity:s@[0,1]"},
                              {"grid", {{"cells_across", "integer@[8,8192]"}, {"cell_size", "quantity:m@positive"}}},
                              {"spacing_factor", "number@(0,2]"},  // (0, 1) for the immersed boundary
                              {"rim_refinement", "number@positive"},
                              {"tolerance", "number@[1e-6,1)"},
                              {"dt_max", "quantity:s@positive"},
                              {"dt_min", "quantity:s@positive"},
                              {"event_dt", "quantity:s@positive"},
                              {"time_limit", "quantity:s@positive"},
                              {"checkpoint_interval", "quantity:s@positive"},
                              {"threads", "integer@[1,2]"},
                              {"wall_poisson_coupling", "boolean"}}}};
  return keys;
}

FittedMeshParams fitted_mesh_params(const ParamsAxi& p) {
  FittedMeshParams mp;
  mp.Rc = p.base.container_radius;
  mp.period = p.base.period;
  mp.cells_inner = p.cells_inner;
  mp.cells_outer = p.cells_outer;
  mp.gap_columns = p.gap_columns;
  mp.wall_row_aspect = p.wall_row_aspect;
  mp.gap_growth = 4.0;  // the column count is chosen for a ratio near 1 + 5 ds / Rc (read_scene_axi)
  return mp;
}

TriMeshParams tri_mesh_params(const ParamsAxi& p) {
  TriMeshParams t;
  t.Rc = p.base.container_radius;
  t.period = p.base.period;
  t.size = kTriangleSize * p.h;
  t.gap_size = p.gap_size;
  return t;
}

ParamsAxi read_scene_axi(const json& sc, json& resolved) {
  ParamsAxi p;
  // 1. The shared physics, read by the 3D tier's reader (the axi section is passed through).
  // Prescribed waves (step, sine) are read by the shared reader (common/scene_shared.hpp SharedScene).
  p.base = full3d::read_scene3d(sc, resolved, /*prescribed_waves=*/true);
  const full3d::Params3d& b = p.base;
  const json& f3 = section_or_empty(sc, "full3d");
  const json& mem = section_or_empty(f3, "membrane");
  if (!b.axisymmetric_wall)
    throw InputError("full3d.membrane.axisymmetric", mem.contains("axisymmetric") ? scene::show(mem["axisymmetric"]) : "false (default)",
                     "--tier axi solves round-wall scenes only: set full3d.membrane.axisymmetric = true (the 3D tier "
                     "then holds the same wall round), or run the buckling wall with --tier 3d");
  if (b.container != "cylinder")
    throw InputError("container.kind", "\"" + b.container + "\"",
                     "the axisymmetric tier models the rigid circular cylinder only (\"cylinder\"); a box or square "
                     "duct is not axisymmetric: run it with --tier 3d");
  if (b.navier_stokes)
    throw InputError("full3d.navier_stokes", "true", "the axisymmetric tier solves Stokes flow: set it to false");
  if (b.wall_inertia)
    throw InputError("full3d.wall_inertia", "true",
                     "the axisymmetric tier models the force-free wall of creeping flow (no wall inertia): set it to false");
  if (b.dry) throw InputError("full3d.dry", "true", "the dry swimmer is a 3D test of the protocol: run it with --tier 3d");
  if (b.membrane.bending != full3d::BendingForm::ReferenceAngle)
    throw InputError("full3d.membrane.bending_form", "\"printed\"",
                     "the axisymmetric wall measures bending from the reference shape (\"reference_angle\")");

  // 2. The wall's moduli: the network's spring constant and the bending rigidity D of the 3D
  // reader (the scene's D; with full3d.membrane.bending_model = "fixed_kb", what the fixed k_b
  // gives the scene's 3D mesh).
  p.ks = b.membrane.ks;
  if (b.seed_amplitude > 0.0)
    throw InputError("full3d.membrane.seed_amplitude", fmt(b.seed_amplitude, ""),
                     "the axisymmetric tier's wall is round (no lobes): set it to 0 or run --tier 3d");
  if (b.secondary_seed_amplitude > 0.0)
    throw InputError("full3d.membrane.secondary_seed_amplitude", fmt(b.secondary_seed_amplitude, ""),
                     "the axisymmetric tier's wall is round (no lobes): set it to 0 or run --tier 3d");
  p.D = b.bending_rigidity;
  p.bending_source = b.bending_source;

  // 3. The axi section.
  json& res_axi = resolved["axi"];
  res_axi = json::object();
  Reader a(section_or_empty(sc, "axi"), "axi", res_axi);
  const double Rc = b.container_radius, width = 2.0 * Rc;
  p.method = a.choice("method", "fitted", {"fitted", "immersed_boundary"}) == "fitted" ? AxiMethod::Fitted
                                                                                     : AxiMethod::ImmersedBoundary;
  const bool ib = p.method == AxiMethod::ImmersedBoundary;
  if (ib && b.wave.prescribed())
    throw InputError("wave.kind", "\"" + b.wave.kind + "\"",
                     "axi.method = \"immersed_boundary\" runs \"force_driven\" only; the prescribed waves (step, "
                     "sine) run with axi.method = \"fitted\"");
  // fitted: the structured quadrilaterals (rebuilt on every shape) or a triangulation moved with
  // the wall and made again where it degrades (rims that hook, docs/axi.md "Triangles")
  p.triangles = a.choice("mesh", "quadrilaterals", {"quadrilaterals", "triangles"}) == "triangles";
  if (p.triangles && ib)
    throw InputError(a.path("mesh"), "\"triangles\"",
                     "\"quadrilaterals\" (the default, unused) with axi.method = \"immersed_boundary\": the mesh is the "
                     "fitted method's");
  if (p.triangles && b.wave.prescribed())
    throw InputError(a.path("mesh"), "\"triangles\"",
                     "\"quadrilaterals\" with a prescribed wave (wave.kind = " + b.wave.kind +
                         "): the triangulation runs the force-driven protocol");
  // triangles: the smallest angle below which the moved triangulation is made again (the mesher
  // keeps its angles above 20.7 degrees where the wall lets it)
  p.remesh_angle = a.quantity("remesh_angle", "rad", "12 degree", Range::open(0.0, 20.0 * std::numbers::pi / 180.0));
  if (!p.triangles && std::abs(p.remesh_angle - 12.0 * std::numbers::pi / 180.0) > 1e-12)
    throw InputError(a.path("remesh_angle"), fmt(p.remesh_angle, "rad"),
                     "12 degree (the default, unused) unless axi.mesh = \"triangles\"");
  // triangles: the simulated time between scheduled remeshes (0: whenever the mesh degrades)
  p.remesh_interval = a.quantity("remesh_interval", "s", p.triangles ? "10 ms" : "0 s", Range::closed(0.0, 1.0));
  if (!p.triangles && p.remesh_interval != 0.0)
    throw InputError(a.path("remesh_interval"), fmt(p.remesh_interval, "s"),
                     "0 s (the default, unused) unless axi.mesh = \"triangles\"");
  // triangles: how much larger than h the triangles may grow in the gap between the tube's ends
  p.gap_size = a.number("gap_size", kGapSize, Range::closed(1.0, 8.0));
  if (!p.triangles && p.gap_size != kGapSize)
    throw InputError(a.path("gap_size"), fmt(p.gap_size, ""),
                     fmt(kGapSize, "") + " (the default, unused) unless axi.mesh = \"triangles\" (the structured mesh grades its "
                     "gap columns itself)");
  {
    Reader g = a.child("grid");
    if (scene::one_of(g, {"cells_across", "cell_size"}, "cells_across") == "cell_size") {
      p.h = g.quantity("cell_size", "m", "", Range::positive());
      if (!multiple_of(Rc, p.h))
        throw InputError(g.path("cell_size"), fmt(p.h, "m"), "must divide the container radius " + fmt(Rc, "m"));
    } else {
      const long n = g.integer("cells_across", ib ? 64 : 32, 8, 8192);
      if (n % 2 != 0)
        throw InputError(g.path("cells_across"), std::to_string(n),
                         "an even number (cells across the container's diameter; the axisymmetric grid spans its radius)");
      p.h = width / double(n);
    }
    if (ib && !multiple_of(b.period, p.h))
      throw InputError("container.period", fmt(b.period, "m"), "must be a multiple of the cell size " + fmt(p.h, "m"));
    p.nr = int(std::lround(Rc / p.h));
    p.nx = int(std::lround(b.period / p.h));
    if (ib && p.nx % 2 != 0)
      throw InputError("container.period", fmt(b.period, "m"),
                       "must hold an even number of cells (" + std::to_string(p.nx) + " of " + fmt(p.h, "m") + ")");
    g.finish();
  }
  // meridional wall node spacing <= spacing_factor * h / 2: the immersed boundary needs several
  // nodes per cell (default 4); the fitted mesh has one element column per wall segment
  // (default 2 per h: the wall's bending boundary layers are shorter than the fluid's scales)
  p.spacing_factor = ib ? a.number("spacing_factor", 0.5, Range::open(0.0, 1.0))
                        : a.number("spacing_factor", 1.0, Range::open(0.0, 2.0 + 1e-12));
  // fitted: the rings are refined geometrically (ratio 1.5) towards the tube's two rims, the end
  // segments min(1, rim_refinement h / R0) times the interior spacing: the flow is singular at
  // the wall's free edge, and an end spacing proportional to h^2 keeps its error second order
  const double rim = a.number("rim_refinement", 1.0, Range::positive());
  if (ib && rim != 1.0)
    throw InputError(a.path("rim_refinement"), fmt(rim, ""),
                     "1 (the default, unused) with axi.method = immersed_boundary: its rings are uniform; the rim "
                     "refinement is the fitted method's");
  // local position error per step in cells: the explicit immersed boundary's steps are bounded
  // by its stability anyway; the fitted method's Rosenbrock steps by the tolerance alone (at
  // 2e-3 h its time error is 1e-5 of the displacement and 1e-3 of the cycle time, docs/axi.md)
  // (a prescribed wave: the quadrature's error in the displacement over the whole run, in cells)
  // (below 1e-6 cells a cycle would take hundreds of times the default's steps, for a time error
  // far below the grids': refused rather than run for days)
  p.tolerance = a.number("tolerance", ib ? 2e-4 : (b.wave.prescribed() ? kPrescribedTolerance : 2e-3),
                         Range{kMinTolerance, 1.0, false, true});
  p.dt_max = a.quantity("dt_max", "s", "8 ms", Range::positive());
  p.dt_min = a.quantity("dt_min", "s", "10 ns", Range::positive());
  p.event_dt = a.quantity("event_dt", "s", "0.1 ms", Range::positive());
  if (!(p.dt_min <= p.event_dt && p.event_dt <= p.dt_max))
    throw InputError(a.path("event_dt"), fmt(p.event_dt, "s"),
                     "must lie between axi.dt_min = " + fmt(p.dt_min, "s") + " and axi.dt_max = " + fmt(p.dt_max, "s"));
  p.time_limit = a.quantity("time_limit", "s", fmt(b.time_limit, "s"), Range::positive());
  // simulated time between checkpoints (a schedule in simulated time keeps a resumed run
  // identical to an uninterrupted one); the 3D tier's default
  p.checkpoint_interval = a.quantity("checkpoint_interval", "s", fmt(10.0 * b.output_interval, "s"), Range::positive());
  // fitted: 2 factors each step's systems on a second thread while the first solves (docs/axi.md
  // "Linear solves"); not part of the physics (the solves stop at the same residual either way)
  p.threads = int(a.integer("threads", 2, 1, 2));
  // a diagnostic of the 1D tier's wall, not the 3D network's: false drops the stretching
  // energy's Poisson coupling (docs/axi.md, "Wall")
  p.poisson_coupling = a.boolean("wall_poisson_coupling", true);
  a.finish();

  // 4. Consistency.
  const double R0 = b.R0, L = b.L;
  if (ib) {
    if (!(R0 + 2.0 * p.h < Rc))
      throw InputError("container.radius", fmt(Rc, "m"),
                       "the swimmer must fit: swimmer.radius + 2 h (kernel support) = " + fmt(R0 + 2.0 * p.h, "m") +
                           " must be below the container radius (h = " + fmt(p.h, "m") + ")");
    if (!(b.protocol.R_f > 2.0 * p.h))
      throw InputError("axi.grid.cells_across", "",
                       "the contracted wall (R_f = " + fmt(b.protocol.R_f, "m") +
                           ") must stay more than 2 cells from the axis: refine the grid (h = " + fmt(p.h, "m") + ")");
    if (!(L + 4.0 * p.h < b.period))
      throw InputError("container.period", fmt(b.period, "m"),
                       "must exceed swimmer.length + 4 h = " + fmt(L + 4.0 * p.h, "m"));
    if (double(p.nr) * p.nx > 4.0e7)
      throw InputError("axi.grid", std::to_string(p.nr) + "x" + std::to_string(p.nx), "more than 4e7 cells; use a coarser grid");
    const double spacing = p.spacing_factor * 0.5 * p.h;
    p.wall_nodes = int(std::ceil(L / spacing)) + 1;
    if (p.wall_nodes > 200000)
      throw InputError("axi.spacing_factor", fmt(p.spacing_factor, ""), "gives more than 2e5 wall nodes");
  } else {
    // The fitted mesh: element rows of about h between the axis and the wall and between the wall
    // and the container, one element column per wall segment, and graded columns across the gap
    // between the tube's ends.
    if (!(R0 + p.h <= Rc))
      throw InputError("container.radius", fmt(Rc, "m"),
                       "the swimmer must fit with one element row outside it: swimmer.radius + h = " + fmt(R0 + p.h, "m") +
                           " must not exceed the container radius (h = " + fmt(p.h, "m") + ")");
    if (!(L + 2.0 * p.h < b.period))
      throw InputError("container.period", fmt(b.period, "m"),
                       "must exceed swimmer.length + 2 h = " + fmt(L + 2.0 * p.h, "m"));
    p.cells_inner = std::max(2, int(std::lround(R0 / p.h)));
    p.cells_outer = std::max(2, int(std::lround((Rc - R0) / p.h)));
    p.rim_refinement = std::min(1.0, rim * p.h / R0);
    if (p.rim_refinement < 1.0) {
      // rows graded towards the wall next to the refined rims (element aspect 2, as the interior's
      // h by h/2), one more row on each side per level of the rims' refinement
      const int levels = int(std::ceil(std::log(1.0 / p.rim_refinement) / std::log(kRimGrowth) - 1e-9));
      p.cells_inner += levels;
      p.cells_outer += levels;
      p.wall_row_aspect = 2.0;
    }
    const double spacing = std::min(L / 4.0, p.spacing_factor * 0.5 * p.h);
    const int uniform_segments = int(std::ceil(L / spacing - 1e-9));
    // the protocol's segment boundaries (Protocol3d's) fall between rings: no ring cell
    // straddles a segment, so the segments' radii and actuation see whole cells on every grid
    std::vector<double> cuts;
    if (!b.wave.prescribed()) {
      const int n = b.protocol.segments;
      const double other = L / (b.protocol.first_ratio + n - 1);
      for (int k = 1; k < n; ++k) cuts.push_back(k * other);
    }
    p.ring_s0 = segment_aligned_ring_positions(L, spacing, p.rim_refinement, kRimGrowth, cuts);
    p.wall_nodes = int(p.ring_s0.size());
    // Gap columns: widths growing geometrically from the wall's interior spacing ds at both ends
    // with the ratio q = 1 + 5 ds / Rc (so that halving ds splits every column: q -> sqrt(q) to
    // first order), as many as fill the gap G: 2 ceil(ln(1 + G (q - 1) / (2 ds)) / ln q); plus
    // as many per end as the rim refinement adds rings (the first gap columns start from the
    // end segment's width).
    {
      const int graded = p.wall_nodes - 1 - uniform_segments;
      const double ds = L / uniform_segments, G = b.period - L, q = 1.0 + 5.0 * ds / Rc;
      const int half = int(std::ceil(std::log(1.0 + G * (q - 1.0) / (2.0 * ds)) / std::log(q)));
      p.gap_columns = std::max(8, 2 * half + std::max(0, graded));
    }
    const double elements = double(p.cells_inner + p.cells_outer) * (p.wall_nodes - 1 + p.gap_columns);
    if (elements > 2.0e6)
      throw InputError("axi.grid", fmt(p.h, "m"), "gives more than 2e6 fitted elements; use a coarser grid");
  }
  return p;
}

}  // namespace swim::axi
