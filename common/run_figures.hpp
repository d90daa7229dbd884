// The figures of a run record that every tier's summary carries: computed in one place,
// written by record::summary (the one builder of summary.json, run_record.hpp) and read as
// numbers by a tier that needs them (the 1D tier's metrics, reduced1d/report.hpp).
#pragma once

#include "common/run_record.hpp"

namespace swim::record {

/// The shared figures of a record; zero when it has no rows.
struct RunFigures {
  double t_end_s = 0, displacement_m = 0;
  double max_displacement_m = 0;  ///< largest centre displacement over the rows
  double mean_velocity_m_per_s = 0, body_lengths_per_s = 0;
  double final_velocity_m_per_s = 0, max_velocity_m_per_s = 0;
  double min_radius_m = 0;
  double pumped_volume_m3 = 0;  ///< the lumen volume expelled backwards through the rear end (z = 0)
  CycleFigures cycles;
};

RunFigures run_figures(const RunRecord& r);

}  // namespace swim::record
