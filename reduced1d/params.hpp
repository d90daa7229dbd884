// Typed, SI parameters of the reduced 1D lubrication fluid-structure model.
//
// The scene layer (reduced1d/scene1d.cpp) fills these from a scene file, after unit
// conversion and validation; the solver never sees unit strings. Every field has its
// default here, and the scene layer echoes every value it used.
//
// Models (docs/reduced1d.md has the derivations, docs/outer-flow-1d.md the outer flows):
//
// Force-free Stokes swimmer (the default, SwimmerModel::ForceFree). In the swimmer frame
// (zeta = z - X(t) in [0, L]):
//   tube wall   m R_tt + C1 (R - R0) = p_in - p_out - q(z,t)       (tube law with actuation q)
//               [- 4 mu |k| R_t with model1d.short_wave_traction: the wall's normal viscous stress]
//   lumen       Q_in = -(pi (R - a_in)^4 / 8 mu) dp_in/dz,  d(pi R^2)/dt + dQ_in/dz = 0
//   outer flow  confined : Poiseuille-Couette annulus (R + a_out .. Rc) in parallel with the
//                          lumen, a free pipe of radius Rc over the rest of the period P - L,
//                          periodic pressure, container wall at rest in the lab frame;
//               unbounded: slender body, resistive-force drag on U plus the axial flow that
//                          the wall's line of sources and the two end jets induce;
//   swimmer     total axial force on the tube = 0 at every instant -> U(t); X' = U.
//
// The paper's 1D model (SwimmerModel::Paper, a labelled reproduction mode):
//   fluid       Q = -(pi R^4 / 8 mu) dp/dz,  d(pi R^2)/dt + dQ/dz = 0, p(0) = p(L) = p_ext
//   swimmer     per area  : m   W = (pi rho / 8 mu L) int R^4 p_z dz - (1 / 2L) int_0^t int R   p_z dz dtau
//               per length: m_l W = (pi rho / 8 mu L) int R^4 p_z dz - (pi / L) int_0^t int R^2 p_z dz dtau
//               with m_l = 2 pi R0 m, and p_z either C1 R_z (tube-law closure, eq. 50) or the
//               lubrication pressure gradient of the flow closure.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace swim::reduced1d {

class TubeLaw;          // reduced1d/tube_law.hpp
struct RecordedRadius;  // reduced1d/recorded_wave.hpp

/// How the radius wave R(z,t) is produced.
enum class WaveKind {
  Step,         ///< prescribed smoothed step (eq. 53) travelling in -z at speed s
  Sine,         ///< prescribed contraction sinusoid travelling in -z
  ForceDriven,  ///< radius evolves under the actuation protocol of Section 3 mapped to 1D
  Recorded,     ///< prescribed R(z,t) replayed from a recorded radius.csv (wave.radius_file)
};

/// Which swimmer model defines the velocity.
enum class SwimmerModel {
  ForceFree,  ///< Stokes: zero total axial force at every instant (default)
  Paper,      ///< the paper's balance (45)/(52), reproduction mode
};

/// Outer flow of the force-free model.
enum class OuterFlow {
  Confined,   ///< lubrication lumen + annulus + free pipe in the scene's container (default)
  Unbounded,  ///< slender-body outer flow in unbounded fluid
};

/// Shape of the rigid container (scene key `container.kind`), shared with the 3D tier.
/// Not the 3D grid's boundary (full3d::GridBoundary), onto which the 3D tier maps it.
enum class ContainerShape { Cylinder, Duct, Box };

/// Pressure gradient used in the swimmer-velocity relation (45)/(51) (paper mode).
enum class Closure {
  TubeLaw,  ///< paper: dp/dz = C1 dR/dz (eq. 50)
  Flow,     ///< source-equations.md §3: dp/dz from lubrication flow with open ends
};

/// Which force balance defines W (source-equations.md §4).
enum class Balance { PerArea, PerLength };

/// External drag on the swimmer body in paper mode. Not in the paper.
enum class ExternalDrag { None, ResistiveForce };

struct Geometry {
  double R0 = 0.125e-6;  ///< reference radius [m]
  double L = 0.4e-6;     ///< length [m]
};

