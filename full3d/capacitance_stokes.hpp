// Exact fast solver of the backward-Euler Stokes step in the square duct by a
// capacitance-matrix (Woodbury) correction of a free-slip spectral solve: the production
// path of the duct and of the staircase cylinder behind StokesSolver (stokes.hpp).
//
// The step's MAC saddle-point system (stokes.hpp, operators.hpp)
//   A u + G p = b,  D u = 0,   A = alpha - mu L,  alpha = rho/dt,
// with the no-slip duct wall rules (wall-normal component zero on the wall faces,
// tangential ghost u_ghost = -u_interior) is written as a low-rank modification of
// the FREE-SLIP system, whose only difference is the tangential ghost u_ghost = +u:
//
//   L_ns = L_fs - (2/h^2) W,   A_ns = A_fs + U Dg U^T,   Dg = (2 mu/h^2) W,
//
// U selecting the m = 4 ny + 4 nz - 8 wall-adjacent tangential nodes of a cross-section
// (W = number of walls next to the node: 1, or 2 in the corners of the x component).
//
// Free-slip base. Along y and z every unknown has a Fourier basis that the MAC
// operators map onto each other:
//   tangential velocity and pressure (cell-centred, ghost = +interior): cos(pi m (j+1/2)/n),
//     m = 0..n-1 (FFTW REDFT10 forward / REDFT01 inverse);
//   wall-normal velocity (faces, zero on the walls):  sin(pi m j/n), m = 1..n-1 (RODFT00);
// with G_y cos_m = g_m sin_m, D_y sin_m = -g_m cos_m, g_m = -2 sin(pi m/(2n))/h, and
// -L_y = g_m^2 on both. Along x (periodic) a real-to-halfcomplex DFT; the x component
// of the axial mode kx (0 < kx < nx/2) is rotated, q = i e^{i theta/2} u^, theta = 2 pi kx/nx,
// which makes its coupling to p real (g_x = -2 sin(theta/2)/h), so that the real and the
// imaginary halfcomplex planes of a mode are two real problems with the same matrix
// (kx = 0 and the Nyquist mode are real already, g_x = 0 and 2/h). Per wavevector the
// 4x4 system is then the periodic box's projection with a real symbol g = (g_x, g_y, g_z):
//   P = g.B / |g|^2  (P = 0 at g = 0: the pressure gauge),  X = (B - g P)/(alpha + mu |g|^2).
// The solve S_fs^{-1} costs one forward and one inverse transform per field.
//
// Woodbury. Per axial mode kx (the geometry is x-invariant, U acts on the cross-section):
//   C(kx) = Dg^{-1} + U^T S_fs(kx)^{-1} U     (m x m, symmetric positive definite: the
//           velocity block of S_fs^{-1} is A^{-1/2}(I - Pi)A^{-1/2} >= 0, Dg^{-1} > 0),
//   y = S_fs^{-1} b,   z = C^{-1} U^T y,   x = y - S_fs^{-1} U z  =  S_ns^{-1} b  exactly.
// C(kx) is assembled column by column from m unit solves (in transform space, all
// partial transforms below), split into four blocks of about m/4 by the reflection
// symmetries y -> Ly - y, z -> Lz - z of the duct (which C commutes with), and each block is
// Cholesky-factorised once per alpha; the factors of the last six alpha values are kept
// (the midpoint IB scheme alternates dt/2 and dt).
//
// The axial mean (kx = 0) of the x component decouples from p and is solved directly in the
// no-slip sine basis (RODFT10): the free-slip base damps its plug mode by alpha only, and
// through Woodbury that would cost a factor mu lambda_1/alpha (1e5 at dt = 1 ms) in accuracy.
//
// One solve: batched x R2HC of b; per mode kx: 2D yz transforms of u, v, w, the
// spectral projection Y = M B, the wall values U^T y evaluated from Y on the four
// wall-adjacent lines only (O(n^2) partial inverse transforms), the dense solve
// z = C^{-1} U^T y (four block substitutions), the transform of the line-supported field
// U z (O(n^2)), X = Y - M T(U z),
// and the 2D inverse transforms of u, v, w, p; then the batched x HC2R. Seven full
// transforms per field set, as in one bare pressure-correction step, plus O(m^2) per mode.
//
// Threads: the x transforms are split over row blocks and the per-mode work over
// contiguous blocks of kx (parallel.hpp, static schedule). Every mode is computed by the
// same code whatever the thread count; only the x transforms' row blocking (and so the
// FFTW algorithm chosen per block) depends on it, so results are deterministic for a
// given thread count and agree to round-off across counts. FFTW's own threads are not used.
//
// Staircase cylinder (constructor with a CylinderOptions; container.hpp). The constrained
// step A u + G p + E^T lam = b, D u = 0, E u = 0 (E: the faces outside r = Rc) is solved as
// a constrained FREE-SLIP problem: when every wall-adjacent tangential node is outside the
// cylinder (supports_cylinder()), the no-slip term U Dg U^T acts only on masked rows and
// drops out. The constraint is imposed on the "ring" R only: the outside faces in the stencil
// of a free face's momentum row or of a fluid cell's continuity row (the remaining outside
// faces then solve a homogeneous Stokes problem with zero boundary values, so they vanish).
// Per axial mode the capacitance C = E_R S_fs^{-1} E_R^T (|R| x |R|) is symmetric positive
// SEMI-definite; its null space is known in closed form, lam = (G q)|_R for q the indicator
// of a group of cells connected through non-ring y/z faces (for kx > 0 only groups with no
// non-ring x face), and is lifted by adding s N N^T, which leaves the solution of the
// consistent system C lam = E_R y unchanged (see docs/full3d-fluid.md). The axial mean of the
// x component is again solved separately, here by a sparse Cholesky factorisation of the
// masked 2D Helmholtz operator. When the floating-point staircase is exactly symmetric under
// both reflections (checked), C is assembled from one unit solve per orbit and factorised in
// the four character blocks, else as one block. A solve, per plane: the 3 forward yz transforms
// of b; the ring values of a copy of Y by partial transforms (the inverse along y of every z
// row, then dense sums along z at the ring nodes only); the block substitutions; the forward
// transform of E_R^T lam likewise (dense along y over the ring nodes, then along z); the 4
// inverse transforms of X: 7 full and 6 half yz transforms (|R| = 280, 5.3 MB per dt at
// 128 x 34 x 34).
// Output: masked faces zero (their computed round-off is reported by last_mask_residual()),
// p with zero mean over the cells with a free face, 0 in the others (the convention of the
// sparse-LU test reference, tests/full3d/reference/direct_stokes.hpp).
#pragma once

