// The suite file (data/validation/*.json), read strictly: every key known and of its type at
// every level, thresholds and lists in range, and every scene the suite names read by the tier
// that will run it, before anything runs or is written. Also the scenes the suite derives from a
// case: a case's scene after its sets, a reference grid's axi scene, a 1D model's scene.
#pragma once

#include <string>
#include <vector>

#include "common/scene.hpp"

namespace swim::validation {

using scene::json;

/// Reads and checks a suite file (InputError naming the key on any problem). The scene of a
/// case with a `reference` is looked up (as given, beside the suite, in data_dir/scenes when
/// data_dir is not empty) and read by the axi tier on every reference grid: a scene the tier
/// refuses is an InputError naming suite.cases[i].reference.
json load_suite(const std::string& path, const std::string& data_dir = "");

/// The checks of load_suite on a suite document read from `path`: every key known and of its
/// type at every level, thresholds and lists in range, and (with `scenes`) every case's scene
/// read by the 3D reader with its time-step variants, every 1D model's scene by the 1D
/// reader (also at each of cells1d and rtol1d), the extremes' scene files, the references' scenes
/// by the axi reader. The 3D reader reads each case (and its time-step variants) at its first
/// grid: it builds the membrane mesh, seconds on a fine grid; on the other grids the case's
/// `full3d` section is checked against the ranges the reader accepts (a grid out of range is
/// an InputError naming suite.cases[i].grids[g]), and rules that join several keys are checked
/// as they run.
void check_suite(const json& suite, const std::string& path, const std::string& data_dir, bool scenes = true);

/// A scene file named by the suite: as given, beside the suite file (suite_dir), or in
/// data_dir/scenes; InputError naming cases[].scene when none exists.
std::string find_scene(const std::string& name, const std::string& suite_dir, const std::string& data_dir);

/// Sets a dotted key of a scene to a JSON value, creating the objects on the way; null removes
/// the key (as `--set key=null` does).
void set_key(json& sc, const std::string& dotted, const json& value);

/// Applies a `set` ({"dotted.key": value}, or null for none) to a scene with set_key.
void apply_sets(json& sc, const json& sets);

/// Whether `name` selects the case: its scene file name (with or without .json) or its own
/// name (the `name` its `set` gives the scene).
bool case_selected_by(const json& cs, const std::string& name);
/// The cases of the suite a run takes: those selected by a name in `only` (case_selected_by),
/// every case when `only` is empty.
std::vector<json> selected_cases(const json& suite, const std::vector<std::string>& only);

/// The scene of one reference grid: the case's scene (after its own set), the reference's
/// set, the grid.
json reference_scene(const json& base, const json& ref, const json& grid);

/// The index in `grids` of a reference's coarsest grid (the largest cell size the axi tier
/// resolves), whatever the order the grids are listed in.
std::size_t coarsest_reference_grid(const json& base, const json& ref);

/// The scene of a reference's time check (its `tolerance_check` factor f): the coarsest grid's
/// reference scene with axi.tolerance at f times the tolerance it resolves to. Null when the
/// reference has no `tolerance_check`.
json tolerance_check_scene(const json& base, const json& ref);

/// The scene of a reference's wall check (its `spacing_check` factor f): the coarsest grid's
/// reference scene with axi.spacing_factor at f times the factor it resolves to (the rings
/// closer, the fluid's grid the same). Null when the reference has no `spacing_check`.
json spacing_check_scene(const json& base, const json& ref);

/// The 3D tier's full3d.recovery_end when a scene does not set it (full3d/scene3d.cpp; a test
/// checks the two agree).
inline constexpr const char* kRecoveryEndDefault3d = "dead_band";

/// The rule that ends a scene's 3D (and axisymmetric) recovery: its full3d.recovery_end, else
/// kRecoveryEndDefault3d.
std::string recovery_end_3d(const json& scene);

/// A force-driven scene whose model1d section names no recovery_end, with model1d.recovery_end
/// set to recovery_end_3d(s): its 1D cycle then ends as its 3D and axisymmetric runs' do. Any
/// other scene unchanged.
json with_recovery_end_3d(json s);

/// A 1D model's scene as the suite runs it: the case's scene `s` with the model's `set` and, for
/// a calibrated model (`"calibrated": true`), the calibration file `cal` in place of the scene's
/// own wall stiffness (its `wall.spring_constant` or `wall.C1`). A force-driven model whose set
/// does not name model1d.recovery_end ends its recovery by the case's full3d.recovery_end (its
/// reference's rule; kRecoveryEndDefault3d when the case does not set it), so that the tiers'
/// cycle times are measured to the same end.
json model_scene(json s, const json& model, const std::string& cal);

}  // namespace swim::validation
