// Run metrics and the output folder of a 1D run (product contract: summary.json,
// series.csv, radius.csv, solver_stats.json).
#pragma once

#include <string>
#include <vector>

#include "common/scene.hpp"
#include "reduced1d/params.hpp"
#include "reduced1d/solver.hpp"

namespace swim::reduced1d {

struct Metrics {
  double t_end_s = 0;
  double displacement_m = 0;
  double max_displacement_m = 0;  ///< largest centre displacement over the output samples
  double mean_velocity_m_per_s = 0;
  double body_lengths_per_s = 0;
  double final_velocity_m_per_s = 0;
  double max_velocity_m_per_s = 0;
  double pumped_volume_m3 = 0;  ///< net volume expelled backwards through the rear end (z = 0)
  int cycles_completed = 0;
  std::vector<double> cycle_times_s;
  double mean_cycle_time_s = 0;
  double min_radius_m = 0;
  long switches = 0;
  /// Per completed cycle (force-driven): displacement over the cycle [m] and its mean velocity.
  std::vector<double> cycle_displacements_m;
  double displacement_per_cycle_m = 0;        ///< mean over completed cycles (prescribed: the transit)
  double mean_velocity_per_cycle_m_per_s = 0;
  bool has_cycle = false;                     ///< false: the per-cycle figures are absent
  std::string no_cycle_reason;
  double pumped_volume_lab_m3 = 0;            ///< -V_rear_lab at the end
  /// Brownian scale over one cycle: sqrt(2 k_B T t_cycle / zeta), and |directed| / that.
  double drag_coefficient_N_s_per_m = 0;
  double thermal_rms_displacement_m = 0;
  double directed_to_diffusive = 0;
  std::vector<std::string> implausible;       ///< physically impossible results, if any
};

Metrics metrics(const Params& p, const Result& r);

/// Write the run folder (record::write_run: series.csv, radius.csv, solver_stats.json,
/// scene.resolved.json, summary.json last) into `dir` (which must exist), from r.record (its
/// stream, when solve() had one) or from the kept samples. Returns the summary; its `status`
/// is "ok" or "failed: <message>".
scene::json write_run(const std::string& dir, const Params& p, const scene::json& resolved, Result& r,
                      double wall_time_s);

}  // namespace swim::reduced1d
