#include "full3d/capacitance_stokes.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "full3d/parallel.hpp"

namespace swim::full3d {

namespace {

constexpr double kPi = std::numbers::pi;

// Dense tables of the unnormalised 1D transforms (FFTW conventions) across the duct along
// one direction with n cells; used for the O(n^2) partial transforms on the wall lines.
struct Dir1d {
  int n = 0;
  std::vector<double> cf;  // cf[m n + j] = 2 cos(pi m (j+1/2)/n): REDFT10, coefficient m of cell values
  std::vector<double> ci;  // ci[j n + m] = (m ? 2 : 1) cos(pi m (j+1/2)/n): REDFT01, value at cell j
  std::vector<double> sn;  // sn[a n + b] = 2 sin(pi a b/n): RODFT00 on faces 1..n-1 (both directions)
  std::vector<double> g;   // g[m] = -2 sin(pi m/(2n))/h: G maps cos_m onto g_m sin_m, -L = g_m^2
  Dir1d(int n_, double h) : n(n_), cf(std::size_t(n_) * n_), ci(std::size_t(n_) * n_), sn(std::size_t(n_) * n_), g(n_) {
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double c = std::cos(kPi * a * (b + 0.5) / n);
        cf[std::size_t(a) * n + b] = 2.0 * c;
        ci[std::size_t(b) * n + a] = (a ? 2.0 : 1.0) * c;
        sn[std::size_t(a) * n + b] = 2.0 * std::sin(kPi * a * b / n);
      }
    for (int m = 0; m < n; ++m) g[m] = -2.0 * std::sin(kPi * m / (2.0 * n)) / h;
  }
};

// Staircase-cylinder layout of the cross-section. Face status per component c (0..2) at
// (j, k) of the dims(c)[1] x dims(c)[2] cross-section: kWall (duct wall face, zero in both
// the free-slip and the no-slip problem), kFree, kRing (outside r = Rc and in the stencil of
// a free face's momentum row -- lateral neighbour of the same component, the MAC Laplacian
// being componentwise and x-neighbours sharing (j, k) -- or of the continuity row of a fluid
// cell), kOuter (outside, in no fluid equation).
enum : char { kWall = 0, kFree = 1, kRing = 2, kOuter = 3 };
struct CylinderLayout {
  std::array<std::array<int, 3>, 3> d{};
  std::array<std::vector<char>, 3> st;
  std::vector<char> fluid;  // per cell k ny + j: has a free face (carries a pressure)
  int ring = 0;
  bool wall_nodes_masked = true;  // every wall-adjacent tangential node is outside
  char at(int c, int j, int k) const {
    if (j < 0 || k < 0 || j >= d[c][1] || k >= d[c][2]) return kWall;
    return st[c][std::size_t(k) * d[c][1] + j];
  }
};
CylinderLayout cylinder_layout(const MacGrid& g, double radius) {
  CylinderLayout L;
  const int ny = g.ny(), nz = g.nz();
  for (int c = 0; c < 3; ++c) {
    L.d[c] = g.dims(c);
    L.st[c].assign(std::size_t(L.d[c][1]) * L.d[c][2], kWall);
    for (int k = 0; k < L.d[c][2]; ++k)
      for (int j = 0; j < L.d[c][1]; ++j)
        if (!g.on_wall(c, 1, j) && !g.on_wall(c, 2, k))
          L.st[c][std::size_t(k) * L.d[c][1] + j] = cylinder_outside(g, radius, c, j, k) ? kOuter : kFree;
  }
  L.fluid.assign(std::size_t(ny) * nz, 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      L.fluid[std::size_t(k) * ny + j] = L.at(0, j, k) == kFree || L.at(1, j, k) == kFree ||
                                         L.at(1, j + 1, k) == kFree || L.at(2, j, k) == kFree ||
                                         L.at(2, j, k + 1) == kFree;
  auto fluid = [&](int j, int k) { return j >= 0 && k >= 0 && j < ny && k < nz && L.fluid[std::size_t(k) * ny + j]; };
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < L.d[c][2]; ++k)
      for (int j = 0; j < L.d[c][1]; ++j) {
        char& s = L.st[c][std::size_t(k) * L.d[c][1] + j];
        if (s != kOuter) continue;
        bool r = L.at(c, j - 1, k) == kFree || L.at(c, j + 1, k) == kFree || L.at(c, j, k - 1) == kFree ||
                 L.at(c, j, k + 1) == kFree;
        if (c == 0) r = r || fluid(j, k);
        if (c == 1) r = r || fluid(j - 1, k) || fluid(j, k);
        if (c == 2) r = r || fluid(j, k - 1) || fluid(j, k);
        if (r) {
          s = kRing;
          ++L.ring;
        }
      }
  // wall-adjacent tangential nodes: u on j = 0, ny-1 or k = 0, nz-1; v on k = 0, nz-1; w on j = 0, ny-1
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      const bool edge_y = j == 0 || j == ny - 1, edge_z = k == 0 || k == nz - 1;
      if ((edge_y || edge_z) && L.at(0, j, k) == kFree) L.wall_nodes_masked = false;
    }
  for (int k : {0, nz - 1})
    for (int j = 1; j < ny; ++j)
      if (L.at(1, j, k) == kFree) L.wall_nodes_masked = false;
  for (int j : {0, ny - 1})
    for (int k = 1; k < nz; ++k)
      if (L.at(2, j, k) == kFree) L.wall_nodes_masked = false;
  return L;
}

bool cylinder_radius_valid(const MacGrid& g, double radius) {
  return g.kind() == ContainerKind::SquareDuct && radius > 0.0 &&
         2.0 * radius <= std::min(g.length(1), g.length(2)) * (1.0 + 1e-12);
}

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

}  // namespace

struct CapacitanceStokes::Impl {
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
  std::vector<FftwPlan> xfwd, xbwd;  // per thread block of rows
  std::array<FftwPlan, 3> yz_fwd;    // u, v, w (planned on plane 0)
  std::array<FftwPlan, 4> yz_inv;    // u, v, w, p
  std::array<std::size_t, 4> yz_at{};  // first transformed element of each component in a plane
  // Axial mean (kx = 0) of the x component: decoupled from p (g_x = 0), a scalar Helmholtz
  // problem solved exactly in the no-slip sine basis (RODFT10 / RODFT01) instead of by the
  // capacitance correction, whose free-slip base has the eigenvalue alpha only on the plug
  // flow and would lose a factor mu lambda_1/alpha of accuracy there (up to 1e5 at dt = 1 ms).
  FftwBuffer u0;
  FftwPlan u0_fwd, u0_inv;
  std::vector<double> u0_lam;  // -L_ns eigenvalue per (my, mz) of the sine basis

  // Wall-adjacent tangential nodes (the columns of U), numbered
  //   [0, 2nz)            u on the rows j = 0 (first nz), j = ny-1, all k (W = 2 at k = 0, nz-1)
  //   [2nz, bv)           u on the columns k = 0, nz-1, j = 1..ny-2
  //   [bv, bw)            v on k = 0, nz-1, interior faces j = 1..ny-1
  //   [bw, m)             w on j = 0, ny-1, interior faces k = 1..nz-1
  int bv = 0, bw = 0, m = 0;
  std::vector<double> dg_inv;  // Dg^{-1} = h^2 / (2 mu W) per node

  // Symmetry-adapted basis of the wall-node space. The duct and both bases are symmetric
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
  std::array<std::size_t, 5> chol_off{};  // packed factor of class c at chol_off[c]

