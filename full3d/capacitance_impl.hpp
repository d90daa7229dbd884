// Private to the capacitance Stokes solver (capacitance_stokes.hpp, where the method is
// described): the state shared by its three parts, each in its own file:
//   capacitance_stokes.cpp    the spectral free-slip base (x and yz transforms, the per-mode
//                             projection), the symmetry-adapted dense factors and their cache,
//                             the driver of a solve;
//   capacitance_duct.cpp      the no-slip duct: Woodbury correction on the wall-adjacent nodes;
//   capacitance_cylinder.cpp  the staircase cylinder: the constrained solve on the ring faces.
// The dense factors are LAPACK packed Cholesky factors (packed_cholesky.hpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.hpp"
#include "full3d/capacitance_stokes.hpp"
#include "full3d/line_transform.hpp"
#include "full3d/packed_cholesky.hpp"

namespace swim::full3d {

namespace capacitance {

constexpr double kPi = std::numbers::pi;

// Dense tables of the unnormalised 1D transforms (FFTW conventions) across the duct along
// one direction with n cells; used for the O(n^2) partial transforms on the wall lines.
struct Dir1d {
  int n = 0;
  std::vector<double> cf;  // cf[m n + j] = 2 cos(pi m (j+1/2)/n): REDFT10, coefficient m of cell values
  std::vector<double> cft; // cft[j n + m] = cf[m n + j] (contiguous in m)
  std::vector<double> ci;  // ci[j n + m] = (m ? 2 : 1) cos(pi m (j+1/2)/n): REDFT01, value at cell j
  std::vector<double> sn;  // sn[a n + b] = 2 sin(pi a b/n): RODFT00 on faces 1..n-1 (both directions)
  std::vector<double> g;   // g[m] = -2 sin(pi m/(2n))/h: G maps cos_m onto g_m sin_m, -L = g_m^2
  Dir1d(int n_, double h);
};

}  // namespace capacitance

struct CapacitanceStokes::Impl {
  using Dir1d = capacitance::Dir1d;
  static constexpr double kPi = capacitance::kPi;

