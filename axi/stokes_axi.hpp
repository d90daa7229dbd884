// Steady axisymmetric (swirl-free) Stokes flow in the rigid cylinder r < Rc, periodic along x.
//
//   radial:      -dp/dr + mu [ (1/r) d/dr(r du/dr) - u/r^2 + d2u/dx2 ] + f_r = 0
//   axial:       -dp/dx + mu [ (1/r) d/dr(r dw/dr) + d2w/dx2 ]         + f_x = 0
//   continuity:  (1/r) d(r u)/dr + dw/dx = 0
//
// u = 0 on the axis (r = 0) and u = w = 0 on the wall (r = Rc); mu constant (Pa s), f in N/m^3.
//
// Discretisation: the second-order MAC scheme on the AxiGrid (grid_axi.hpp), with conservative
// r-weighted fluxes:
//   radial momentum at face i = 1..nr-1, cell j:
//     -(p[i][j] - p[i-1][j])/h + mu [ (r_cell(i)(u[i+1]-u[i]) - r_cell(i-1)(u[i]-u[i-1])) / (r_face(i) h^2)
//                                      - u[i]/r_face(i)^2 + (u[j+1] - 2u[j] + u[j-1])/h^2 ] + f_r = 0
//   axial momentum at cell i = 0..nr-1, face j:
//     -(p[i][j] - p[i][j-1])/h + mu [ (r_face(i+1)(w[i+1]-w[i]) - r_face(i)(w[i]-w[i-1])) / (r_cell(i) h^2)
//                                      + (w[j+1] - 2w[j] + w[j-1])/h^2 ] + f_x = 0
//   continuity at cell (i, j):
//     (r_face(i+1) u[i+1] - r_face(i) u[i]) / (r_cell(i) h) + (w[j+1] - w[j])/h = 0
// with u = 0 on rows 0 (axis) and nr (wall); no flux through the axis (r_face(0) = 0); no slip
// at the wall by the ghost rule w[nr] = -w[nr-1] (as the 3D tier's duct walls). In the
// r-weighted inner product (weights r_face on u points, r_cell on w and p points) the discrete
// gradient is minus the adjoint of the divergence and the viscous operator is symmetric, so
// the solution operator f -> (u, w) is self-adjoint (reciprocity).
//
// Method: real-to-complex FFT along x (FFTW, batched over the radial rows). In index space the
// x-differences become (a_j - a_{j-1}) -> (1 - e^{-i th}) a^, (a_{j+1} - a_j) -> (e^{i th} - 1) a^
// and the second difference -> -4 sin^2(th/2) a^, th = 2 pi k / nx. Each axial wavenumber
// k = 0..nx/2 is one complex banded system in the radial unknowns, interleaved per radial
// index i as [w_i, p_i, u_{i+1}] (3 nr unknowns; the last u is the wall row, u_nr = 0, kept as
// an identity row), which has 3 sub- and 3 super-diagonals. Scaling for O(1) entries: the
// momentum rows are multiplied by h^2/mu, the continuity rows by h, and the pressure unknown
// is P = p h / mu. Every system is factored once in the constructor (LAPACK zgbtrf, partial
// pivoting) and solved per call (zgbtrs).
//
// Pressure gauge: the k = 0 system is singular (pressure up to a constant; the r_cell-weighted
// continuity rows sum to zero). Its continuity row of the last cell (i = nr-1) is replaced by
// the gauge P_{nr-1} = 0; the dropped row then holds automatically (the other rows give
// r_face(i) u_i = r_face(0) u_0 = 0, i.e. u = 0 exactly for the mean mode). The returned
// pressure is shifted to zero PLAIN mean over the nr nx cells (every cell counts once, not
// the r-weighted volume mean).
//
// Memory: (nx/2 + 1) band factors of 10 x 3 nr complex values plus pivots, i.e. about
// 480 nr (nx/2 + 1) bytes (126 MB at nr = 256, nx = 2048).
#pragma once

#include <complex>
#include <cstddef>
#include <vector>

#include "axi/grid_axi.hpp"
#include "full3d/fft.hpp"

namespace swim::axi {

class AxiStokes {
 public:
  /// Factors the nx/2 + 1 banded systems. Throws std::invalid_argument for nr < 2, nx < 4 or
  /// odd, h <= 0 or mu <= 0 (or not finite); swim::NumericalError if LAPACK reports a
  /// singular factor.
  AxiStokes(const AxiGrid& g, double mu, const full3d::FftOptions& fft = {});

  /// Steady Stokes solve. fr: radial force density, size u_size() (rows 0 and nr ignored);
  /// fx: axial force density, size w_size(); N/m^3. Outputs u (size u_size(), rows 0 and nr
  /// set to 0), w (size w_size()), m/s, and optionally p (size p_size(), Pa, zero plain mean
  /// over the cells). Inputs and outputs may not alias each other. Uses the object's
  /// workspace: not re-entrant (one solve at a time per object), no allocation.
  void solve(const double* fr, const double* fx, double* u, double* w, double* p = nullptr);

  /// The same with std::vector arguments; sizes checked (std::invalid_argument), outputs resized.
  void solve(const std::vector<double>& fr, const std::vector<double>& fx, std::vector<double>& u,
             std::vector<double>& w, std::vector<double>* p = nullptr);

  const AxiGrid& grid() const { return g_; }
  double viscosity() const { return mu_; }
  /// Bytes held by the band factors and pivots.
  std::size_t factor_bytes() const;

  /// Band layout of one mode's system (exposed for tests and documentation).
  static constexpr int kSub = 3, kSuper = 3, kLdab = 2 * kSub + kSuper + 1;

 private:
  AxiGrid g_;
  double mu_;
  int n_;    ///< order of each system, 3 nr
  int nk_;   ///< nx/2 + 1 modes
  std::vector<std::complex<double>> ab_;  ///< nk_ factors, kLdab x n_ each (LAPACK band storage)
  std::vector<int> ipiv_;                 ///< nk_ x n_ pivots
  std::vector<std::complex<double>> rhs_; ///< one mode's right-hand side / solution
  // rows of the real buffers (nx each) and of the spectra (nk_ each): w/fx 0..nr-1,
  // u/fr (faces 1..nr-1) nr..2nr-2, p 2nr-1..3nr-2.
  full3d::FftwBuffer real_in_, real_out_, spec_;
  full3d::FftwPlan forward_, inverse_velocity_, inverse_all_;
};

}  // namespace swim::axi
