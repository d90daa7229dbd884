// A run folder belongs to one run.
//
//   - The run takes a lock (".swim.lock", flock: released by the kernel when the process
//     ends, even on kill -9). A second run into a locked folder is an InputError (exit 2)
//     naming the PID that holds it.
//   - The owner is recorded in ".swim-run.json" (tier, scene hash, PID). A new run into a
//     folder that holds another run's results is refused (exit 2) unless `overwrite`; then
//     the old run's files are removed first. Re-running the identical resolved scene on
//     the same tier replaces a finished run's results (its files are removed first) without
//     --overwrite; an interrupted (resumable) run is only replaced with --overwrite.
//   - The same holds for `swim screen` and `swim calibrate` folders (tiers "screen" and
//     "calibration"; their status is in screen.json and calibration.json).
//   - Files swim did not write (not a result name, not listed in the old summary.json) are
//     never removed: such a folder is refused even with --overwrite.
//   - `resume` continues only a run of the same tier whose folder holds a checkpoint.
//   - mark_failed(): a write failure leaves summary.json saying "failed: ..." (or no
//     summary.json at all when even that cannot be written): nothing claims success.
#pragma once

#include <string>
#include <vector>

#include "common/scene.hpp"

namespace swim::output {

struct RunFolderOptions {
  std::string tier;        ///< "1d", "3d", "axi", "screen", "optimize" or "calibration"
  scene::json resolved;    ///< the resolved scene (or sweep) of this run (its hash identifies the run)
  bool overwrite = false;  ///< --overwrite
  bool resume = false;     ///< --resume
  std::string key = "--out";  ///< the flag named in messages
  /// The file written last, whose "status" says whether the run finished ("summary.json";
  /// "screen.json" for a sweep, "calibration.json" for a calibration).
  std::string summary = "summary.json";
  /// A sub-folder of child runs (the 3D confirmation runs of a sweep or search) that a new run
  /// of the same identity keeps, so that it reuses them; such a run also continues a folder
  /// whose previous run of the same identity did not finish. Everything under it counts as
  /// this run's results (removed with --overwrite or by another run). Empty: none.
  std::string keep{};
};

class RunFolder {
 public:
  /// Creates the folder if needed, takes the lock, checks ownership (InputError, exit 2),
  /// clears replaced results and records this run as the owner.
  RunFolder(std::string dir, const RunFolderOptions& options);
  ~RunFolder();
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;

  const std::string& dir() const { return dir_; }
  /// Best effort, never throws: the summary's status becomes "failed: <message>" (the
  /// file is removed when it cannot be rewritten). Returns false when it had to be removed.
  bool mark_failed(const std::string& message) noexcept;

  /// Names of the result files a swim run may write into its folder (for clearing).
  static bool is_result_name(const std::string& relative_path);
  /// The tier ("1d", "3d") of the run whose results the folder holds, from its run record
  /// or its summary.json; "" when unknown. Reads only.
  static std::string tier_of(const std::string& dir);

 private:
  std::string dir_;
  std::string summary_;
  int lock_fd_ = -1;
};

/// Why the results of a finished folder cannot be trusted, "" when they can: its summary
/// (`summary`, "summary.json" or "calibration.json") carries its own checksum and it matches
/// (output::check_own_checksum), and every file it lists (`files`) exists with the listed size and
/// FNV-1a 64 checksum; each name of `required` must be listed. The reason names the file and
/// what is wrong with it ("series.csv: 1204 bytes, summary.json lists 1210").
std::string verify_folder(const std::string& dir, const std::vector<std::string>& required = {},
                          const std::string& summary = "summary.json");

/// FNV-1a 64-bit hash of the compact dump of `value`, 16 hex digits.
std::string json_hash(const scene::json& value);
/// The same with the legacy offset basis (kFnv1a64LegacyOffset): the scene hash of run records
/// written before the standard basis.
std::string json_hash_legacy(const scene::json& value);

}  // namespace swim::output