  // ==== spectral free-slip base and dense factors (capacitance_stokes.cpp) ==================
  MacGrid grid;
  double mu;
  int threads;
  int nx, ny, nz, nxh;
  Dir1d dy, dz;
  // Cross-section rows (one row = the nx values of one (component, j, k)) in MacGrid order:
  // u (ny nz), v ((ny+1) nz), w (ny (nz+1)), p (ny nz); off[c] = first row of component c.
  std::array<int, 5> off{};
  std::size_t P = 0;  // plane stride in doubles (multiple of 8: all planes share one alignment)
  // real: rows x nx (x fastest); planes: nx halfcomplex planes of the cross-section,
  // plane r holding Re (r <= nx/2) or Im (r > nx/2) of axial mode min(r, nx - r).
  FftwBuffer real, planes;
  std::vector<FftwPlan> xfwd;                      // per thread block of rows
  std::array<std::vector<FftwPlan>, 4> xbwd;       // per component (u, v, w, p) and thread block
  std::array<std::vector<std::pair<long, long>>, 4> xbwd_rows;  // the rows [b, e) of each
  bool pressure_wanted = true;
  // Cross-section transforms (dense, line_transform.hpp): along y (each z row) then across z.
  // Per component c (u, v, w, p): the first transformed element of a plane, the lengths along
  // y and z (v: the ny-1 interior y faces, DST-I; w: the nz-1 interior z layers, DST-I), the
  // row length, and the transforms each way (REDFT10 forward, REDFT01 inverse, DST-I both).
  std::array<std::size_t, 4> yz_at{};
  struct YzLayout {
    int ly = 0, lz = 0, row = 0;
    const LineTransform *fy = nullptr, *fz = nullptr, *iy = nullptr, *iz = nullptr;
  };
  std::array<YzLayout, 4> yz;
  LineTransform y10, y01, y00, z10, z01, z00;
  // 2D transform (forward or inverse) of component c of plane f in place (tmp: a plane-sized
  // work array).
  void yz_transform(int c, double* f, double* tmp, bool inverse) const;
  // Zero the slots of a plane that no cross-section transform writes: v on the wall faces
  // j = 0, ny, w on the wall layers k = 0, nz.
  void zero_wall_slots(double* f) const;
  int m = 0;  // correction nodes per cross-section (duct: wall nodes; cylinder: ring faces)
  // Symmetry-adapted basis of the correction nodes (shown for the wall nodes; the ring of a
  // symmetric staircase cylinder likewise, setup_cylinder). The duct and both bases are symmetric
  // under the reflections Ry: y -> Ly - y (v -> -v) and Rz: z -> Lz - z (w -> -w), which map
  // the wall nodes onto themselves with signs; C(kx) commutes with them, so in the basis of
  // the four characters (sy, sz) = (+-1, +-1) it is block diagonal: four blocks of about m/4,
  // a quarter of the factor memory and of the substitution work. Each basis vector combines
  // the (at most 4) nodes of one orbit: Q_c e = sum_g chi_c(g) sign_g e_{g(a)}, normalised.
  struct SymVec {
    int n = 0;
    std::array<int, 4> node{};
    std::array<double, 4> w{};
  };
  std::vector<SymVec> sym;         // m vectors, grouped by class
  std::array<int, 5> cls_off{};    // class c: sym[cls_off[c], cls_off[c+1])
  std::size_t factor_doubles = 0;  // packed factor storage of one axial mode (all classes)
  struct Factors {
    double alpha = 0.0;
    // per axial mode kx: the Cholesky factors L_c of the four symmetry blocks C_c = Q_c^T C Q_c
    // (LAPACK packed storage; a class with no node has an empty factor). (An explicit inverse
    // would cost the same but is not backward stable: C(0) is ill-conditioned through the
    // axial plug mode, and the inverse lost 4 digits before that mode was split off.)
    std::vector<std::array<PackedCholesky, 4>> chol;
    // cylinder: sparse Cholesky factor of the axial-mean x problem (alpha - mu L) on the free u faces
    std::unique_ptr<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>> u0llt;
    std::size_t bytes = 0;
  };
  // The factors of the last `slots` alpha values (least recently used replaced): the
  // adaptive time step of the run driver moves over a ladder of dt values, each of which
  // should be factorised once per run.
  static constexpr int kCacheSlots = CapacitanceStokes::kCachedAlphas;
  std::array<Factors, kCacheSlots> cache;
  std::array<long, kCacheSlots> used_at{};
  int slots = kCacheSlots;  ///< capacity in use (StokesSolver lowers it to fit its memory limit)
  long use_clock = 0;
  Factors& free_slot() {
    int best = 0;
    for (int k = 1; k < slots; ++k)
      if (used_at[k] < used_at[best]) best = k;
    used_at[best] = ++use_clock;
    return cache[best];
  }
  double factor_seconds = 0.0;
  double factor_seconds_total = 0.0;
  long factorizations = 0;
  bool factorized_last = false;
  struct Scratch {
    std::vector<double> r, y;       // plane-shaped work arrays (u, v, w, p parts)
    std::vector<double> a0, a1, b0, b1, e;
    std::vector<double> inv_lam, inv_den;  // per (my, mz): 1/|g|^2 (0 at g = 0), 1/(alpha + mu |g|^2)
    Eigen::MatrixXd w;                      // m x 2: wall values U^T y, then z = C^{-1} U^T y
    std::vector<double> tb;                 // one plane: the transforms' intermediate (between y and z)
    std::vector<double> fb;                 // cylinder: one plane of ring-supported coefficients
    Eigen::VectorXd u0b, u0x;               // cylinder: axial-mean x problem on the free u faces
  };
  std::vector<Scratch> scratch;
  Impl(const MacGrid& g, double mu_, const CylinderOptions* cylopt, int thr, const FftOptions& fft_in);
  double* plane(int r) { return planes.data() + std::size_t(r) * P; }
  bool paired(int kx) const { return kx > 0 && 2 * kx != nx; }
  // x symbol of mode kx in the (rotated) real frame: G_x = gx, D_x = -gx
  double gx_of(int kx) const {
    if (paired(kx)) return -2.0 * std::sin(kPi * kx / nx) / grid.h();
    return kx == 0 ? 0.0 : 2.0 / grid.h();  // Nyquist: (1 - e^{-i pi})/h
  }
  // 1/|g|^2 and 1/(alpha + mu |g|^2) of every wavevector of mode kx (symbol gx) into s.
  void mode_tables(double gx, double alpha, Scratch& s) const;
  // Spectral free-slip projection per wavevector (my, mz), the box formula with a real symbol:
  //   P = g.B/|g|^2 (0 at g = 0),  X = (B - g P)/(alpha + mu |g|^2).
  // B: u, v, w coefficients of a plane-shaped array; X: u, v, w, p coefficients; the tables
  // of mode_tables(gx, alpha). subtract: X = scale (X - M B), else X = scale M B (B may alias X).
  void apply_M(const double* B, double* X, double gx, const Scratch& s, double scale, bool subtract) const;
  // Mode kx's np planes F to the yz spectral (rotated) frame and back (the common first and
  // last stages of the duct's and the cylinder's mode solves).
  void mode_to_spectral(int kx, double* const F[2], int np, Scratch& s);
  void mode_from_spectral(int kx, double* const F[2], int np, bool pressure, Scratch& s);
  // The whole cross-section solve of axial mode kx on its one or two planes.
  void solve_mode(int kx, const Factors& fac, double alpha, Scratch& s);
  // Rotation of the x component of a paired mode into the real frame, q = i e^{i theta/2} u^
  // (dir = +1), and back, u^ = -i e^{-i theta/2} q (dir = -1); re / im: the two planes.
  void rotate(double* re, double* im, int kx, int dir) const;
  // The factors of this alpha: cached, else factorised (the duct's or the cylinder's
  // capacitance per axial mode; the cylinder's sparse axial-mean factor).
  const Factors& factors(double alpha);
  // Cholesky factors of the symmetry blocks Q_c^T C Q_c of the capacitance C of mode kx.
  // Throws NumericalError (naming the solver `what`) when a block is not positive definite.
  void factor_blocks(const Eigen::MatrixXd& C, std::array<PackedCholesky, 4>& l, long kx, double alpha,
                     const char* what) const;
  // s.w(:, q) = C^{-1} s.w(:, q), q < np: to the symmetry-adapted basis (s.e: 2 columns of m),
  // the four block solves with the factors l, and back.
  void block_solve(const std::array<PackedCholesky, 4>& l, int np, Scratch& s) const;
  // image(a, g, node, sign): the image of node a under g = gy + 2 gz (gy: Ry applied, gz: Rz)
  template <class Image>
  void build_symmetry_with(Image&& image) {
    std::array<std::vector<SymVec>, 4> cls;
    std::vector<char> done(std::size_t(m), 0);
    for (int a = 0; a < m; ++a) {
      if (done[a]) continue;
      std::array<int, 4> img{};
      std::array<double, 4> sgn{};
      for (int g = 0; g < 4; ++g) {  // g = gy + 2 gz
        image(a, g, img[g], sgn[g]);
        done[img[g]] = 1;
      }
      for (int cl = 0; cl < 4; ++cl) {  // character chi(g) = sy^gy sz^gz, sy = -1 if cl & 1
        SymVec v;
        for (int g = 0; g < 4; ++g) {
          const double chi = ((cl & 1) && (g & 1) ? -1.0 : 1.0) * ((cl & 2) && (g & 2) ? -1.0 : 1.0);
          int slot = 0;
          while (slot < v.n && v.node[slot] != img[g]) ++slot;
          if (slot == v.n) {
            v.node[v.n] = img[g];
            v.w[v.n++] = 0.0;
          }
          v.w[slot] += chi * sgn[g];
        }
        double nrm = 0.0;
        int keep = 0;
        for (int q = 0; q < v.n; ++q)
          if (std::abs(v.w[q]) > 0.5) {
            v.node[keep] = v.node[q];
            v.w[keep++] = v.w[q];
            nrm += v.w[q] * v.w[q];
          }
        v.n = keep;
        if (keep == 0) continue;
        for (int q = 0; q < keep; ++q) v.w[q] /= std::sqrt(nrm);
        cls[cl].push_back(v);
      }
    }
    sym.clear();
    for (int cl = 0; cl < 4; ++cl) {
      cls_off[cl] = int(sym.size());
      sym.insert(sym.end(), cls[cl].begin(), cls[cl].end());
    }
    cls_off[4] = int(sym.size());
    if (cls_off[4] != m)
      throw NumericalError("capacitance solver: symmetry-adapted wall basis has " + std::to_string(cls_off[4]) +
                               " vectors for " + std::to_string(m) + " wall nodes",
                           "report this grid (ny, nz)");
    factor_doubles = 0;
    for (int cl = 0; cl < 4; ++cl) factor_doubles += PackedCholesky::packed_size(cls_off[cl + 1] - cls_off[cl]);
  }
  // b = beta * un + f (un == nullptr: b = f), fused into the copy into the transform rows.
  // u may alias un: every row is read before any output is written.
  void solve(const VectorField* un, double beta, const VectorField& f, VectorField& u, ScalarField& p,
             double alpha);

