#include "reduced1d/report.hpp"

#include <algorithm>
#include <cmath>

#include "common/output.hpp"

namespace swim::reduced1d {

using scene::json;

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
  m.min_radius_m = last.R_min;
  for (const auto& s : r.series) {
    m.max_velocity_m_per_s = std::max(m.max_velocity_m_per_s, s.W);
    m.max_displacement_m = std::max(m.max_displacement_m, s.X);
    m.min_radius_m = std::min(m.min_radius_m, s.R_min);
  }
  m.cycles_completed = static_cast<int>(r.cycle_end.size());
  for (size_t k = 0; k < r.cycle_end.size() && k < r.cycle_start.size(); ++k)
    m.cycle_times_s.push_back(r.cycle_end[k] - r.cycle_start[k]);
  if (!m.cycle_times_s.empty()) {
    double sum = 0;
    for (double c : m.cycle_times_s) sum += c;
    m.mean_cycle_time_s = sum / m.cycle_times_s.size();
  }
  m.switches = r.switches;
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
  summary["final_velocity_m_per_s"] = m.final_velocity_m_per_s;
  summary["max_velocity_m_per_s"] = m.max_velocity_m_per_s;
  summary["pumped_volume_m3"] = m.pumped_volume_m3;
  summary["min_radius_m"] = m.min_radius_m;
  summary["protocol_switches"] = m.switches;
  summary["segment_reached_s"] = r.segment_reached;
  summary["derived"] = {{"C1_Pa_per_m", p.wall.C1},
                        {"mass_per_area_kg_per_m2", p.wall.m},
                        {"mass_per_length_kg_per_m", p.wall.m * 2.0 * M_PI * p.geometry.R0},
                        {"aspect_ratio_R0_over_L", p.geometry.R0 / p.geometry.L},
                        {"contracted_ratio", (p.wave == WaveKind::Sine ? p.geometry.R0 - p.sine.amplitude
                                              : p.wave == WaveKind::Step ? p.step.R_min
                                                                         : p.protocol.R_f) /
                                                 p.geometry.R0},
                        {"actuation_pressure_Pa", p.wave == WaveKind::ForceDriven ? p.protocol.q : 0.0}};
  summary["wall_time_s"] = wall_time_s;

  {
    output::CsvWriter csv(dir + "/series.csv",
                          {"t_s", "x_center_m", "velocity_m_per_s", "energy_J", "min_radius_m", "max_radius_m",
                           "flux_rear_m3_per_s", "flux_front_m3_per_s", "volume_rear_m3", "volume_front_m3",
                           "tube_volume_m3", "phase"});
    for (const auto& s : r.series)
      csv.row({s.t, s.X, s.W, s.energy, s.R_min, s.R_max, s.Q_rear, s.Q_front, s.V_rear, s.V_front, s.tube_volume,
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
