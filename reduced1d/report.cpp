#include "reduced1d/report.hpp"

#include <algorithm>
#include <cmath>

#include "common/output.hpp"

namespace swim::reduced1d {

using scene::json;

namespace {
constexpr double kBoltzmann = 1.380649e-23;  // J/K

/// Centre displacement at time t (linear between output samples).
double x_at(const Result& r, double t) {
  const auto& s = r.series;
  if (s.empty()) return 0.0;
  if (t <= s.front().t) return s.front().X;
  for (std::size_t k = 1; k < s.size(); ++k)
    if (s[k].t >= t) {
      const double w = (t - s[k - 1].t) / std::max(s[k].t - s[k - 1].t, 1e-300);
      return s[k - 1].X + w * (s[k].X - s[k - 1].X);
    }
  return s.back().X;
}

std::string model_name(const Params& p) {
  if (p.swimmer.model == SwimmerModel::Paper) return "paper";
  return p.swimmer.outer == OuterFlow::Confined ? "force_free_confined" : "force_free_unbounded";
}
}  // namespace

Metrics metrics(const Params& p, const Result& r) {
  Metrics m;
  if (r.series.empty()) return m;
  const Sample& last = r.series.back();
  m.t_end_s = last.t;
  m.displacement_m = last.X;
  m.mean_velocity_m_per_s = last.t > 0 ? last.X / last.t : 0.0;
  m.body_lengths_per_s = m.mean_velocity_m_per_s / p.geometry.L;
  m.final_velocity_m_per_s = last.W;
  m.pumped_volume_m3 = -last.V_rear;
  m.pumped_volume_lab_m3 = -last.V_rear_lab;
  m.min_radius_m = last.R_min;
  m.max_velocity_m_per_s = r.series.front().W;
  m.max_displacement_m = r.series.front().X;
  for (const auto& s : r.series) {
    m.max_velocity_m_per_s = std::max(m.max_velocity_m_per_s, s.W);
    m.max_displacement_m = std::max(m.max_displacement_m, s.X);
    m.min_radius_m = std::min(m.min_radius_m, s.R_min);
  }
  m.cycles_completed = static_cast<int>(r.cycle_end.size());
  for (size_t k = 0; k < r.cycle_end.size() && k < r.cycle_start.size(); ++k) {
    m.cycle_times_s.push_back(r.cycle_end[k] - r.cycle_start[k]);
    m.cycle_displacements_m.push_back(x_at(r, r.cycle_end[k]) - x_at(r, r.cycle_start[k]));
  }
  if (!m.cycle_times_s.empty()) {
    double sum = 0, dx = 0;
    for (double c : m.cycle_times_s) sum += c;
    for (double d : m.cycle_displacements_m) dx += d;
    m.mean_cycle_time_s = sum / m.cycle_times_s.size();
    m.displacement_per_cycle_m = dx / m.cycle_displacements_m.size();
    m.mean_velocity_per_cycle_m_per_s = dx / sum;
    m.has_cycle = true;
  } else if (p.wave != WaveKind::ForceDriven && !r.failure && last.t >= end_time(p) * (1 - 1e-9)) {
    // a prescribed wave's "cycle" is its transit over the run
    m.mean_cycle_time_s = last.t;
    m.displacement_per_cycle_m = last.X;
    m.mean_velocity_per_cycle_m_per_s = m.mean_velocity_m_per_s;
    m.has_cycle = true;
  } else {
    m.no_cycle_reason = r.failure ? "the run stopped before completing a cycle"
                                  : "no cycle completed within the run's duration";
  }
  m.switches = r.switches;
  // Brownian scale of the design over one cycle (or the run when no cycle completed).
  m.drag_coefficient_N_s_per_m = r.drag_coefficient;
  const double t_cycle = m.has_cycle ? m.mean_cycle_time_s : last.t;
  if (r.drag_coefficient > 0 && t_cycle > 0) {
    m.thermal_rms_displacement_m = std::sqrt(2.0 * kBoltzmann * p.fluid.temperature * t_cycle / r.drag_coefficient);
    const double directed = m.has_cycle ? m.displacement_per_cycle_m : last.X;
    m.directed_to_diffusive = std::abs(directed) / m.thermal_rms_displacement_m;
  }
  // Plausibility: a peristaltic swimmer cannot outrun its wave; per cycle the wave crosses
  // the tube once (length L), so |displacement per cycle| <= L.
  if (p.swimmer.model == SwimmerModel::ForceFree && m.has_cycle && std::abs(m.displacement_per_cycle_m) > p.geometry.L)
    m.implausible.push_back("displacement per cycle exceeds the wave's travel (the swimmer length)");
  return m;
}

json write_run(const std::string& dir, const Params& p, const json& resolved, const Result& r, double wall_time_s) {
  const Metrics m = metrics(p, r);
  json summary = json::object();
  summary["tier"] = "1d";
  summary["scene"] = resolved;
  summary["status"] = r.failure ? "failed: " + std::string(r.failure->what()) : "ok";
  summary["t_end_s"] = m.t_end_s;
  summary["displacement_m"] = m.displacement_m;
  summary["max_displacement_m"] = m.max_displacement_m;
  summary["cycles_completed"] = m.cycles_completed;
  summary["cycle_times_s"] = m.cycle_times_s;
  summary["cycle_start_times_s"] = r.cycle_start;
  summary["mean_velocity_m_per_s"] = m.mean_velocity_m_per_s;
  summary["body_lengths_per_s"] = m.body_lengths_per_s;
  if (m.has_cycle) {
    summary["displacement_per_cycle_m"] = m.displacement_per_cycle_m;
    summary["mean_velocity_per_cycle_m_per_s"] = m.mean_velocity_per_cycle_m_per_s;
    summary["body_lengths_per_cycle_per_s"] = m.mean_velocity_per_cycle_m_per_s / p.geometry.L;
  } else {
    summary["displacement_per_cycle_m"] = nullptr;
    summary["mean_velocity_per_cycle_m_per_s"] = nullptr;
    summary["body_lengths_per_cycle_per_s"] = nullptr;
    summary["per_cycle_absent_because"] = m.no_cycle_reason;
  }
  summary["cycle_displacements_m"] = m.cycle_displacements_m;
  summary["final_velocity_m_per_s"] = m.final_velocity_m_per_s;
  summary["max_velocity_m_per_s"] = m.max_velocity_m_per_s;
  summary["pumped_volume_m3"] = m.pumped_volume_m3;
  summary["pumped_volume_lab_m3"] = m.pumped_volume_lab_m3;
  summary["min_radius_m"] = m.min_radius_m;
  summary["protocol_switches"] = m.switches;
  summary["segment_reached_s"] = r.segment_reached;
  summary["model1d"] = model_name(p);
  summary["brownian"] = {{"temperature_K", p.fluid.temperature},
                         {"drag_coefficient_N_s_per_m", m.drag_coefficient_N_s_per_m},
                         {"thermal_rms_displacement_per_cycle_m", m.thermal_rms_displacement_m},
                         {"directed_to_diffusive_ratio", m.directed_to_diffusive}};
  summary["plausible"] = m.implausible.empty();
  summary["implausible_because"] = m.implausible;
  summary["derived"] = {{"C1_Pa_per_m", p.wall.C1},
                        {"mass_per_area_kg_per_m2", p.wall.m},
                        {"mass_per_length_kg_per_m", p.wall.m * 2.0 * M_PI * p.geometry.R0},
                        {"aspect_ratio_R0_over_L", p.geometry.R0 / p.geometry.L},
                        {"contracted_ratio", (p.wave == WaveKind::Sine ? p.geometry.R0 - p.sine.amplitude
                                              : p.wave == WaveKind::Step ? p.step.R_min
                                                                         : p.protocol.R_f) /
                                                 p.geometry.R0},
                        {"actuation_pressure_Pa", p.wave == WaveKind::ForceDriven ? p.protocol.q : 0.0},
                        {"container_radius_1d_m", p.container.radius_eff},
                        {"hydraulic_offset_inner_m", p.swimmer.a_in},
                        {"hydraulic_offset_outer_m", p.swimmer.a_out}};
  summary["wall_time_s"] = wall_time_s;

  {
    output::CsvWriter csv(dir + "/series.csv",
                          {"t_s", "x_center_m", "velocity_m_per_s", "energy_J", "min_radius_m", "max_radius_m",
                           "flux_rear_m3_per_s", "flux_front_m3_per_s", "volume_rear_m3", "volume_front_m3",
                           "tube_volume_m3", "pressure_rear_Pa", "pressure_front_Pa", "flux_total_m3_per_s",
                           "force_lumen_N", "force_outer_N", "volume_rear_lab_m3", "volume_front_lab_m3", "phase"});
    for (const auto& s : r.series)
      csv.row({s.t, s.X, s.W, s.energy, s.R_min, s.R_max, s.Q_rear, s.Q_front, s.V_rear, s.V_front, s.tube_volume,
               s.p_rear, s.p_front, s.Q_total, s.F_lumen, s.F_outer, s.V_rear_lab, s.V_front_lab,
               static_cast<double>(s.phase)});
  }
  {
    output::CsvWriter csv(dir + "/radius.csv", {"t_s", "z_m", "radius_m"});
    const size_t n = r.z.size();
    for (size_t k = 0; k < r.radius_times.size(); ++k)
      for (size_t i = 0; i < n; ++i) csv.row({r.radius_times[k], r.z[i], r.radius[k * n + i]});
  }
  json stats = json::object();
  for (const auto& [k, v] : r.stats) stats[k] = v;
  stats["protocol_switches"] = r.switches;
  output::write_json(dir + "/solver_stats.json", stats);
  output::write_json(dir + "/scene.resolved.json", resolved);
  output::write_json(dir + "/summary.json", summary);
  return summary;
}

}  // namespace swim::reduced1d
