// The checkpoint part of a 3D run: checkpoint.bin in the run folder (format:
// full3d/checkpoint.hpp). A checkpoint holds the named records of the stepping,
// measuring and output parts and the wall time so far; its header carries the hash of
// the scene as it must match on resume (every key except full3d.checkpoint_interval,
// full3d.threads and full3d.time_limit).
//
// Reading checks, before anything is restored: the file's structure and checksum
// (CheckpointReader), the scene hash, and the values: the time finite and within the
// run's span [0, t_end], step counts and protocol counters in range and consistent with
// the time, array sizes matching the scene's mesh and grid, every number finite, node
// positions within the container. Any failure is an InputError (key "--resume", exit 2)
// naming the file, what is wrong and what to do.
#pragma once

#include <cstdint>
#include <string>

#include "common/scene.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/run3d_setup.hpp"

namespace swim::full3d {

class Stepper;
class Measurements;
class RunOutput;

class RunCheckpoint {
 public:
  RunCheckpoint(const RunSetup& run, const scene::json& resolved, const std::string& dir);

  const std::string& path() const { return path_; }
  /// Writes checkpoint.bin atomically. Throws OutputError naming checkpoint.bin.
  void save(const Stepper& stepper, const Measurements& measured, const RunOutput& output,
            const std::vector<double>& output_marks, double wall) const;
  /// Reads and validates checkpoint.bin (see above) and the partial results it continues
  /// (series.csv.part and radius.csv.part must match its marks). Throws InputError.
  CheckpointReader open() const;
  /// open(), then restores the parts; returns the wall time of the run so far, s.
  double restore(Stepper& stepper, Measurements& measured, RunOutput& output, std::uintmax_t max_bytes = 0) const;

  /// The hash of the scene as it must match on resume.
  static std::uint64_t scene_hash(const scene::json& resolved);

 private:
  const RunSetup& run_;
  std::uint64_t hash_;
  std::string dir_, path_;
};

}  // namespace swim::full3d
