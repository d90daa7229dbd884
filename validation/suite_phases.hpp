// The phases of the validation suite (suite.hpp), one function each; run_suite calls them in
// order for every case, then the extremes. Each phase adds its entries to the case's report
// (report.json's "cases"[i]); the runs it makes go through the suite's RunCache.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "validation/richardson.hpp"
#include "validation/run_cache.hpp"

namespace swim::validation {

/// A progress line ("case 2/7 (name): 3D grid 3/3 ..."); never empty (a no-op when quiet).
using Say = std::function<void(const std::string&)>;

/// One case of a suite, read once for every phase.
struct SuiteCase {
  json spec;               ///< the case's entry in the suite file
  json base;               ///< its scene, after the case's `set`
  std::string scene_path;  ///< the scene file found for it
  std::string scene_dir;   ///< where the scene's relative files are looked up
  std::string name;        ///< the scene's name (else the file's stem)
  std::string grid_key;    ///< the dotted key of the 3D grid the study varies
  json grids;              ///< the values of grid_key, coarse to fine
  std::size_t calibration_grid = 0;  ///< index into grids
  bool paper_max = false;  ///< the paper gives the largest centre displacement
  std::string tag;         ///< "case i/n (name)", for progress lines
};

/// Case `index` of `count` (its entry `spec`): its scene found (find_scene) and read.
SuiteCase open_case(const json& spec, std::size_t index, std::size_t count, const std::string& suite_dir,
                    const std::string& data_dir);

/// The case's report entry before any run: name, scene (relative to the source tree when it is
/// a shipped one), group, grid key, the paper's values, description, sweep value.
json case_entry(const SuiteCase& c, const std::string& data_dir);

/// The 1D tier's design targets of a case (`cases[].targets1d`, else the suite's `targets1d`;
/// the keys of `thresholds`), or null when neither gives them. Each 1D model is judged against
/// them by the thresholds' rules into `target_verdicts`.
const json& case_targets1d(const SuiteCase& c, const json& suite);

/// 1. The 3D resolution study: the scene on every grid (the finest with membrane frames, about
/// 12 per cycle of the grid before it). Adds "length_m" and "runs3d".
std::vector<Run3d> resolution_study(const SuiteCase& c, RunCache& cache, const Say& say, int progress, json& cr);

/// The observed orders the 3D scheme can show: the case's, else the suite's, else the immersed
/// boundary's.
OrderRange orders_3d(const SuiteCase& c, const json& suite);

/// A run of a grid series as a reference of U(t) (a 3D or an axi run): its centre history and
/// its first cycle.
struct VelocityRun {
  const Series* series = nullptr;
  bool has_cycle = false;
  double cycle_time_s = 0;
  double h = 0;  ///< m, the run's cell size
};

/// U(t) of a series (cycle time cycle_time_s) against the finest of `runs` (a grid series,
/// coarse to fine) that completed a cycle, in cycle phase and in time: phase_l2_relative,
/// phase_correlation, time_l2_relative, time_correlation, reference_cell_size_m; and the
/// uncertainty of the phase correlation, its spread over the (up to) three finest runs that
/// completed a cycle (phase_correlation_grid_spread, phase_correlation_grids), when two or
/// more did. Empty when no run completed a cycle.
json velocity_vs_runs(const Series& s, double cycle_time_s, const std::vector<VelocityRun>& runs);

/// 2b. The converged reference: the case's scene on the axi tier at each reference grid,
/// extrapolated with the reference's order range (target: the suite's
/// reference_target_relative), and the 3D extrapolation against it. Adds "reference",
/// "comparison_3d_vs_reference" and "velocity_3d_vs_reference" (U(t) of the finest 3D run
/// against the finest axi run, velocity_vs_runs); nothing for a case without a reference.
/// Returns the axi runs, coarse to fine (none without a reference).
std::vector<RunAxi> axi_reference_study(const SuiteCase& c, const json& suite, const std::vector<Run3d>& runs,
                                        RunCache& cache, const Say& say, int progress, json& cr);

/// 3. The calibration at the case's calibration grid. Adds "calibration"; returns the
/// calibration file, "" when it failed.
std::string calibrate_case(const SuiteCase& c, RunCache& cache, const Say& say, json& cr, int progress = 0);

/// 4. Every 1D model of the suite, compared with the case's judged reference, with the 3D run
/// at the calibration grid, and (U(t), velocity_vs_runs) with the finest 3D run
/// ("velocity_vs_finest3d") and, when the case has an axi reference, with the finest axi run
/// of `aruns` ("velocity_vs_reference"); verdicts against the thresholds, U(t)'s against the
/// axi run when there is one (judged_velocity, verdicts.hpp). Returns the "models1d" entries.
json judge_models(const SuiteCase& c, const json& suite, const std::string& cal_file, const std::vector<Run3d>& runs,
                  const std::vector<RunAxi>& aruns, const json& cr, const Say& say);

/// 5. Speed/accuracy: the first 1D model over cell counts and integrator tolerances, 3D over
/// the grids and the case's time-step variants (at the calibration grid), each point's error
/// against the judged reference. Returns the "speed_accuracy" entries (none without a
/// reference).
json speed_accuracy(const SuiteCase& c, const json& suite, const std::string& cal_file, const std::vector<Run3d>& runs,
                    const json& cr, RunCache& cache, const Say& say, int progress);

/// The wall times of the case's 3D study and 1D models, and their ratio at the calibration grid
/// (the 3D run there against the first 1D model, when both completed a cycle).
void wall_times(const SuiteCase& c, const std::vector<Run3d>& runs, json& cr);

/// 3D at the extremes: each of the suite's extremes3d against the outcome it states.
json extremes_3d(const json& suite, const std::string& suite_dir, const std::string& data_dir, RunCache& cache,
                 const Say& say);

}  // namespace swim::validation
