// The backward-Euler step of the unsteady Stokes equations on the MAC grid (the fluid
// sub-step (29) of the paper's Lie splitting, with a finite-difference MAC discretisation in
// place of the paper's P1-iso-P2/P1 finite elements):
//
//   rho (u^{n+1} - u^n)/dt = -G p^{n+1} + mu L u^{n+1} + f,     D u^{n+1} = 0,
//
// i.e. A u + G p = b with A = rho/dt - mu L, b = rho/dt u^n + f (f in N/m^3 on the faces),
// D, G, L the second-order operators of operators.hpp. One production path per container,
// each exact (no iteration; D u = 0 to round-off):
//
// PeriodicBox: spectral projection. Every operator is diagonal in the discrete Fourier basis
//   (3D r2c, x contiguous). With the staggered gradient symbol g_c = (1 - e^{-i th_c})/h
//   (th_c = 2 pi k_c / n_c), D = -g^H, |g|^2 = sum (4/h^2) sin^2(th_c/2):
//     p^ = (g^H b^) / |g|^2,   u^ = (b^ - g p^) / (rho/dt + mu |g|^2).
//   Three forward and four inverse 3D transforms.
//
// SquareDuct: the capacitance solver (capacitance_stokes.hpp): the free-slip system is
//   diagonal in R2HC (x) x {REDFT10, RODFT00} (y, z) and solved like the box; the no-slip
//   walls are a diagonal correction on the wall-adjacent tangential nodes, applied per axial
//   mode by the Woodbury identity with a Cholesky-factorised capacitance matrix (cached per dt).
//
// Cylinder (StokesOptions::cylinder, duct grid; container.hpp): the paper's fictitious domain
//   with a distributed Lagrange multiplier lam on the staircase rows E u = 0 (every face whose
//   centre lies outside r = Rc),
//     A u + G p + E^T lam = b,  D u = 0,  E u = 0,
//   solved by the same capacitance solver as a constrained free-slip problem (the cylinder at
//   least half a cell inside the duct walls, as the scenes build it): the constraint is
//   imposed on the ring of masked faces next to the fluid through a packed Cholesky
//   factorisation (LAPACK) of the ring capacitance per axial mode. The multiplier follows from
//   the step's result, lam = E (b - A u - G p) (recover_multiplier, container.hpp).
//
// Advection (StokesOptions::advection; advection.hpp): when enabled, step() first runs the
//   explicit Navier-Stokes sub-step (28) on u^n, then the Stokes step.
//
// Test references (an iterative PCG and a per-mode sparse LU solving the same duct and
// cylinder systems) live in tests/full3d/reference/; the bench's cost unit, one incremental
// pressure-correction step, in full3d/reference/duct_fft.hpp (library swim_full3d_duct_fft,
// outside swim_full3d). None is reachable from `swim run`.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "full3d/advection.hpp"
#include "full3d/container.hpp"
#include "full3d/fft.hpp"
#include "full3d/grid.hpp"

namespace swim::full3d {

struct FluidParams {
  double rho = 1.0e3;    ///< density, kg/m^3
  double mu = 1.2e-3;    ///< dynamic viscosity, Pa s
};

struct StokesOptions {
  FftOptions fft{};
  /// Duct and cylinder: threads of the capacitance solver's transforms and per-mode solves
  /// (parallel.hpp); 0 = fft.threads.
  int threads = 0;
  /// Memory for the capacitance factors, GiB: the cache keeps as many dt values as fit (up to
  /// CapacitanceStokes::kCachedAlphas); a grid whose factors for two dt values do not fit is
  /// rejected with swim::InputError.
  double memory_limit_gib = 4.0;
  /// The paper's rigid circular container inside the duct (container.hpp); duct only.
  CylinderOptions cylinder{};
  /// Navier-Stokes advection sub-step (28) before the Stokes step (advection.hpp).
  AdvectionOptions advection{};
};

struct StokesStats {
  int iterations = 0;               ///< iterations of an iterative solve: 0 for StokesSolver (the test references' PCG fills it)
  double relative_residual = 0.0;   ///< the test references' PCG: final relative residual
  double max_divergence = 0.0;      ///< max |D u^{n+1}| after the step, 1/s
  double max_constraint = 0.0;      ///< cylinder, the test references' PCG: max |E u^{n+1}|, m/s (StokesSolver: masked faces are exactly 0)
  double advection_cfl = 0.0;       ///< CFL number of the advection sub-step (0 when off)
  double factorization_seconds = 0.0;  ///< duct and cylinder: time spent (re)factorising in this step (new dt), s
};

/// Duct and cylinder: how many time steps' capacitance factors o.memory_limit_gib holds (at
/// most CapacitanceStokes::kCachedAlphas); swim::InputError naming full3d.grid.cells_across and
/// full3d.memory_limit_gib when it holds fewer than two. Periodic box: kCachedAlphas (no factors).
int factor_slots(const MacGrid& g, const StokesOptions& o);

class StokesSolver {
 public:
  /// Throws swim::InputError for rho <= 0 or mu <= 0, a cylinder on a box grid, a cylinder
  /// closer than half a cell to the duct walls (CapacitanceStokes::supports_cylinder), or a
  /// grid whose capacitance factors would exceed StokesOptions::memory_limit_gib.
  StokesSolver(const MacGrid& grid, const FluidParams& fluid, const StokesOptions& opt = {});
  ~StokesSolver();
  StokesSolver(StokesSolver&&) noexcept;
  StokesSolver& operator=(StokesSolver&&) noexcept;

  /// u: in u^n, out u^{n+1}; f: body-force density on the faces, N/m^3.
  /// Throws swim::NumericalError if a capacitance matrix is not positive definite.
  StokesStats step(VectorField& u, const VectorField& f, double dt);
  /// The same step from un = u^n into u (duct and cylinder without advection: no copy of u^n).
  StokesStats step(const VectorField& un, VectorField& u, const VectorField& f, double dt);
  /// The same step from a fluid at rest, u^n = 0, into u.
  StokesStats step_from_rest(VectorField& u, const VectorField& f, double dt);

  /// Pressure of the last step that computed it, Pa: zero mean (cylinder: zero mean over the
  /// cells with a free face, 0 in the others).
  const ScalarField& pressure() const;
  /// Duct and cylinder: whether steps compute the pressure (default true; the box always
  /// does). The velocity does not depend on it; a run that writes no pressure turns it off
  /// and on again before a step whose pressure it writes.
  void compute_pressure(bool on);
  bool computes_pressure() const;
  /// Replaces the pressure (checkpoint restore). Throws swim::InputError if p does not have
  /// one value per cell.
  void set_pressure(const ScalarField& p);
  /// Duct and cylinder: the number of dt values whose factors are kept, up to
  /// CapacitanceStokes::kCachedAlphas, fewer when their estimated memory exceeds
  /// StokesOptions::memory_limit_gib; 0 for the box.
  int cached_time_steps() const;
  /// Duct and cylinder: capacitance factorisations so far (one per dt not in the cache) and
  /// their total wall time, s; 0 for the box.
  long factorizations() const;
  double factorization_seconds() const;
  /// Duct and cylinder: measured memory of the cached capacitance factors, bytes; 0 for the box.
  std::size_t factor_bytes() const;
  /// Cylinder: the constraint rows E (nullptr otherwise). The multiplier of a step is
  /// recover_multiplier(*constraints(), b, u^{n+1}, pressure(), rho/dt, mu, lambda) with
  /// b = rho/dt u^n + f (container.hpp).
  const VelocityConstraints* constraints() const;
  const MacGrid& grid() const;
  const FluidParams& fluid() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swim::full3d
