// Subcommands of the `swim` executable. Each is a thin driver over the tier libraries;
// errors propagate as swim::InputError (exit 2) or swim::NumericalError (exit 3).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "reduced1d/params.hpp"

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
  int threads = 0;  ///< 3D: threads of the run (full3d.threads); 0: the scene's
  /// 3D: also run the scene on a coarser grid (RUN/error_estimate/coarse) and report the run's
  /// discretisation error in summary.json's error_estimate (validation/error_estimate.hpp)
  bool error_estimate = false;
};

int run(const RunOptions& o);
int demo(const std::string& out, int progress);
/// swim screen: a 1D sweep; confirm > 0: that many designs also run in 3D with `threads`
/// threads each (design/confirm.hpp), reported in confirm.json, confirm.md and confirm.png.
/// grid_check > 0: every design also runs on twice its cells, and the metric's relative change
/// is reported per design (designs.csv) and over the sweep (screen.json "grid_check"), with
/// grid_check the tolerance the change is counted against.
int screen(const std::string& sweep, const std::string& out, int jobs, int progress, bool overwrite, int confirm = 0,
           int threads = 1, double grid_check = 0);
/// swim optimize: a continuous design search on the 1D tier (design/optimize.hpp); confirm:
/// the best design also runs in 3D with `threads` threads.
int optimize(const std::string& spec, const std::string& out, int progress, bool overwrite, bool confirm, int threads);
/// fine_cycles: cells across of one cycle each of the paper's buckling wall (paper_aspect_L0.2,
/// seeded as the buckling suite's paper_aspect_L0.2_seeded), `--fine-cycle N`; fine_sets: scene
/// overrides of those cycles (`--fine-cycle-set KEY=VALUE`, e.g. full3d.wall_stabilization).
int bench(const std::string& out, bool quick, bool paper_cycle, const std::string& tier = "all",
          const std::vector<int>& fine_cycles = {}, const std::vector<std::string>& fine_sets = {});
int scenes();
/// swim calibrate: C1 of the 1D tier from 3D uniform loads (validation/calibration.hpp).
/// wet: also confirm one load with a fluid-coupled 3D run (minutes at the default grid).
/// threads > 0: the 3D runs' threads (full3d.threads); 0: the scene's.
/// tube_law: also the whole static tube law on both branches (calibration.json "tube_law").
/// progress: -1 on a terminal, 0 never, 1 always (a line per load on stderr).
int calibrate(const std::string& scene, const std::vector<std::string>& sets, const std::string& out, bool wet,
              bool overwrite, int threads = 0, bool tube_law = false, int progress = -1);

/// swim validate: the 1D-vs-3D validation suite and its report (validation/suite.hpp).
/// only: case filter (scene file names); empty: every case.
int validate(const std::string& suite, bool quick, const std::string& out, int threads, int progress,
             const std::vector<std::string>& only);

/// One independent run of a distributed command (app/ranks.hpp), by its payload's "kind":
/// "1d" (a screen design: reduced1d::outcome_to_json), "confirm3d" (design::confirmed_to_json),
/// "validate" (validation::run_planned).
scene::json run_task(const scene::json& payload);
/// Scheduling estimates of a run's cost (larger first): 1D cells x simulated time, 3D cells x steps.
double cost_1d(const reduced1d::Params& design);
double cost_3d(const scene::json& scene);

/// Directory of the shipped data (scenes, sweeps): $SWIM_DATA_DIR or the source tree's data/.
std::string data_dir();
/// Run a plotting script of tools/ with Debian's python3 (run_child); returns false (with a
/// warning on stderr saying whether python3-matplotlib is missing or the script failed) when
/// plotting is unavailable. Plots are a convenience: their failure never fails a run, but an
/// interruption does (Interrupted).
bool plot(const std::string& script, const std::vector<std::string>& args);

/// A command interrupted by a signal (SIGINT, SIGTERM, SIGHUP) while a child process ran: the
/// child has been stopped and waited for. Exit status 128 + the signal.
class Interrupted : public std::runtime_error {
 public:
  Interrupted(int signal, const std::string& during);
  int signal() const { return signal_; }

 private:
  int signal_;
};

/// How a child process ended.
struct ChildResult {
  std::string spawn_error;  ///< not started (the program is missing): the reason
  int exit_code = -1;       ///< its exit status when it exited
  int killed_by = 0;        ///< the signal that ended it otherwise
};

/// Runs argv (argv[0] a path) as a child in its own process group (posix_spawn), its stderr
/// sent to swim's stdout. While it runs, SIGINT, SIGTERM and SIGHUP sent to swim are forwarded
/// to its group; swim waits for it, then throws Interrupted naming `what` when a signal came.
ChildResult run_child(const std::vector<std::string>& argv, const std::string& what);

}  // namespace swim::app
