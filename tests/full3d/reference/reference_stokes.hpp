// TEST REFERENCES of the backward-Euler Stokes step in the square duct and the cylinder
// (library swim_full3d_reference, linked by the tests only; not in the product library and
// not selectable by `swim run`). The product step is StokesSolver (full3d/stokes.hpp):
// spectral projection in the box, capacitance solver in the duct and the cylinder. These
// solve the same MAC systems by independent algorithms, so the tests can compare:
//
//   Method::Pcg       the pressure (and multiplier) Schur complement by preconditioned
//                     conjugate gradients, Cahouet-Chabard preconditioner
//                     M^{-1} = mu I + alpha (-DG)^{-1} (the Poisson term dropped when
//                     alpha < cc_poisson_drop_ratio mu lambda_min(-DG)), blockdiag with
//                     E A E^T for the cylinder's multiplier; every inner solve is one
//                     transform pair (reference::DuctFft). Warm-started from the previous
//                     step's pressure and multiplier; stops when
//                     sqrt(h^2 ||D u_k||^2 + ||E u_k||^2) <= cg_rtol max(||u_k||, ||u_0||);
//                     then one exact Neumann projection. Every cylinder wall kind (below).
//   Method::SparseLu  per axial Fourier mode sparse LU (reference::DirectStokes,
//                     direct_stokes.hpp here); plain duct and the staircase cylinder.
//
// Cylinder walls (WallOptions; the product has the staircase only):
//   Staircase:     u = 0 on every face whose centre lies outside r = Rc;
//   GhostLinear:   on an outside face g with a fluid neighbour i along y or z (the one most
//                  aligned with the radial direction), the linear interpolant along g-i
//                  vanishes where the line crosses r = Rc: (1 - t) u_i + t u_g = 0 (a
//                  ghost-cell wall, Tseng and Ferziger 2003); other outside faces held at 0;
//   SurfacePoints: the paper's Remark 1: u = 0 on faces with r > Rc + mask_gap h, plus the
//                  bilinear interpolant of every component vanishing at points on r = Rc
//                  about surface_spacing h apart, in every x-layer (ghost nodes fold onto
//                  their mirror with weight -w, wall faces drop).
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "full3d/container.hpp"
#include "full3d/grid.hpp"
#include "full3d/stokes.hpp"

namespace swim::full3d::reference {

enum class Method { Pcg, SparseLu };
enum class CylinderWall { Staircase, GhostLinear, SurfacePoints };

struct WallOptions {
  CylinderWall wall = CylinderWall::Staircase;
  double surface_spacing = 1.0;  ///< SurfacePoints: arc spacing of the surface points, in cells h
  double mask_gap = 1.0;         ///< SurfacePoints: mask only r > Rc + mask_gap h (cells)
};

/// The constraint rows E of a cylinder wall. Throws swim::InputError for a non-duct grid, a
/// radius <= 0 or 2 Rc > min(Ly, Lz), a non-positive spacing or a negative gap.
VelocityConstraints wall_constraints(const MacGrid& g, double radius, const WallOptions& wall);

struct Options {
  Method method = Method::Pcg;
  FftOptions fft{};
  int threads = 1;                ///< SparseLu: threads of the per-mode factorisations and solves
  CylinderOptions cylinder{};     ///< enabled, radius
  WallOptions wall{};             ///< Pcg: any wall; SparseLu: Staircase only (InputError otherwise)
  double cg_rtol = 1e-10;
  int cg_max_iterations = 500;
  double cc_poisson_drop_ratio = 1e-2;
};

class ReferenceStokes {
 public:
  /// Throws swim::InputError for a non-duct grid, rho or mu <= 0, or SparseLu with a
  /// non-staircase wall.
  ReferenceStokes(const MacGrid& g, const FluidParams& fluid, const Options& opt);
  ~ReferenceStokes();
  ReferenceStokes(ReferenceStokes&&) noexcept;
  ReferenceStokes& operator=(ReferenceStokes&&) noexcept;

  /// u: in u^n, out u^{n+1}. Pcg: iterations, relative_residual, max_constraint filled.
  /// Throws swim::NumericalError if the PCG does not converge.
  StokesStats step(VectorField& u, const VectorField& f, double dt);
  /// Pcg: zero mean, arbitrary in fully masked cells. SparseLu: zero mean over the cells with
  /// a free face, 0 in the others.
  const ScalarField& pressure() const;
  void set_pressure(const ScalarField& p);
  /// Cylinder: the rows and the multiplier of the last step (SparseLu: recovered on demand).
  const VelocityConstraints* constraints() const;
  const std::vector<double>& multiplier() const;
  /// SparseLu: measured memory of the cached LU factors, bytes; 0 for Pcg.
  std::size_t factor_bytes() const;
  /// SparseLu: true when the cross-section cell (j, k) carries a pressure unknown.
  bool has_pressure(int j, int k) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swim::full3d::reference
