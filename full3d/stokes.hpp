// Fast solver for one backward-Euler step of the unsteady Stokes equations on
// the MAC grid (the fluid sub-step (29) of the paper's Lie splitting, with a
// finite-difference MAC discretisation in place of the paper's P1-iso-P2/P1
// finite elements):
//
//   rho (u^{n+1} - u^n)/dt = -G p^{n+1} + mu L u^{n+1} + f,     D u^{n+1} = 0,
//
// i.e. A u + G p = b with A = rho/dt - mu L, b = rho/dt u^n + f (f in N/m^3 on
// the faces), D, G, L the second-order operators of operators.hpp.
//
// PeriodicBox: every operator is diagonal in the discrete Fourier basis (3D
//   r2c, x contiguous). With the staggered gradient symbol g_c = (1 - e^{-i th_c})/h
//   (th_c = 2 pi k_c / n_c), D = -g^H, |g|^2 = sum (4/h^2) sin^2(th_c/2):
//     p^ = (g^H b^) / |g|^2,   u^ = (b^ - g p^) / (rho/dt + mu |g|^2),
//   an exact discrete projection (D u = 0 to round-off), no iteration.
//
// SquareDuct: each velocity component's Helmholtz operator A (with its own
//   wall condition) and the Neumann pressure Laplacian D G are diagonalised by
//   FFTW r2r kinds: x R2HC/HC2R (periodic); across the duct
//     tangential component (cell-centred, ghost u_-1 = -u_0): RODFT10 / RODFT01
//     wall-normal component (faces, zero on wall faces):      RODFT00 on n-1 faces
//     pressure (cell-centred, Neumann):                       REDFT10 / REDFT01
//   Since G does not map the pressure basis onto the tangential velocity basis,
//   the coupled system is solved on the pressure Schur complement
//     S p = -D A^{-1} b,  S = -D A^{-1} G  (SPD on zero-mean p)
//   by preconditioned conjugate gradients with the Cahouet-Chabard
//   preconditioner M^{-1} = mu I + (rho/dt) (-D G)^{-1} (exact for the box);
//   every inner solve is one fast transform. The velocity u = A^{-1}(b - G p)
//   is then made exactly discrete-divergence-free by one final Neumann
//   projection u -= G phi, D G phi = D u; the momentum residual this leaves is
//   O(CG tolerance). Pressure is warm-started from the previous step.
//
// bare_fft_solve(): the transform-only variant used for benchmarking. Box: the
//   same exact solve. Duct: one incremental pressure-correction step
//   (u* = A^{-1}(b - G p_old); D G phi = D u*; u = u* - G phi; p = p_old + rho/dt phi),
//   divergence-free to round-off but with an O(dt) tangential slip at walls.
#pragma once

#include <memory>

#include "full3d/fft.hpp"
#include "full3d/grid.hpp"

namespace swim::full3d {

struct FluidParams {
  double rho = 1.0e3;    ///< density, kg/m^3
  double mu = 1.2e-3;    ///< dynamic viscosity, Pa s
};

struct StokesOptions {
  FftOptions fft{};
  double cg_rtol = 1e-10;     ///< duct: relative residual ||D A^{-1}(b - G p)|| / ||D A^{-1} b||
  int cg_max_iterations = 500;
};

struct StokesStats {
  int iterations = 0;          ///< PCG iterations (0 for the box)
  double relative_residual = 0.0;
  double max_divergence = 0.0;  ///< max |D u^{n+1}| after the step, 1/s
};

class StokesSolver {
 public:
  /// Throws swim::InputError for rho <= 0 or mu <= 0.
  StokesSolver(const MacGrid& grid, const FluidParams& fluid, const StokesOptions& opt = {});
  ~StokesSolver();
  StokesSolver(StokesSolver&&) noexcept;
  StokesSolver& operator=(StokesSolver&&) noexcept;

  /// u: in u^n, out u^{n+1}; f: body-force density on the faces, N/m^3.
  /// Throws swim::NumericalError if the PCG does not converge.
  StokesStats step(VectorField& u, const VectorField& f, double dt);
  /// Transform-only solve (see header comment).
  StokesStats bare_fft_solve(VectorField& u, const VectorField& f, double dt);

  /// Pressure of the last step, Pa (zero mean).
  const ScalarField& pressure() const;
  const MacGrid& grid() const;
  const FluidParams& fluid() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swim::full3d
