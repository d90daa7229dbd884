// The output part of a 3D run: VTK frames of the membrane (vtk/membrane_*.vtp +
// membrane.pvd) and of the fluid (vtk/fluid_*.vti + fluid.pvd, on request), and the
// result files: series.csv, radius.csv, solver_stats.json, scene.resolved.json and
// summary.json (last).
#pragma once

#include <string>

#include "common/scene.hpp"
#include "common/vtk.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/run3d_measure.hpp"
#include "full3d/run3d_setup.hpp"
#include "full3d/run3d_stepper.hpp"

namespace swim::full3d {

class RunOutput {
 public:
  /// vtk: membrane frames; fluid: fluid frames.
  RunOutput(const RunSetup& run, const scene::json& resolved, std::string dir, bool vtk, bool fluid);

  bool vtk() const { return vtk_; }
  bool fluid() const { return fluid_; }
  void write_membrane_frame(const Stepper& stepper);
  void write_fluid_frame(const Stepper& stepper);
  /// Writes the result files (summary.json last) and returns the summary.
  scene::json write_results(const std::string& status, double wall, const Stepper& stepper,
                            const Measurements& measured) const;

  /// The frame times; load() also rewrites the collections of the enabled frame kinds.
  void save(CheckpointWriter& w) const;
  void load(const CheckpointReader& r);

 private:
  const RunSetup& run_;
  const scene::json& resolved_;
  std::string dir_;
  bool vtk_, fluid_;
  vtk::Collection pvd_, fluid_pvd_;
};

}  // namespace swim::full3d
