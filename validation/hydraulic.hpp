// Hydraulic radii of the immersed wall: the lumen and outer radii the fluid actually sees.
//
// The 3D wall is an immersed boundary: its force is smeared over about +-2h by the kernel, so
// the no-slip surfaces seen by the flow sit inside and outside R0. The 1D tier carries this as
// hydraulic offsets (model1d.hydraulic_offsets): lumen radius R - a_in, outer radius R + a_out.
//
// Measurement, at the scene's grid, on the undeformed tube held rigid in the scene's container
// (a duct is replaced by its inscribed cylinder, the shape the annulus model describes):
//   - a uniform axial body force g (N/m^3) drives steady Stokes flow through the periodic
//     container (the Stokes step with dt = 1e3 s: the inertia term rho/dt is ~1e-13 of the
//     viscous one);
//   - the tube is held by node forces F found by conjugate gradients on the mobility problem
//     J S^-1 spread(F) = -J S^-1 g (zero velocity at every node; J S^-1 spread is symmetric
//     positive semi-definite: spreading and interpolation are adjoint and S is symmetric);
//   - on the axial velocity faces of the planes near the tube's middle, the lumen profile is
//     fitted (GSL, linear least squares) to Poiseuille, u = c0 - c1 r^2 on r < R0 - 2h, whose
//     zero gives the lumen radius a = sqrt(c0 / c1); the annulus profile to Poiseuille in an
//     annulus, u = A - c1 r^2 + c2 ln r on R0 + 2h < r < Rc - h, whose two zeros give the
//     outer radius b of the tube and the effective container radius.
//   - a_in = R0 - a, a_out = b - R0, each the mean over the planes, with the spread between
//     planes and the fits' standard errors as the uncertainty.
// A consistency check compares the measured lumen flux with pi a^4 G / (8 mu), G = 4 mu c1.
//
// Second, independent measure of a_out: the drag of the towed tube.
//   - The same undeformed tube in the same container, without body force, is towed rigidly
//     along its axis at a speed U: node forces hold the tube at U e_x, found by the same
//     conjugate gradients with the prescribed velocity on the right-hand side. The forces
//     are the axisymmetric ones (per ring, an axial and a radial force density), the
//     constraint each ring's mean velocity: node by node, the non-axisymmetric node-force
//     modes finer than the grid form a near null space in which CG keeps adding forces and
//     dissipation without converging (the drag grows by 60 % over 2000 iterations on 16
//     cells across), while on the ring modes it converges to 1e-6 and the drag to 1e-5
//     or better. The towing force is sum_i F_x,i, and zeta = force / U.
//   - Far-field condition: the grid's pressure is periodic along the axis, so the mean pressure
//     gradient over the period is zero and the net flux is free (the tube drives one). This is
//     the 1D confined model's condition (the pressure rise along the tube plus along the free
//     pipe is zero; the lab-frame flux W through the free pipe follows), and there too the
//     towing force is balanced by the container's shear. No body force is applied. The
//     measured net flux is reported beside the 1D model's W at the inverted offsets.
//   - Inversion: a_out is the root of confined_drag_coefficient(R0, L, a_in, a_out, Rc, P, mu)
//     = zeta (GSL Brent), with a_in from the profile fit and Rc the nominal radius of the
//     cylinder simulated. The 1D drag is lubrication without end corrections, so this a_out
//     also absorbs the 3D flow's end effects and the annulus model's error: it is the outer
//     offset that makes the 1D tier's drag of the straight tube of the scene's length equal
//     to 3D's (it falls with the length: docs/validation.md), and the 1D tier keeps reading
//     the profile-fit a_out.
#pragma once

#include <string>

#include "common/scene.hpp"
#include "full3d/scene3d.hpp"

