// Subcommands of the `swim` executable. Each is a thin driver over the tier libraries;
// errors propagate as swim::InputError (exit 2) or swim::NumericalError (exit 3).
#pragma once

#include <string>
#include <vector>

namespace swim::app {

struct RunOptions {
  std::string scene;
  std::string tier = "1d";
  std::string out;
  std::vector<std::string> sets;
  int progress = -1;  ///< -1 auto (terminal), 0 off, 1 on
  bool plot = false;
  std::string resume;  ///< 3D: continue the run whose output folder (with checkpoint.bin) is given
  bool overwrite = false;  ///< replace another run's results in the output folder
};

int run(const RunOptions& o);
int demo(const std::string& out, int progress);
/// swim screen: a 1D sweep; confirm > 0: that many designs also run in 3D with `threads`
/// threads each (design/confirm.hpp), reported in confirm.json, confirm.md and confirm.png.
int screen(const std::string& sweep, const std::string& out, int jobs, int progress, bool overwrite, int confirm = 0,
           int threads = 1);
/// swim optimize: a continuous design search on the 1D tier (design/optimize.hpp); confirm:
/// the best design also runs in 3D with `threads` threads.
int optimize(const std::string& spec, const std::string& out, int progress, bool overwrite, bool confirm, int threads);
int bench(const std::string& out, bool quick, bool paper_cycle, const std::string& tier = "all");
int scenes();
/// swim calibrate: C1 of the 1D tier from 3D uniform loads (validation/calibration.hpp).
/// wet: also confirm one load with a fluid-coupled 3D run (minutes at the default grid).
int calibrate(const std::string& scene, const std::vector<std::string>& sets, const std::string& out, bool wet,
              bool overwrite);

/// swim validate: the 1D-vs-3D validation suite and its report (validation/suite.hpp).
/// only: case filter (scene file names); empty: every case.
int validate(const std::string& suite, bool quick, const std::string& out, int threads, int progress,
             const std::vector<std::string>& only);

/// Directory of the shipped data (scenes, sweeps): $SWIM_DATA_DIR or the source tree's data/.
std::string data_dir();
/// Run a plotting script of tools/ with Debian's python3; returns false (with a warning on
/// stderr) when plotting is unavailable. Plots are a convenience: their failure never fails a run.
bool plot(const std::string& script, const std::vector<std::string>& args);

}  // namespace swim::app