struct Fluid {
  double mu = 1.2e-3;         ///< dynamic viscosity [Pa s]
  double rho = 1.0e3;         ///< density [kg/m^3]
  double temperature = 310.0; ///< absolute temperature [K] (Brownian scale of the design)
};

/// The rigid periodic container. The 1D tier sees a circular pipe of radius `radius_eff`:
/// the cylinder's own radius, or for the square duct of half-width `radius` the radius of
/// the circular pipe with the same Poiseuille conductance (1.0939 x half-width).
struct Container {
  ContainerShape shape = ContainerShape::Duct;
  double radius = 0.25e-6;      ///< cylinder radius or duct half-width [m]
  double period = 2.0e-6;       ///< axial period [m]
  double radius_eff = 0.25e-6;  ///< circular radius the 1D tier uses [m]
};

struct Wall {
  double C1 = 4.06e6;    ///< wall stiffness: pressure per unit radial displacement [Pa/m]
  double m = 1.0e-3;     ///< wall mass per unit wall area [kg/m^2]
  bool inertia = false;  ///< keep m R_tt in the wall equation (force-driven wave only)
  /// Nonlinear static tube law w(R) in place of C1 (R - R0) (wall.law, docs/tube-law.md);
  /// nullptr: the linear law. Force-free model, force-driven wave only. C1 then is the law's
  /// calibrated small-load stiffness and sets the scales (time, pressure) only.
  std::shared_ptr<const TubeLaw> law;
  /// Bending rigidity of the wall along the axis, D [J] (model1d.axial_bending): the term
  /// D d^4R/dz^4 of an axisymmetric thin shell in the wall equation, so that a load of axial
  /// wavenumber k meets the stiffness C1 + D k^4 (docs/reduced1d.md, section 5). 0: the
  /// local law alone. Force-free model, force-driven wave only.
  double D_axial = 0.0;
};

/// Prescribed smoothed step, eq. (53): R = R_min + (R0 - R_min) H((z*(t) - z)/w),
/// z*(t) = L - s t, H(x) = (1 + tanh x)/2. R = R0 behind the front (z < z*), R_min ahead.
struct StepWave {
  double R_min = 0.55 * 0.125e-6;  ///< contracted radius [m]
  double speed = 1.0e-5;           ///< front speed s > 0 (front moves towards -z) [m/s]
  double width = 0.01e-6;          ///< smoothing width w [m]
};

/// Prescribed sinusoid: R = R0 - (a/2) (1 - cos(2 pi (z + s t) / lambda)), travelling in -z.
struct SineWave {
  double amplitude = 0.45 * 0.125e-6;  ///< a = R0 - R_min [m]
  double wavelength = 0.4e-6;          ///< lambda [m]
  double speed = 1.0e-5;               ///< s > 0 [m/s]
};

/// How the recovery of a force-driven cycle ends (model1d.recovery_end; the 3D and axisymmetric
/// tiers' full3d.recovery_end has the same values): Energy, the paper's rule, E < energy_tol E_ref;
/// DeadBand, E < max(energy_tol E_ref, E_delta) with E_delta the wall energy of the tube uniformly
/// at R0 - delta; Shape, every cell's radius within delta of R0.
enum class RecoveryEnd { Energy, DeadBand, Shape };
/// The scene's name of a rule ("energy", "dead_band", "shape").
inline const char* recovery_end_name(RecoveryEnd e) {
  return e == RecoveryEnd::Shape ? "shape" : e == RecoveryEnd::DeadBand ? "dead_band" : "energy";
}

/// Force-driven protocol of Section 3 mapped to 1D (source-equations.md §7).
/// Segment k = 0..n-1 covers [z_k, z_{k+1}); the rightmost segment (k = n-1) is the first one
/// driven and the shortest: its length is first_ratio times the length of each other segment.
struct Protocol {
  double R_f = 0.55 * 0.125e-6;  ///< target contracted radius [m]
  double q = 0.32;               ///< actuation pressure F_ext / (wall area) [Pa], inward positive
  int segments = 6;              ///< number of segments n >= 2
  double first_ratio = 1.0 / 3.0;  ///< length of the first (rightmost) segment / other segments
  double delta = 0.02 * 0.125e-6;  ///< radius tolerance delta [m]
  double energy_tol = 1e-3;        ///< recovery ends when E < energy_tol * E_ref,
                                   ///< E_ref = elastic energy of the tube uniformly at R_f
  RecoveryEnd recovery_end = RecoveryEnd::Energy;  ///< the rule that ends the recovery
  int cycles = 1;                  ///< number of contraction+recovery cycles (>= 1)
};