  // ==== no-slip duct: Woodbury correction on the wall nodes (capacitance_duct.cpp) ==========
  // Wall-adjacent tangential nodes (the columns of U), numbered
  //   [0, 2nz)            u on the rows j = 0 (first nz), j = ny-1, all k (W = 2 at k = 0, nz-1)
  //   [2nz, bv)           u on the columns k = 0, nz-1, j = 1..ny-2
  //   [bv, bw)            v on k = 0, nz-1, interior faces j = 1..ny-1
  //   [bw, m)             w on j = 0, ny-1, interior faces k = 1..nz-1
  int bv = 0, bw = 0;  // m: see above
  std::vector<double> dg_inv;  // Dg^{-1} = h^2 / (2 mu W) per node
  // Axial mean (kx = 0) of the x component (transforms planned by the constructor): decoupled
  // from p (g_x = 0), a scalar Helmholtz problem solved exactly in the no-slip sine basis
  // (RODFT10 / RODFT01) instead of by the capacitance correction, whose free-slip base has
  // the eigenvalue alpha only on the plug flow and would lose a factor mu lambda_1/alpha of
  // accuracy there (up to 1e5 at dt = 1 ms).
  FftwBuffer u0;
  FftwPlan u0_fwd, u0_inv;
  std::vector<double> u0_lam;  // -L_ns eigenvalue per (my, mz) of the sine basis
  void setup_wall_nodes();
  // Wall node number of (component c, j, k) (the numbering above), and its image under Ry
  // (dir 1) or Rz (dir 2) with the sign of the reflected component.
  int node_of(int c, int j, int k) const;
  void node_position(int a, int& c, int& j, int& k) const;
  void reflect(int& c, int& j, int& k, double& sign, int dir) const;
  void build_symmetry();
  // out = U^T T^{-1} F (unnormalised inverse): the values at the wall nodes of the field
  // with yz coefficients F, evaluated line by line (contraction across the line, then the
  // dense 1D inverse along it): O(n^2) instead of a full 2D inverse transform.
  void wall_values(const double* F, double* out, Scratch& s) const;
  // R = T U z (unnormalised forward yz transform of the field equal to z on the wall nodes
  // and zero elsewhere): per line a dense 1D transform along it, then the rank-one spread
  // across it (the line's cross-direction basis values). Writes every coefficient of u, v, w.
  void wall_transform(const double* z, double* R, Scratch& s) const;
  // Capacitance matrix of mode kx: C = Dg^{-1} + U^T S_fs(kx)^{-1} U, one unit solve per column.
  // (x symbol gx; the tables of mode_tables(gx, alpha) in s)
  Eigen::MatrixXd capacitance(int kx, double gx, Scratch& s) const;
  // Exact no-slip solve of the axial mean of the x component (plane 0, u part, real space,
  // x-unnormalised) in place: u = (alpha - mu L_ns)^{-1} b, scaled by 1/nx like the planes.
  void solve_mean_x(double* f, double alpha);
  // Mode kx's Woodbury correction of the free-slip solution in F (see correct_ring).
  void correct_walls(int kx, double* const F[2], int np, double gx, const Factors& fac, Scratch& s) const;

