// TEST REFERENCE (library swim_full3d_reference; reference_stokes.hpp, Method::SparseLu):
// direct solver of the backward-Euler Stokes step in the square duct and in the staircase
// cylinder by sparse LU per axial Fourier mode, exploiting the invariance of both geometries
// along the periodic x axis. An algorithm independent of the product's capacitance solver,
// against which the tests check it.
//
// A batched r2c FFT along x turns the step's saddle-point system
//   A u + G p = b,  D u = 0,  A = alpha - mu L,  alpha = rho/dt,
// into nx/2+1 independent 2D problems on the ny x nz cross-section, one per
// axial wavenumber kx (theta = 2 pi kx / nx, s = 2 sin(theta/2)/h). The x-face
// component is shifted by half a cell and rotated, q = i e^{i theta/2} u^,
// which makes every mode's matrix REAL (and symmetric):
//
//   [ A_k   G_k ] [u_k]   [b_k]      A_k = alpha + mu s^2 - mu L_yz (duct ghost rule),
//   [ G_k^T  0  ] [p_k] = [ 0 ]      G_k = [-s I; G_y; G_z]  (D_k = -G_k^T),
//
// so the real and imaginary parts of the transformed right-hand side are two
// columns of one real sparse solve. Faces on the duct walls and (cylinder)
// faces outside r = Rc (the staircase mask of container.hpp) are eliminated as
// Dirichlet zeros: this is exactly the fictitious-domain constraint E u = 0
// with its multiplier, satisfied without iteration. Cells with no free face
// carry no pressure unknown. The pressure null space (constants on each group
// of cells connected through free y/z faces, for kx = 0; for kx > 0 only groups
// without a free x face) is removed by pinning one cell per group, whose
// divergence row is redundant.
//
// Every mode is factorised once per alpha with Eigen::SparseLU (COLAMD), the
// factors of the last two alpha values are kept (the midpoint IB scheme
// alternates dt/2 and dt). A solve is one batched forward transform, one pair
// of triangular solves per mode (modes spread over threads) and one inverse
// transform.
#pragma once

#include <cstddef>
#include <memory>

#include "full3d/container.hpp"
#include "full3d/fft.hpp"
#include "full3d/grid.hpp"

namespace swim::full3d::reference {

class DirectStokes {
 public:
  /// cylinder: nullptr for the plain duct; otherwise the staircase mask of radius
  /// cylinder->radius (wall kind is not consulted). threads: worker threads for the
  /// per-mode factorisations and solves (>= 1). Throws swim::InputError for a non-duct grid.
  DirectStokes(const MacGrid& g, double mu, const CylinderOptions* cylinder, int threads, const FftOptions& fft);
  ~DirectStokes();
  DirectStokes(DirectStokes&&) noexcept;
  DirectStokes& operator=(DirectStokes&&) noexcept;

  /// Solves A u + G p = b, D u = 0 (masked faces zero) with A = alpha - mu L.
  /// b: right-hand side on the faces (wall and masked entries ignored). u, p: outputs
  /// (p has zero mean over the cells that carry a pressure, 0 in the others).
  /// Factorises on the first call with a new alpha (two alpha values cached).
  /// Throws swim::NumericalError if a mode's factorisation fails.
  void solve(const VectorField& b, VectorField& u, ScalarField& p, double alpha);

  /// A priori estimate of the factor memory for one alpha, bytes.
  static std::size_t estimate_bytes(const MacGrid& g);
  /// Measured memory of the factors currently cached (all alpha values), bytes.
  std::size_t factor_bytes() const;
  /// Wall time of the last factorisation (all modes), s; 0 before the first.
  double last_factorization_seconds() const;
  /// True when the last solve() had to factorise.
  bool last_solve_factorized() const;
  /// Number of unknowns of one mode (velocity + pressure).
  std::size_t unknowns_per_mode() const;
  /// True when the cell (j, k) of the cross-section carries a pressure unknown.
  bool has_pressure(int j, int k) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swim::full3d::reference
