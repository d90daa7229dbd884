// Navier-Stokes advection module, the paper's Lie sub-step (28):
//
//   du/dt + (u . grad) u = 0   on (t^n, t^{n+1}),   u(t^n) given,
//
// run explicitly on the MAC grid before the Stokes step (stokes.hpp) when
// AdvectionOptions::enabled. Space: the advective form with centred
// differences, second order:
//   N_c(u) = sum_d ubar_d (u_c(x + h e_d) - u_c(x - h e_d)) / (2h),
// where ubar_d is u_d itself (d = c) or the average of the four u_d nodes
// around the u_c node (d != c). Duct walls use the grid's rules: wall-normal
// wall faces stay zero, a tangential neighbour beyond a wall is the ghost
// value -u. Time: SSP-RK3 (default; its stability region contains the
// imaginary axis up to sqrt(3), where centred advection's eigenvalues lie) or
// Heun's RK2 (second order, weakly unstable for pure centred advection:
// |G|^2 = 1 + z^4/4 at z = i*CFL, damped by the viscous step that follows).
// A CFL number sum_d max|u_d| dt / h above max_cfl raises swim::NumericalError.
#pragma once

#include "full3d/grid.hpp"

namespace swim::full3d {

enum class AdvectionScheme { Rk2, SspRk3 };

struct AdvectionOptions {
  bool enabled = false;  ///< run module (28) before each Stokes step (Navier-Stokes); off = Stokes
  AdvectionScheme scheme = AdvectionScheme::SspRk3;
  double max_cfl = 0.5;  ///< sum_d max|u_d| dt / h allowed
};

/// N = (u . grad) u on the faces (wall faces zero), 1/s * m/s.
void advective_term(const MacGrid& g, const VectorField& u, VectorField& N);

/// CFL number sum_d max|u_d| dt / h.
double advective_cfl(const MacGrid& g, const VectorField& u, double dt);

/// Advances u by one explicit sub-step (28) of length dt. Returns the CFL number.
/// Throws swim::NumericalError if it exceeds opt.max_cfl (u left unchanged).
double advect(const MacGrid& g, VectorField& u, double dt, const AdvectionOptions& opt);

}  // namespace swim::full3d
