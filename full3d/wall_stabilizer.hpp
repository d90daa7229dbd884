// Linear stabilisation of the explicit wall update (full3d.wall_stabilization; docs/full3d.md,
// "The stabilised wall step").
//
// The forward-Euler node update X^{n+1} = X^n + dt U(X^n) is stable while dt lambda < 2 for
// every mode of the wall coupled through the fluid, lambda = M(k) K(k): the mobility of a wall
// mode of wavenumber k through the fluid times its elastic stiffness. The stiffest modes sit
// at the grid scale, k ~ 1/h: stretching gives lambda ~ Y k / mu ~ h^-1 and bending with a
// rigidity D fixed on every grid lambda ~ D k^3 / mu ~ h^-3, so on fine grids the bending sets
// the step. The stabilised update is
//     X^{n+1} - X^n = dt G M G F(X^n),    G = (I + dt B)^{-1/2},
// M the coupled mobility (spreading, the Stokes solve, interpolation) and F the node forces:
// a forward-Euler step of the wall's dynamics with the mobility G M G in place of M. G is
// symmetric positive definite, so G M G is symmetric positive semi-definite like M: the
// update moves the wall down its energy, and its linearisation G M G H (H the wall's
// stiffness) has real eigenvalues, so that a power iteration's largest magnitude is its
// stability limit. (The one-sided form (I + dt B)^{-1} M F is neither: with M and B not
// commuting its linearisation has complex eigenvalues, and on 128-160 cells across it grew a
// mesh distortion at steps the magnitude estimate allowed.) B is a scalar operator on the
// wall's own mesh (the same for the three components),
//     B = P^{-1/2} K P^{-1/2},
//     K = m0 kappa_b (S^T Lt S + E^3) / l_h
//                                     the bending's stiffness near k = 1/h: S the rows of the
//                                     mesh's graph Laplacian Lg (unit weights) of the nodes off
//                                     the end rings, Lt its block on those nodes (Lg^3 away
//                                     from the ends), E = (3/2) R on the end rings, R the graph
//                                     Laplacian of the ring's own edges (the bending along the
//                                     free rim, in Lg's units; zero elsewhere);
//     P = (I + Lf / (q l_h))^q, q = 8 a low-pass filter, Lf = (S^T S + E^2)^{1/2} (Lg away
//                                     from the ends): the fluid moves a wall mode finer than
//                                     the grid less and less (the kernel's transfer function),
//                                     and B follows it;
//     kappa_b = A (2 / (3 a^2))^2 D   (a node's bending force A D lap^2 x, with
//                                      lap ~ -(2 / (3 a^2)) Lg on a triangular lattice of edge a),
//     l_h = (3/2) (a / h)^2           (Lg's value on a mode of wavenumber 1/h),
//     m0 = factor * h / (4 mu A)      (the mobility of a sheet mode, 1 / (4 mu k) per area, at k = 1/h),
// A the mean node area and a the mean rest edge. Per mode, with l = Lg's value on it,
//     sigma(l) = m0 kappa_b (l^3 / l_h) / (1 + l / (q l_h))^q:
// near the grid scale (l ~ l_h) it is the bending's own rate there (within e^-1), below it
// it falls as (k h)^6 where bending goes as (k h)^4, so that the modes the wall's physics lives
// on (the buckling lobes, the contraction fronts), whose bending is balanced by the load, are
// not damped as if they were stiff, and above it (the mesh's own scale, a < h/2) it falls
// again, so that the mesh's fine modes, which the fluid barely moves, are not frozen either.
// E is there for the free rims: per azimuthal mode m > 0, S has a null pair decaying away from
// each end ring (a field harmonic in the graph Laplacian's sense), which the wall's hinges
// bend (their energy is the curvature's full square, not the Laplacian's) but S^T Lt S does not
// see; without E such a rim mode, radial and three quarters on the two end rings at each end,
// set the stabilised step's rate on a stiff wall (932 /s against 438 /s with E, the forward-
// Euler rate being 1 507 /s).
// Without the filter (sigma growing as l^3 to the mesh scale) the update froze them and the
// buckled wall recovered 16-33 % faster on 48 cells across, even with a tenth of m0. The tube's
// ends are free: a field linear along the axis has S f = 0, so K, Lf and B are zero on it, as
// the wall's bending is, and G leaves it alone (the tube's stretching and tilting, its rigid
// translations). Per mode shared by M H and B the update's factor is 1 - dt lambda / (1 + dt
// sigma): stable for every dt where sigma >= lambda / 2, and a relative change of order dt sigma
// of a mode's motion, which vanishes with dt and with h.
//
// The mesh is a stack of rings of n_theta nodes, alternate rings offset by half a step, so the
// graph Laplacian commutes with the rotation by one node: in the azimuthal Fourier modes
// exp(i m phi) of the nodes' own angles it is, per m, the real tridiagonal matrix along the rings
//     (Lg_m v)_r = (deg_r - 2 cos(2 pi m / n_theta)) v_r - 2 cos(pi m / n_theta) (v_{r-1} + v_{r+1}),
// deg_r = 6 (4 on the end rings), and S_m, Lt_m its rows and block of rings 1 .. n_rings - 2;
// E_m is (3/2)(2 - 2 cos(2 pi m / n_theta)) on the two end rings.
// B_m = U_m diag(sigma_m) U_m^T is decomposed once per run (dense symmetric eigen-problems of
// n_rings, spread over the threads); G and B are then a batched real FFT per ring and
// component, two dense products per mode and the inverse FFT.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "full3d/membrane.hpp"

