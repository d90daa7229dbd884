// Checks the command line applies to a scene on top of the tier's own reader, shared with
// the tests (tests/common/test_scene_fuzz.cpp runs them in process):
//   - the other tier's sections must be well-formed (so the resolved scene runs on both),
//   - the estimated output must stay below output.max_bytes.
#pragma once

#include <string>

#include "common/scene.hpp"
#include "common/sweep.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/params.hpp"

namespace swim::app {

/// Throws InputError naming the key when a section of the tier that is not running
/// (`running_tier` "1d": full3d and axi; "3d": model1d, numerics1d and axi; "axi": model1d and
/// numerics1d; the full3d section is read by the axisymmetric tier itself) is malformed. In a
/// 3D or axi run (and a calibration) the 1D sections' values are also read by the 1D reader:
/// `numerics1d.cells = 0` is refused there as in a 1D run.
void check_other_tier(const scene::json& scene, const std::string& running_tier);

/// The sections of a sweep's scenes that the 1D reader does not read, checked as `swim run`
/// checks them (check_other_tier) for the base scene and for every value of every axis: an axis
/// `full3d.nosuch` is refused like `--set full3d.nosuch=...`. InputError naming vary.<key>.
void check_sweep_scenes(const sweep::Sweep& sw);

/// Estimated bytes a run writes (series, radius samples, VTK frames), and the key whose
/// interval dominates the estimate. Zero when the run's span is not known before it runs
/// (force-driven with time.duration "auto").
struct OutputEstimate {
  double bytes = 0;
  std::string key;
};
OutputEstimate estimate_output(const reduced1d::Params& p);
OutputEstimate estimate_output(const full3d::Params3d& p);

/// Throws InputError (naming the dominant interval key) when the estimate exceeds
/// output.max_bytes of the scene.
void check_output_size(const OutputEstimate& e, const scene::json& scene);

/// A 1D force-driven run with time.duration "auto" has no estimate before it runs. When the
/// output of its end-time bound (reduced1d::end_time) exceeds output.max_bytes, it is first
/// integrated without output up to the time its samples would reach the limit: if its cycles
/// have not completed by then, InputError naming time.output_interval (before anything is
/// written). A run that fails numerically before that is left to fail as itself.
void check_auto_run_output(const reduced1d::Params& p, const scene::json& scene);

}  // namespace swim::app