  struct Factors {
    double alpha = 0.0;
    // per axial mode kx: the Cholesky factors L_c of the four symmetry blocks C_c = Q_c^T C Q_c
    // (see `sym` below), each lower triangle packed by columns (column j of a block of order
    // n starts at packed_col(j, n)), concatenated at chol_off[c]. The substitutions read them
    // column by column, contiguously, for both right-hand sides at once. (An explicit inverse
    // would cost the same but is not backward stable: C(0) is ill-conditioned through the
    // axial plug mode, and the inverse lost 4 digits before that mode was split off.)
    std::vector<std::vector<double>> chol;
    // cylinder: sparse Cholesky factor of the axial-mean x problem (alpha - mu L) on the free u faces
    std::unique_ptr<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>> u0llt;
    std::size_t bytes = 0;
  };
  // The factors of the last kCacheSlots alpha values (least recently used replaced): the
  // adaptive time step of the run driver moves over a ladder of a few dt values.
  static constexpr int kCacheSlots = 6;
  std::array<Factors, kCacheSlots> cache;
  std::array<long, kCacheSlots> used_at{};
  long use_clock = 0;
  Factors& free_slot() {
    int best = 0;
    for (int k = 1; k < kCacheSlots; ++k)
      if (used_at[k] < used_at[best]) best = k;
    used_at[best] = ++use_clock;
    return cache[best];
  }
  double factor_seconds = 0.0;
  bool factorized_last = false;

  struct Scratch {
    std::vector<double> r, y;       // plane-shaped work arrays (u, v, w, p parts)
    std::vector<double> a0, a1, b0, b1, e;
    std::vector<double> inv_lam, inv_den;  // per (my, mz): 1/|g|^2 (0 at g = 0), 1/(alpha + mu |g|^2)
    Eigen::MatrixXd w;                      // m x 2: wall values U^T y, then z = C^{-1} U^T y
    FftwBuffer fb;                          // cylinder: one plane, aligned like the planes (FFTW new-array execution)
    Eigen::VectorXd u0b, u0x;               // cylinder: axial-mean x problem on the free u faces
  };
  std::vector<Scratch> scratch;

  // ---- staircase cylinder ----------------------------------------------------------------
  // The ring nodes R (m of them) replace the wall nodes; node a is the face at plane index
  // ring[a] (= the cross-section row) of component ring_c[a].
  bool cyl = false;
  std::vector<char> row_masked;  // per u/v/w row (< off[3]): wall face or outside the cylinder
  std::vector<char> cell_fluid;  // per cell k ny + j: has a free face
  std::vector<int> ring;
  std::vector<char> ring_c;
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