#include <cstddef>
#include <memory>

#include "full3d/container.hpp"
#include "full3d/fft.hpp"
#include "full3d/grid.hpp"

namespace swim::full3d {

class CapacitanceStokes {
 public:
  /// Largest number of alpha values whose factors are kept (least recently used replaced):
  /// the adaptive step's ladder dt_max 2^(-k/4) spans a factor 256 in dt with 32 levels.
  static constexpr int kCachedAlphas = 32;
  /// threads: worker threads (>= 1). fft: planner rigor (its thread count is ignored:
  /// plans are single-threaded and executed concurrently on disjoint data).
  /// Throws swim::InputError for a non-duct grid.
  CapacitanceStokes(const MacGrid& g, double mu, int threads, const FftOptions& fft);
  /// cylinder: nullptr for the plain duct, else the staircase mask of radius cylinder->radius
  /// (wall kind not consulted). Throws swim::InputError if !supports_cylinder(g, *cylinder).
  CapacitanceStokes(const MacGrid& g, double mu, const CylinderOptions* cylinder, int threads,
                    const FftOptions& fft);
  /// True when the staircase cylinder of this radius can be solved: a duct grid, a valid
  /// radius, and every wall-adjacent tangential node outside r = Rc (the cylinder at least
  /// half a cell inside the duct walls; the scenes' duct is two cells wider than the cylinder).
  static bool supports_cylinder(const MacGrid& g, const CylinderOptions& cylinder);
  ~CapacitanceStokes();
  CapacitanceStokes(CapacitanceStokes&&) noexcept;
  CapacitanceStokes& operator=(CapacitanceStokes&&) noexcept;

  /// Solves A u + G p = b, D u = 0 with the no-slip duct walls, A = alpha - mu L.
  /// b: right-hand side on the faces (wall-face entries ignored). u, p: outputs (wall
  /// faces zero, p with zero mean). Factorises the capacitance matrices on the first call
  /// with a new alpha (six alpha values cached).
  /// Throws swim::NumericalError if a capacitance matrix is not positive definite.
  void solve(const VectorField& b, VectorField& u, ScalarField& p, double alpha);
  /// The backward-Euler step itself: u (in u^n, out u^{n+1}) and p solve the system above with
  /// b = alpha u^n + f, formed on the fly (wall-face entries of u^n and f ignored).
  void step(VectorField& u, const VectorField& f, ScalarField& p, double alpha);
  /// The same step from un = u^n into u (un may be u).
  void step(const VectorField& un, const VectorField& f, VectorField& u, ScalarField& p, double alpha);
  /// Whether solves produce the pressure (default true). Off, p is left as it was: the
  /// velocity does not depend on it (the solve is exact), and its inverse transforms are
  /// 1 of the 7 per solve along x and 1 of 7 across.
  void compute_pressure(bool on);
  bool computes_pressure() const;

  /// Upper bound of the capacitance factor memory for one alpha, bytes: (nx/2+1) packed
  /// Cholesky factors of four symmetry blocks of about m/4 (about (nx/2+1) m^2/8 doubles).
  static std::size_t estimate_bytes(const MacGrid& g);
  /// Cylinder: (nx/2+1) packed Cholesky factors of order |R| (about (nx/2+1) |R|^2/2 doubles)
  /// plus the sparse factor of the axial-mean problem (small); cylinder == nullptr: the above.
  static std::size_t estimate_bytes(const MacGrid& g, const CylinderOptions* cylinder);
  /// Cylinder: max |u| on the masked faces as computed, before they are set to zero (round-off
  /// of the exact constrained solve), m/s; 0 for the plain duct.
  double last_mask_residual() const;
  /// Memory of the factors currently cached (all alpha values), bytes.
  std::size_t factor_bytes() const;
  /// Wall time of the last (re)factorisation, s; 0 before the first.
  double last_factorization_seconds() const;
  /// True when the last solve() had to factorise.
  bool last_solve_factorized() const;
  /// Factorisations so far (one per alpha not in the cache) and their total wall time, s.
  long factorizations() const;
  double factorization_seconds_total() const;
  /// Keep the factors of at most `slots` alpha values (1 <= slots <= kCachedAlphas; the
  /// default is kCachedAlphas). Factors beyond the new capacity are dropped.
  void limit_cache(int slots);
  int cache_slots() const;
  /// Number m of wall-adjacent tangential nodes per cross-section (the capacitance size);
  /// cylinder: the number |R| of ring faces per cross-section.
  int wall_nodes() const;
  int threads() const;
  /// Number of reflection-symmetry blocks the capacitance is split into: 4, or 1 for a
  /// cylinder whose floating-point staircase mask is not exactly symmetric.
  int symmetry_blocks() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swim::full3d
