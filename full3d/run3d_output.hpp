// The output part of a 3D run: VTK frames of the membrane (vtk/membrane_*.vtp +
// membrane.pvd) and of the fluid (vtk/fluid_*.vti + fluid.pvd, on request), and the
// result files: series.csv, radius.csv, solver_stats.json, scene.resolved.json and
// summary.json (last).
#pragma once

#include <string>

#include "common/run_record.hpp"
#include "common/scene.hpp"
#include "common/vtk.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/run3d_measure.hpp"
#include "full3d/run3d_setup.hpp"
#include "full3d/run3d_stepper.hpp"

namespace swim::full3d {

/// summary.json's "wrinkle_by_cycle": per protocol cycle, {"cycle", "max_wrinkle_m",
/// "max_wrinkle_mode", "modes_over_half_cell"} (CycleWrinkles).
scene::json wrinkle_by_cycle_json(const CycleWrinkles& w);

/// The note `swim run` prints after a 3D run whose wall wrinkled beyond half a cell, from its
/// summary.json (empty when it did not, or the summary has no wrinkle figures). It names the lobe
/// number the wall buckled into and what chose it: the seed (`derived.seed_mode`,
/// `derived.seed_amplitude`), or, without one, the grid. It says so when the wall grew another
/// lobe number than the seed's, and when its lobes changed from one buckled shape to another
/// during the run (`wrinkle_modes_over_half_cell` holds two or more), naming the cycle where the
/// new lobes first exceeded half a cell: the cycles from there on belong to another buckled shape.
std::string wrinkle_note(const scene::json& summary);

class RunOutput {
 public:
  /// vtk: membrane frames; fluid: fluid frames. The record's rows and ring radii stream into
  /// the folder (record::RunStream) from start() or load() on.
  RunOutput(const RunSetup& run, const scene::json& resolved, std::string dir, bool vtk, bool fluid,
            record::RunRecord& rec);
  ~RunOutput();

  /// A fresh run: open the streams; max_bytes bounds the run's output (record::RunStream::limit):
  /// the two streamed files, every VTK frame written and the collections' size count toward
  /// it, and the row or frame that passes it throws NumericalError.
  void start(std::uintmax_t max_bytes = 0);

  bool vtk() const { return vtk_; }
  bool fluid() const { return fluid_; }
  void write_membrane_frame(const Stepper& stepper);
  void write_fluid_frame(const Stepper& stepper);
  /// The final result files (series.csv and radius.csv published, summary.json last); returns
  /// the summary. `status`: "ok" or "failed: ...".
  scene::json write_results(const std::string& status, double wall, const Stepper& stepper,
                            const Measurements& measured);
  /// A running run's snapshot before a checkpoint (the streams flushed, summary.json with
  /// this status listing the part files so far). Returns the streams' marks for the checkpoint.
  std::vector<double> write_snapshot(const std::string& status, double wall, const Stepper& stepper,
                                     const Measurements& measured);
  /// summary.json again as write_snapshot wrote it, now listing the checkpoint written after it:
  /// the summary is the last file of every checkpoint, as of the end.
  void write_snapshot_summary();

  /// The frame times, the bytes of the frames written and the streams' marks; load() also
  /// rewrites the collections of the enabled frame kinds, continues the streams from the
  /// marks and counts the frames' bytes and the collections toward the limit again.
  void save(CheckpointWriter& w, const std::vector<double>& marks) const;
  void load(const CheckpointReader& r, std::uintmax_t max_bytes = 0);

 private:
  /// The record's summary keys of a 3D run (derived values, extras, statistics, status).
  void fill(const std::string& status, double wall, const Stepper& stepper, const Measurements& measured);
  /// Count a frame just written (kind 0: membrane, 1: fluid), and what its collection grew
  /// by, toward the output limit.
  void count_frame(int kind, const std::string& frame, double t);

  const RunSetup& run_;
  const scene::json& resolved_;
  std::string dir_;
  bool vtk_, fluid_;
  vtk::Collection pvd_, fluid_pvd_;
  record::RunRecord& rec_;
  std::unique_ptr<record::RunStream> stream_;
  std::uintmax_t frame_bytes_[2] = {0, 0};  ///< bytes of the membrane and fluid frames written
  std::uintmax_t pvd_bytes_[2] = {0, 0};    ///< size of membrane.pvd and fluid.pvd as last counted
};

/// The checkpoint record of the streams' marks.
inline constexpr const char* kOutputMarks = "output_marks";
/// The checkpoint record of the bytes of the frames written: membrane, fluid (without the
/// collections, which are rewritten and counted again on resume).
inline constexpr const char* kFrameBytes = "frame_bytes";

}  // namespace swim::full3d