  void setup_cylinder(double radius) {
    const CylinderLayout L = cylinder_layout(grid, radius);
    if (!L.wall_nodes_masked)
      throw InputError("container.radius", std::to_string(radius),
                       "the capacitance cylinder solver needs every wall-adjacent tangential face outside the "
                       "cylinder (radius <= duct half-width - h/2); use a smaller radius or "
                       "full3d.cylinder_wall = \"ghost_linear\" (iterative solver)");
    cyl = true;
    const double h = grid.h();
    row_masked.assign(std::size_t(off[3]), 0);
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < L.d[c][2]; ++k)
        for (int j = 0; j < L.d[c][1]; ++j) {
          const char st = L.at(c, j, k);
          const int row = off[c] + k * L.d[c][1] + j;
          row_masked[row] = st != kFree;
          if (st == kRing) {
            ring.push_back(row);
            ring_c.push_back(char(c));
          }
        }
    m = int(ring.size());
    cell_fluid = L.fluid;
    // groups of cells connected through free or outer y/z faces
    std::vector<int> parent(std::size_t(ny) * nz);
    for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = int(i);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j) {
        const int cell = k * ny + j;
        const char sv = L.at(1, j, k), sw = L.at(2, j, k);
        if (j > 0 && (sv == kFree || sv == kOuter)) parent[find_root(parent, cell)] = find_root(parent, cell - 1);
        if (k > 0 && (sw == kFree || sw == kOuter)) parent[find_root(parent, cell)] = find_root(parent, cell - ny);
      }
    std::vector<int> root(parent.size());
    std::vector<char> has_x(parent.size(), 0);  // group has a free or outer x face
    for (std::size_t i = 0; i < parent.size(); ++i) {
      root[i] = find_root(parent, int(i));
      const char su = L.st[0][i];
      if (su == kFree || su == kOuter) has_x[root[i]] = 1;
    }
    std::vector<NullVec> grp(parent.size());
    for (int a = 0; a < m; ++a) {
      const int c = ring_c[a], r = ring[a] - off[c];
      const int j = r % L.d[c][1], k = r / L.d[c][1];
      if (c == 0) {
        grp[root[std::size_t(k) * ny + j]].ux.push_back(a);
      } else {
        // y face j between cells j-1 and j: (q_j - q_{j-1})/h (likewise z)
        const int c1 = k * ny + j, c0 = c == 1 ? c1 - 1 : c1 - ny;
        if (root[c1] != root[c0]) {
          grp[root[c1]].yz.emplace_back(a, 1.0 / h);
          grp[root[c0]].yz.emplace_back(a, -1.0 / h);
        }
      }
    }
    for (std::size_t i = 0; i < grp.size(); ++i) {
      if (root[i] != int(i)) continue;
      if (!grp[i].yz.empty()) null0.push_back(NullVec{grp[i].yz, {}});
      if (!has_x[i] && (!grp[i].yz.empty() || !grp[i].ux.empty())) null1.push_back(grp[i]);
    }
    u0_id.assign(std::size_t(ny) * nz, -1);
    for (std::size_t i = 0; i < u0_id.size(); ++i)
      if (L.st[0][i] == kFree) u0_id[i] = u0_n++;

    // Reflection symmetry. When the face statuses are invariant under Ry and Rz (the centred
    // staircase; the mask is computed in floating point, so it is checked, not assumed), the
    // ring maps onto itself, C(kx) and the lift N N^T commute with both reflections (the
    // groups map onto groups), and the capacitance splits into the four character blocks
    // (as for the duct's wall nodes); C is then assembled from one column per orbit. Otherwise
    // one block of order m.
    auto refl = [&](int c, int& j, int& k, double& sg, int g) {
      if (g & 1) {
        j = c == 1 ? ny - j : ny - 1 - j;
        if (c == 1) sg = -sg;
      }
      if (g & 2) {
        k = c == 2 ? nz - k : nz - 1 - k;
        if (c == 2) sg = -sg;
      }
    };
    sym_ok = true;
    for (int c = 0; c < 3 && sym_ok; ++c)
      for (int k = 0; k < L.d[c][2] && sym_ok; ++k)
        for (int j = 0; j < L.d[c][1] && sym_ok; ++j)
          for (int g = 1; g < 4; ++g) {
            int jj = j, kk = k;
            double sg = 1.0;
            refl(c, jj, kk, sg, g);
            if (L.at(c, jj, kk) != L.at(c, j, k)) sym_ok = false;
          }
    std::vector<int> ring_of_row(std::size_t(off[3]), -1);
    for (int a = 0; a < m; ++a) ring_of_row[ring[a]] = a;
    for (int g = 0; g < 4; ++g) {
      ring_img[g].assign(std::size_t(m), 0);
      ring_sgn[g].assign(std::size_t(m), 1.0);
    }
    if (sym_ok) {
      for (int a = 0; a < m; ++a) {
        const int c = ring_c[a], r = ring[a] - off[c];
        const int d1 = L.d[c][1];
        for (int g = 0; g < 4; ++g) {
          int j = r % d1, k = r / d1;
          double sg = 1.0;
          refl(c, j, k, sg, g);
          ring_img[g][a] = ring_of_row[std::size_t(off[c] + k * d1 + j)];
          ring_sgn[g][a] = sg;
        }
      }
      build_symmetry_with([&](int a, int g, int& node, double& sg) {
        node = ring_img[g][a];
        sg = ring_sgn[g][a];
      });
      std::vector<char> done(std::size_t(m), 0);
      for (int a = 0; a < m; ++a)
        if (!done[a]) {
          orbit_rep.push_back(a);
          for (int g = 0; g < 4; ++g) done[ring_img[g][a]] = 1;
        }
    } else {
      sym.assign(std::size_t(m), SymVec{});
      for (int a = 0; a < m; ++a) {
        sym[a].n = 1;
        sym[a].node[0] = a;
        sym[a].w[0] = 1.0;
        ring_img[0][a] = a;
        orbit_rep.push_back(a);
      }
      cls_off = {0, m, m, m, m};
      chol_off = {0, packed_col(m, m), packed_col(m, m), packed_col(m, m), packed_col(m, m)};
    }
  }
  bool sym_ok = false;
  std::array<std::vector<int>, 4> ring_img;     // image of ring node a under g (g = gy + 2 gz)
  std::array<std::vector<double>, 4> ring_sgn;  // sign of the reflected component
  std::vector<int> orbit_rep;                   // one ring node per orbit (all nodes without symmetry)

  // Sparse (alpha - mu L) of the axial mean x component on the free u faces of the cross-section
  // (5-point, masked neighbours zero, duct-wall ghost -u), Cholesky-factorised.
  std::unique_ptr<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>> factor_mean_x(double alpha) const {
    const double ih2 = 1.0 / (grid.h() * grid.h());
    std::vector<Eigen::Triplet<double>> t;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j) {
        const int i = u0_id[std::size_t(k) * ny + j];
        if (i < 0) continue;
        double diag = alpha + 4.0 * mu * ih2;
        const int nb[4][2] = {{j - 1, k}, {j + 1, k}, {j, k - 1}, {j, k + 1}};
        for (const auto& q : nb) {
          if (q[0] < 0 || q[0] >= ny || q[1] < 0 || q[1] >= nz) {
            diag += mu * ih2;  // ghost u = -u_0 across the duct wall
            continue;
          }
          const int n = u0_id[std::size_t(q[1]) * ny + q[0]];
          if (n >= 0) t.emplace_back(i, n, -mu * ih2);
        }
        t.emplace_back(i, i, diag);
      }
    Eigen::SparseMatrix<double> A(u0_n, u0_n);
    A.setFromTriplets(t.begin(), t.end());
    auto llt = std::make_unique<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>>(A);
    if (llt->info() != Eigen::Success)
      throw NumericalError("axial-mean factorisation of the cylinder capacitance solver failed",
                           "change the grid (full3d.grid.cells_across) or use full3d.cylinder_wall = "
                           "\"ghost_linear\" (iterative solver)");
    return llt;
  }

  Impl(const MacGrid& g, double mu_, const CylinderOptions* cylopt, int thr, const FftOptions& fft_in)
      : grid(g), mu(mu_), threads(std::max(1, thr)), nx(g.nx()), ny(g.ny()), nz(g.nz()), nxh(g.nx() / 2 + 1),
        dy(g.ny(), g.h()), dz(g.nz(), g.h()) {
    if (g.kind() != ContainerKind::SquareDuct)
      throw InputError("container", to_string(g.kind()), "the capacitance Stokes solver needs a square_duct grid");
    off[0] = 0;
    for (int c = 0; c < 4; ++c) {
      const auto d = g.dims(c);
      off[c + 1] = off[c] + d[1] * d[2];
    }
    P = (std::size_t(off[4]) + 7) / 8 * 8;
    real = FftwBuffer(std::size_t(off[4]) * nx);
    planes = FftwBuffer(P * nx);
    FftOptions fft = fft_in;
    fft.threads = 1;  // our own threads run the plans concurrently

    // batched x transforms, one plan per thread block (planned on its own rows)
    auto plan_x = [&](int rows, bool forward, std::vector<FftwPlan>& out) {
      const int T = block_count(rows, threads);
      for (int t = 0; t < T; ++t) {
        const long b = long(rows) * t / T, e = long(rows) * (t + 1) / T;
        const int n[1] = {nx};
        double* r = real.data() + std::size_t(b) * nx;
        double* s = planes.data() + b;
        if (forward) {
          const fftw_r2r_kind k = FFTW_R2HC;
          out.push_back(plan_many_r2r(1, n, int(e - b), r, nullptr, 1, nx, s, nullptr, int(P), 1, &k, fft));
        } else {
          const fftw_r2r_kind k = FFTW_HC2R;
          out.push_back(plan_many_r2r(1, n, int(e - b), s, nullptr, int(P), 1, r, nullptr, 1, nx, &k, fft));
        }
      }
    };
    plan_x(off[3], true, xfwd);
    plan_x(off[4], false, xbwd);

    // 2D cross-section transforms of one plane (new-array execution on every plane)
    double* p0 = planes.data();
    yz_at = {std::size_t(off[0]), std::size_t(off[1]) + 1, std::size_t(off[2]) + ny, std::size_t(off[3])};
    auto plan_yz = [&](int c, bool forward) {
      const fftw_r2r_kind cosk = forward ? FFTW_REDFT10 : FFTW_REDFT01;
      int n[2] = {nz, ny}, embed[2] = {nz, ny};
      fftw_r2r_kind kinds[2] = {cosk, cosk};
      if (c == 1) {  // v: interior y faces 1..ny-1 of rows of ny+1
        n[1] = ny - 1;
        embed[1] = ny + 1;
        kinds[1] = FFTW_RODFT00;
      } else if (c == 2) {  // w: interior z faces 1..nz-1 of nz+1 layers
        n[0] = nz - 1;
        embed[0] = nz + 1;
        kinds[0] = FFTW_RODFT00;
      }
      double* at = p0 + yz_at[c];
      return plan_many_r2r(2, n, 1, at, embed, 1, 0, at, embed, 1, 0, kinds, fft);
    };
    for (int c = 0; c < 3; ++c) yz_fwd[c] = plan_yz(c, true);
    for (int c = 0; c < 4; ++c) yz_inv[c] = plan_yz(c, false);
    u0 = FftwBuffer(std::size_t(ny) * nz);
    {
      const int n2[2] = {nz, ny};
      const fftw_r2r_kind kf[2] = {FFTW_RODFT10, FFTW_RODFT10}, ki[2] = {FFTW_RODFT01, FFTW_RODFT01};
      u0_fwd = plan_many_r2r(2, n2, 1, u0.data(), nullptr, 1, 0, u0.data(), nullptr, 1, 0, kf, fft);
      u0_inv = plan_many_r2r(2, n2, 1, u0.data(), nullptr, 1, 0, u0.data(), nullptr, 1, 0, ki, fft);
    }
    u0_lam.resize(std::size_t(ny) * nz);
    for (int mz = 0; mz < nz; ++mz)
      for (int my = 0; my < ny; ++my) {
        const double sy = std::sin(kPi * (my + 1) / (2.0 * ny)), sz = std::sin(kPi * (mz + 1) / (2.0 * nz));
        u0_lam[std::size_t(mz) * ny + my] = 4.0 / (g.h() * g.h()) * (sy * sy + sz * sz);
      }

    if (cylopt) {
      if (!cylinder_radius_valid(g, cylopt->radius))
        throw InputError("container.radius", std::to_string(cylopt->radius),
                         "a positive radius Rc with 2 Rc <= the duct side");
      setup_cylinder(cylopt->radius);
    } else {
      setup_wall_nodes();
    }
    scratch.resize(std::size_t(threads));
    const std::size_t nl = std::size_t(std::max(ny, nz)) + 1;
    for (auto& s : scratch) {
      s.r.assign(P, 0.0);
      s.y.assign(P, 0.0);
      for (auto* v : {&s.a0, &s.a1, &s.b0, &s.b1}) v->assign(nl, 0.0);
      s.e.assign(std::size_t(2) * m, 0.0);
      s.inv_lam.assign(std::size_t(ny) * nz, 0.0);
      s.inv_den.assign(std::size_t(ny) * nz, 0.0);
      s.w = Eigen::MatrixXd::Zero(m, 2);
      if (cyl) {
        s.fb = FftwBuffer(P);
        std::fill(s.fb.data(), s.fb.data() + P, 0.0);
        s.u0b.resize(u0_n);
        s.u0x.resize(u0_n);
      }
    }
  }

  void setup_wall_nodes() {
    // wall nodes
    bv = 2 * nz + 2 * (ny - 2);
    bw = bv + 2 * (ny - 1);
    m = bw + 2 * (nz - 1);
    const double h = grid.h();
    dg_inv.assign(std::size_t(m), h * h / (2.0 * mu));
    for (int js = 0; js < 2; ++js) {  // corners of u touch two walls
      dg_inv[std::size_t(js) * nz] = h * h / (4.0 * mu);
      dg_inv[std::size_t(js) * nz + nz - 1] = h * h / (4.0 * mu);
    }

    build_symmetry();
  }

  double* plane(int r) { return planes.data() + std::size_t(r) * P; }
  // start of column j of a packed lower triangle of order n (packed_col(n, n): its size)
  static std::size_t packed_col(int j, int n) { return std::size_t(j) * n - std::size_t(j) * (j - 1) / 2; }

  // Wall node number of (component c, j, k) (the numbering above), and its image under Ry
  // (dir 1) or Rz (dir 2) with the sign of the reflected component.
  int node_of(int c, int j, int k) const {
    if (c == 0) {
      if (j == 0) return k;
      if (j == ny - 1) return nz + k;
      return 2 * nz + (k == 0 ? 0 : ny - 2) + j - 1;
    }
    if (c == 1) return bv + (k == 0 ? 0 : ny - 1) + j - 1;
    return bw + (j == 0 ? 0 : nz - 1) + k - 1;
  }
  void node_position(int a, int& c, int& j, int& k) const {
    if (a < 2 * nz) {
      c = 0, j = a < nz ? 0 : ny - 1, k = a % nz;
    } else if (a < bv) {
      const int r = a - 2 * nz;
      c = 0, k = r < ny - 2 ? 0 : nz - 1, j = r % (ny - 2) + 1;
    } else if (a < bw) {
      const int r = a - bv;
      c = 1, k = r < ny - 1 ? 0 : nz - 1, j = r % (ny - 1) + 1;
    } else {
      const int r = a - bw;
      c = 2, j = r < nz - 1 ? 0 : ny - 1, k = r % (nz - 1) + 1;
    }
  }
  void reflect(int& c, int& j, int& k, double& sign, int dir) const {
    if (dir == 1) {
      j = c == 1 ? ny - j : ny - 1 - j;
      if (c == 1) sign = -sign;
    } else {
      k = c == 2 ? nz - k : nz - 1 - k;
      if (c == 2) sign = -sign;
    }
  }
  void build_symmetry() {
    build_symmetry_with([&](int a, int g, int& node, double& sg) {
      int c, j, k;
      node_position(a, c, j, k);
      sg = 1.0;
      if (g & 1) reflect(c, j, k, sg, 1);
      if (g & 2) reflect(c, j, k, sg, 2);
      node = node_of(c, j, k);
    });
  }
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
    chol_off[0] = 0;
    for (int cl = 0; cl < 4; ++cl) {
      const int n = cls_off[cl + 1] - cls_off[cl];
      chol_off[cl + 1] = chol_off[cl] + packed_col(n, n);
    }
  }

  // z = C_c^{-1} z for nr = 1 or 2 columns z[0], z[1] of length n: L y = z (forward, column
  // axpys), then L^T x = y (backward, column dots), L packed by columns.
  static void cholesky_solve(const double* l, int n, double* const z[2], int nr) {
    const int m = n;
    auto packed = [m](int j) { return packed_col(j, m); };
    double* z0 = z[0];
    double* z1 = nr > 1 ? z[1] : z[0];
    for (int j = 0; j < m; ++j) {
      const double* c = l + packed(j);
      const int len = m - j;
      const double a = z0[j] / c[0], b = z1[j] / c[0];
      z0[j] = a;
      z1[j] = b;  // nr = 1: the same column twice (idempotent)
      double* y0 = z0 + j;
      double* y1 = z1 + j;
      if (nr > 1)
        for (int i = 1; i < len; ++i) {
          y0[i] -= c[i] * a;
          y1[i] -= c[i] * b;
        }
      else
        for (int i = 1; i < len; ++i) y0[i] -= c[i] * a;
    }
    for (int j = m - 1; j >= 0; --j) {
      const double* c = l + packed(j);
      const int len = m - j;
      const double* y0 = z0 + j;
      const double* y1 = z1 + j;
      double s0 = 0.0, s1 = 0.0;
      if (nr > 1)
        for (int i = 1; i < len; ++i) {
          s0 += c[i] * y0[i];
          s1 += c[i] * y1[i];
        }
      else
        for (int i = 1; i < len; ++i) s0 += c[i] * y0[i];
      z0[j] = (z0[j] - s0) / c[0];
      if (nr > 1) z1[j] = (z1[j] - s1) / c[0];
    }
  }
  bool paired(int kx) const { return kx > 0 && 2 * kx != nx; }
  // x symbol of mode kx in the (rotated) real frame: G_x = gx, D_x = -gx
  double gx_of(int kx) const {
    if (paired(kx)) return -2.0 * std::sin(kPi * kx / nx) / grid.h();
    return kx == 0 ? 0.0 : 2.0 / grid.h();  // Nyquist: (1 - e^{-i pi})/h
  }

  // 1/|g|^2 and 1/(alpha + mu |g|^2) of every wavevector of mode kx (symbol gx) into s.
  void mode_tables(double gx, double alpha, Scratch& s) const {
    for (int mz = 0; mz < nz; ++mz)
      for (int my = 0; my < ny; ++my) {
        const double lam = gx * gx + dz.g[mz] * dz.g[mz] + dy.g[my] * dy.g[my];
        const std::size_t i = std::size_t(mz) * ny + my;
        s.inv_lam[i] = lam > 0.0 ? 1.0 / lam : 0.0;
        s.inv_den[i] = 1.0 / (alpha + mu * lam);
      }
  }

  // Spectral free-slip projection per wavevector (my, mz), the box formula with a real symbol:
  //   P = g.B/|g|^2 (0 at g = 0),  X = (B - g P)/(alpha + mu |g|^2).
  // B: u, v, w coefficients of a plane-shaped array; X: u, v, w, p coefficients; the tables
  // of mode_tables(gx, alpha). subtract: X = scale (X - M B), else X = scale M B (B may alias X).
  void apply_M(const double* B, double* X, double gx, const Scratch& s, double scale, bool subtract) const {
    const double* Bu = B + off[0];
    const double* Bv = B + off[1];
    const double* Bw = B + off[2];
    double* Xu = X + off[0];
    double* Xv = X + off[1];
    double* Xw = X + off[2];
    double* Xp = X + off[3];
    for (int mz = 0; mz < nz; ++mz) {
      const double gz = dz.g[mz];
      for (int my = 0; my < ny; ++my) {
        const double gy = dy.g[my];
        const std::size_t iu = std::size_t(mz) * ny + my, iv = std::size_t(mz) * (ny + 1) + my;
        const double cu = Bu[iu], cv = my ? Bv[iv] : 0.0, cw = mz ? Bw[iu] : 0.0;
        const double pp = (gx * cu + gy * cv + gz * cw) * s.inv_lam[iu];
        const double inv = s.inv_den[iu];
        const double xu = (cu - gx * pp) * inv, xv = (cv - gy * pp) * inv, xw = (cw - gz * pp) * inv;
        if (subtract) {
          Xu[iu] = scale * (Xu[iu] - xu);
          Xp[iu] = scale * (Xp[iu] - pp);
          if (my) Xv[iv] = scale * (Xv[iv] - xv);
          if (mz) Xw[iu] = scale * (Xw[iu] - xw);
        } else {
          Xu[iu] = scale * xu;
          Xp[iu] = scale * pp;
          if (my) Xv[iv] = scale * xv;
          if (mz) Xw[iu] = scale * xw;
        }
      }
    }
  }

  // out = U^T T^{-1} F (unnormalised inverse): the values at the wall nodes of the field
  // with yz coefficients F, evaluated line by line (contraction across the line, then the
  // dense 1D inverse along it): O(n^2) instead of a full 2D inverse transform.
  void wall_values(const double* F, double* out, Scratch& s) const {
    const double* Fu = F + off[0];
    const double* Fv = F + off[1];
    const double* Fw = F + off[2];
    double* t = s.a0.data();
    // u on the rows j = 0, ny-1
    for (int js = 0; js < 2; ++js) {
      const double* cy = dy.ci.data() + std::size_t(js ? ny - 1 : 0) * ny;
      for (int mz = 0; mz < nz; ++mz) {
        const double* f = Fu + std::size_t(mz) * ny;
        double acc = 0.0;
        for (int my = 0; my < ny; ++my) acc += cy[my] * f[my];
        t[mz] = acc;
      }
      for (int k = 0; k < nz; ++k) {
        const double* cz = dz.ci.data() + std::size_t(k) * nz;
        double acc = 0.0;
        for (int mz = 0; mz < nz; ++mz) acc += cz[mz] * t[mz];
        out[js * nz + k] = acc;
      }
    }
    // u on the columns k = 0, nz-1 (j = 1..ny-2) and v on the same columns (j = 1..ny-1)
    for (int ks = 0; ks < 2; ++ks) {
      const double* cz = dz.ci.data() + std::size_t(ks ? nz - 1 : 0) * nz;
      std::fill(t, t + ny, 0.0);
      double* tv = s.a1.data();
      std::fill(tv, tv + ny, 0.0);
      for (int mz = 0; mz < nz; ++mz) {
        const double c = cz[mz];
        const double* fu = Fu + std::size_t(mz) * ny;
        const double* fv = Fv + std::size_t(mz) * (ny + 1);
        for (int my = 0; my < ny; ++my) t[my] += c * fu[my];
        for (int my = 1; my < ny; ++my) tv[my] += c * fv[my];
      }
      for (int j = 1; j < ny - 1; ++j) {
        const double* cy = dy.ci.data() + std::size_t(j) * ny;
        double acc = 0.0;
        for (int my = 0; my < ny; ++my) acc += cy[my] * t[my];
        out[2 * nz + ks * (ny - 2) + j - 1] = acc;
      }
      for (int j = 1; j < ny; ++j) {
        const double* sy = dy.sn.data() + std::size_t(j) * ny;
        double acc = 0.0;
        for (int my = 1; my < ny; ++my) acc += sy[my] * tv[my];
        out[bv + ks * (ny - 1) + j - 1] = acc;
      }
    }
    // w on the rows j = 0, ny-1 (interior z faces k = 1..nz-1)
    for (int js = 0; js < 2; ++js) {
      const double* cy = dy.ci.data() + std::size_t(js ? ny - 1 : 0) * ny;
      for (int mz = 1; mz < nz; ++mz) {
        const double* f = Fw + std::size_t(mz) * ny;
        double acc = 0.0;
        for (int my = 0; my < ny; ++my) acc += cy[my] * f[my];
        t[mz] = acc;
      }
      for (int k = 1; k < nz; ++k) {
        const double* sz = dz.sn.data() + std::size_t(k) * nz;
        double acc = 0.0;
        for (int mz = 1; mz < nz; ++mz) acc += sz[mz] * t[mz];
        out[bw + js * (nz - 1) + k - 1] = acc;
      }
    }
  }

  // R = T U z (unnormalised forward yz transform of the field equal to z on the wall nodes
  // and zero elsewhere): per line a dense 1D transform along it, then the rank-one spread
  // across it (the line's cross-direction basis values). Writes every coefficient of u, v, w.
  void wall_transform(const double* z, double* R, Scratch& s) const {
    double* Ru = R + off[0];
    double* Rv = R + off[1];
    double* Rw = R + off[2];
    const int jl = ny - 1, kl = nz - 1;
    double *a0 = s.a0.data(), *a1 = s.a1.data(), *b0 = s.b0.data(), *b1 = s.b1.data();
    // u: rows j = 0 / ny-1 transformed along z (a), columns k = 0 / nz-1 along y (b)
    for (int mz = 0; mz < nz; ++mz) {
      const double* cz = dz.cf.data() + std::size_t(mz) * nz;
      double s0 = 0.0, s1 = 0.0;
      for (int k = 0; k < nz; ++k) {
        s0 += cz[k] * z[k];
        s1 += cz[k] * z[nz + k];
      }
      a0[mz] = s0;
      a1[mz] = s1;
    }
    for (int my = 0; my < ny; ++my) {
      const double* cy = dy.cf.data() + std::size_t(my) * ny;
      double s0 = 0.0, s1 = 0.0;
      for (int j = 1; j < ny - 1; ++j) {
        s0 += cy[j] * z[2 * nz + j - 1];
        s1 += cy[j] * z[2 * nz + (ny - 2) + j - 1];
      }
      b0[my] = s0;
      b1[my] = s1;
    }
    for (int mz = 0; mz < nz; ++mz) {
      const double cz0 = dz.cf[std::size_t(mz) * nz], cz1 = dz.cf[std::size_t(mz) * nz + kl];
      double* r = Ru + std::size_t(mz) * ny;
      for (int my = 0; my < ny; ++my) {
        const double cy0 = dy.cf[std::size_t(my) * ny], cy1 = dy.cf[std::size_t(my) * ny + jl];
        r[my] = cy0 * a0[mz] + cy1 * a1[mz] + cz0 * b0[my] + cz1 * b1[my];
      }
    }
    // v: columns k = 0 / nz-1, sine transform along y
    for (int my = 1; my < ny; ++my) {
      const double* sy = dy.sn.data() + std::size_t(my) * ny;
      double s0 = 0.0, s1 = 0.0;
      for (int j = 1; j < ny; ++j) {
        s0 += sy[j] * z[bv + j - 1];
        s1 += sy[j] * z[bv + (ny - 1) + j - 1];
      }
      b0[my] = s0;
      b1[my] = s1;
    }
    for (int mz = 0; mz < nz; ++mz) {
      const double cz0 = dz.cf[std::size_t(mz) * nz], cz1 = dz.cf[std::size_t(mz) * nz + kl];
      double* r = Rv + std::size_t(mz) * (ny + 1);
      for (int my = 1; my < ny; ++my) r[my] = cz0 * b0[my] + cz1 * b1[my];
    }
    // w: rows j = 0 / ny-1, sine transform along z
    for (int mz = 1; mz < nz; ++mz) {
      const double* sz = dz.sn.data() + std::size_t(mz) * nz;
      double s0 = 0.0, s1 = 0.0;
      for (int k = 1; k < nz; ++k) {
        s0 += sz[k] * z[bw + k - 1];
        s1 += sz[k] * z[bw + (nz - 1) + k - 1];
      }
      a0[mz] = s0;
      a1[mz] = s1;
    }
    for (int mz = 1; mz < nz; ++mz) {
      double* r = Rw + std::size_t(mz) * ny;
      for (int my = 0; my < ny; ++my) {
        const double cy0 = dy.cf[std::size_t(my) * ny], cy1 = dy.cf[std::size_t(my) * ny + jl];
        r[my] = cy0 * a0[mz] + cy1 * a1[mz];
      }
    }
  }

  // Capacitance matrix of mode kx: C = Dg^{-1} + U^T S_fs(kx)^{-1} U, one unit solve per column.
  Eigen::MatrixXd capacitance(int kx, double alpha, Scratch& s) const {
    const double gx = gx_of(kx);
    const double syz = 1.0 / (4.0 * ny * nz);
    Eigen::MatrixXd C(m, m);
    std::fill(s.e.begin(), s.e.end(), 0.0);
    mode_tables(gx, alpha, s);
    for (int a = 0; a < m; ++a) {
      s.e[a] = 1.0;
      wall_transform(s.e.data(), s.r.data(), s);
      apply_M(s.r.data(), s.y.data(), gx, s, syz, false);
      wall_values(s.y.data(), C.col(a).data(), s);
      C(a, a) += dg_inv[a];
      s.e[a] = 0.0;
    }
    if (kx == 0) {
      // the x component of the axial mean is solved separately (solve_mean_x); its nodes are
      // decoupled from v, w here (g_x = 0: exact zeros), so their block is replaced by I
      const int nu = bv;
      C.topLeftCorner(nu, nu).setIdentity();
    }
    // S_fs^{-1} is symmetric: remove the round-off asymmetry before Cholesky
    return 0.5 * (C + C.transpose());
  }

  // ---- cylinder: capacitance, factorisation and mode solve --------------------------------
  // Unnormalised forward yz transform of the unit field at ring node a, written into the
  // coefficient slots of R (u, v, w parts; all other slots left untouched, zero): separable,
  // the product of the 1D basis values across y and z.
  void ring_unit_transform(int a, double* R) const {
    const int c = ring_c[a], r = ring[a] - off[c];
    const int d1 = c == 1 ? ny + 1 : ny;
    const int j = r % d1, k = r / d1;
    double* X = R + off[c];
    if (c == 0) {
      for (int mz = 0; mz < nz; ++mz) {
        const double cz = dz.cf[std::size_t(mz) * nz + k];
        for (int my = 0; my < ny; ++my) X[std::size_t(mz) * ny + my] = cz * dy.cf[std::size_t(my) * ny + j];
      }
    } else if (c == 1) {
      for (int mz = 0; mz < nz; ++mz) {
        const double cz = dz.cf[std::size_t(mz) * nz + k];
        for (int my = 1; my < ny; ++my) X[std::size_t(mz) * (ny + 1) + my] = cz * dy.sn[std::size_t(my) * ny + j];
      }
    } else {
      for (int mz = 1; mz < nz; ++mz) {
        const double sz = dz.sn[std::size_t(mz) * nz + k];
        for (int my = 0; my < ny; ++my) X[std::size_t(mz) * ny + my] = sz * dy.cf[std::size_t(my) * ny + j];
      }
    }
  }
  void clear_ring_unit(int a, double* R) const {
    const int c = ring_c[a];
    const std::size_t n = c == 1 ? std::size_t(nz) * (ny + 1) : c == 2 ? std::size_t(nz + 1) * ny : std::size_t(nz) * ny;
    std::fill(R + off[c], R + off[c] + n, 0.0);
  }

  // Capacitance of mode kx for the cylinder: C = E_R S_fs(kx)^{-1} E_R^T + s N N^T (see the
  // header): one unit solve per column (separable forward transform, spectral projection, three
  // inverse 2D transforms, gather on the ring). kx = 0: the ring x faces are decoupled
  // (g_x = 0, exact zeros) and solved separately; their block is replaced by I.
  Eigen::MatrixXd capacitance_cyl(int kx, double alpha, Scratch& s) const {
    const double gx = gx_of(kx);
    const double syz = 1.0 / (4.0 * ny * nz);
    Eigen::MatrixXd C(m, m);
    std::fill(s.r.begin(), s.r.end(), 0.0);
    mode_tables(gx, alpha, s);
    double* fb = s.fb.data();
    for (int a : orbit_rep) {
      ring_unit_transform(a, s.r.data());
      apply_M(s.r.data(), fb, gx, s, syz, false);
      clear_ring_unit(a, s.r.data());
      for (int c = 0; c < 3; ++c) yz_inv[c].execute_r2r(fb + yz_at[c], fb + yz_at[c]);
      double* col = C.col(a).data();
      for (int b = 0; b < m; ++b) col[b] = fb[ring[b]];
      if (sym_ok)  // C(g b, g a) = sign_g(b) sign_g(a) C(b, a)
        for (int g = 1; g < 4; ++g) {
          const int ga = ring_img[g][a];
          if (ga == a) continue;
          double* cg = C.col(ga).data();
          const double sa = ring_sgn[g][a];
          for (int b = 0; b < m; ++b) cg[ring_img[g][b]] = ring_sgn[g][b] * sa * col[b];
        }
    }
    // s: the mean diagonal of the coupled part, the scale of the null-space lift (and of the
    // decoupled kx = 0 x block); with s far from the spectrum of C the Cholesky factor of the
    // lifted matrix would mix round-off of the lifted directions into the others
    double sc = 0.0;
    int ns = 0;
    for (int a = 0; a < m; ++a)
      if (kx != 0 || ring_c[a] != 0) {
        sc += C(a, a);
        ++ns;
      }
    sc = ns ? sc / ns : 1.0;
    if (kx == 0)
      for (int a = 0; a < m; ++a)
        if (ring_c[a] == 0) {
          C.row(a).setZero();
          C.col(a).setZero();
          C(a, a) = sc;
        }
    Eigen::MatrixXd Cs = 0.5 * (C + C.transpose());
    // lift the null space: + s n n^T per (normalised) null vector
    std::vector<std::pair<int, double>> v;
    for (const NullVec& nv : kx == 0 ? null0 : null1) {
      v = nv.yz;
      if (kx != 0)
        for (int a : nv.ux) v.emplace_back(a, gx);
      double n2 = 0.0;
      for (const auto& e : v) n2 += e.second * e.second;
      if (!(n2 > 0.0)) continue;
      for (const auto& e : v)
        for (const auto& f : v) Cs(e.first, f.first) += sc * e.second * f.second / n2;
    }
    return Cs;
  }

  const Factors& factors_cyl(double alpha) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::vector<double>> chol(static_cast<std::size_t>(nxh));
    parallel_blocks(nxh, threads, [&](long b, long e, int t) {
      for (long kx = b; kx < e; ++kx) {
        const Eigen::MatrixXd C = capacitance_cyl(int(kx), alpha, scratch[t]);
        factor_blocks(C, chol[kx], kx, alpha, "cylinder");
      }
    });
    auto u0llt = factor_mean_x(alpha);
    Factors& f = free_slot();
    f.alpha = alpha;
    f.chol = std::move(chol);
    f.u0llt = std::move(u0llt);
    f.bytes = std::size_t(nxh) * chol_off[4] * sizeof(double) +
              std::size_t(f.u0llt->matrixL().nestedExpression().nonZeros()) * (sizeof(double) + sizeof(int));
    factor_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    factorized_last = true;
    return f;
  }

  // Mode solve for the cylinder: free-slip Y = M T b, ring values y_R (3 inverse transforms of a
  // copy), lam = C^{-1} y_R, X = Y - M T E_R^T lam (3 forward transforms), then the inverses.
  void solve_mode_cyl(int kx, const Factors& fac, double alpha, Scratch& s) {
    const bool two = paired(kx);
    const int np = two ? 2 : 1;
    double* F[2] = {plane(kx), two ? plane(nx - kx) : nullptr};
    double* fb = s.fb.data();
    if (kx == 0) std::copy_n(F[0] + off[0], std::size_t(ny) * nz, s.y.data());  // b of the axial mean u
    for (int q = 0; q < np; ++q)
      for (int c = 0; c < 3; ++c) yz_fwd[c].execute_r2r(F[q] + yz_at[c], F[q] + yz_at[c]);
    if (two) rotate(F[0], F[1], kx, +1);
    const double gx = gx_of(kx);
    const double syz = 1.0 / (4.0 * ny * nz), inv_n = syz / nx;
    mode_tables(gx, alpha, s);
    for (int q = 0; q < np; ++q) {
      apply_M(F[q], F[q], gx, s, 1.0, false);
      std::copy_n(F[q], std::size_t(off[3]), fb);
      for (int c = 0; c < 3; ++c) yz_inv[c].execute_r2r(fb + yz_at[c], fb + yz_at[c]);
      double* w = s.w.col(q).data();
      for (int a = 0; a < m; ++a) w[a] = syz * fb[ring[a]];
      if (kx == 0)
        for (int a = 0; a < m; ++a)
          if (ring_c[a] == 0) w[a] = 0.0;
    }
    block_solve(fac.chol[kx].data(), np, s);
    for (int q = 0; q < np; ++q) {
      std::fill(fb, fb + off[3], 0.0);
      const double* z = s.w.col(q).data();
      for (int a = 0; a < m; ++a) fb[ring[a]] = z[a];
      for (int c = 0; c < 3; ++c) yz_fwd[c].execute_r2r(fb + yz_at[c], fb + yz_at[c]);
      apply_M(fb, F[q], gx, s, inv_n, true);
    }
    if (two) rotate(F[0], F[1], kx, -1);
    for (int q = 0; q < np; ++q) {
      double* f = F[q];
      for (int k = 0; k < nz; ++k) {
        f[off[1] + std::size_t(k) * (ny + 1)] = 0.0;
        f[off[1] + std::size_t(k) * (ny + 1) + ny] = 0.0;
      }
      std::fill(f + off[2], f + off[2] + ny, 0.0);
      std::fill(f + off[2] + std::size_t(nz) * ny, f + off[2] + std::size_t(nz + 1) * ny, 0.0);
      for (int c = 0; c < 4; ++c) yz_inv[c].execute_r2r(f + yz_at[c], f + yz_at[c]);
    }
    if (kx == 0) {  // exact axial mean of u on the free faces (masked ones 0), scaled by 1/nx like the planes
      double* u = F[0] + off[0];
      for (std::size_t i = 0; i < u0_id.size(); ++i)
        if (u0_id[i] >= 0) s.u0b[u0_id[i]] = s.y[i];
      s.u0x = fac.u0llt->solve(s.u0b);
      for (std::size_t i = 0; i < u0_id.size(); ++i) u[i] = u0_id[i] >= 0 ? s.u0x[u0_id[i]] / nx : 0.0;
    }
  }

  const Factors& factors(double alpha) {
    for (int k = 0; k < kCacheSlots; ++k)
      if (!cache[k].chol.empty() && cache[k].alpha == alpha) {
        used_at[k] = ++use_clock;
        factorized_last = false;
        return cache[k];
      }
    if (cyl) return factors_cyl(alpha);
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::vector<double>> chol(static_cast<std::size_t>(nxh));
    parallel_blocks(nxh, threads, [&](long b, long e, int t) {
      for (long kx = b; kx < e; ++kx) {
        const Eigen::MatrixXd C = capacitance(int(kx), alpha, scratch[t]);
        factor_blocks(C, chol[kx], kx, alpha, "duct");
      }
    });
    Factors& f = free_slot();
    f.alpha = alpha;
    f.chol = std::move(chol);
    f.bytes = std::size_t(nxh) * chol_off[4] * sizeof(double);
    factor_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    factorized_last = true;
    return f;
  }

  // Cholesky factors of the symmetry blocks Q_c^T C Q_c, packed into l at chol_off[c].
  void factor_blocks(const Eigen::MatrixXd& C, std::vector<double>& l, long kx, double alpha, const char* what) const {
        l.resize(chol_off[4]);
        for (int cl = 0; cl < 4; ++cl) {
          const int o = cls_off[cl], n = cls_off[cl + 1] - o;
          if (n == 0) continue;
          Eigen::MatrixXd B(n, n);  // Q_c^T C Q_c
          for (int jb = 0; jb < n; ++jb)
            for (int ib = jb; ib < n; ++ib) {
              const SymVec &vi = sym[o + ib], &vj = sym[o + jb];
              double acc = 0.0;
              for (int p = 0; p < vi.n; ++p)
                for (int q = 0; q < vj.n; ++q) acc += vi.w[p] * vj.w[q] * C(vi.node[p], vj.node[q]);
              B(ib, jb) = acc;
            }
          const Eigen::LLT<Eigen::MatrixXd> llt(B);  // reads the lower triangle
          if (llt.info() != Eigen::Success)
            throw NumericalError(
                std::string("capacitance matrix of the ") + what +
                    " Stokes solver is not positive definite for axial mode " + std::to_string(kx) + " (rho/dt = " + std::to_string(alpha) + ")",
                "change the time step or the grid (full3d.grid.cells_across), or use full3d.cylinder_wall = "
                "\"ghost_linear\" (iterative solver)");
          const Eigen::MatrixXd& lm = llt.matrixLLT();  // lower triangle holds L
          double* dst = l.data() + chol_off[cl];
          for (int j = 0; j < n; ++j)
            for (int i = j; i < n; ++i) dst[packed_col(j, n) + std::size_t(i - j)] = lm(i, j);
        }
  }

  // Rotation of the x component of a paired mode into the real frame, q = i e^{i theta/2} u^
  // (dir = +1), and back, u^ = -i e^{-i theta/2} q (dir = -1); re / im: the two planes.
  void rotate(double* re, double* im, int kx, int dir) const {
    const double th2 = kPi * kx / nx, cs = std::cos(th2), sn = std::sin(th2);
    const int n = ny * nz;
    double* ur = re + off[0];
    double* ui = im + off[0];
    if (dir > 0) {
      for (int i = 0; i < n; ++i) {
        const double a = ur[i], b = ui[i];
        ur[i] = -(cs * b + sn * a);
        ui[i] = cs * a - sn * b;
      }
    } else {
      for (int i = 0; i < n; ++i) {
        const double qr = ur[i], qi = ui[i];
        ur[i] = cs * qi - sn * qr;
        ui[i] = -(cs * qr + sn * qi);
      }
    }
  }

  // s.w(:, q) = C^{-1} s.w(:, q), q < np: to the symmetry-adapted basis (s.e: 2 columns of m),
  // the four block solves with the packed factors l, and back.
  void block_solve(const double* l, int np, Scratch& s) const {
    for (int q = 0; q < np; ++q) {
      const double* w = s.w.col(q).data();
      double* e = s.e.data() + std::size_t(q) * m;
      for (int i = 0; i < m; ++i) {
        const SymVec& v = sym[i];
        double acc = 0.0;
        for (int t = 0; t < v.n; ++t) acc += v.w[t] * w[v.node[t]];
        e[i] = acc;
      }
    }
    for (int cl = 0; cl < 4; ++cl) {
      const int o = cls_off[cl], n = cls_off[cl + 1] - o;
      if (n == 0) continue;
      double* const zc[2] = {s.e.data() + o, s.e.data() + m + o};
      cholesky_solve(l + chol_off[cl], n, zc, np);
    }
    for (int q = 0; q < np; ++q) {
      double* w = s.w.col(q).data();
      const double* e = s.e.data() + std::size_t(q) * m;
      std::fill(w, w + m, 0.0);
      for (int i = 0; i < m; ++i) {
        const SymVec& v = sym[i];
        for (int t = 0; t < v.n; ++t) w[v.node[t]] += v.w[t] * e[i];
      }
    }
  }

  // Exact no-slip solve of the axial mean of the x component (plane 0, u part, real space,
  // x-unnormalised) in place: u = (alpha - mu L_ns)^{-1} b, scaled by 1/nx like the planes.
  void solve_mean_x(double* f, double alpha) {
    std::copy_n(f, std::size_t(ny) * nz, u0.data());
    u0_fwd.execute();
    const double scale = 1.0 / (4.0 * ny * nz * nx);
    for (std::size_t i = 0; i < u0_lam.size(); ++i) u0[i] *= scale / (alpha + mu * u0_lam[i]);
    u0_inv.execute();
    std::copy_n(u0.data(), std::size_t(ny) * nz, f);
  }

  // The whole cross-section solve of axial mode kx on its one or two planes.
  void solve_mode(int kx, const Factors& fac, double alpha, Scratch& s) {
    const bool two = paired(kx);
    const int np = two ? 2 : 1;
    double* F[2] = {plane(kx), two ? plane(nx - kx) : nullptr};
    if (kx == 0) std::copy_n(F[0] + off[0], std::size_t(ny) * nz, s.y.data());  // b of the axial mean u
    for (int q = 0; q < np; ++q)
      for (int c = 0; c < 3; ++c) yz_fwd[c].execute_r2r(F[q] + yz_at[c], F[q] + yz_at[c]);
    if (two) rotate(F[0], F[1], kx, +1);
    const double gx = gx_of(kx);
    const double syz = 1.0 / (4.0 * ny * nz), inv_n = syz / nx;
    mode_tables(gx, alpha, s);
    // free-slip solution Y = M T b (in place), and its wall values U^T y
    for (int q = 0; q < np; ++q) {
      apply_M(F[q], F[q], gx, s, 1.0, false);
      wall_values(F[q], s.w.col(q).data(), s);
    }
    // z = C^{-1} U^T y (syz: the normalisation of the inverse transform)
    for (int q = 0; q < np; ++q)
      for (int i = 0; i < m; ++i) s.w(i, q) *= syz;
    // to the symmetry-adapted basis (s.e: 2 columns of m), the four block solves, and back
    block_solve(fac.chol[kx].data(), np, s);
    // X = Y - M T (U z), normalised
    for (int q = 0; q < np; ++q) {
      wall_transform(s.w.col(q).data(), s.r.data(), s);
      apply_M(s.r.data(), F[q], gx, s, inv_n, true);
    }
    if (two) rotate(F[0], F[1], kx, -1);
    for (int q = 0; q < np; ++q) {
      double* f = F[q];
      for (int k = 0; k < nz; ++k) {  // wall faces (not transformed): zero
        f[off[1] + std::size_t(k) * (ny + 1)] = 0.0;
        f[off[1] + std::size_t(k) * (ny + 1) + ny] = 0.0;
      }
      std::fill(f + off[2], f + off[2] + ny, 0.0);
      std::fill(f + off[2] + std::size_t(nz) * ny, f + off[2] + std::size_t(nz + 1) * ny, 0.0);
      for (int c = 0; c < 4; ++c) yz_inv[c].execute_r2r(f + yz_at[c], f + yz_at[c]);
    }
    if (kx == 0) {
      std::copy_n(s.y.data(), std::size_t(ny) * nz, F[0] + off[0]);
      solve_mean_x(F[0] + off[0], alpha);
    }
  }

  // b = beta * un + f (un == nullptr: b = f), fused into the copy into the transform rows.
  // u may alias un: every row is read before any output is written.
  void solve(const VectorField* un, double beta, const VectorField& f, VectorField& u, ScalarField& p,
             double alpha) {
    const Factors& fac = factors(alpha);
    for (int c = 0; c < 3; ++c) u.c[c].resize(grid.size(c));
    p.v.resize(grid.cells());
    // rows [rb, re) of the stacked arrays <-> component arrays
    auto rows_of = [&](long rb, long re, auto&& fn) {
      for (int c = 0; c < 4; ++c) {
        const long lo = std::max<long>(rb, off[c]), hi = std::min<long>(re, off[c + 1]);
        if (lo < hi) fn(c, lo, hi);
      }
    };
    parallel_blocks(off[3], threads, [&](long rb, long re, int t) {
      rows_of(rb, re, [&](int c, long lo, long hi) {
        const std::size_t first = std::size_t(lo - off[c]) * nx, len = std::size_t(hi - lo) * nx;
        double* dst = real.data() + std::size_t(lo) * nx;
        const double* fc = f.c[c].data() + first;
        if (un) {
          const double* uc = un->c[c].data() + first;
          for (std::size_t i = 0; i < len; ++i) dst[i] = beta * uc[i] + fc[i];
        } else {
          std::memcpy(dst, fc, sizeof(double) * len);
        }
      });
      if (cyl)  // masked rows: b ignored (their momentum rows carry the multiplier)
        for (long r = rb; r < re; ++r)
          if (row_masked[r]) std::fill_n(real.data() + std::size_t(r) * nx, nx, 0.0);
      xfwd[t].execute();
    });
    parallel_blocks(nxh, threads, [&](long kb, long ke, int t) {
      for (long kx = kb; kx < ke; ++kx) {
        if (cyl)
          solve_mode_cyl(int(kx), fac, alpha, scratch[t]);
        else
          solve_mode(int(kx), fac, alpha, scratch[t]);
      }
    });
    parallel_blocks(off[4], threads, [&](long rb, long re, int t) {
      xbwd[t].execute();
      rows_of(rb, re, [&](int c, long lo, long hi) {
        double* dst = c < 3 ? u.c[c].data() : p.v.data();
        std::memcpy(dst + std::size_t(lo - off[c]) * nx, real.data() + std::size_t(lo) * nx,
                    sizeof(double) * std::size_t(hi - lo) * nx);
      });
    });
    if (cyl) {
      // masked faces: zero in exact arithmetic (ring: the constraint; outer: the homogeneous
      // outside problem); record their round-off and set them to 0. Pressure: zero mean over
      // the fluid cells, 0 in the others (serial sums: deterministic).
      double res = 0.0;
      for (int c = 0; c < 3; ++c) {
        const auto d = grid.dims(c);
        for (int r = 0; r < d[1] * d[2]; ++r)
          if (row_masked[off[c] + r]) {
            double* x = u.c[c].data() + std::size_t(r) * nx;
            for (int i = 0; i < nx; ++i) res = std::max(res, std::abs(x[i]));
            std::fill_n(x, nx, 0.0);
          }
      }
      mask_residual = res;
      double psum = 0.0;
      std::size_t cnt = 0;
      for (std::size_t cell = 0; cell < cell_fluid.size(); ++cell)
        if (cell_fluid[cell]) {
          for (int i = 0; i < nx; ++i) psum += p.v[cell * nx + i];
          cnt += std::size_t(nx);
        }
      const double pm = cnt ? psum / double(cnt) : 0.0;
      for (std::size_t cell = 0; cell < cell_fluid.size(); ++cell) {
        double* pc = p.v.data() + cell * nx;
        if (cell_fluid[cell])
          for (int i = 0; i < nx; ++i) pc[i] -= pm;
        else
          std::fill_n(pc, nx, 0.0);
      }
      return;
    }
    // the pressure's zero mode is the gauge (0); remove its round-off mean (serial sum: deterministic)
    double sum = 0.0;
    for (double x : p.v) sum += x;
    const double mean = sum / double(p.v.size());
    for (double& x : p.v) x -= mean;
  }
};

