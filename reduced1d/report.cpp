#include "reduced1d/report.hpp"

#include <algorithm>
#include <cmath>

#include "common/output.hpp"
#include "common/run_figures.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/recorded_wave.hpp"

namespace swim::reduced1d {

using scene::json;

namespace {
constexpr double kBoltzmann = 1.380649e-23;  // J/K
}  // namespace

Metrics metrics(const Params& p, const Result& r) {
  Metrics m;
  // every sample of solve() went through its record; a Result of the solver's internal entry
  // points has only its kept samples
  const bool own = r.record.series.count() > 0 || r.series.empty();
  const record::RunRecord built = own ? record::RunRecord{} : record_of(p, r);
  const record::RunRecord& rec = own ? r.record : built;
  const record::Series& s = rec.series;
  if (s.count() == 0) return m;
  // the figures every tier's summary carries, from the one place that computes them
  const record::RunFigures f = record::run_figures(rec);
  m.t_end_s = f.t_end_s;
  m.displacement_m = f.displacement_m;
  m.mean_velocity_m_per_s = f.mean_velocity_m_per_s;
  m.body_lengths_per_s = f.body_lengths_per_s;
  m.final_velocity_m_per_s = f.final_velocity_m_per_s;
  m.pumped_volume_m3 = f.pumped_volume_m3;
  m.pumped_volume_lab_m3 = -s.last()[s.index("volume_rear_lab_m3")];
  m.min_radius_m = f.min_radius_m;
  m.max_velocity_m_per_s = f.max_velocity_m_per_s;
  m.max_displacement_m = f.max_displacement_m;
  const record::CycleFigures& c = f.cycles;
  m.cycles_completed = c.cycles_completed;
  m.cycle_times_s = c.cycle_times_s;
  m.cycle_displacements_m = c.cycle_displacements_m;
  m.has_cycle = c.has_cycle;
  m.no_cycle_reason = c.absent_because;
  if (c.has_cycle) {
    m.mean_cycle_time_s = c.cycle_time_s;
    m.displacement_per_cycle_m = c.displacement_per_cycle_m;
    m.mean_velocity_per_cycle_m_per_s = c.mean_velocity_per_cycle_m_per_s;
  }
  m.switches = rec.events.switches;
  // Brownian scale of the design over one cycle (or the run when no cycle completed).
  m.drag_coefficient_N_s_per_m = r.drag_coefficient;
  const double t_cycle = m.has_cycle ? m.mean_cycle_time_s : m.t_end_s;
  if (r.drag_coefficient > 0 && t_cycle > 0) {
    m.thermal_rms_displacement_m = std::sqrt(2.0 * kBoltzmann * p.fluid.temperature * t_cycle / r.drag_coefficient);
    const double directed = m.has_cycle ? m.displacement_per_cycle_m : m.displacement_m;
    m.directed_to_diffusive = std::abs(directed) / m.thermal_rms_displacement_m;
  }
  m.implausible = rec.implausible;
  return m;
}

json write_run(const std::string& dir, const Params& p, const json& resolved, Result& r, double wall_time_s) {
  // without a stream the files are written from kept rows: from the typed samples when the
  // record kept none (or is empty: a Result of the solver's internal entry points)
  const record::Series& kept = r.record.series;
  if (!r.record.stream() && !r.series.empty() && (kept.count() == 0 || kept.rows() != kept.count()))
    r.record = record_of(p, r);
  const Metrics m = metrics(p, r);
  record::RunRecord& rec = r.record;
  rec.extras = json::object();
  rec.extras["pumped_volume_lab_m3"] = m.pumped_volume_lab_m3;
  rec.extras["brownian"] = {{"temperature_K", p.fluid.temperature},
                            {"drag_coefficient_N_s_per_m", m.drag_coefficient_N_s_per_m},
                            {"thermal_rms_displacement_per_cycle_m", m.thermal_rms_displacement_m},
                            {"directed_to_diffusive_ratio", m.directed_to_diffusive}};
  rec.derived = {{"C1_Pa_per_m", p.wall.C1},
                 {"mass_per_area_kg_per_m2", p.wall.m},
                 {"mass_per_length_kg_per_m", p.wall.m * 2.0 * M_PI * p.geometry.R0},
                 {"aspect_ratio_R0_over_L", p.geometry.R0 / p.geometry.L},
                 {"contracted_ratio", (p.wave == WaveKind::Sine       ? p.geometry.R0 - p.sine.amplitude
                                       : p.wave == WaveKind::Step     ? p.step.R_min
                                       : p.wave == WaveKind::Recorded ? p.recorded->min_radius()
                                                                      : p.protocol.R_f) /
                                          p.geometry.R0},
                 {"actuation_pressure_Pa", p.wave == WaveKind::ForceDriven ? p.protocol.q : 0.0},
                 {"container_radius_1d_m", p.container.radius_eff},
                 {"hydraulic_offset_inner_m", p.swimmer.a_in},
                 {"hydraulic_offset_outer_m", p.swimmer.a_out}};
  if (p.wave == WaveKind::ForceDriven) {
    rec.derived["recovery_end"] = recovery_end_name(p.protocol.recovery_end);
    if (p.protocol.recovery_end != RecoveryEnd::Shape)
      rec.derived["recovery_end_energy_J"] = detail::recovery_end_energy(p);
  }
  rec.wall_time_s = wall_time_s;
  return record::write_run(dir, rec, resolved);
}

}  // namespace swim::reduced1d
