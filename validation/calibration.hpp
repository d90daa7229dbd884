// Calibration of the 1D tier from the 3D membrane: the wall stiffness C1 from uniform loads
// (the paper's Figure 10, done with pressures: source-equations.md §1).
//
// For each pressure P of a series, the 3D spring-network membrane of the scene is relaxed to
// equilibrium under the uniform inward load P A_i e_r per node (full3d::relax_under_pressure,
// the static "dry" path), and the radial displacement delta = R0 - R_mid of the middle
// ring(s), away from the tube's ends, is measured. C1 is fitted to P = C1 delta with GSL:
// through the origin (gsl_fit_mul) and with an intercept (gsl_fit_linear), over the loads for
// which the response stays linear (secant P / delta within 1 % of the smallest load's).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/scene.hpp"
#include "full3d/membrane.hpp"
#include "full3d/scene3d.hpp"

namespace swim::validation {

struct LoadPoint {
  double pressure_Pa = 0;
  double displacement_m = 0;   ///< R0 - R_mid
  double secant_C1_Pa_per_m = 0;
  int iterations = 0;
  bool in_linear_range = false;
  /// Second derivative of the loaded energy along the unit ring modes V_i = cos(n phi_i) e_r,i / |V|
  /// at the equilibrium, n = 2 .. 32 (entry n - 2; further while the last is the softest), N/m: the symmetric equilibrium is
  /// unstable to ring buckling when one is negative.
  std::vector<double> ring_mode_stiffness_N_per_m;
  int softest_ring_mode = 0;                     ///< n of the smallest entry
  double softest_ring_mode_stiffness_N_per_m = 0;
  /// Smallest eigenvalue of the loaded energy's Hessian without the rigid motions (Lanczos,
  /// 150 Hessian-vector products), N/m: negative proves the symmetric equilibrium unstable.
  double lowest_eigenvalue_N_per_m = 0;
  bool stable() const { return softest_ring_mode_stiffness_N_per_m > 0 && lowest_eigenvalue_N_per_m > 0; }
};

struct C1Fit {
  double c1 = 0, c1_stderr = 0, r2 = 0;           ///< through the origin, Pa/m
  double slope = 0, slope_stderr = 0;             ///< with an intercept, Pa/m
  double intercept = 0, intercept_stderr = 0, r2_linear = 0;  ///< Pa
  double linear_up_to_Pa = 0;                     ///< largest load within 1 % of linear
  bool linear_over_all_loads = false;             ///< no load left the 1 % band: the range is a lower bound
  int points = 0;                                 ///< loads used in the fits
};

struct StaticCalibration {
  std::vector<LoadPoint> loads;
  C1Fit fit;
  double spring_network_c1 = 0;  ///< 2 k_s / (sqrt 3 R0^2), Pa/m
  int n_theta = 0, n_rings = 0, nodes = 0;
  /// > 0: the loads from this pressure on reached no static state (the first such load's
  /// reason below); they are not in `loads`
  double no_static_state_from_Pa = 0;
  std::string no_static_state_reason;
};

/// Loads as fractions of the static load C1_net (R0 - R_f) that holds the scene's target
/// radius (C1_net the spring-network estimate): thirteen loads from 1 % to 150 %, dense below 20 % where ring buckling sets in.
std::vector<double> default_loads(const full3d::Params3d& p);

/// Loads are relaxed in increasing order. A load whose relaxation does not converge ends the
/// series when three or more loads have converged (StaticCalibration::no_static_state_from_Pa;
/// a deep target such as R_f = 0.35 R0 puts the largest default loads beyond the tube's
/// range); before that it throws NumericalError. InputError for loads <= 0.
/// Points that are unstable to ring buckling (LoadPoint::stable) are reported and left out of
/// the fits.
/// on_load (optional): called after each load with the number of loads relaxed so far.
/// The loads act on the round tube (full3d::make_round_mesh): a scene's seed imperfection starts
/// the buckling of its dynamic runs and is left out; the static loads find the round tube's
/// buckling on their own (the stability checks).
StaticCalibration calibrate_static(const full3d::Params3d& p, const std::vector<double>& pressures,
                                   const std::function<void(std::size_t)>& on_load = {});

// ---- The wall's stiffness along the axis, C(k) ----------------------------------------------
//
// A thin cylindrical shell under an axisymmetric radial load p(x) with free axial ends obeys
// D w'''' + (Y / R0^2) w = p (w the inward radial displacement, D the bending rigidity, Y the
// 2D stretching modulus, C1 = Y / R0^2): a load p0 cos(k x) gives the amplitude p0 / C(k) with
// C(k) = C1 + D k^4. The 1D tier's local law p = C1 (R0 - R) is the k = 0 limit; its bending
// term D d^4R/dz^4 needs the D the network actually has along the axis.
//
// measure_axial_stiffness: a long round tube of the scene's wall (R0, k_s, D, form of eq. 8)
// and node spacing (the round calibration mesh's n_theta; rings at the equilateral spacing) is
// loaded with the inward ring pressures P_k = p0 cos(k (x_k - x_mid)) (x_k the ring's reference
// axial position, x_mid the tube's middle) and relaxed to its static state
// (full3d::relax_under_ring_pressures). The amplitude a of the inward ring displacement
// R0 - r_k is fitted by least squares to a cos + b sin + c over the middle window (an integer
// number of wavelengths, away from the open ends), and C(k) = p0 / a. C1 is measured the same
// way with a uniform load (k = 0: the mean displacement over the window). Every load is set for
// an amplitude of 1e-3 R0 (linear range). Wavelengths: lambda_j = lambda_0 2^j, j = 0..3, with
// lambda_0 = max(1.5 l_b, 8 dx) (l_b = (D / C1_net)^(1/4) the bending length from the scene's D
// and the network's C1_net = 2 k_s / (sqrt 3 R0^2), dx the ring spacing); the window is
// 2 lambda_3 long and each end margin max(10 l_b, 2 lambda_0) (an end disturbance decays as
// exp(-x / (sqrt 2 l_b))). Fits (GSL, weights 1 / C^2): C - C1 = D_axial K^4 through the
// origin (gsl_fit_wmul), K = (2 / dx) sin(k dx / 2) the ring lattice's wavenumber (its fourth
// difference: D k^4 less 6-9 % at 8-10 rings per wavelength); the same on k^4, for comparison;
// and C - C1 = A k^2 + D K^4 (gsl_multifit_wlinear) to show whether a k^2 term is needed (the
// shell's bending coupling of the axial and hoop curvatures gives A = -2 nu_b D / R0^2).
struct AxialStiffness {
  std::vector<double> wavelengths_m, wavenumbers_per_m;
  std::vector<double> lattice_wavenumbers_per_m;  ///< K = (2 / dx) sin(k dx / 2), dx the ring spacing
  std::vector<double> load_amplitudes_Pa;      ///< p0 per wavelength
  std::vector<double> response_amplitudes_m;   ///< a, inward
  std::vector<double> C_Pa_per_m;              ///< p0 / a
  std::vector<double> quadrature_ratio;        ///< |b| / a (sin component; 0 for a symmetric response)
  std::vector<double> profile_residual_ratio;  ///< rms of the fit's residual over the window / a
  std::vector<int> iterations;                 ///< Newton iterations per load
  double c1 = 0;                               ///< uniform load on the long tube, Pa/m
  double c1_load_Pa = 0, c1_displacement_m = 0;
  double d_fit = 0, d_fit_stderr = 0, d_fit_r2 = 0;      ///< C - C1 = D K^4, J: D_axial
  double d_fit_continuum_k = 0, d_fit_continuum_k_stderr = 0;  ///< C - C1 = D k^4, J
  double k2_coefficient = 0, k2_coefficient_stderr = 0;  ///< A of C - C1 = A k^2 + D K^4, N/m
  double d_fit_k2 = 0, d_fit_k2_stderr = 0;              ///< D of the same fit, J
  double d_wall = 0;                  ///< the scene's resolved D (Params3d::bending_rigidity), J
  double bending_length_m = 0;        ///< (D_wall / C1)^(1/4), C1 measured here
  double tube_length_m = 0, window_m = 0, end_margin_m = 0, ring_spacing_m = 0;
  double bending_constant_N = 0;      ///< k_b of eq. (8) on the long tube
  int n_theta = 0, n_rings = 0, nodes = 0;
  double wall_time_s = 0;
};
/// The long tube's k_b gives it the scene's resolved D (k_b = D / (D / k_b of the long mesh)),
/// with either bending model: with FixedKb the scene's D is that of its own mesh. Throws
/// swim::NumericalError when a load reaches no static state.
AxialStiffness measure_axial_stiffness(const full3d::Params3d& p);
/// calibration.json's "axial_stiffness" section.
scene::json to_json(const AxialStiffness& a);
/// Adds the "axial_stiffness" section and the top-level "axial_bending_rigidity_J" (the fitted
/// D_axial: the rigidity the 1D tier's bending term reads) to calibration.json `j`.
void add_axial_stiffness(scene::json& j, const AxialStiffness& a);
/// measure_axial_stiffness for a calibration, whose C1 and offsets stay measurable when it fails.
struct AxialStiffnessOutcome {
  std::optional<AxialStiffness> measured;
  std::string failure;  ///< the reason when it reached no static state
  /// calibration.json's entries: {"axial_stiffness", "axial_bending_rigidity_J"}
  /// (add_axial_stiffness), or {"axial_stiffness": {"status": "failed: <reason>"}} without the
  /// rigidity (the 1D models that read it are then refused). For json::update.
  scene::json entries() const;
};
AxialStiffnessOutcome try_measure_axial_stiffness(const full3d::Params3d& p);

/// Fluid-coupled confirmation of one static load: the scene's 3D tube, immersed in its fluid and
/// container, under the same uniform inward pressure, stepped (forward Euler, the step set to
/// half the explicit stability limit of the coupling, IbSolver::explicit_rate) until the middle
/// radius is steady: it changes by less than 1e-3 of its displacement over the last tenth of
/// the elapsed time, or 4 000 steps pass. With axisymmetric_wall (the default) the wall moves
/// in ring motions only (IbOptions::axisymmetric_wall), the branch the static path computes
/// and C1 describes; the free wall buckles into lobes beyond a few per cent of the target load
/// (docs/validation.md).
struct WetConfirmation {
  double pressure_Pa = 0;
  double displacement_m = 0;         ///< R0 - R_mid at the end of the wet run
  double static_displacement_m = 0;  ///< the static path's at the same load
  double relative_difference = 0;    ///< wet / static - 1
  double simulated_time_s = 0, dt_s = 0, wall_time_s = 0;
  int steps = 0;
  bool steady = false;
  bool axisymmetric_wall = true;
};
WetConfirmation confirm_wet(const full3d::Params3d& p, double pressure, double static_displacement_m,
                            bool axisymmetric_wall = true);

// ---- The whole static tube law (docs/tube-law.md) -------------------------------------------
//
// Uniform inward loads P, relaxed to equilibrium on the 3D membrane, in increasing order with
// each load starting from the previous equilibrium (continuation), until the middle radius is
// at most `deepest_ratio` R0. Two branches:
//  - round: the symmetric stack of circular rings (relax_under_pressure), the branch of a wall
//    held axisymmetric (full3d.membrane.axisymmetric = true); nothing buckles. Checked against
//    the spring network's closed form for a ring of springs (round_closed_form_c1);
//  - buckled: the paper's free wall. The full mesh (every node free) is relaxed by minimising the
//    loaded energy (L-BFGS) at the same loads in increasing order, each from the previous
//    equilibrium plus a seeded ring mode cos(n phi) e_r of the round branch's buckling n
//    (amplitude seed_amplitude_ratio R0, uniform along the tube). The load fades within
//    axis_contact_ratio R0 of the axis (minimise_loaded_energy), where a collapsing wall meets
//    itself (the membrane has no self-contact).
// The radius is the mean node radius of the middle ring(s), as for C1.
struct LawPoint {
  double pressure_Pa = 0;
  double mid_radius_m = 0;      ///< mean node radius of the middle ring(s)
  double area_radius_m = 0;     ///< sqrt(area enclosed by the middle ring / pi)
  double radius_spread_m = 0;   ///< max - min node radius on the middle ring(s) (0: round)
  double min_node_radius_m = 0; ///< smallest node radius on the whole mesh
  double softest_ring_mode_stiffness_N_per_m = 0;  ///< round branch: < 0 from the buckling load on
  int softest_ring_mode = 0;
  double residual_force_N = 0;  ///< largest nodal force imbalance at the accepted equilibrium
  int iterations = 0;
};

/// The monotone law of one branch: knots (R ascending, w = -P; the last knot (R0, 0)), the
/// Steffen interpolant's slope at R0, and leave-one-out residuals (each interior knot left out,
/// the law rebuilt and evaluated there).
struct LawBranch {
  std::vector<LawPoint> points;
  std::vector<double> knots_R, knots_w;
  double slope_at_R0 = 0;          ///< Pa/m
  double slope_at_R0_loo = 0;      ///< the same with the smallest-load knot left out
  double loo_max_abs_Pa = 0, loo_rms_Pa = 0, loo_max_rel = 0;
  int dropped_non_monotone = 0;    ///< points that broke strict monotonicity (left out)
  std::string stopped_because;     ///< why the load series ended
  double wall_time_s = 0;
};

struct TubeLawOptions {
  double deepest_ratio = 0.3;            ///< the series ends once R_mid <= this * R0
  double seed_amplitude_ratio = 1e-3;    ///< seeded ring mode at every load, fraction of R0
  double axis_contact_ratio = 0.01;      ///< the load fades within this * R0 of the axis
  int collapse_bisections = 3;           ///< free wall: bisections of the load bracket of the collapse
  int loads_after_collapse = 4;          ///< free wall: at least these loads beyond the collapse
  double lbfgs_tolerance = 1e-3;         ///< max nodal force / max nodal load P A_i
  int lbfgs_max_iterations = 20000;
  bool buckled = true;                   ///< also the free wall's branch
};

struct TubeLawCalibration {
  LawBranch round, buckled;
  double c1_fit = 0, c1_fit_stderr = 0;  ///< C1 from the small loads (StaticCalibration)
  double closed_form_c1 = 0;             ///< 2 k_s sin(pi/n) / (R0 dx): the ring of springs
  double round_max_rel_dev_closed_form = 0;  ///< round points against P = C1_closed (R0 - R)
  double buckling_load_Pa = 0;           ///< round branch: softest ring-mode stiffness crosses zero (interpolated)
  int buckling_mode = 0;                 ///< its n
  double collapse_load_Pa = 0;           ///< free wall: first load whose equilibrium is not round (spread > 0.01 R0)
  double round_up_to_Pa = 0;             ///< free wall: the load before it (still round)
  bool buckled_computed = false;
  std::string buckled_absent_because;
};

/// Minimum of the loaded energy E(X) + P sum A_i r_i over every node position from `start`
/// (L-BFGS, memory 20, line search on the directional derivative), until the largest nodal
/// force is at most tol_force (N) or max_iterations.
struct Minimised {
  Eigen::Matrix3Xd X;
  int iterations = 0;
  double residual = 0;  ///< largest nodal force, N
  bool converged = false;
};
/// eps > 0: the load potential P A_i (sqrt(r_i^2 + eps^2) - eps), which fades within eps of
/// the axis: the membrane has no self-contact, and a collapsing wall's nodes would otherwise
/// sit on the axis's cone point, where no force balance exists.
Minimised minimise_loaded_energy(const full3d::CylinderMesh& mesh, const full3d::MembraneParams& mp, double P,
                                 const Eigen::Matrix3Xd& start, double tol_force, int max_iterations,
                                 double eps = 0.0);

/// The spring network's closed form for the round branch: each ring a regular polygon of n
/// springs (chord 2 r sin(pi/n)), the diagonals to the neighbouring rings at their rest length
/// (the free ends let the tube lengthen), load P A_i on the node area A_i = c0 dx of an interior
/// node: P = 2 k_s sin(pi/n) / (R0 dx) (R0 - r), exactly linear down to r = 0.
double round_closed_form_c1(const full3d::CylinderMesh& mesh, double ks);

/// Loads: increasing, each from the previous equilibrium; the round branch first. `c1`, `c1_stderr`: the
/// small-load fit the law's slope at R0 is compared with.
TubeLawCalibration calibrate_tube_law(const full3d::Params3d& p, double c1, double c1_stderr,
                                      const TubeLawOptions& o = {});
/// Knots and leave-one-out residuals of a branch from its points (fills the LawBranch fields
/// after `points`).
void fit_branch(LawBranch& b, double R0);
/// calibration.json's "tube_law" section.
scene::json to_json(const TubeLawCalibration& t, double R0);

/// calibration.json: the fit, the load points, the wall mass per area, the grid and the scene.
scene::json to_json(const StaticCalibration& c, const full3d::Params3d& p, const scene::json& resolved);

}  // namespace swim::validation
