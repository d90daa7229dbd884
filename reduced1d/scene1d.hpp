// Scene -> 1D parameters. Reads the physical sections shared by both tiers (swimmer,
// fluid, wall, wave, protocol, time) and the 1D sections (model1d, numerics1d); the 3D
// section (full3d) is passed through unchanged. Every value used is echoed into `resolved`.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "common/scene.hpp"
#include "reduced1d/params.hpp"

namespace swim::reduced1d {

/// Throws swim::InputError naming the key, the value and what is allowed.
/// `scene_dir` is used to find a calibration file given by a relative path.
Params read_scene(const scene::json& scene, scene::json& resolved, const std::string& scene_dir = ".");

/// Spring-network estimate of the wall stiffness: C1 = 2 k_s / (sqrt(3) R0^2), the in-plane
/// Young modulus 2 k_s / sqrt(3) of an equilateral triangular spring lattice over R0^2.
double c1_from_spring_constant(double k_s, double R0);

/// Read C1 [Pa/m] from a calibration.json (key "C1_Pa_per_m"). Throws InputError for `key`.
/// Read the hydraulic offsets (a_in, a_out) [m] from a calibration.json (keys
/// "hydraulic_offset_inner_m", "hydraulic_offset_outer_m"). Throws InputError for `key`.
std::pair<double, double> hydraulic_offsets_from_calibration(const std::string& key, const std::string& path,
                                                             const std::string& scene_dir);
double c1_from_calibration(const std::string& key, const std::string& path, const std::string& scene_dir);
/// Read the static tube law of `branch` ("round" or "buckled") from a calibration.json
/// (tube_law.<branch>.knots_radius_m, knots_wall_pressure_Pa; docs/tube-law.md), for a tube of
/// radius R0. Throws InputError for `key`.
std::shared_ptr<const TubeLaw> tube_law_from_calibration(const std::string& key, const std::string& path,
                                                         const std::string& scene_dir, const std::string& branch,
                                                         double R0);

}  // namespace swim::reduced1d
