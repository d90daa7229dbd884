// The 1D-vs-3D validation suite (swim validate).
//
// A suite file (data/validation/*.json) lists cases (a scene, the 3D grids of its resolution
// study, the grid the 1D tier is calibrated at, optional paper values) and the 1D models to
// judge, with the thresholds of the verdicts. For every case:
//   1. the 3D tier runs on every grid (cached by resolved scene in OUT/runs/, so an
//      interrupted suite resumes from the runs already done);
//   2. displacement per cycle, cycle time and mean velocity per cycle are extrapolated to
//      h -> 0 (richardson.hpp): the 3D reference, with its error estimate;
//   3. the 1D tier is calibrated from 3D at the calibration grid (static C1 and hydraulic
//      radii, calibration.hpp / hydraulic.hpp; cached in OUT/calibrations/);
//   4. every 1D model runs (calibrated models read the calibration file) and is compared with
//      the extrapolated reference and with the 3D run at the calibration grid; U(t) is
//      compared with the finest 3D run (compare.hpp);
//   5. the 1D default model runs at several cell counts for the speed/accuracy trade.
// The result is report.json (every metric, threshold and verdict, with downsampled U(t)
// series for the figures); tools/plot_validation.py turns it into report.md, report.html and
// the PNG figures.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common/scene.hpp"

namespace swim::validation {

struct SuiteOptions {
  std::string suite;     ///< suite file
  std::string out_dir;   ///< created by the caller
  std::string data_dir;  ///< shipped data (scenes are looked up relative to the suite, then data/scenes)
  int threads = 1;       ///< full3d.threads for the 3D runs
  /// run only these cases (scene file names, with or without .json); empty: all
  std::vector<std::string> only;
  /// progress lines ("case 2/7: 3D grid 3/3 ...") on stderr; empty: quiet
  std::function<void(const std::string&)> progress;
};

/// Runs the suite and returns report.json's content. Throws InputError for a malformed suite
/// (before any run); numerical failures of single runs are recorded in the report.
scene::json run_suite(const SuiteOptions& o);

/// Reads and checks a suite file (InputError naming the key on any problem).
scene::json load_suite(const std::string& path);

}  // namespace swim::validation
