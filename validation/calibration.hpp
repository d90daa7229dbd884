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

#include <string>
#include <vector>

#include "common/scene.hpp"
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
StaticCalibration calibrate_static(const full3d::Params3d& p, const std::vector<double>& pressures,
                                   const std::function<void(std::size_t)>& on_load = {});

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

/// calibration.json: the fit, the load points, the wall mass per area, the grid and the scene.
scene::json to_json(const StaticCalibration& c, const full3d::Params3d& p, const scene::json& resolved);

}  // namespace swim::validation