CapacitanceStokes::CapacitanceStokes(const MacGrid& g, double mu, int threads, const FftOptions& fft)
    : impl_(std::make_unique<Impl>(g, mu, nullptr, threads, fft)) {}
CapacitanceStokes::CapacitanceStokes(const MacGrid& g, double mu, const CylinderOptions* cylinder, int threads,
                                     const FftOptions& fft)
    : impl_(std::make_unique<Impl>(g, mu, cylinder, threads, fft)) {}

bool CapacitanceStokes::supports_cylinder(const MacGrid& g, const CylinderOptions& cylinder) {
  if (!cylinder_radius_valid(g, cylinder.radius)) return false;
  return cylinder_layout(g, cylinder.radius).wall_nodes_masked;
}

std::size_t CapacitanceStokes::estimate_bytes(const MacGrid& g, const CylinderOptions* cylinder) {
  if (!cylinder) return estimate_bytes(g);
  const std::size_t m = std::size_t(cylinder_layout(g, cylinder->radius).ring);
  // packed dense factors per mode, plus the sparse axial-mean factor (bounded by a band of n)
  const std::size_t cells = std::size_t(g.ny()) * g.nz();
  return std::size_t(g.nx() / 2 + 1) * (m * (m + 1) / 2) * sizeof(double) +
         cells * std::size_t(std::max(g.ny(), g.nz())) * (sizeof(double) + sizeof(int));
}
double CapacitanceStokes::last_mask_residual() const { return impl_->mask_residual; }
CapacitanceStokes::~CapacitanceStokes() = default;
CapacitanceStokes::CapacitanceStokes(CapacitanceStokes&&) noexcept = default;
CapacitanceStokes& CapacitanceStokes::operator=(CapacitanceStokes&&) noexcept = default;

