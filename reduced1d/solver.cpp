#include "reduced1d/solver.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "common/si_format.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/outer_flow.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/recorded_wave.hpp"
#include "reduced1d/tube_law.hpp"
#include "common/errors.hpp"

namespace swim::reduced1d {

namespace detail {

namespace {
void require(bool ok, const char* key, double value, const char* allowed) {
  if (!ok || std::isnan(value)) throw InputError(key, significant(value), allowed);
}
}  // namespace

void validate(const Params& p) {
  const double R0 = p.geometry.R0;
  require(p.geometry.R0 > 0 && std::isfinite(R0), "swimmer.radius", R0, "must be a positive length");
  require(p.geometry.L > 0 && std::isfinite(p.geometry.L), "swimmer.length", p.geometry.L,
          "must be a positive length");
  require(p.fluid.mu > 0 && std::isfinite(p.fluid.mu), "fluid.viscosity", p.fluid.mu, "must be positive");
  require(p.fluid.rho >= 0 && std::isfinite(p.fluid.rho), "fluid.density", p.fluid.rho, "must be >= 0");
  require(p.wall.C1 > 0 && std::isfinite(p.wall.C1), "wall.C1", p.wall.C1, "must be positive");
  require(p.wall.m > 0 && std::isfinite(p.wall.m), "wall.mass_per_area", p.wall.m, "must be positive");
  if (p.wall.law && (p.swimmer.model != SwimmerModel::ForceFree || p.wave != WaveKind::ForceDriven))
    throw InputError("wall.law", "a calibrated tube law",
                     "is available for the force-free model with the force-driven wave only");
  if (p.wall.law && !(std::abs(p.wall.law->R0() / R0 - 1.0) <= 1e-12))
    throw InputError("wall.law", "a tube law of R0 = " + std::to_string(p.wall.law->R0()) + " m",
                     "the law's undeformed radius must be swimmer.radius");
  require(p.numerics.cells >= 2, "numerics1d.cells", p.numerics.cells, "must be >= 2");
  require(p.numerics.rtol > 0 && p.numerics.rtol < 1, "numerics1d.rtol", p.numerics.rtol,
          "must be in (0, 1)");
  require(p.numerics.atol_scale > 0 && p.numerics.atol_scale < 1, "numerics1d.atol_scale",
          p.numerics.atol_scale, "must be in (0, 1)");
  require(p.numerics.output_interval > 0, "time.output_interval", p.numerics.output_interval,
          "must be positive");
  require(p.numerics.max_steps > 0, "numerics1d.max_steps", double(p.numerics.max_steps),
          "must be positive");
  require(p.duration >= 0 && std::isfinite(p.duration), "time.duration", p.duration, "must be >= 0");
  if (p.swimmer.model == SwimmerModel::ForceFree && p.swimmer.outer == OuterFlow::Confined) {
    require(p.container.radius_eff > R0 + p.swimmer.a_out, "container.radius", p.container.radius,
            "must exceed swimmer.radius + model1d.hydraulic_offsets.outer");
    require(p.container.period > p.geometry.L, "container.period", p.container.period,
            "must exceed swimmer.length");
  }
  require(p.swimmer.a_in >= 0 && p.swimmer.a_in < 0.5 * R0, "model1d.hydraulic_offsets.inner", p.swimmer.a_in,
          "must be in [0, R0/2)");
  if (p.wall.inertia && p.swimmer.model == SwimmerModel::ForceFree && p.swimmer.outer == OuterFlow::Confined)
    throw InputError("model1d.wall_inertia", "true", "not available with the confined force-free model");
  require(p.swimmer.a_out >= 0, "model1d.hydraulic_offsets.outer", p.swimmer.a_out, "must be >= 0");
  if ((p.swimmer.end_junction || p.swimmer.end_lumen > 0 || p.swimmer.end_annulus > 0) &&
      (p.swimmer.model != SwimmerModel::ForceFree || p.swimmer.outer != OuterFlow::Confined))
    throw InputError("model1d.end_effects", p.swimmer.end_junction ? "\"junction\"" : "\"open_ends\"",
                     "the open ends' flow is modelled for the confined force-free model");
  if (p.wave == WaveKind::ForceDriven && (p.swimmer.end_lumen > 0 || p.swimmer.end_annulus > 0))
    throw InputError("model1d.end_effects", "\"open_ends\"",
                     "with wave.kind = \"force_driven\" the open ends are modelled by the calibrated junction");
  switch (p.wave) {
    case WaveKind::Step:
      require(p.step.R_min > 0, "wave.contracted_radius", p.step.R_min, "must be positive");
      require(p.step.speed > 0, "wave.speed", p.step.speed, "must be positive");
      require(p.step.width > 0, "wave.width", p.step.width, "must be positive");
      break;
    case WaveKind::Sine:
      require(p.sine.amplitude >= 0 && p.sine.amplitude < R0, "wave.contracted_radius", p.sine.amplitude,
              "must be in [0, R0)");
      require(p.sine.wavelength > 0, "wave.wavelength", p.sine.wavelength, "must be positive");
      require(p.sine.speed > 0, "wave.speed", p.sine.speed, "must be positive");
      break;
    case WaveKind::Recorded:
      if (!p.recorded || p.recorded->t.size() < 2 || p.recorded->z.size() < 2 || !(p.recorded->period() > 0))
        throw InputError("wave.radius_file", "a record", "must hold at least 2 times and 2 rings");
      require(p.recorded->min_radius() > 0, "wave.radius_file", p.recorded->min_radius(),
              "the recorded radius must be positive");
      break;
    case WaveKind::ForceDriven: {
      const auto& q = p.protocol;
      require(q.R_f > 0 && q.R_f < R0, "wave.contracted_radius", q.R_f, "must be in (0, R0)");
      require(q.q > 0 && std::isfinite(q.q), "protocol.pressure", q.q, "must be a positive pressure");
      require(q.segments >= 2, "protocol.segments", q.segments, "must be >= 2");
      require(q.first_ratio > 0 && std::isfinite(q.first_ratio), "protocol.first_segment_ratio",
              q.first_ratio, "must be positive");
      require(q.delta > 0 && q.delta < 0.2 * R0 && q.delta < q.R_f && q.delta < R0 - q.R_f,
              "protocol.tolerance_ratio", q.delta,
              "must be positive and below 0.2 R0, R_f and R0 - R_f (the bands must be ordered)");
      require(q.energy_tol > 0 && q.energy_tol < 1, "protocol.energy_tolerance", q.energy_tol,
              "must be in (0, 1)");
      require(q.cycles >= 1, "protocol.cycles", q.cycles, "must be >= 1");
      const auto b = segment_bounds(p);
      double shortest = b[1] - b[0];
      for (int k = 0; k < q.segments; ++k) shortest = std::min(shortest, b[k + 1] - b[k]);
      const int needed = static_cast<int>(std::ceil(p.geometry.L / shortest - 1e-9));
      if (p.numerics.cells < needed)
        throw InputError("numerics1d.cells", std::to_string(p.numerics.cells),
                         "must be >= " + std::to_string(needed) +
                             " so that the cell width does not exceed the shortest protocol segment");
      break;
    }
  }
}

double relaxation_time(const Params& p) {
  const double R0 = p.geometry.R0, L = p.geometry.L;
  return 16.0 * p.fluid.mu * L * L / (p.wall.C1 * R0 * R0 * R0);
}

std::vector<double> segment_bounds(const Params& p) {
  const int n = p.protocol.segments;
  const double L = p.geometry.L;
  const double ell = L / (n - 1 + p.protocol.first_ratio);  // length of segments 0..n-2
  std::vector<double> b(n + 1);
  for (int k = 0; k < n; ++k) b[k] = k * ell;
  b[n] = L;
  return b;
}

std::vector<CellOverlap> segment_overlaps(const Params& p) {
  const int N = p.numerics.cells, n = p.protocol.segments;
  const double h = p.geometry.L / N;
  const auto b = segment_bounds(p);
  std::vector<CellOverlap> out(N);
  int k = 0;
  for (int i = 0; i < N; ++i) {
    const double z0 = i * h, z1 = (i + 1) * h;
    while (k < n - 1 && b[k + 1] <= z0) ++k;
    CellOverlap c;
    c.seg_a = k;
    if (k < n - 1 && b[k + 1] < z1) {
      c.seg_b = k + 1;
      c.w = std::clamp((b[k + 1] - z0) / h, 0.0, 1.0);
    } else {
      c.seg_b = k;
      c.w = 1.0;
    }
    out[i] = c;
  }
  return out;
}

}  // namespace detail

double end_time(const Params& p) {
  if (p.duration > 0) return p.duration;
  switch (p.wave) {
    case WaveKind::Step:
      return p.geometry.L / p.step.speed;
    case WaveKind::Sine:
      return p.sine.wavelength / p.sine.speed;
    case WaveKind::Recorded:
      return p.recorded ? p.recorded->period() : 0.0;
    case WaveKind::ForceDriven:
    default: {
      // Upper bound for a run of protocol.cycles cycles (docs/reduced1d.md, "End time"):
      // tau (R0/R_f)^3 is the relaxation time of the tube narrowed to R_f, and the log term
      // grows as q approaches the least pressure C1 (R0 - R_f) that can reach R_f.
      const double R0 = p.geometry.R0;
      const double Rf = p.protocol.R_f;
      double tau = detail::relaxation_time(p) * std::pow(R0 / Rf, 3);
      // The short-wave traction resists a wall motion of wavenumber k by 4 mu k, whatever
      // the radius: on the segment scale k = pi n / L that adds 4 mu pi n / (C1 L).
      if (p.swimmer.model == SwimmerModel::ForceFree && p.swimmer.short_wave_traction)
        tau += 4.0 * p.fluid.mu * M_PI * p.protocol.segments / (p.wall.C1 * p.geometry.L);
      const double need = p.wall.law ? -detail::wall_law(p)(Rf) : p.wall.C1 * (R0 - Rf);
      const double margin = need / std::max(p.protocol.q - need, 1e-12 * need);
      return p.protocol.cycles * 5.0 * tau * (1.0 + std::log1p(std::min(margin, 1e6)));
    }
  }
}

bool finite(const Sample& s) {
  for (double v : {s.t, s.X, s.W, s.energy, s.R_min, s.R_max, s.Q_rear, s.Q_front, s.V_rear, s.V_front,
                   s.tube_volume, s.p_rear, s.p_front, s.Q_total, s.F_lumen, s.F_outer, s.V_rear_lab, s.V_front_lab})
    if (!std::isfinite(v)) return false;
  return true;
}

double straight_tube_drag(const Params& p) {
  if (p.swimmer.model != SwimmerModel::ForceFree) return 0.0;
  const double R0 = p.geometry.R0, L = p.geometry.L, mu = p.fluid.mu;
  if (p.swimmer.outer == OuterFlow::Unbounded) return outer::slender_drag_per_length(L, R0, mu) * L;
  return outer::confined_drag_coefficient(R0, L, p.swimmer.a_in, p.swimmer.a_out, p.container.radius_eff,
                                          p.container.period, mu);
}

namespace detail {
void emit(Result& res, const Output& out, const Sample& s, const double* R, int N, double t_end) {
  if (out.record) {
    out.record->add_row(series_row(s));
    out.record->add_radius(s.t, {R, std::size_t(N)});
  }
  if (out.keep_samples) {
    res.series.push_back(s);
    res.radius_times.push_back(s.t);
    res.radius.insert(res.radius.end(), R, R + N);
  }
  if (out.progress) out.progress(s.t, t_end);
}
}  // namespace detail

const std::vector<std::string>& series_columns() {
  static const std::vector<std::string> c = [] {
    std::vector<std::string> v = record::common_series_columns();
    for (const char* k : {"pressure_rear_Pa", "pressure_front_Pa", "flux_total_m3_per_s", "force_lumen_N",
                          "force_outer_N", "volume_rear_lab_m3", "volume_front_lab_m3"})
      v.push_back(k);
    return v;
  }();
  return c;
}

std::vector<double> series_row(const Sample& s) {
  return {s.t,       s.X,       s.W,         s.energy,  s.R_min,   s.R_max,      s.Q_rear,      s.Q_front,
          s.V_rear,  s.V_front, s.tube_volume, double(s.phase), s.p_rear, s.p_front, s.Q_total, s.F_lumen,
          s.F_outer, s.V_rear_lab, s.V_front_lab};
}

namespace {
std::string model_name(const Params& p) {
  if (p.swimmer.model == SwimmerModel::Paper) return "paper";
  return p.swimmer.outer == OuterFlow::Confined ? "force_free_confined" : "force_free_unbounded";
}
std::vector<double> cell_centres(const Params& p) {
  const int N = p.numerics.cells;
  std::vector<double> z(N);
  for (int i = 0; i < N; ++i) z[i] = (i + 0.5) * p.geometry.L / N;
  return z;
}

/// What the solver leaves in the Result and not in the record: events, status, plausibility.
void finish_record(const Params& p, const Result& r, record::RunRecord& rec) {
  rec.events.segment_reached_s = r.segment_reached;
  rec.events.switches = r.switches;
  rec.status = r.failure ? "failed: " + std::string(r.failure->what()) : "ok";
  rec.transit_is_cycle = p.wave != WaveKind::ForceDriven && !r.failure && rec.series.count() > 0 &&
                         rec.t_end() >= end_time(p) * (1 - 1e-9);
  // the paper's inertial model is exempt from the Stokes-flow bound
  if (p.swimmer.model == SwimmerModel::ForceFree) record::check_plausible(rec, {p.fluid.rho, p.fluid.mu});
  else rec.implausible.clear();
  for (const auto& [k, v] : r.stats) rec.stats[k] = v;
  rec.stats["protocol_switches"] = r.switches;
}
}  // namespace

record::RunRecord new_record(const Params& p) {
  return record::RunRecord("1d", model_name(p), p.geometry.L, series_columns(), cell_centres(p));
}

record::RunRecord record_of(const Params& p, const Result& r) {
  record::RunRecord rec = new_record(p);
  const std::size_t n = rec.radius.z().size();
  record::replay(
      rec, r.series.size(), [&](std::size_t k) { return r.series[k].t; },
      [&](std::size_t k) {
        rec.add_row(series_row(r.series[k]));
        if (k < r.radius_times.size()) rec.add_radius(r.radius_times[k], {r.radius.data() + k * n, n});
      },
      r.cycle_start, r.cycle_end);
  finish_record(p, r, rec);
  return rec;
}

Result solve(const Params& params, const SolveOptions& o) {
  detail::validate(params);
  record::RunRecord rec = new_record(params);
  rec.keep(o.keep_record_rows);
  rec.attach(o.stream);
  detail::Output out(o.progress);
  out.keep_samples = o.keep_samples;
  out.record = &rec;
  Result r = params.wave == WaveKind::ForceDriven ? detail::solve_force_driven(params, out)
                                                  : detail::solve_prescribed(params, out);
  r.drag_coefficient = straight_tube_drag(params);
  finish_record(params, r, rec);
  r.record = std::move(rec);  // still attached to the caller's stream, which write_run commits
  return r;
}

Result solve(const Params& params, const ProgressFn& progress) {
  SolveOptions o;
  o.progress = progress;
  return solve(params, o);
}

}  // namespace swim::reduced1d