namespace swim::full3d {

/// Whether the wall update is stabilised (full3d.wall_stabilization: none or bending).
enum class WallStabilization { None, Bending };
WallStabilization wall_stabilization_from(const std::string& name);
std::string to_string(WallStabilization w);

class WallStabilizer {
 public:
  /// mesh: the wall's mesh (rings of n_theta nodes, rest lengths, node areas); h: the grid's
  /// cell, m; mu: viscosity, Pa s; D: the wall's bending rigidity, J; factor: m0's multiple of
  /// the grid-scale mobility (> 0); threads: for the per-mode decompositions and products. Throws
  /// std::invalid_argument for kind None or a mesh that is not a stack of three or more rings.
  WallStabilizer(const CylinderMesh& mesh, double h, double mu, double D, WallStabilization kind,
                 double factor = 1.0, int threads = 1);
  ~WallStabilizer();
  WallStabilizer(const WallStabilizer&) = delete;
  WallStabilizer& operator=(const WallStabilizer&) = delete;

  /// x <- G x = (I + dt B)^{-1/2} x (3 x N_n, each component alike), dt > 0: the update's
  /// filter, applied to the node forces before they are spread and to the node velocities
  /// interpolated back.
  void apply_root(double dt, Eigen::Matrix3Xd& x) const;
  /// x <- (I + dt B)^{-1} x = G^2 x, dt > 0.
  void apply(double dt, Eigen::Matrix3Xd& x) const;
  /// B x for a 3 x N_n field (the model's rates), 1/s times x.
  Eigen::Matrix3Xd rate(const Eigen::Matrix3Xd& x) const;
  /// The largest rate of B, 1/s.
  double largest_rate() const;

  double mobility() const { return m0_; }            ///< m0, m/(N s)
  double kappa_bending() const { return kappa_b_; }  ///< N/m
  double laplacian_at_h() const { return l_h_; }     ///< l_h
  WallStabilization kind() const { return kind_; }

 private:
  struct Impl;
  /// x <- f(m, coefficients) in the azimuthal modes: forward transform, f per mode on the
  /// n_rings x 6 block (3 components, real and imaginary parts), inverse transform.
  template <class F>
  void in_modes(Eigen::Matrix3Xd& x, F&& per_mode) const;
  /// x <- U diag(gain(sigma)) U^T x per mode.
  template <class G>
  void spectral(Eigen::Matrix3Xd& x, G&& gain) const;
  WallStabilization kind_;
  int threads_ = 1;  ///< for the per-mode products of every application
  int n_theta_ = 0, n_rings_ = 0, n_modes_ = 0;
  double m0_ = 0.0, kappa_b_ = 0.0, l_h_ = 0.0;
  /// per mode m: B_m's eigenvectors U_m (n_rings x n_rings, orthonormal) and rates sigma_m, 1/s
  std::vector<Eigen::MatrixXd> vectors_;
  std::vector<Eigen::VectorXd> rates_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swim::full3d