void CapacitanceStokes::solve(const VectorField& b, VectorField& u, ScalarField& p, double alpha) {
  impl_->solve(nullptr, 0.0, b, u, p, alpha);
}
void CapacitanceStokes::step(VectorField& u, const VectorField& f, ScalarField& p, double alpha) {
  impl_->solve(&u, alpha, f, u, p, alpha);
}

std::size_t CapacitanceStokes::estimate_bytes(const MacGrid& g) {
  // four symmetry blocks of at most m/4 + 1 nodes each (an upper bound within a few per cent)
  const std::size_t m = std::size_t(4 * g.ny() + 4 * g.nz() - 8), mb = m / 4 + 1;
  return std::size_t(g.nx() / 2 + 1) * 4 * (mb * (mb + 1) / 2) * sizeof(double);
}
std::size_t CapacitanceStokes::factor_bytes() const {
  std::size_t b = 0;
  for (const auto& f : impl_->cache) b += f.bytes;
  return b;
}
double CapacitanceStokes::last_factorization_seconds() const { return impl_->factor_seconds; }
bool CapacitanceStokes::last_solve_factorized() const { return impl_->factorized_last; }
int CapacitanceStokes::wall_nodes() const { return impl_->m; }
int CapacitanceStokes::threads() const { return impl_->threads; }
int CapacitanceStokes::symmetry_blocks() const { return impl_->cyl && !impl_->sym_ok ? 1 : 4; }

}  // namespace swim::full3d
