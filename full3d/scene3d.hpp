// Scene -> 3D parameters. The sections every tier shares (name, swimmer, fluid, container,
// wall, wave, protocol, time) are read by scene::SharedScene (common/scene_shared.hpp) and
// mapped here; the 3D section "full3d" is read here, the 1D sections (model1d, numerics1d)
// and the axi section passed through unchanged. Every value used is echoed into `resolved`.
// Everything is validated here, before anything is written.
//
// 3D-specific rules (docs/scenes.md, "The full3d section"):
//   - the spring network needs k_s: wall.C1 and wall.calibration (1D lumped
//     stiffnesses) are rejected; wall.spring_constant (default 5.5e-8 N/m) is k_s.
//   - node masses m_i = (mass per area) * A_i, A_i the node's reference area.
//   - wave.kind must be force_driven (no prescribed kinematics in 3D; the axisymmetric tier
//     reads the same scene with prescribed_waves).
#pragma once

#include <string>

#include "common/scene.hpp"
#include "common/scene_shared.hpp"
#include "full3d/buckling_estimate.hpp"
#include "full3d/grid.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/membrane.hpp"
#include "full3d/protocol3d.hpp"

namespace swim::full3d {

/// Adaptive time-step control of the fluid-coupled run (full3d.adaptive; docs/full3d.md,
/// "Adaptive time step"). Each step is the smallest of: dt_max; growth-limited previous
/// step; the CFL target cfl h / max|U|; stability_fraction times the explicit-coupling limit
/// 2 / lambda_max (IbSolver::explicit_rate); the local-error bound sqrt(2 tolerance h / |dU/dt|);
/// the predicted time to the next contraction event. Snapped down to the ladder
/// dt_max 2^(-k/4) so that the fluid solver's per-dt factorisations are reused.
struct AdaptiveStep {
  bool enabled = false;
  double cfl = 0.25;                ///< target max|U| dt / h (below full3d.max_cfl)
  double tolerance = 1e-3;          ///< local position error per step, in cells (h)
  double dt_min = 1e-6;             ///< s; a smaller step ends the run (exit 3)
  double dt_max = 16e-3;            ///< s
  double event_dt = 0.25e-3;        ///< s; first step and the step after each protocol event
  double stability_fraction = 0.5;  ///< dt <= fraction * 2 / lambda_max (Chebyshev: fraction * beta_s / lambda_max)
  int max_stages = 8;               ///< full3d.scheme = chebyshev: the most stages of a step
};

struct Params3d {
  std::string name = "unnamed";
  // shared physics (SI)
  double R0 = 0.125e-6, L = 0.4e-6;
  FluidParams fluid{};
  MembraneParams membrane{};      ///< ks from wall.spring_constant; kb, bending form from full3d.membrane
  double mass_per_area = 0.0;     ///< kg/m^2
  ProtocolParams protocol{};
  /// The wave section; prescribed kinds (step, sine) only when the reader allows them (the
  /// axisymmetric tier), the protocol then keeps its defaults with R_f.
  scene::WaveSpec wave{};
  double duration = 0.0;          ///< s; <= 0: until protocol.cycles cycles are complete
  double output_interval = 5e-4;  ///< s
  // full3d
  std::string container = "duct";  ///< box | duct | cylinder
  double container_radius = 0.25e-6;  ///< Rc (cylinder) or half-width (box, duct), m
  double period = 2.0e-6;          ///< container length along x, m
  int nx = 128, ny = 32, nz = 32;  ///< grid cells
  double h = 0.5e-6 / 32;          ///< cell size, m
  /// The wall's bending rigidity D, J, as read (docs/full3d.md, "The wall model"):
  ///  - BendingModel::Rigidity (default): D is full3d.membrane.bending_rigidity, or the paper's
  ///    k_b (full3d.membrane.bending_constant) mapped to D on the scene's tube meshed at the
  ///    reference edge (full3d.membrane.reference_edge); membrane.kb is then set per mesh so
  ///    that eq. (8) gives the wall this D on the run's mesh (bending_rigidity_per_kb);
  ///  - BendingModel::FixedKb (the paper's literal eq. 8, a reproduction setting): membrane.kb
  ///    is bending_constant on every mesh and D is what it gives the run's mesh.
  enum class BendingModel { Rigidity, FixedKb };
  BendingModel bending_model = BendingModel::Rigidity;
  double bending_rigidity = 0.0;
  double reference_edge = 0.0;     ///< m; the edge length bending_constant is mapped at (0: not used)
  std::string bending_source;      ///< where D comes from (summary.json derived.bending_rigidity_from)
  /// full3d.membrane.seed_mode, seed_amplitude: lobes m of amplitude eps R0 in the stress-free
  /// shape (seed_ring_mode); 0: none
  int seed_mode = 0;
  double seed_amplitude = 0.0;
  /// full3d.membrane.seed_mode = "auto": seed_mode is the lobe number the linear buckling
  /// estimate of the contraction grows fastest in the fluid (buckling_estimate.hpp,
  /// auto_seed_mode), 0 when every stage is stable or the wall is held axisymmetric.
  bool seed_auto = false;
  /// full3d.membrane.secondary_seed_mode, secondary_seed_amplitude: a second lobe number of the
  /// stress-free shape, added to the seed (seed_ring_modes); 0: none. The lobes a buckled wall's
  /// secondary instability grows (docs/full3d.md, "Lobes that change: the secondary instability").
  int secondary_seed_mode = 0;
  double secondary_seed_amplitude = 0.0;
  /// full3d.membrane.axisymmetric: the wall moves in axisymmetric ring motions only
  /// (IbOptions::axisymmetric_wall); false (default): every node follows the fluid.
  bool axisymmetric_wall = false;
  double spacing_factor = 0.6;     ///< longest reference edge < factor * h/2 (docs/full3d.md)
  /// full3d.membrane.ring_nodes_multiple: the node count per ring is a multiple of it (1: the
  /// coarsest count the spacing allows). 4 gives every grid the square's symmetry of the
  /// Cartesian fluid grid (docs/full3d.md, "Lobes that change: the secondary instability").
  int ring_nodes_multiple = 1;
  double dt = 1e-3;                ///< s (resolution study: docs/performance-3d.md); fixed step
  AdaptiveStep adaptive{};         ///< full3d.adaptive: step control instead of the fixed dt
  IbScheme scheme = IbScheme::ForwardEuler;
  /// full3d.wall_stabilization, full3d.stabilization_factor: the stabilised wall update
  /// (wall_stabilizer.hpp; docs/full3d.md, "The stabilised wall step")
  WallStabilization wall_stabilization = WallStabilization::None;
  double stabilization_factor = 1.0;
  /// full3d.memory_limit_gib: the memory the fluid solver's factors may take, GiB
  double memory_limit_gib = 4.0;
  bool wall_inertia = false;       ///< -m a term of eq. (16) in the fluid-coupled run
  bool navier_stokes = false;      ///< StokesOptions::advection (eq. 28 sub-step before each Stokes step)
  /// energy: the paper's end of recovery (E < energy_tolerance E_ref); dead_band: also ends
  /// once E is below the energy of the tube uniformly at R0 - delta; shape: ring radii and
  /// axial ring positions back within delta of the reference (docs/full3d.md).
  std::string recovery_end = "dead_band";
  bool dry = false;                ///< paper's dry swimmer: m r'' + nu r' - F(r) = F_ext
  double dry_damping = 1e4;        ///< nu per wall area, kg/(m^2 s) (node damping nu A_i)
  double max_cfl = 0.5;
  double energy_growth = 50.0;     ///< guard: wall energy above this many times max(E_ref, E_static)
  double time_limit = 2.0;         ///< s; run cap when the duration is auto
  bool vtk = true;
  double vtk_interval = 5e-4;      ///< s
  bool fluid_fields = false;
  double fluid_interval = 5e-3;    ///< s
  double checkpoint_interval = 5e-3;  ///< s of simulated time
  int threads = 1;

