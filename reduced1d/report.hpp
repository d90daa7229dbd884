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
};

Metrics metrics(const Params& p, const Result& r);

/// Write summary.json, series.csv, radius.csv and solver_stats.json into `dir` (which must
/// exist). Returns the summary. `status` is "ok" or "failed: <message>".
scene::json write_run(const std::string& dir, const Params& p, const scene::json& resolved, const Result& r,
                      double wall_time_s);

}  // namespace swim::reduced1d