namespace swim::validation {

struct HydraulicRadii {
  double a_in_m = 0, a_in_uncertainty_m = 0;
  double a_out_m = 0, a_out_uncertainty_m = 0;
  double container_radius_effective_m = 0;  ///< zero of the annulus fit near Rc
  double lumen_flux_m3_per_s = 0;           ///< measured through the middle plane, r < R0
  double lumen_flux_poiseuille_m3_per_s = 0;  ///< pi a^4 G / (8 mu) from the fit
  double body_force_N_per_m3 = 0;
  /// Axial force of the held tube on the fluid (sum of the node forces), N. By reciprocity
  /// with the towed tube, -holding_force / (g P) = the towed tube's net flux per speed.
  double holding_force_N = 0;
  double max_node_speed_m_per_s = 0;         ///< residual of the held-tube constraint
  double max_fluid_speed_m_per_s = 0;
  int cg_iterations = 0;
  int planes = 0;
  double wall_time_s = 0;
};

/// Throws NumericalError when the held-tube solve does not converge or a fit is degenerate.
/// `axisymmetric_forces` (the calibration's choice): hold the tube with one axial and one
/// radial force per ring, the towed tube's force space (the exact holding force of this
/// axisymmetric flow is axisymmetric); CG converges to 1e-6 and holding_force_N satisfies
/// reciprocity with the towed tube. false: a free force per node, whose space includes forces
/// finer than the grid resolves (a near null space): CG stalls near 1e-3 and the holding force
/// is about 10 % off (docs/validation.md).
HydraulicRadii measure_hydraulic_radii(const full3d::Params3d& p, bool axisymmetric_forces = true);

scene::json to_json(const HydraulicRadii& h);

/// Geometry of the towed tube as the 1D confined model sees it (SI).
struct ConfinedTow {
  double radius_m = 0, length_m = 0, container_radius_m = 0, period_m = 0, viscosity_Pa_s = 0;
};
/// The scene's tow geometry (a duct by its inscribed cylinder, as measured).
ConfinedTow confined_tow(const full3d::Params3d& p);
/// The 1D confined model's drag coefficient of the straight tube with offsets a_in, a_out, N s/m
/// (reduced1d::outer::confined_drag_coefficient); 0 when the geometry is invalid.
double confined_drag(const ConfinedTow& g, double a_in_m, double a_out_m);

struct TowedTube {
  ConfinedTow geometry;
  double speed_m_per_s = 0;
  double force_N = 0;  ///< axial force of the tube on the fluid, the towing force (the drag is -force)
  double drag_coefficient_N_s_per_m = 0;              ///< force / speed
  double drag_coefficient_uncertainty_N_s_per_m = 0;  ///< CG: see measure_towed_tube
  double net_flux_m3_per_s = 0;   ///< lab-frame flux through the cross-section half a period from the tube's middle
  double max_slip_m_per_s = 0;    ///< max |u(X_i) - U e_x|, residual of the towing constraint
  double max_fluid_speed_m_per_s = 0;
  double cg_relative_residual = 0;
  int cg_iterations = 0;
  double wall_time_s = 0;
};

/// The undeformed tube towed at `speed` (m/s, nonzero) along its axis through the scene's
/// container, in steady Stokes flow. The drag's CG uncertainty: CG from F = 0 takes
/// zeta_k = b . F_k / U^2 (b = U e_x at every node) towards zeta (in exact arithmetic
/// monotonically: the step k adds alpha_k |r_k|^2 / U^2, the residual's share, and the error
/// of iterate k is r_k^T A^-1 r_k / U^2, the increments still to come). It is estimated by
/// the change over the last iterations (10 % of them, at least one). Throws NumericalError
/// when the solve does not hold the wall at U (a ring's node slipping by more than 1 % of the
/// largest flow speed), InputError for a zero or non-finite speed.
TowedTube measure_towed_tube(const full3d::Params3d& p, double speed_m_per_s = 1e-6);

/// a_out such that confined_drag(g, a_in, a_out) = zeta, by GSL Brent on the physical range
/// 0 <= a_out < 0.999 Rc - R0 (the 1D tier's own bounds). Throws NumericalError, saying which
/// end is passed, when zeta lies outside the drags of that range, and InputError for a_in
/// outside [0, R0).
double outer_offset_from_drag(const ConfinedTow& g, double zeta_N_s_per_m, double a_in_m);

/// Lab-frame net flux per towing speed of the 1D confined model's towed tube, W / U (m^2): the
/// flux through the free pipe that the tow drives with the pressure periodic.
double confined_tow_flux_per_speed(const ConfinedTow& g, double a_in_m, double a_out_m);

struct OuterOffsetFromDrag {
  bool found = false;
  double a_in_m = 0;              ///< the inner offset the inversion used
  double container_radius_m = 0;  ///< the container radius the inversion used
  double a_out_m = 0, uncertainty_m = 0;
  double from_a_in_m = 0;   ///< |d a_out / d a_in| sigma(a_in)
  double from_drag_m = 0;   ///< |d a_out / d zeta| sigma(zeta)
  std::string note;         ///< why there is no value, when !found
};
/// The inversion with its uncertainty: sigma(a_in) and sigma(zeta) propagated through the
/// derivatives of the root (central differences of the inversion), combined in quadrature.
/// Does not throw for a missing root: found = false with the reason in `note`.
OuterOffsetFromDrag outer_offset_from_drag(const ConfinedTow& g, double zeta_N_s_per_m, double zeta_uncertainty,
                                           double a_in_m, double a_in_uncertainty_m);

/// calibration.json entries: the headline figures at the top level
/// (hydraulic_offset_outer_from_drag_m and its uncertainty, null when there is no root, the
/// reason under towed_tube.no_offset_reason; towed_drag_coefficient_N_s_per_m) and the details
/// under "towed_tube". `at_effective_container` (optional): the same inversion with the
/// container's effective radius from the profile fit, reported as a sensitivity.
scene::json to_json(const TowedTube& t, const OuterOffsetFromDrag& a,
                    const OuterOffsetFromDrag* at_effective_container = nullptr);

/// The towed-tube part of a calibration: the tow at 1 um/s, a_out from its drag at the
/// profile-fitted a_in, and the same with the container's effective radius. A towed solve that
/// fails (NumericalError) leaves `measured` false, null offsets in `json` and the reason under
/// towed_tube.status: the rest of the calibration stands.
struct TowedCalibration {
  bool measured = false;
  TowedTube tube;
  OuterOffsetFromDrag nominal, effective;
  std::string error;
  scene::json json;  ///< the entries for calibration.json
};
TowedCalibration calibrate_towed(const full3d::Params3d& p, const HydraulicRadii& hr);

}  // namespace swim::validation
