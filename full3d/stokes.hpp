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
//   preconditioner M^{-1} = mu I + (rho/dt) (-D G)^{-1} (exact for the box; the
//   Poisson term is dropped in the quasi-steady regime, see cc_poisson_drop_ratio);
//   every inner solve is one fast transform. The unprojected velocity
//   u_k = A^{-1}(b - G p_k) is updated alongside the iterate, then made exactly
//   discrete-divergence-free by one final Neumann projection u -= G phi,
//   D G phi = D u; the momentum residual this leaves is O(CG tolerance).
//   Pressure (and multiplier) are warm-started from the previous step.
//
// Cylinder (StokesOptions::cylinder, duct only; container.hpp): the paper's
//   fictitious domain with a distributed Lagrange multiplier lam on linear
//   velocity rows E u = 0 (the faces outside the cylinder):
//     A u + G p + E^T lam = b,  D u = 0,  E u = 0,
//   solved by the same PCG on y = (p, lam) with K = [G, E^T]:
//     K^T A^{-1} K y = K^T A^{-1} b,  preconditioner blockdiag(Cahouet-Chabard, E A E^T).
//
// Capacitance path (StokesOptions::method Capacitance, the Auto choice for the plain
//   duct and the staircase cylinder; capacitance_stokes.hpp): exact. The same system with FREE-SLIP walls (tangential
//   ghost +u) is diagonal per wavevector in the bases R2HC (x) x {REDFT10, RODFT00} (y, z),
//   so it is solved like the box. No-slip differs by a diagonal term on the m = 4(ny+nz)-8
//   wall-adjacent tangential nodes, A_ns = A_fs + U Dg U^T, Dg = 2 mu W/h^2; per axial mode
//   the Woodbury identity with the SPD capacitance matrix C = Dg^{-1} + U^T S_fs^{-1} U
//   (Cholesky, once per dt, six dt cached) gives the no-slip solution from one free-slip
//   solve and O(n^2) partial transforms on the wall lines: about one bare solve; the
//   transforms and per-mode solves are split over direct_threads (parallel.hpp).
//   Staircase cylinder (when every wall-adjacent tangential face is masked, i.e. the cylinder
//   is at least half a cell inside the duct walls): the constrained free-slip system, the
//   constraint E u = 0 imposed through the "ring" of masked faces next to the fluid, with the
//   positive semidefinite capacitance E_R S_fs^{-1} E_R^T made definite by adding s N N^T on
//   its known null space (outside pressure constants); exact, about 1.5 bare solves. The
//   multiplier is recovered on demand as on the Direct path.
//
// Direct path (StokesOptions::method Direct, the Auto choice for a staircase cylinder the
//   capacitance path does not support; direct_stokes.hpp): duct and staircase cylinder solved exactly per axial Fourier mode
//   by sparse LU factors computed once per dt (masked faces eliminated: E u = 0 holds
//   exactly). The PCG above stays selectable with method = Iterative (and is used for the
//   GhostLinear / SurfacePoints walls).
//
// Advection (StokesOptions::advection; advection.hpp): when enabled, step()
//   first runs the explicit Navier-Stokes sub-step (28) on u^n, then the Stokes step.
//
// bare_fft_solve(): the transform-only variant used for benchmarking. Box: the
//   same exact solve. Duct: one incremental pressure-correction step
//   (u* = A^{-1}(b - G p_old); D G phi = D u*; u = u* - G phi; p = p_old + rho/dt phi),
//   divergence-free to round-off but with an O(dt) tangential slip at walls.
#pragma once

#include <cstddef>
#include <memory>

#include "full3d/advection.hpp"
#include "full3d/container.hpp"
#include "full3d/fft.hpp"
#include "full3d/grid.hpp"

