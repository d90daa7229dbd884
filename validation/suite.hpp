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
// A case with a `reference` (an axisymmetric grid series, `--tier axi`) also runs the axi tier
// on each of its grids (cached in OUT/runs/ like the 3D runs) and extrapolates its figures with
// the reference's order range: that extrapolation is then the case's reference for the 1D
// verdicts and the findings (verdicts.hpp), its convergence is stated against the suite's
// `reference_target_relative` (default 1 %), and the 3D extrapolation is compared with it
// figure by figure (agree when |3D - ref| <= e_3d + e_ref).
// The result is report.json (every metric, threshold and verdict, with downsampled U(t)
// series for the figures); tools/plot_validation.py turns it into report.md, report.html and
// the PNG figures.
//
// The parts: the suite file (suite_file.hpp), the cache of runs and calibrations
// (run_cache.hpp), the extrapolated references (extrapolated_reference.hpp) and the phases of a
// case (suite_phases.hpp); run_suite calls the phases in the order above.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/scene.hpp"
#include "validation/suite_file.hpp"

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
  /// the progress of each 3D and axi run (its percentage, rate and time left, common/progress.hpp):
  /// -1 on a terminal only, 0 never, 1 always
  int run_progress = 0;
  /// the suite's scenes were read by check_suite already (swim validate does it before it
  /// creates the output folder): run_suite checks the file's keys only
  bool scenes_checked = false;
};

/// Runs the suite and returns report.json's content. Throws InputError for a malformed suite
/// (before any run); numerical failures of single runs are recorded in the report.
scene::json run_suite(const SuiteOptions& o);

/// The suite's heavy runs (every 3D run of the resolution studies, the time-step variants and
/// the extremes, every axi reference run, every calibration) as independent jobs, for `mpirun`
/// to spread over ranks before run_suite: [{"job": {...}, "cost": estimate, "after": [jobs that
/// must finish first], "label": for messages}]. Each job run by run_planned puts its result in the suite's cache
/// (OUT/runs, OUT/calibrations), exactly as run_suite would make it, so that run_suite then finds
/// them all and its report is the one a single process writes.
scene::json plan_runs(const SuiteOptions& o);
/// Runs one job of plan_runs into the cache (a finished one is reused); returns {"status", ...}.
/// The job's "progress" (0 or 1, default 0) is the run's own progress (SuiteOptions::run_progress).
scene::json run_planned(const scene::json& job);

/// The time left of plan_runs's jobs as the ranks work through them. The plan's costs are
/// comparable within a kind of job (3d, axi, calibration), not across kinds, so each kind gets
/// its own seconds per unit of cost, measured on the jobs of that kind computed so far (a job
/// answered from the cache takes no time and measures nothing). Work left is each unfinished
/// job's estimate (less the time a running one has had), shared over the ranks but never less
/// than the longest single job left. Times are seconds on any one clock.
class PlanClock {
 public:
  PlanClock(const scene::json& plan, int ranks);
  void started(std::size_t job, double t);
  /// computed: false for a job answered from the cache (or failed at once): it does not time its kind
  void finished(std::size_t job, double t, bool computed);
  struct Left {
    double seconds = 0;        ///< the timed kinds' work left
    std::size_t untimed = 0;   ///< unfinished jobs of kinds without a computed job yet (not in seconds)
    std::string untimed_kinds; ///< those kinds, "axi, calibration"
  };
  Left left(double t) const;
  double started_at(std::size_t job) const { return start_[job]; }
  /// "about 12 min left", "about 12 min left and 3 axi run(s) not yet timed", "time left not yet known"
  static std::string describe(const Left& l);

 private:
  std::vector<std::string> kind_;
  std::vector<double> cost_, start_;
  std::vector<bool> done_;
  std::vector<std::pair<std::string, std::array<double, 2>>> timed_;  // kind: {seconds, cost}
  int ranks_;
  const std::array<double, 2>* rate(const std::string& kind) const;
};

}  // namespace swim::validation
