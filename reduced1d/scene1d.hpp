// Scene -> 1D parameters. The sections every tier shares (name, swimmer, fluid, container,
// wall, wave, protocol, time) are read by scene::SharedScene (common/scene_shared.hpp) and
// mapped here, with the 1D rules (a calibration file's C1 and tube law, the cells per protocol
// segment); the 1D sections (model1d, numerics1d) are read here, the other tiers' sections
// (full3d, axi) passed through unchanged. Every value used is echoed into `resolved`.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "common/scene.hpp"
#include "reduced1d/params.hpp"

namespace swim::reduced1d {

/// The screening grids: up to this many cells a scene's default `numerics1d.rtol` is 1e-4 (the
/// grid's own error is far above the integration's), above it 1e-6.
inline constexpr int kScreeningCells = 100;

/// Throws swim::InputError naming the key, the value and what is allowed.
/// `scene_dir` is used to find a calibration file given by a relative path.
Params read_scene(const scene::json& scene, scene::json& resolved, const std::string& scene_dir = ".");

/// The wall's bending rigidity along the axis [J], `axial_bending_rigidity_J` of a calibration
/// file (model1d.axial_bending.source = "calibration"). InputError naming `key` when absent or
/// not positive.
double axial_bending_from_calibration(const std::string& key, const std::string& path, const std::string& scene_dir);
/// Read the hydraulic offsets (a_in, a_out) [m] from a calibration.json (keys
/// "hydraulic_offset_inner_m", "hydraulic_offset_outer_m"). Throws InputError for `key`.
std::pair<double, double> hydraulic_offsets_from_calibration(const std::string& key, const std::string& path,
                                                             const std::string& scene_dir);
/// Read C1 [Pa/m] from a calibration.json (key "C1_Pa_per_m"). Throws InputError for `key`.
double c1_from_calibration(const std::string& key, const std::string& path, const std::string& scene_dir);
/// Read the static tube law of `branch` ("round" or "buckled") from a calibration.json
/// (tube_law.<branch>.knots_radius_m, knots_wall_pressure_Pa; docs/tube-law.md), for a tube of
/// radius R0. Throws InputError for `key`.
std::shared_ptr<const TubeLaw> tube_law_from_calibration(const std::string& key, const std::string& path,
                                                         const std::string& scene_dir, const std::string& branch,
                                                         double R0);

}  // namespace swim::reduced1d