namespace swim::full3d {

struct FluidParams {
  double rho = 1.0e3;    ///< density, kg/m^3
  double mu = 1.2e-3;    ///< dynamic viscosity, Pa s
};

/// Solver of the duct / cylinder step (the periodic box is always the exact Fourier projection).
///   Capacitance: free-slip spectral solve plus the per-axial-mode Woodbury correction to no-slip
///              (capacitance_stokes.hpp), exact, about one bare FFT solve (1.5 for the cylinder);
///              plain duct, and the Staircase cylinder when CapacitanceStokes::supports_cylinder
///              (the cylinder at least half a cell inside the duct walls, as in the scenes).
///   Direct:    per-axial-mode sparse LU (direct_stokes.hpp), factorised once per dt; plain duct
///              and the Staircase cylinder wall only.
///   Iterative: the multiplier PCG below (every wall kind).
///   Auto:      plain duct and supported Staircase cylinder: Capacitance; other Staircase cylinders:
///              Direct; each only when its estimated factor memory for the cached dt values (six
///              for Capacitance, two for Direct) is below
///              direct_memory_limit_gib (a cylinder over the limit for Capacitance tries Direct),
///              else Iterative.
enum class StokesMethod { Auto, Direct, Iterative, Capacitance };

struct StokesOptions {
  FftOptions fft{};
  StokesMethod method = StokesMethod::Auto;
  /// Direct: threads for the per-mode factorisations and solves; 0 = std::thread::hardware_concurrency().
  /// Capacitance: threads for the transforms and per-mode solves (parallel.hpp); 0 = fft.threads.
  int direct_threads = 0;
  /// Auto: largest estimated factor memory (all cached dt values) for which Direct or
  /// Capacitance is chosen, GiB.
  double direct_memory_limit_gib = 4.0;
  /// Direct / Capacitance: follow the solve by the exact Neumann projection of the iterative path
  /// (one more Poisson transform pair; not needed, the direct solve's divergence is at round-off).
  bool direct_final_projection = false;
  /// duct: the PCG stops when the constraint residual of the unprojected velocity u_k,
  /// sqrt(h^2 ||D u_k||^2 + ||E u_k||^2), is below cg_rtol * max(||u_k||, ||u_0||)
  /// (u_0: the velocity of the warm-started multipliers), Euclidean norms over the grid.
  double cg_rtol = 1e-10;
  int cg_max_iterations = 500;
  /// Cahouet-Chabard M^{-1} = mu I + alpha (-DG)^{-1}: the Poisson term is dropped when
  /// alpha / (mu lambda_min(-DG)) < this ratio (quasi-steady regime, where it changes M by
  /// less than the ratio); 0 keeps it always.
  double cc_poisson_drop_ratio = 1e-2;
  /// The paper's rigid circular container inside the duct (container.hpp); duct only.
  CylinderOptions cylinder{};
  /// Navier-Stokes advection sub-step (28) before the Stokes step (advection.hpp).
  AdvectionOptions advection{};
};

struct StokesStats {
  int iterations = 0;          ///< PCG iterations (0 for the box)
  double relative_residual = 0.0;
  double max_divergence = 0.0;  ///< max |D u^{n+1}| after the step, 1/s
  double max_constraint = 0.0;  ///< cylinder: max |E u^{n+1}| (velocity outside / on the wall), m/s
  double advection_cfl = 0.0;   ///< CFL number of the advection sub-step (0 when off)
  bool direct = false;          ///< the step used an exact per-mode solver (Direct or Capacitance)
  double factorization_seconds = 0.0;  ///< Direct / Capacitance: time spent (re)factorising in this step (new dt), s
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

  /// Pressure of the last step, Pa. Iterative: zero mean, arbitrary in fully masked
  /// cylinder cells. Direct, and Capacitance with the cylinder: zero mean over the cells with a
  /// free face, 0 in the others. Capacitance, plain duct: zero mean.
  const ScalarField& pressure() const;
  /// Replaces the pressure (checkpoint restore; the iterative path's warm start).
  /// Throws swim::InputError if p does not have one value per cell.
  void set_pressure(const ScalarField& p);
  /// True when step() uses an exact per-mode solver, Direct or Capacitance (StokesOptions::method).
  bool uses_direct() const;
  /// The duct method step() uses after resolving Auto: Direct, Capacitance or Iterative
  /// (Auto for the periodic box, which is always the exact Fourier projection).
  StokesMethod active_method() const;
  /// Direct: measured memory of the cached LU factors; Capacitance: of the cached capacitance
  /// Cholesky factors (up to six dt values for Capacitance, two for Direct), bytes; 0 otherwise.
  std::size_t direct_factor_bytes() const;
  /// Cylinder: the constraint rows and the multiplier of the last step (N/m^3 per row).
  /// Direct and Capacitance: the multiplier is recovered on demand, lambda = E (b - A u - G p).
  const VelocityConstraints* constraints() const;
  const std::vector<double>& multiplier() const;
  const MacGrid& grid() const;
  const FluidParams& fluid() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swim::full3d
