// Scene -> parameters of the axisymmetric reference tier (`swim run SCENE --tier axi`).
//
// The tier solves the same scene as the 3D tier's round wall: the shared sections (swimmer,
// fluid, wall, wave, protocol, time, container; common/scene_shared.hpp) and the full3d
// section's wall keys are read through the 3D tier's own reader (full3d/scene3d.hpp), so
// that both tiers run the same physics; the `axi` section holds this tier's numerics
// (docs/axi.md, docs/scenes.md "The axi section"). Model only what the scene asks for:
//   - the wall must be held round: full3d.membrane.axisymmetric = true;
//   - the container must be the rigid cylinder (container.kind = "cylinder");
//   - Stokes flow, no wall inertia, no dry swimmer (full3d.navier_stokes, full3d.wall_inertia,
//     full3d.dry must be false), the reference-angle bending form;
//   - wave.kind = step | sine (the prescribed waves, as on the 1D tier; the protocol
//     section is then refused) with axi.method = fitted only.
// Anything else is an InputError (exit 2) naming the key, before anything is written.
#pragma once

#include <string>
#include <vector>

#include "axi/fitted_mesh.hpp"
#include "axi/tri_mesh.hpp"
#include "common/scene.hpp"
#include "full3d/scene3d.hpp"

namespace swim::axi {

/// How the wall is coupled to the fluid (axi.method).
enum class AxiMethod {
  ImmersedBoundary,  ///< MAC grid, FFT along the axis, Peskin kernel: the 3D tier's family, first order
  Fitted,            ///< finite elements on a mesh fitted to the wall (sharp interface), implicit wall steps
};

/// Default axi.tolerance of a prescribed wave: the time quadrature's error in the displacement
/// over the run, in cells h (docs/axi.md "Prescribed waves").
inline constexpr double kPrescribedTolerance = 1e-4;
/// The smallest axi.tolerance a scene may ask for (cells per step).
inline constexpr double kMinTolerance = 1e-6;

/// Growth ratio of the ring spacing from the rims inwards (axi.rim_refinement < 1).
inline constexpr double kRimGrowth = 1.5;

struct ParamsAxi {
  full3d::Params3d base;       ///< the shared physics, as the 3D tier reads it
  AxiMethod method = AxiMethod::Fitted;
  // fitted mesh (method Fitted): element rows and gap columns from h (docs/axi.md)
  int cells_inner = 0, cells_outer = 0, gap_columns = 0;
  bool triangles = false;      ///< axi.mesh = triangles: the moved triangulation (axi/tri_mesh.hpp) instead
  double remesh_angle = 0.0;   ///< rad: triangles, the smallest angle below which the mesh is made again
  double gap_size = 1.0;       ///< triangles: the gap's largest size bound over h (TriMeshParams::gap_size)
  /// triangles: s of simulated time between the scheduled remeshes, whose times the steps land
  /// on; between them only a mesh that cannot follow the wall, or whose smallest angle fell below
  /// half the threshold, is made again (0: made again whenever it degrades, checked every step)
  double remesh_interval = 0.0;
  // grid
  int nr = 32, nx = 256;       ///< radial and axial cells
  double h = 0.0;              ///< m
  // wall
  double spacing_factor = 0.5; ///< meridional node spacing <= spacing_factor * h / 2 (immersed boundary), <= h (fitted)
  int wall_nodes = 0;
  double rim_refinement = 1.0; ///< fitted: end ring spacing / interior spacing, min(1, axi.rim_refinement h / R0)
  double wall_row_aspect = 0.0; ///< fitted: rows graded towards the wall where columns are narrow (FittedMeshParams)
  std::vector<double> ring_s0; ///< reference ring positions (fitted; empty: uniform), m
  double ks = 0.0;             ///< N/m, the network's spring constant
  bool poisson_coupling = true; ///< axi.wall_poisson_coupling: false is the diagnostic wall of Poisson ratio 0
  double D = 0.0;              ///< J, the wall's bending rigidity
  std::string bending_source;  ///< "full3d.membrane.bending_rigidity" or the k_b mapping used
  // time stepping (immersed boundary: explicit trapezoidal rule with an embedded Euler error
  // estimate; fitted: the two-stage Rosenbrock method ROS2 with its embedded first-order step)
  double tolerance = 2e-4;     ///< local position error per step, in cells (h)
  double dt_max = 8e-3, dt_min = 1e-8, event_dt = 1e-4;  ///< s
  double time_limit = 2.0;     ///< s; run cap when the duration is auto
  double checkpoint_interval = 0.0;  ///< s of simulated time between checkpoints (protocol-driven runs)
  int threads = 2;             ///< fitted: 2 = factorisations on a second thread (axi.threads)

  const std::string& name() const { return base.name; }
  const char* method_name() const { return method == AxiMethod::Fitted ? "fitted" : "immersed_boundary"; }
  double x_start() const { return 0.5 * (nx * h - base.L); }  ///< axial position of the rear end
};

/// The fitted mesh's parameters (method Fitted; read_scene_axi derives them from h).
FittedMeshParams fitted_mesh_params(const ParamsAxi& p);

/// The triangulation's parameters (axi.mesh = triangles): triangles' longest edge
/// kTriangleSize h away from the wall.
inline constexpr double kTriangleSize = 1.0;
/// The default of axi.gap_size: beyond the tube's ends the triangles' size bound grows to this
/// multiple of h (TriMeshParams::gap_size).
inline constexpr double kGapSize = 3.0;
TriMeshParams tri_mesh_params(const ParamsAxi& p);

/// Throws swim::InputError naming the key, the value and what is allowed.
ParamsAxi read_scene_axi(const scene::json& scene, scene::json& resolved);

/// The keys of the `axi` section (for the other tiers' pass-through check).
const scene::json& section_keys();

}  // namespace swim::axi