struct Swimmer {
  SwimmerModel model = SwimmerModel::ForceFree;
  OuterFlow outer = OuterFlow::Confined;
  double a_in = 0.0;   ///< hydraulic offset of the lumen: the lumen conducts as radius R - a_in [m]
  double a_out = 0.0;  ///< hydraulic offset of the outside: the outer flow sees radius R + a_out [m]
  /// End effects of the open ends (confined force-free model, prescribed waves): each end acts as
  /// a rigid extension of the lumen by end_lumen R_i and of the annulus by end_annulus (Rc - R_o)
  /// (docs/outer-flow-1d.md §2b). 0: the plain lubrication junction.
  double end_lumen = 0.0, end_annulus = 0.0;
  /// The open ends as the calibrated junction (outer::kCalibratedJunction; prescribed and
  /// force-driven waves, docs/outer-flow-1d.md §2c)
  bool end_junction = false;
  /// Short-wave wall traction (force-driven wave only): the viscous normal stress 2 mu |k| Rdot
  /// that each fluid (lumen, outside) exerts on a wall moving at axial wavenumbers the
  /// lubrication flow does not resolve, added to the tube law (docs/outer-flow-1d.md, 3b).
  /// Off in this struct (the library's lubrication-only wall, as the struct's wave defaults
  /// to a prescribed step); the scene layer turns it on for the force-free force-driven wave.
  bool short_wave_traction = false;
  /// The traction operator's end condition, beta in [0, 1] (model1d.short_wave_traction_end):
  /// each field's value beyond an open end is (1 - beta + beta r_j) times the end cell's, r_j
  /// the field's decay along a wall at rest. 0: mirror ends (the wall continued by its own
  /// motion); 1: the tube continued by a wall at rest (docs/outer-flow-1d.md §2c).
  double traction_end = 0.0;
  /// Paper mode only:
  Closure closure = Closure::TubeLaw;
  Balance balance = Balance::PerArea;
  bool thrust = true;  ///< keep the displaced-momentum (thrust) term of (45)
  ExternalDrag drag = ExternalDrag::None;
};

/// The open ends of a force-driven wave.
enum class OpenEnd {
  Drainage,   ///< at the static radius of the end's actuation; the half cell a drainage layer
  Linear,     ///< at the static radius of the end's actuation; R linear across the half cell
  Continued,  ///< the end cell's radius continued to the mouth (with the short-wave traction only)
};

struct Numerics {
  int cells = 200;              ///< number of finite-volume cells along z
  double rtol = 1e-6;           ///< relative tolerance of CVODE/IDA
  double atol_scale = 1e-6;     ///< absolute tolerance as a fraction of each state's scale
  double output_interval = 1e-3;  ///< series/radius output interval [s]
  long max_steps = 2000000;     ///< integrator step budget for the whole run
  /// Threads of a force-driven run: 2 evaluates the output samples on a second thread while
  /// the first integrates (the same results bit for bit).
  int threads = 1;
  /// Force-driven wave without the axial bending or the calibrated junction (whose ends are
  /// their own): the open ends (numerics1d.open_end; docs/reduced1d.md, "The open ends' half
  /// cells").
  OpenEnd open_end = OpenEnd::Drainage;
};

struct Params {
  std::string name = "unnamed";
  Geometry geometry;
  Fluid fluid;
  Wall wall;
  WaveKind wave = WaveKind::Step;
  StepWave step;
  SineWave sine;
  /// wave.kind = "recorded": the record (its span is the period); nullptr otherwise
  std::shared_ptr<const RecordedRadius> recorded;
  Protocol protocol;
  Swimmer swimmer;
  Container container;
  Numerics numerics;
  /// End time [s]. For prescribed waves the default is the wave transit time; for the
  /// force-driven wave, <= 0 means "run until protocol.cycles cycles have completed".
  double duration = 0.0;
};

}  // namespace swim::reduced1d
