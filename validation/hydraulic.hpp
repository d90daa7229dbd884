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
#pragma once

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
  double max_node_speed_m_per_s = 0;         ///< residual of the held-tube constraint
  double max_fluid_speed_m_per_s = 0;
  int cg_iterations = 0;
  int planes = 0;
  double wall_time_s = 0;
};

/// Throws NumericalError when the held-tube solve does not converge or a fit is degenerate.
HydraulicRadii measure_hydraulic_radii(const full3d::Params3d& p);

scene::json to_json(const HydraulicRadii& h);

}  // namespace swim::validation
