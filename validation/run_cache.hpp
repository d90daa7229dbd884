// The suite's runs and calibrations, cached in its output folder (OUT/runs, OUT/calibrations) so
// that an interrupted suite resumes from what is done and an MPI rank's run is the one a single
// process would make.
//
// A 3D or axi run is found by the physics of its resolved scene (without output settings,
// threads, name, description or the 1D sections), by its folder's name or by the folder's own
// scene.resolved.json resolved again by the current reader. A finished run is used only when its
// folder passes verify_folder (common/run_folder.hpp); a run stopped part way continues from its
// checkpoint; anything else is recomputed. A calibration file is found the same way, by the
// physics it was written for and its format version. Every file read back is read by the strict
// reader (common/strict_json.hpp). What the cache reused or rejected, and every folder and file
// the suite read, verified again at the end, go into the report (RunCache::report).
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "common/run_record.hpp"
#include "common/scene.hpp"

namespace swim::validation {

using scene::json;

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// A run's centre history: times strictly increasing.
struct Series {
  std::vector<double> t, x, u;
};

/// The centre history of a record's kept rows (times strictly increasing).
Series series_of(const record::RunRecord& rec);

/// The series sampled at n + 1 evenly spaced times on [0, t_end], for the report's figures.
json downsample(const Series& s, double t_end, int n = 400);

/// One 3D run as the report sees it.
struct Run3d {
  json record;  ///< report entry
  Series series;
  record::CycleFigures cyc;
  double h = 0, wall = 0, length = 0;
  double max_displacement = std::numeric_limits<double>::quiet_NaN();  ///< m, over the run
  bool ok = false;
  bool cached = false;  ///< read back from a finished folder, not run by this call
};

/// One axisymmetric run as the report sees it.
struct RunAxi {
  json record;  ///< report entry
  Series series;
  record::CycleFigures cyc;
  double h = 0, wall = 0;
  double max_displacement = std::numeric_limits<double>::quiet_NaN();  ///< m, over the run
  bool ok = false;
  bool cached = false;
};

/// The cache key of a resolved 3D scene (the folder name's hash).
std::string run_key_3d(const json& resolved);
/// The cache key of a resolved axi scene: its physics tagged with the tier, so that an axi run
/// is never taken for a 3D one.
std::string run_key_axi(const json& resolved);

/// The cache keys of the run folders' and calibration files' scenes read so far, per file and
/// its modification time. Resolving a scene again costs tens of ms (a fine 3D grid's mesh,
/// seconds) and every lookup that misses scans every folder, so the keys are kept for as long
/// as the owner lives: the suite's pass, or a rank's life for the jobs it runs.
class FolderKeys {
 public:
  /// The key (run_key_3d, or run_key_axi with axi_tier) of `file`'s scene resolved again by the
  /// current reader, or of its `member` ("scene" of a calibration file); "" when unreadable.
  std::string of(const std::filesystem::path& file, const char* member, bool axi_tier = false);

 private:
  std::map<std::string, std::pair<std::filesystem::file_time_type, std::string>> keys_;
};

/// The runs and calibrations of one suite, or one planned job, in the cache folders.
class RunCache {
 public:
  /// runs_dir and cal_dir must exist (cal_dir may be "" when no calibration is asked for);
  /// `threads` is full3d.threads of the 3D runs and calibrations (not part of any key).
  RunCache(std::string runs_dir, std::string cal_dir, int threads, FolderKeys& keys);

  /// The 3D run of scene `sc`, reused when finished, resumed when interrupted, else run.
  /// frame_interval > 0: membrane frames (VTK) at that interval, for the side-view figure;
  /// `progress` as SuiteOptions::run_progress.
  Run3d run_3d(const json& sc, double frame_interval = 0, int progress = 0);

  /// The axi run of scene `sc`: a finished run whose physics (its scene resolved again by the
  /// current reader) is this scene's is reused, found by its folder name or by its own
  /// scene.resolved.json; any other change reruns it.
  RunAxi run_axi(const json& sc, int progress = 0);

  /// The calibration of `base` at `grid` (set at grid_key): read from the calibrations folder
  /// when a valid one of this physics and format is there, else computed and written
  /// (`starting` called first). Returns the calibration file ("" when it failed) and its
  /// content in cal_j. `progress` as SuiteOptions::run_progress: a line per load, then the
  /// hydraulic radii and the towed tube, with the time left (as swim calibrate).
  std::string calibration(const json& base, const std::string& grid_key, const json& grid, const std::string& name,
                          json& cal_j, const std::function<void()>& starting = {}, int progress = 0);

  /// The report's "cache": what was reused and rejected (and why), and whether every folder and
  /// calibration read is still what was read (verified again now).
  json report() const;

 private:
  json finished_summary(const std::string& dir);
  /// The finished run of the tier (3D, or axi) whose scene resolves to `key`: in `dir`, else in
  /// another folder of the runs folder (then `dir` names it); null when there is none.
  json find_finished(std::string& dir, const std::string& key, bool axi_tier);
  std::string cached_calibration(const json& physics);
  void reject(const std::string& path, const std::string& reason);
  /// Whether the interrupted run in dir continues from its checkpoint: `check` (the tier's
  /// check_resumable) accepts it; a checkpoint it refuses is recorded as rejected.
  bool resumes(const std::string& dir, const std::function<void()>& check);

  std::string runs_dir_, cal_dir_;
  int threads_;
  FolderKeys& keys_;
  long reused_ = 0;
  json rejected_ = json::array();  ///< {"path", "reason"}
  std::vector<std::string> folders_, calibrations_;
};

}  // namespace swim::validation