  // ==== staircase cylinder: constrained solve on the ring faces (capacitance_cylinder.cpp) ==
  bool cyl = false;
  std::vector<char> row_masked;  // per u/v/w row (< off[3]): wall face or outside the cylinder
  std::vector<char> cell_fluid;  // per cell k ny + j: has a free face
  std::vector<int> ring;
  std::vector<char> ring_c;
  // Partial cross-section transforms of the ring: per component the inverse across z of every
  // y column (ring values) and the forward across z of every y column (ring-supported fields);
  // the halves along y are dense sums over the ring nodes only, contiguous along y.
  // Values at the ring nodes of the inverse yz transforms of the u, v, w coefficients in F,
  // times scale, into w (m values); tmp: a plane-sized work array.
  void ring_values(const double* F, double scale, double* w, double* tmp) const;
  // Forward yz transforms of the field equal to z on the ring nodes and 0 elsewhere into the
  // u, v, w coefficient slots of fb (all of them written); tmp: a plane-sized work array.
  void ring_forward(const double* z, double* fb, double* tmp) const;
  // Null vectors of C(kx): lam = (G q)|_R for q the indicator of a group of cells connected
  // through non-ring y/z faces (real-space G: (q_j - q_{j-1})/h on y faces, g_x q on x faces in
  // the rotated frame). yz: the y/z-face entries; ux: the ring x faces of the group (coefficient g_x).
  // null0: every group (kx = 0, g_x = 0); null1: the groups with no free or outer x face (kx > 0).
  struct NullVec {
    std::vector<std::pair<int, double>> yz;
    std::vector<int> ux;
  };
  std::vector<NullVec> null0, null1;
  std::vector<int> u0_id;  // per cell: index of its free x face in the axial-mean problem, -1 if masked
  int u0_n = 0;
  double mask_residual = 0.0;
  void setup_cylinder(double radius);
  bool sym_ok = false;
  std::array<std::vector<int>, 4> ring_img;     // image of ring node a under g (g = gy + 2 gz)
  std::array<std::vector<double>, 4> ring_sgn;  // sign of the reflected component
  std::vector<int> orbit_rep;                   // one ring node per orbit (all nodes without symmetry)
  // Sparse (alpha - mu L) of the axial mean x component on the free u faces of the cross-section
  // (5-point, masked neighbours zero, duct-wall ghost -u), Cholesky-factorised.
  std::unique_ptr<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>> factor_mean_x(double alpha) const;
  // Unnormalised forward yz transform of the unit field at ring node a, written into the
  // coefficient slots of R (u, v, w parts; all other slots left untouched, zero): separable,
  // the product of the 1D basis values across y and z.
  void ring_unit_transform(int a, double* R) const;
  void clear_ring_unit(int a, double* R) const;
  // Capacitance of mode kx for the cylinder: C = E_R S_fs(kx)^{-1} E_R^T + s N N^T (see the
  // header): one unit solve per column (separable forward transform, spectral projection, the
  // ring values by ring_values). kx = 0: the ring x faces are decoupled
  // (g_x = 0, exact zeros) and solved separately; their block is replaced by I.
  // (x symbol gx; the tables of mode_tables(gx, alpha) in s)
  Eigen::MatrixXd capacitance_cyl(int kx, double gx, Scratch& s) const;
  // Mode kx's ring correction of the free-slip solution Y = M T b in its np planes F: ring
  // values y_R (ring_values of a copy), lam = C^{-1} y_R, X = Y - M T E_R^T lam (ring_forward).
  void correct_ring(int kx, double* const F[2], int np, double gx, const Factors& fac, Scratch& s) const;
  // The cylinder's axial mean of u (kx = 0) from its sparse factor.
  void mean_x_ring(double* u, const Factors& fac, Scratch& s) const;
};

}  // namespace swim::full3d
