// Axisymmetric immersed-boundary transfer between wall rings and the AxiGrid (meridian plane),
// with Peskin's four-point kernel phi (paper eq. 18, full3d/kernel.hpp).
//
// A wall "node" is a ring: X(0, k) = axial position x_k (any real value, wrapped by the period
// nx h), X(1, k) = ring radius r_k > 0, X(2, k) unused. F(0, k), F(1, k) = axial and radial force
// of the WHOLE ring, N.
//
// Spreading, on each component's own staggered points g = (r_g, x_g) (radial force on the u
// points, axial force on the w points):
//   f(g) = sum_k F_k phi((r_g - r_k)/h) phi((x_g - x_k)/h) / (2 pi r_g h^2),          N/m^3
// so that sum_g 2 pi r_g h^2 f(g) = sum_k F_k (the force is conserved).
// Interpolation (the plain 2D kernel average in the meridian plane):
//   U_k = sum_g u(g) phi((r_g - r_k)/h) phi((x_g - x_k)/h),                            m/s
// The two are adjoint in the r-weighted inner product <f, u> = sum_g 2 pi r_g h^2 f(g) u(g):
//   <spread(F), u> = sum_k F_k . U_k.
//
// The container wall truncates the kernel as in the 3D tier: stencil points outside the fluid
// (w rows i >= nr) and on the no-slip wall face (u row nr) are dropped in both operations
// (adjointness kept; the dropped force is absorbed by the wall). Near the axis the stencil
// would reach r <= 0, where the ring model has no meaning: a ring with r_k < 2h (plus a
// margin of 1e-9 h) is a swim::NumericalError. A non-finite position is one too.
//
// Point sampling (sample_w, sample_u, disc_flux): the same kernel at an arbitrary point
// 0 <= r <= Rc, with the stencil completed by images instead of truncated: across the axis w
// is even and u odd (w(-r) = w(r), u(-r) = -u(r)); across the wall both are odd about r = Rc
// (the ghost rule w[nr] = -w[nr-1] of the Stokes discretisation; u vanishes on the wall).
// The kernel weights then sum to 1 everywhere, so a constant w is reproduced exactly
// within 2h of the axis and interpolation is second-order accurate up to the wall.
#pragma once

#include <Eigen/Core>

#include <vector>

#include "axi/grid_axi.hpp"

namespace swim::axi {

/// fr (size u_size(), rows 0 and nr zero) and fx (size w_size()) = spread(F), N/m^3: the
/// vectors are resized and zeroed, then the rings are added. X, F: 3 x N (m, N).
/// Throws swim::NumericalError for a ring within 2 cells of the axis or a non-finite position,
/// std::invalid_argument if X and F have different column counts.
void spread(const AxiGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, std::vector<double>& fr,
            std::vector<double>& fx);

/// U (resized to 3 x N) = the velocities of the rings X: row 0 axial (from w, size w_size()),
/// row 1 radial (from u, size u_size()), row 2 = 0. Throws as spread.
void interpolate(const AxiGrid& g, const Eigen::Matrix3Xd& X, const double* u, const double* w,
                 Eigen::Matrix3Xd& U);

/// w at the point (x, r), 0 <= r <= Rc, by the kernel with axis and wall images (see above).
/// Throws std::invalid_argument for r outside [0, Rc] or a non-finite x.
double sample_w(const AxiGrid& g, const double* w, double x, double r);
/// u at the point (x, r), 0 <= r <= Rc, likewise (u rows 0 and nr are taken as 0).
double sample_u(const AxiGrid& g, const double* u, double x, double r);

/// Volume flux through the disc r < radius at axial position x, relative to a frame moving
/// axially at frame_velocity: integral_0^radius 2 pi r (w(r, x) - frame_velocity) dr, m^3/s,
/// by the midpoint rule with n_radial points and w = sample_w. Throws std::invalid_argument
/// for radius outside [0, Rc], n_radial < 1 or a non-finite x.
double disc_flux(const AxiGrid& g, const double* w, double x, double radius, double frame_velocity,
                 int n_radial);

}  // namespace swim::axi
