// The reference duct solver of `swim bench` and of the tests: the transform-diagonal pieces of
// the square duct and the incremental pressure-correction step built from them. Not a
// production Stokes path and not in the product library swim_full3d: it is its own library,
// swim_full3d_duct_fft, which `swim run` never reaches; the product's duct and cylinder step
// is the capacitance solver (capacitance_stokes.hpp, behind StokesSolver). Two users:
//   * `swim bench` times PressureCorrectionStep::step as its cost unit ("bare FFT solve":
//     the fewest transforms one divergence-free duct step can take);
//   * the test references of tests/full3d/reference/ (the Cahouet-Chabard PCG) build on
//     DuctFft.
//
// DuctFft. Each velocity component's Helmholtz operator A = alpha - mu L (with its own wall
// rule) and the Neumann pressure Laplacian -D G are diagonal in FFTW r2r bases:
//   x (periodic):                                        R2HC / HC2R
//   across the duct, tangential component (cell-centred, ghost u_-1 = -u_0): RODFT10 / RODFT01
//   across the duct, wall-normal component (zero on the wall faces):        RODFT00 on n-1 faces
//   pressure (cell-centred, Neumann):                                       REDFT10 / REDFT01
// so A^{-1} and (-DG)^{-1} are one forward transform, a diagonal scaling and one inverse
// transform each (3D r2r plans, FftOptions threads). A and -DG do not commute with G (the
// tangential and the pressure bases differ), which is why the coupled no-slip step needs
// either an iteration (the reference PCG) or the capacitance correction.
//
// PressureCorrectionStep: u* = A^{-1}(b - G p_old); D G phi = D u*; u = u* - G phi;
// p = p_old + alpha phi (b = alpha u^n + f, alpha = rho/dt). Divergence-free to round-off
// but with an O(dt) tangential slip at the walls: not a solution of the no-slip step.
// Eight full transforms (three Helmholtz pairs and one Poisson pair).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "full3d/fft.hpp"
#include "full3d/grid.hpp"
#include "full3d/stokes.hpp"

namespace swim::full3d::reference {

class DuctFft {
 public:
  /// Throws swim::InputError for a non-duct grid.
  DuctFft(const MacGrid& g, const FftOptions& fft);
  ~DuctFft();
  DuctFft(DuctFft&&) noexcept;
  DuctFft& operator=(DuctFft&&) noexcept;

  /// x = A^{-1} r per component, A = alpha - mu L with the duct's wall rules (wall faces of x zero).
  void helmholtz(const VectorField& r, VectorField& x, double alpha, double mu);
  /// x = (-D G)^{-1} r with the Neumann walls, the constant mode set to zero.
  void poisson(const ScalarField& r, ScalarField& x);
  /// u -= G phi with D G phi = D u (u exactly discrete-divergence-free afterwards, wall faces
  /// zero); phi is returned (it is the pressure increment / alpha of the pressure correction).
  const ScalarField& project(VectorField& u);
  /// Smallest nonzero eigenvalue of -D G, 1/m^2.
  double lambda_min() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The bench's "bare FFT solve" (header comment); square duct only (the cylinder is ignored).
class PressureCorrectionStep {
 public:
  /// Throws swim::InputError for a non-duct grid or rho, mu <= 0.
  PressureCorrectionStep(const MacGrid& g, const FluidParams& fluid, const FftOptions& fft);
  /// u: in u^n, out u^{n+1}; f: body-force density on the faces, N/m^3.
  StokesStats step(VectorField& u, const VectorField& f, double dt);
  const ScalarField& pressure() const { return p_; }

 private:
  MacGrid grid_;
  FluidParams fluid_;
  DuctFft fft_;
  ScalarField p_, div_;
  VectorField b_, gp_;
};

}  // namespace swim::full3d::reference