  double c1_estimate() const;      ///< 2 ks / (sqrt(3) R0^2), Pa/m
  GridBoundary grid_boundary() const;
  /// Axis start (centre of ring 0): the swimmer is centred in the container.
  Eigen::Vector3d axis_start() const;
};

/// Throws swim::InputError naming the key, the value and what is allowed.
/// prescribed_waves: accept wave.kind = step | sine (the axisymmetric tier's fitted method;
/// the protocol section is then refused, as the 1D tier does); false: force_driven only.
Params3d read_scene3d(const scene::json& scene, scene::json& resolved, bool prescribed_waves = false);

/// The protocol parameters with the recovery-end energy of full3d.recovery_end filled in.
ProtocolParams effective_protocol(const Params3d& p, const CylinderMesh& mesh);

/// The reference mesh of the scene (no-leak rule with the scene's spacing factor), with the
/// scene's seed imperfection (full3d.membrane.seed_mode, seed_amplitude) in its stress-free shape.
CylinderMesh make_mesh(const Params3d& p);
/// The scene's contraction stages of the linear buckling estimate (contraction_buckling): the
/// network's 2D Young's modulus Y = 2 k_s / sqrt(3), the hoop compression q R0 that holds R_f,
/// the scene's D and viscosity.
std::vector<ContractionStage> scene_contraction_buckling(const Params3d& p);
/// The lobe number seed_mode = "auto" resolves to for the scene's wall, load and protocol: of the
/// contraction's stages (scene_contraction_buckling), the mode of the fastest-growing one; 0 when
/// no stage buckles, for an axisymmetric or dry wall, or without a force-driven load.
int auto_seed_mode(const Params3d& p);
/// The same tube without the seed imperfection: the round tube whose law the calibration
/// measures and on which D / k_b is measured.
CylinderMesh make_round_mesh(const Params3d& p);

/// The default of full3d.membrane.reference_edge, m: the longest-edge bound of the default
/// grid of the paper's container, 0.6 * (0.5 um / 32) / 2 = 4.6875 nm.
inline constexpr double kDefaultReferenceEdge = 4.6875e-9;
/// D / k_b (m) of eq. (8) on the tube of radius R0 and length L meshed at the reference edge
/// a_ref (the coarsest mesh whose longest edge is below a_ref): the map from the paper's k_b
/// to the wall's D. Cached per (R0, L, a_ref, form).
double reference_rigidity_per_kb(double R0, double L, double a_ref, BendingForm form);

}  // namespace swim::full3d
