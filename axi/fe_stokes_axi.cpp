#include "axi/fe_stokes_axi.hpp"
#include "axi/serial_openmp.hpp"
#include "axi/supernodal_solve.hpp"

#include <dlfcn.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "common/errors.hpp"
#include "common/si_format.hpp"

namespace swim::axi {

namespace {

/// UMFPACK's dense kernels run in the system BLAS. A threaded OpenBLAS (Debian's default
/// provider once installed) spins its worker threads between calls, which on a shared 2-core
/// machine costs more than it gains on these small fronts and fights the other tiers' own
/// threads: the product runs one solve per core and asks any OpenBLAS for one thread. Looked up
/// at run time, so any BLAS provider works.
void single_threaded_blas() {
  static const bool done = [] {
    using SetThreads = void (*)(int);
    if (auto f = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) f(1);
    return true;
  }();
  (void)done;
}

/// CHOLMOD's supernodal factorisation runs OpenMP loops that name their own thread count (4, a
/// constant of Debian's build, CHOLMOD_OMP_NUM_THREADS), which omp_set_num_threads does not
/// override. On these fronts the extra threads mostly spin and wake, and every new thread that
/// calls CHOLMOD starts a pool of its own: one cycle of paper_amplitude_0.82 took 30 s with them
/// and 21 s without at 16 cells, 141 s and 97 s at 32 (docs/performance.md). The product
/// runs one solve per core, so the CHOLMOD calls run their OpenMP regions inline on the calling
/// thread (SerialOpenMp: no team, no barrier, no system call per region) and, should a region
/// reach libgomp all the same, with no active parallel level (max-active-levels 0: a team of the
/// calling thread alone); the caller's settings are put back afterwards. Per thread: a
/// background factorisation sets its own.
class OneOpenMpThread {
 public:
  OneOpenMpThread() : threads_(omp_get_max_threads()), levels_(omp_get_max_active_levels()) {
    omp_set_num_threads(1);
    omp_set_max_active_levels(0);
  }
  ~OneOpenMpThread() {
    omp_set_max_active_levels(levels_);
    omp_set_num_threads(threads_);
  }
  OneOpenMpThread(const OneOpenMpThread&) = delete;
  OneOpenMpThread& operator=(const OneOpenMpThread&) = delete;

 private:
  int threads_, levels_;
  SerialOpenMp inline_;
};

}  // namespace

std::string blas_provider() {
  using Config = char* (*)();
  if (auto f = reinterpret_cast<Config>(dlsym(RTLD_DEFAULT, "openblas_get_config")))
    if (const char* c = f()) return std::string(c).rfind("OpenBLAS", 0) == 0 ? std::string(c) : "OpenBLAS " + std::string(c);
  return "not OpenBLAS (the reference BLAS or another provider)";
}

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr int kLoc = 21;  // 9 nodes x 2 velocity components + 3 pressure coefficients

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// An n x n column-compressed pattern with zero values from `count` entries in column order (then
/// row order within a column); colrow(k) gives entry k's (column, row).
template <class ColRow>
void sorted_pattern(Eigen::SparseMatrix<double, Eigen::ColMajor, int>& M, int n, std::size_t count, ColRow colrow) {
  M.resize(n, n);
  M.resizeNonZeros(Eigen::Index(count));
  int* outer = M.outerIndexPtr();
  int* inner = M.innerIndexPtr();
  std::fill(outer, outer + n + 1, 0);
  for (std::size_t k = 0; k < count; ++k) {
    const auto [c, r] = colrow(k);
    ++outer[c + 1];
    inner[k] = r;
  }
  for (int c = 0; c < n; ++c) outer[c + 1] += outer[c];
  std::fill(M.valuePtr(), M.valuePtr() + count, 0.0);
}

// 1D quadratic Lagrange basis on the nodes -1, 0, 1 and its derivative.
inline double lag(int i, double t) {
  switch (i) {
    case 0: return 0.5 * t * (t - 1.0);
    case 1: return 1.0 - t * t;
    default: return 0.5 * t * (t + 1.0);
  }
}
inline double dlag(int i, double t) {
  switch (i) {
    case 0: return t - 0.5;
    case 1: return -2.0 * t;
    default: return t + 0.5;
  }
}

// 3-point Gauss-Legendre on [-1, 1].
constexpr double kG = 0.7745966692414834;  // sqrt(3/5)
constexpr double kGp[3] = {-kG, 0.0, kG};
constexpr double kGw[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};

// Reference tables at the 9 quadrature points q = 3 qb + qa (qa along xi): Q2 shape functions
// (local node a = 3 b + i, i along xi) and their reference derivatives.
struct RefTables {
  double N[9][9], Nxi[9][9], Neta[9][9], w[9], xi[9], eta[9];
  RefTables() {
    for (int qb = 0; qb < 3; ++qb)
      for (int qa = 0; qa < 3; ++qa) {
        const int q = 3 * qb + qa;
        xi[q] = kGp[qa];
        eta[q] = kGp[qb];
        w[q] = kGw[qa] * kGw[qb];
        for (int b = 0; b < 3; ++b)
          for (int i = 0; i < 3; ++i) {
            const int a = 3 * b + i;
            N[q][a] = lag(i, xi[q]) * lag(b, eta[q]);
            Nxi[q][a] = dlag(i, xi[q]) * lag(b, eta[q]);
            Neta[q][a] = lag(i, xi[q]) * dlag(b, eta[q]);
          }
      }
  }
};
const RefTables& ref() {
  static const RefTables t;
  return t;
}

// The P2+ triangle (Crouzeix-Raviart): P2 enriched by the cubic bubble B = 27 l0 l1 l2, in its
// nodal (Lagrange) basis on the vertices, the edges' midpoints and the centroid, at the 7 points
// of Radon's degree-5 rule (slots 7, 8 and points 7, 8 unused: zero weight and zero functions).
// With lambda = (1 - xi - eta, xi, eta): vertex i: l_i (2 l_i - 1) + 3 l0 l1 l2; edge (i, j):
// 4 l_i l_j - 12 l0 l1 l2; centroid: 27 l0 l1 l2.
void p2plus(double xi, double eta, double N[9], double Nxi[9], double Neta[9]) {
  const double l[3] = {1.0 - xi - eta, xi, eta};
  const double dxi[3] = {-1.0, 1.0, 0.0}, deta[3] = {-1.0, 0.0, 1.0};
  const double b = l[0] * l[1] * l[2];
  const double bxi = dxi[0] * l[1] * l[2] + l[0] * dxi[1] * l[2] + l[0] * l[1] * dxi[2];
  const double beta = deta[0] * l[1] * l[2] + l[0] * deta[1] * l[2] + l[0] * l[1] * deta[2];
  for (int i = 0; i < 3; ++i) {
    N[i] = l[i] * (2.0 * l[i] - 1.0) + 3.0 * b;
    Nxi[i] = (4.0 * l[i] - 1.0) * dxi[i] + 3.0 * bxi;
    Neta[i] = (4.0 * l[i] - 1.0) * deta[i] + 3.0 * beta;
    const int j = (i + 1) % 3;
    N[3 + i] = 4.0 * l[i] * l[j] - 12.0 * b;
    Nxi[3 + i] = 4.0 * (dxi[i] * l[j] + l[i] * dxi[j]) - 12.0 * bxi;
    Neta[3 + i] = 4.0 * (deta[i] * l[j] + l[i] * deta[j]) - 12.0 * beta;
  }
  N[6] = 27.0 * b;
  Nxi[6] = 27.0 * bxi;
  Neta[6] = 27.0 * beta;
  N[7] = N[8] = Nxi[7] = Nxi[8] = Neta[7] = Neta[8] = 0.0;
}

struct TriTables {
  double N[9][9], Nxi[9][9], Neta[9][9], w[9], xi[9], eta[9];
  TriTables() {
    const double s = std::sqrt(15.0);
    const double a1 = (6.0 - s) / 21.0, b1 = (9.0 + 2.0 * s) / 21.0, w1 = (155.0 - s) / 2400.0;
    const double a2 = (6.0 + s) / 21.0, b2 = (9.0 - 2.0 * s) / 21.0, w2 = (155.0 + s) / 2400.0;
    const double px[7] = {1.0 / 3.0, a1, b1, a1, a2, b2, a2}, pe[7] = {1.0 / 3.0, a1, a1, b1, a2, a2, b2};
    const double pw[7] = {9.0 / 80.0, w1, w1, w1, w2, w2, w2};
    for (int q = 0; q < 9; ++q) {
      xi[q] = q < 7 ? px[q] : 1.0 / 3.0;
      eta[q] = q < 7 ? pe[q] : 1.0 / 3.0;
      w[q] = q < 7 ? pw[q] : 0.0;
      if (q < 7)
        p2plus(xi[q], eta[q], N[q], Nxi[q], Neta[q]);
      else
        for (int a = 0; a < 9; ++a) N[q][a] = Nxi[q][a] = Neta[q][a] = 0.0;
    }
  }
};
const TriTables& tri_ref() {
  static const TriTables t;
  return t;
}

// The pressure basis's centre and scales on a triangle: its centroid and sqrt(2 area), about
// its edges' length on a shape-regular triangle.
void triangle_pressure_scales(const double cx[4], const double cr[4], double& xc, double& rc, double& hx,
                              double& hr) {
  xc = (cx[0] + cx[1] + cx[2]) / 3.0;
  rc = (cr[0] + cr[1] + cr[2]) / 3.0;
  hx = hr = std::sqrt(std::abs((cx[1] - cx[0]) * (cr[2] - cr[0]) - (cx[2] - cx[0]) * (cr[1] - cr[0])));
}

// Centre and scales of an element's pressure basis {1, (x - xc)/hx, (r - rc)/hr}: the mean of
// its corners, the mean length of its two xi-edges and its mean eta-extent. Positive for any
// valid element, whatever the tilt of its sides; on an element with vertical sides hx is its
// width when the top and bottom edges are level. The scaling does not change the pressure space.
void pressure_scales(const double cx[4], const double cr[4], double& xc, double& rc, double& hx, double& hr) {
  xc = 0.25 * (cx[0] + cx[1] + cx[2] + cx[3]);
  rc = 0.25 * (cr[0] + cr[1] + cr[2] + cr[3]);
  const bool vertical = cx[0] == cx[3] && cx[1] == cx[2];
  if (vertical) {  // the vertical-line mesh: its width and mean height
    hx = cx[1] - cx[0];
    hr = 0.5 * ((cr[3] - cr[0]) + (cr[2] - cr[1]));
    return;
  }
  hx = 0.5 * (std::hypot(cx[1] - cx[0], cr[1] - cr[0]) + std::hypot(cx[2] - cx[3], cr[2] - cr[3]));
  hr = 0.5 * (std::hypot(cx[3] - cx[0], cr[3] - cr[0]) + std::hypot(cx[2] - cx[1], cr[2] - cr[1]));
}

}  // namespace

// Per-element quadrature data: physical gradients of the 9 Q2 shape functions, position and
// weight (2 pi w_q det J, without the r of the volume measure) at each of the 9 points.
struct FittedStokes::Geometry {
  Eigen::Matrix<double, 9, 9> N, gx, gr;  // (point, shape function)
  double x[9], r[9], wdet[9];
  double xc, rc, hx, hr;                  // pressure basis centre and scales
};

void FittedStokes::element_geometry(int e, Geometry& g) const {
  double cx[4], cr[4];
  mesh_->corners(e, cx, cr);
  if (triangles_) {  // the affine map of the reference triangle (0,0), (1,0), (0,1)
    const TriTables& T = tri_ref();
    triangle_pressure_scales(cx, cr, g.xc, g.rc, g.hx, g.hr);
    const double xx = cx[1] - cx[0], xe = cx[2] - cx[0], rx = cr[1] - cr[0], re = cr[2] - cr[0];
    const double det = xx * re - xe * rx, inv = 1.0 / det;
    for (int q = 0; q < 9; ++q) {
      const double xi = T.xi[q], eta = T.eta[q];
      g.x[q] = cx[0] + xx * xi + xe * eta;
      g.r[q] = cr[0] + rx * xi + re * eta;
      g.wdet[q] = kTwoPi * T.w[q] * det;
      for (int a = 0; a < 9; ++a) {
        g.N(q, a) = T.N[q][a];
        g.gx(q, a) = (re * T.Nxi[q][a] - rx * T.Neta[q][a]) * inv;
        g.gr(q, a) = (-xe * T.Nxi[q][a] + xx * T.Neta[q][a]) * inv;
      }
    }
    return;
  }
  const RefTables& T = ref();
  pressure_scales(cx, cr, g.xc, g.rc, g.hx, g.hr);
  for (int q = 0; q < 9; ++q) {
    const double xi = T.xi[q], eta = T.eta[q];
    const BilinearPoint b = bilinear_map(cx, cr, xi, eta);
    const double x = b.x, r = b.r, xx = b.xx, xe = b.xe, rx = b.rx, re = b.re;
    const double det = xx * re - xe * rx, inv = 1.0 / det;
    g.x[q] = x;
    g.r[q] = r;
    g.wdet[q] = kTwoPi * T.w[q] * det;
    for (int a = 0; a < 9; ++a) {
      g.N(q, a) = T.N[q][a];
      g.gx(q, a) = (re * T.Nxi[q][a] - rx * T.Neta[q][a]) * inv;
      g.gr(q, a) = (-xe * T.Nxi[q][a] + xx * T.Neta[q][a]) * inv;
    }
  }
}

FittedStokes::FittedStokes(const FittedMeshParams& p, double mu, int membrane_nodes, Coupling coupling)
    : FittedStokes(std::make_unique<FittedMesh>(p, membrane_nodes), mu, coupling) {}

FittedStokes::FittedStokes(std::unique_ptr<MeridianMesh> mesh, double mu, Coupling coupling)
    : mesh_(std::move(mesh)), mu_(mu), coupling_(coupling) {
  single_threaded_blas();
  if (!mesh_) throw std::invalid_argument("FittedStokes: no mesh");
  if (!(std::isfinite(mu) && mu > 0))
    throw InputError("fluid.viscosity", significant(mu) + " Pa s", "must be a positive finite viscosity");
  lref_ = mesh_->length_scale();
  triangles_ = mesh_->element_shape() == ElementShape::triangle;
  ps_ = mu_ / lref_;
  const int membrane_nodes = mesh_->membrane_nodes();
  const bool closed = mesh_->closed();

  // Velocity DOFs, node-major: u_x except on the container wall, u_r except on the axis and the
  // container wall.
  const int nodes = mesh_->nodes();
  dof_x_.assign(nodes, -1);
  dof_r_.assign(nodes, -1);
  int d = 0;
  for (int nd = 0; nd < nodes; ++nd) {
    const NodeKind kind = mesh_->node_kind(nd);
    if (kind != NodeKind::container) dof_x_[nd] = d++;
    if (kind == NodeKind::interior) dof_r_[nd] = d++;
  }
  n_vel_ = d;
  const int E = mesh_->elements();
  n_ = n_vel_ + 3 * E - 1;  // element 0's constant pressure is pinned

  loc_.assign(std::size_t(E) * kLoc, -1);
  for (int e = 0; e < E; ++e) {
    int* L = &loc_[std::size_t(e) * kLoc];
    for (int a = 0; a < 9; ++a) {
      const int nd = mesh_->element_slot(e, a);
      if (nd < 0) continue;  // a triangle's unused slots
      L[2 * a] = dof_x_[nd];
      L[2 * a + 1] = dof_r_[nd];
    }
    for (int q = 0; q < 3; ++q) L[18 + q] = (e == 0 && q == 0) ? -1 : n_vel_ + 3 * e + q - 1;
  }

  // Pattern: every (row, col) pair of an element except pressure-pressure, plus the membrane
  // vertex pairs up to 2 apart. Keys col * n + row, sorted: column-major order.
  std::vector<std::int64_t> keys;
  keys.reserve(std::size_t(E) * (kLoc * kLoc - 9) + std::size_t(membrane_nodes) * 20);
  for (int e = 0; e < E; ++e) {
    const int* L = &loc_[std::size_t(e) * kLoc];
    for (int j = 0; j < kLoc; ++j) {
      if (L[j] < 0) continue;
      for (int i = 0; i < kLoc; ++i)
        if (L[i] >= 0 && (i < 18 || j < 18)) keys.push_back(std::int64_t(L[j]) * n_ + L[i]);
    }
  }
  // Transfer stencils of the membrane vertices (slots V_{k-1}, M_{k-1/2}, V_k, M_{k+1/2}, V_{k+1}).
  const int nm = membrane_nodes;
  gnode_.assign(nm, {-1, -1, -1, -1, -1});
  gw_.assign(nm, {0, 0, 0, 0, 0});
  for (int k = 0; k < nm; ++k) {
    auto& g = gnode_[k];
    g[2] = mesh_->wall_node(k);
    if (coupling_ == Coupling::vertex) continue;
    if (k > 0 || closed) {
      const int km = (k + nm - 1) % nm;
      g[0] = mesh_->wall_node(km);
      g[1] = mesh_->wall_midside_node(km);
    }
    if (k < nm - 1 || closed) {
      g[3] = mesh_->wall_midside_node(k);
      g[4] = mesh_->wall_node((k + 1) % nm);
    }
  }
  // The stiffness couplings dt G K G^T: trace nodes of vertices up to 2 apart.
  for (int k = 0; k < nm; ++k)
    for (int dk = -2; dk <= 2; ++dk) {
      int l = k + dk;
      if (closed)
        l = ((l % nm) + nm) % nm;
      else if (l < 0 || l >= nm)
        continue;
      for (int nk : gnode_[k])
        for (int nl : gnode_[l]) {
          if (nk < 0 || nl < 0) continue;
          const int rk[2] = {dof_x_[nk], dof_r_[nk]}, rl[2] = {dof_x_[nl], dof_r_[nl]};
          for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) keys.push_back(std::int64_t(rl[b]) * n_ + rk[a]);
        }
    }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());

  sorted_pattern(A_, n_, keys.size(), [&](std::size_t k) { return std::pair{int(keys[k] / n_), int(keys[k] % n_)}; });
  keys.clear();
  keys.shrink_to_fit();

  pos_.assign(std::size_t(E) * kLoc * kLoc, -1);
  for (int e = 0; e < E; ++e) {
    const int* L = &loc_[std::size_t(e) * kLoc];
    int* P = &pos_[std::size_t(e) * kLoc * kLoc];
    for (int i = 0; i < kLoc; ++i)
      for (int j = 0; j < kLoc; ++j)
        if (L[i] >= 0 && L[j] >= 0 && (i < 18 || j < 18)) P[i * kLoc + j] = find_position(L[i], L[j]);
  }

  // per column, the first entry on or below the diagonal (rows are sorted within a column)
  lower_begin_.resize(std::size_t(n_));
  for (int c = 0; c < n_; ++c) {
    const int* b = A_.innerIndexPtr() + A_.outerIndexPtr()[c];
    const int* e = A_.innerIndexPtr() + A_.outerIndexPtr()[c + 1];
    lower_begin_[std::size_t(c)] = int(std::lower_bound(b, e, c) - A_.innerIndexPtr());
  }

  lu_ = new_lu();
  chol_.factor = new_cholesky();
  spare_.factor = new_cholesky();
  build_schur_pattern();
  rhs_.setZero(n_);
  sol_.setZero(n_);
}

void FittedStokes::build_schur_pattern() {
  // S's pattern is A_'s velocity block: the penalty B^T B / e couples the velocities of one
  // element (a pressure unknown's column holds its element's velocity rows), which A_ couples.
  const int* outer = A_.outerIndexPtr();
  const int* inner = A_.innerIndexPtr();
  // S's pattern (both triangles, S's own order), per entry its entry in A_, and per pair of
  // entries of each pressure column of A_ the entry of S it adds to: what P S P^T's maps are
  // made from (below)
  std::vector<int> schur_src, pen_pos;
  std::vector<int> souter(n_vel_ + 1, 0), sinner;
  for (int c = 0; c < n_vel_; ++c) {
    for (int q = outer[c]; q < outer[c + 1]; ++q)
      if (inner[q] < n_vel_) {
        sinner.push_back(inner[q]);
        schur_src.push_back(q);
      }
    souter[c + 1] = int(sinner.size());
  }
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> schur(n_vel_, n_vel_);
  schur.resizeNonZeros(Eigen::Index(sinner.size()));
  std::copy(souter.begin(), souter.end(), schur.outerIndexPtr());
  std::copy(sinner.begin(), sinner.end(), schur.innerIndexPtr());
  std::fill(schur.valuePtr(), schur.valuePtr() + sinner.size(), 0.0);
  auto position = [&](int row, int col) {
    const int* b = sinner.data() + souter[col];
    const int* e = sinner.data() + souter[col + 1];
    const int* it = std::lower_bound(b, e, row);
    if (it == e || *it != row)
      throw std::logic_error("FittedStokes: a pressure unknown couples velocities its element does not");
    return int(it - sinner.data());
  };
  for (int c = n_vel_; c < n_; ++c)
    for (int a = outer[c]; a < outer[c + 1]; ++a)
      if (inner[a] >= n_vel_) throw std::logic_error("FittedStokes: pressure unknowns coupled to each other");
  // per element, its velocity unknowns' pairs (the pressure columns hold their own element's
  // velocity rows only)
  pen_nv_ = triangles_ ? 14 : 18;
  const int E = mesh_->elements();
  pen_pos.assign(std::size_t(E) * pen_nv_ * pen_nv_, -1);
  for (int e = 0; e < E; ++e) {
    const int* L = &loc_[std::size_t(e) * kLoc];
    int* Q = &pen_pos[std::size_t(e) * pen_nv_ * pen_nv_];
    for (int k = 0; k < 3; ++k)
      if (L[18 + k] >= 0)
        for (int i = pen_nv_; i < 18; ++i)
          if (L[i] >= 0)
            throw std::logic_error("FittedStokes: a triangle's pressure couples an unused velocity slot");
    for (int i = 0; i < pen_nv_; ++i)
      for (int j = 0; j < pen_nv_; ++j)
        if (L[i] >= 0 && L[j] >= 0) Q[i * pen_nv_ + j] = position(L[i], L[j]);
  }
  chol_.bval.assign(std::size_t(A_.nonZeros() - outer[n_vel_]), 0.0);
  spare_.bval = chol_.bval;

  // The factored matrix is P S P^T, stored by its lower triangle, with P the fill-reducing
  // ordering CHOLMOD chooses for S (AMD, postordered), found once here. Factored with the natural
  // ordering, a lower triangle goes to CHOLMOD's supernodal kernels as it is: given S's lower
  // triangle in its own order, each factorisation first built the permuted transpose (a
  // 1.4-million-entry copy and its allocation at 32 cells across: about a third of the worker's
  // time), and given P S P^T's upper triangle, its transpose. Each value of S is written
  // straight into its place in P S P^T (lo_src_, lo_pen_pos_); S's upper triangle is not stored.
  {
    Cholesky probe;
    probe.cholmod().print = 0;
    probe.analyzePattern(schur);
    if (probe.info() != Eigen::Success || probe.factor() == nullptr)
      throw NumericalError("the symbolic analysis of the fitted Stokes system's Cholesky failed (CHOLMOD)",
                           "use fewer cells (axi.fitted.cells_inner, axi.fitted.cells_outer, axi.fitted.gap_columns)");
    const int* pp = static_cast<const int*>(probe.factor()->Perm);
    perm_.assign(pp, pp + n_vel_);
  }
  std::vector<int> pinv(static_cast<std::size_t>(n_vel_));
  for (int k = 0; k < n_vel_; ++k) pinv[std::size_t(perm_[std::size_t(k)])] = k;
  // the lower entries of S (row >= column) as (column, row) of P S P^T's lower triangle
  std::vector<std::array<int, 3>> entries;  // (new column, new row, entry of S)
  for (int c = 0; c < n_vel_; ++c)
    for (int q = souter[c]; q < souter[c + 1]; ++q) {
      const int r = sinner[std::size_t(q)];
      if (r < c) continue;
      const int a = pinv[std::size_t(r)], b = pinv[std::size_t(c)];
      entries.push_back({std::min(a, b), std::max(a, b), q});
    }
  std::sort(entries.begin(), entries.end());
  sorted_pattern(schur_lo_, n_vel_, entries.size(),
                 [&](std::size_t k) { return std::pair{entries[k][0], entries[k][1]}; });
  std::vector<int> lo_of(sinner.size(), -1);  // entry of S -> entry of P S P^T (-1: S's upper triangle)
  for (std::size_t k = 0; k < entries.size(); ++k) lo_of[std::size_t(entries[k][2])] = int(k);
  lo_src_.assign(entries.size(), -1);
  for (std::size_t k = 0; k < schur_src.size(); ++k)
    if (lo_of[k] >= 0) lo_src_[std::size_t(lo_of[k])] = schur_src[k];
  lo_pen_pos_.resize(pen_pos.size());
  for (std::size_t k = 0; k < pen_pos.size(); ++k)
    lo_pen_pos_[k] = pen_pos[k] >= 0 ? lo_of[std::size_t(pen_pos[k])] : -1;
}

const FittedMesh& FittedStokes::mesh() const {
  const auto* m = dynamic_cast<const FittedMesh*>(mesh_.get());
  if (!m) throw std::logic_error("FittedStokes::mesh: the solver's mesh is not the structured one");
  return *m;
}

FittedStokes::~FittedStokes() {
  if (worker_.joinable()) worker_.join();
}

int FittedStokes::find_position(int row, int col) const {
  const int* inner = A_.innerIndexPtr();
  const int* b = inner + A_.outerIndexPtr()[col];
  const int* e = inner + A_.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(b, e, row);
  return (it != e && *it == row) ? int(it - inner) : -1;
}

void FittedStokes::transfer_weights() {
  const int nm = mesh_->membrane_nodes();
  for (auto& w : gw_) w = {0, 0, 0, 0, 0};
  if (coupling_ == Coupling::vertex) {
    for (auto& w : gw_) w[2] = 1.0;
    return;
  }
  // G_{a,k} = int phi_k N_a dA / A_k over the membrane edges (2 pi r ds; the integrand is a
  // polynomial of degree 4 in the edge parameter: 3-point Gauss is exact).
  const bool closed = mesh_->closed();
  std::vector<double> area(nm, 0.0);
  const int edges = closed ? nm : nm - 1;
  for (int k = 0; k < edges; ++k) {
    const int l = (k + 1) % nm;
    // the wall's rings in the fitted mesh (point k + 1 = ring l, + P when wrapped)
    const Eigen::Vector2d wk = mesh_->wall_point(k), wl = mesh_->wall_point(k + 1);
    const double dx = wl.x() - wk.x();
    const double r0 = wk.y(), r1 = wl.y();
    const double len = std::hypot(dx, r1 - r0);
    for (int q = 0; q < 3; ++q) {
      const double t = kGp[q], r = 0.5 * (r0 * (1 - t) + r1 * (1 + t));
      const double w = kGw[q] * kTwoPi * r * 0.5 * len;
      const double pk = 0.5 * (1 - t), pl = 0.5 * (1 + t);
      area[k] += w * pk;
      area[l] += w * pl;
      for (int m = 0; m < 3; ++m) {
        gw_[k][2 + m] += w * pk * lag(m, t);  // V_k, M_{k+1/2}, V_{k+1} seen from k
        gw_[l][m] += w * pl * lag(m, t);      // V_k, M_{k+1/2}, V_{k+1} seen from l = k+1
      }
    }
  }
  for (int k = 0; k < nm; ++k)
    for (double& w : gw_[k]) w /= area[k];
}

void FittedStokes::assemble(const Eigen::SparseMatrix<double>* K, double scale) {
  double* val = A_.valuePtr();
  std::fill(val, val + A_.nonZeros(), 0.0);
  const int E = mesh_->elements();
  Geometry g;
  // One element with np quadrature points and nf shape functions (Q2: 9 and 9; the P2+ triangle:
  // 7 and 7, the last two slots of Geometry unused). A = G^T diag(w) G sums over the points as
  // nf x nf products (G: point by shape function), the pressure couplings as C^T (...) with C the
  // points' weighted pressure basis. The products are coefficient-based: Eigen sends fixed
  // products of these sizes (np + 2 nf >= its threshold of 20) through its general matrix-matrix
  // kernel, whose packing and blocking cost more than the multiply-adds themselves.
  auto element = [&]<int np, int nf>(int e) {
    element_geometry(e, g);
    const auto N = g.N.topLeftCorner<np, nf>();
    const auto gx = g.gx.topLeftCorner<np, nf>();
    const auto gr = g.gr.topLeftCorner<np, nf>();
    Eigen::Matrix<double, np, nf> Wgx, Wgr, WN, rgx, rgrN;
    Eigen::Matrix<double, np, 3> C;
    for (int q = 0; q < np; ++q) {
      const double r = g.r[q], W = mu_ * g.wdet[q] * r;
      Wgx.row(q) = W * gx.row(q);
      Wgr.row(q) = W * gr.row(q);
      WN.row(q) = (2.0 * mu_ * g.wdet[q] / r) * N.row(q);
      rgx.row(q) = r * gx.row(q);
      rgrN.row(q) = r * gr.row(q) + N.row(q);
      const double c = -ps_ * g.wdet[q];
      C(q, 0) = c;
      C(q, 1) = c * (g.x[q] - g.xc) / g.hx;
      C(q, 2) = c * (g.r[q] - g.rc) / g.hr;
    }
    Eigen::Matrix<double, nf, nf> Axx, Arr, Axr;
    Eigen::Matrix<double, 3, nf> Bx, Br;
    Axx.noalias() = 2.0 * gx.transpose().lazyProduct(Wgx) + gr.transpose().lazyProduct(Wgr);
    Arr.noalias() = 2.0 * gr.transpose().lazyProduct(Wgr) + gx.transpose().lazyProduct(Wgx);
    Arr.noalias() += N.transpose().lazyProduct(WN);
    Axr.noalias() = gr.transpose().lazyProduct(Wgx);
    Bx.noalias() = C.transpose().lazyProduct(rgx);
    Br.noalias() = C.transpose().lazyProduct(rgrN);
    const int* P = &pos_[std::size_t(e) * kLoc * kLoc];
    auto add = [&](int i, int j, double v) {
      const int p = P[i * kLoc + j];
      if (p >= 0) val[p] += v;
    };
    for (int a = 0; a < nf; ++a)
      for (int b = 0; b < nf; ++b) {
        add(2 * a, 2 * b, Axx(a, b));
        add(2 * a + 1, 2 * b + 1, Arr(a, b));
        add(2 * a, 2 * b + 1, Axr(a, b));
        add(2 * b + 1, 2 * a, Axr(a, b));
      }
    for (int k = 0; k < 3; ++k)
      for (int b = 0; b < nf; ++b) {
        add(18 + k, 2 * b, Bx(k, b));
        add(2 * b, 18 + k, Bx(k, b));
        add(18 + k, 2 * b + 1, Br(k, b));
        add(2 * b + 1, 18 + k, Br(k, b));
      }
  };
  if (triangles_)
    for (int e = 0; e < E; ++e) element.template operator()<7, 7>(e);
  else
    for (int e = 0; e < E; ++e) element.template operator()<9, 9>(e);
  if (K && scale != 0.0) {
    const int nm = mesh_->membrane_nodes();
    for (int c = 0; c < K->outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(*K, c); it; ++it) {
        if (it.value() == 0.0) continue;
        const int i = int(it.row()), j = int(it.col()), k = i / 2, l = j / 2;
        int d = std::abs(k - l);
        if (mesh_->closed()) d = std::min(d, nm - d);
        if (d > 2)
          throw std::invalid_argument("FittedStokes::factor: K couples membrane vertices " + std::to_string(k) +
                                      " and " + std::to_string(l) + " (more than 2 apart, n = " +
                                      std::to_string(nm) + ")");
        for (int s = 0; s < 5; ++s) {
          const int ns = gnode_[k][s];
          if (ns < 0) continue;
          const int gi = (i % 2 == 0) ? dof_x_[ns] : dof_r_[ns];
          for (int t = 0; t < 5; ++t) {
            const int nt = gnode_[l][t];
            if (nt < 0) continue;
            const int gj = (j % 2 == 0) ? dof_x_[nt] : dof_r_[nt];
            val[find_position(gi, gj)] += scale * it.value() * gw_[k][s] * gw_[l][t];
          }
        }
      }
  }
}

void FittedStokes::set_reuse(bool on, int refactor_after, double tolerance) {
  if (refactor_after < 0) throw std::invalid_argument("FittedStokes::set_reuse: refactor_after must be >= 0");
  if (!(tolerance > 0.0 && tolerance < 1.0))
    throw std::invalid_argument("FittedStokes::set_reuse: tolerance must be in (0, 1)");
  if (!on) join_background(true);
  reuse_ = on;
  refactor_after_ = refactor_after;
  tol_ = tolerance;
}

std::unique_ptr<Eigen::UmfPackLU<Eigen::SparseMatrix<double, Eigen::ColMajor, int>>> FittedStokes::new_lu() {
  auto lu = std::make_unique<Eigen::UmfPackLU<Eigen::SparseMatrix<double, Eigen::ColMajor, int>>>();
  // One step of iterative refinement (UMFPACK's default allows two): without it the
  // threshold-pivoted LU of the saddle-point system leaves relative errors near 1e-9; one step
  // brings them to round-off at the cost of one more solve and residual.
  lu->umfpackControl()(UMFPACK_IRSTEP) = 1;
  return lu;
}

std::unique_ptr<FittedStokes::Cholesky> FittedStokes::new_cholesky() {
  auto f = std::make_unique<Cholesky>();
  f->cholmod().print = 0;  // failures are reported through info(), not printed
  return f;
}

void FittedStokes::give_up_cholesky() {
  use_chol_ = false;
  ++fallbacks_;
}

std::string FittedStokes::preconditioner() const { return use_chol_ ? "Cholesky (CHOLMOD)" : "LU (UMFPACK)"; }

void FittedStokes::set_background_factorisation(bool on) {
  if (!on) join_background(true);
  background_ = on;
}

void FittedStokes::forget_factorisation() {
  join_background(false);
  analysed_ = lu_valid_ = lu_current_ = false;
  last_iters_ = 0;
  lu_ = new_lu();
  for (CholeskySlot* c : {&chol_, &spare_}) {
    c->factor = new_cholesky();
    c->analysed = false;
  }
  pc_chol_ = false;
  use_chol_ = true;
  for (Eigen::VectorXd& g : guess_) g.resize(0);
}

bool FittedStokes::factor_into(CholeskySlot& slot) const {
  double d = 0.0;  // the velocity block's largest diagonal entry (lower_begin_: its position)
  {
    const int* outer = A_.outerIndexPtr();
    const int* inner = A_.innerIndexPtr();
    const double* av = A_.valuePtr();
    for (int c = 0; c < n_vel_; ++c)
      if (const int q = lower_begin_[std::size_t(c)]; q < outer[c + 1] && inner[q] == c) d = std::max(d, std::abs(av[q]));
  }
  if (!(d > 0.0 && std::isfinite(d))) return false;
  // S = A_vv + B^T B / e on its fixed pattern; the factored B kept for the applications
  slot.pen = kPressureRegularisation * d;
  const double inv = 1.0 / slot.pen;
  const double* av = A_.valuePtr();
  const int* outer = A_.outerIndexPtr();
  double* sv = schur_lo_.valuePtr();
  for (std::size_t k = 0; k < lo_src_.size(); ++k) sv[k] = av[lo_src_[k]];
  // B^T B / e element by element: the element's rows of B (its three pressure columns of A_,
  // through the assembly's positions), then their dense outer products summed, one scattered
  // add per pair of its velocity unknowns instead of one per pair and pressure unknown
  const int E = mesh_->elements(), nv = pen_nv_;
  for (int e = 0; e < E; ++e) {
    const int* P = &pos_[std::size_t(e) * kLoc * kLoc];
    const int* Q = &lo_pen_pos_[std::size_t(e) * nv * nv];
    double c[3][18];
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < nv; ++i) {
        const int p = P[i * kLoc + 18 + k];
        c[k][i] = p >= 0 ? av[p] : 0.0;
      }
    for (int i = 0; i < nv; ++i) {
      const double b0 = c[0][i] * inv, b1 = c[1][i] * inv, b2 = c[2][i] * inv;
      for (int j = 0; j < nv; ++j)
        if (const int q = Q[i * nv + j]; q >= 0) sv[q] += b0 * c[0][j] + b1 * c[1][j] + b2 * c[2][j];
    }
  }
  std::copy(av + outer[n_vel_], av + outer[n_], slot.bval.begin());
  const OneOpenMpThread one;  // per thread: the worker's own setting
  if (!slot.analysed) {
    // P S P^T is already in the fill-reducing order: the natural ordering, not postordered again
    cholmod_common& cm = slot.factor->cholmod();
    cm.nmethods = 1;
    cm.method[0].ordering = CHOLMOD_NATURAL;
    cm.postorder = 0;
    slot.factor->analyzePattern(schur_lo_);
    slot.analysed = slot.factor->info() == Eigen::Success;
    if (!slot.analysed) return false;
  }
  slot.factor->factorize(schur_lo_);
  return slot.factor->info() == Eigen::Success;
}

bool FittedStokes::cholesky_factor() {
  join_background(false);  // a pending one would be of this system too: factored here instead
  const auto t0 = Clock::now();
  lu_valid_ = lu_current_ = pc_chol_ = false;
  const bool ok = factor_into(chol_);
  timing_.factor += seconds_since(t0);
  if (!ok) {
    give_up_cholesky();
    return false;
  }
  ++timing_.factorisations;
  lu_valid_ = lu_current_ = pc_chol_ = true;
  last_iters_ = 0;
  return true;
}

void FittedStokes::launch_background() {
  worker_ok_ = false;
  worker_seconds_ = 0.0;
  worker_ = std::thread([this] {
    const auto t0 = Clock::now();
    bool ok = false;
    try {
      ok = factor_into(spare_);
    } catch (...) {  // out of memory in CHOLMOD or Eigen: reported as a failed factorisation
      ok = false;
    }
    worker_ok_ = ok;
    worker_seconds_ = seconds_since(t0);
  });
}

bool FittedStokes::join_background(bool install) {
  if (!worker_.joinable()) return false;
  const auto t0 = Clock::now();
  worker_.join();
  timing_.factor += seconds_since(t0);
  timing_.factor_background += worker_seconds_;
  ++timing_.factorisations;
  if (!install) return false;
  if (!worker_ok_) {  // S not positive definite: UMFPACK's LU from the next factorisation on
    give_up_cholesky();
    lu_valid_ = lu_current_ = pc_chol_ = false;
    return false;
  }
  std::swap(chol_, spare_);
  lu_valid_ = lu_current_ = pc_chol_ = true;  // of the current A_ until the next assembly
  last_iters_ = 0;
  return true;
}

void FittedStokes::refactor_now() {
  if (worker_.joinable() && join_background(true)) return;
  numeric_factor(true);
}

Eigen::VectorXd FittedStokes::cholesky_apply(const Eigen::VectorXd& v) const {
  // the factored system's B: A_'s pressure columns (its pattern) with the values kept in bval_
  const int* outer = A_.outerIndexPtr();
  const int* inner = A_.innerIndexPtr();
  const int q0 = outer[n_vel_];
  const double pen = chol_.pen;
  const std::vector<double>& bval = chol_.bval;
  Eigen::VectorXd f = v.head(n_vel_);
  for (int c = n_vel_; c < n_; ++c) {
    const double gc = v[c] / pen;
    for (int q = outer[c]; q < outer[c + 1]; ++q) f[inner[q]] += bval[std::size_t(q - q0)] * gc;
  }
  Eigen::VectorXd z(n_);
  supernodal_llt_solve(*chol_.factor->factor(), f, apply_work_, perm_.data());
  z.head(n_vel_) = f;
  for (int c = n_vel_; c < n_; ++c) {
    double bu = 0.0;
    for (int q = outer[c]; q < outer[c + 1]; ++q) bu += bval[std::size_t(q - q0)] * z[inner[q]];
    z[c] = (bu - v[c]) / pen;
  }
  return z;
}

void FittedStokes::numeric_factor(bool regularised) {
  if (regularised && use_chol_ && cholesky_factor()) return;
  join_background(false);
  const auto t0 = Clock::now();
  lu_valid_ = lu_current_ = pc_chol_ = false;
  if (!analysed_) {
    lu_->analyzePattern(A_);
    if (lu_->info() != Eigen::Success)
      throw NumericalError("the symbolic analysis of the fitted Stokes system failed (UMFPACK status " +
                               std::to_string(lu_->umfpackFactorizeReturncode()) + ")",
                           "use fewer cells (axi.fitted.cells_inner, axi.fitted.cells_outer, axi.fitted.gap_columns)");
    analysed_ = true;
  }
  lu_->factorize(A_);
  timing_.factor += seconds_since(t0);
  if (lu_->info() != Eigen::Success)
    throw NumericalError("the sparse LU factorisation of the fitted Stokes system failed (UMFPACK status " +
                             std::to_string(lu_->umfpackFactorizeReturncode()) +
                             (lu_->umfpackFactorizeReturncode() == 1 ? ": singular matrix" : "") + ")",
                         "check the wall's shape and the stiffness term; change axi.fitted.cells_inner, "
                         "axi.fitted.cells_outer or axi.fitted.gap_columns");
  ++timing_.factorisations;
  lu_valid_ = lu_current_ = true;
  last_iters_ = 0;
}

void FittedStokes::factor(const Eigen::Matrix3Xd& X, const Eigen::SparseMatrix<double>* K, double scale, bool force) {
  const int nm = mesh_->membrane_nodes();
  if (K && (K->rows() != 2 * nm || K->cols() != 2 * nm))
    throw std::invalid_argument("FittedStokes::factor: K must be " + std::to_string(2 * nm) + " x " +
                                std::to_string(2 * nm));
  if (K && !std::isfinite(scale)) throw std::invalid_argument("FittedStokes::factor: non-finite scale");
  factored_ = solved_ = false;
  auto t0 = Clock::now();
  mesh_->fit(X);
  transfer_weights();
  // the previous system's background factorisation: the preconditioner from now on
  if (worker_.joinable()) {
    const auto tj = Clock::now();
    join_background(true);
    t0 += Clock::now() - tj;  // accounted as factorisation
  }
  lu_current_ = false;  // A_ changes now (the stored LU, if any, stays valid as a preconditioner)
  assemble(K, scale);
  timing_.assemble += seconds_since(t0);
  solves_on_system_ = 0;
  // The iteration-count trigger is checked at the next solve (see the header comment).
  if (!reuse_ || !lu_valid_ || force)
    numeric_factor(reuse_);
  else if (background_ && pc_chol_ && use_chol_)
    launch_background();
  factored_ = true;
}

void FittedStokes::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  // one thread (a background factorisation may be using the other core), the lower triangle
  // column by column: an entry a_ij (i > j) adds a_ij x_j to y_i and a_ij x_i to y_j
  const int* outer = A_.outerIndexPtr();
  const int* inner = A_.innerIndexPtr();
  const double* val = A_.valuePtr();
  const double* xv = x.data();
  y.setZero(n_);
  double* yv = y.data();
  for (int c = 0; c < n_; ++c) {
    int q = lower_begin_[std::size_t(c)];
    const int end = outer[c + 1];
    const double xc = xv[c];
    double s0 = 0.0, s1 = 0.0;
    if (q < end && inner[q] == c) s0 = val[q] * xc, ++q;
    for (; q + 1 < end; q += 2) {
      const int i0 = inner[q], i1 = inner[q + 1];
      yv[i0] += val[q] * xc;
      yv[i1] += val[q + 1] * xc;
      s0 += val[q] * xv[i0];
      s1 += val[q + 1] * xv[i1];
    }
    if (q < end) {
      yv[inner[q]] += val[q] * xc;
      s0 += val[q] * xv[inner[q]];
    }
    yv[c] += s0 + s1;
  }
}

bool FittedStokes::gmres(int max_iterations, bool fresh, int& iters, double& relres, const Eigen::VectorXd* x0) {
  const int m = std::min(20, std::max(1, max_iterations));  // restart length
  iters = 0;
  sol_.setZero(n_);
  const double bnorm = rhs_.norm();
  if (bnorm == 0.0) {
    relres = 0.0;
    return true;
  }
  Eigen::VectorXd r = rhs_;
  double res = 1.0;  // true relative residual of sol_
  if (x0 && x0->size() == n_) {
    // the best multiple alpha x0 (one product): b - alpha A x0 orthogonal to A x0
    Eigen::VectorXd ax(n_);
    multiply(*x0, ax);
    const double axn2 = ax.squaredNorm();
    if (axn2 > 0.0 && std::isfinite(axn2)) {
      const double alpha = ax.dot(rhs_) / axn2;
      const Eigen::VectorXd r0 = rhs_ - alpha * ax;
      const double res0 = r0.norm() / bnorm;
      if (std::isfinite(res0) && res0 < 1.0) {
        sol_ = alpha * *x0;
        r = r0;
        res = res0;
      }
    }
  }
  if (kv_.rows() != n_ || kv_.cols() != m + 1) kv_.resize(n_, m + 1);
  if (kz_.rows() != n_ || kz_.cols() != m) kz_.resize(n_, m);
  lu_->umfpackControl()(UMFPACK_IRSTEP) = 0;  // preconditioner solves: no refinement (see header)
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + 1, m);
  Eigen::VectorXd cs(m), sn(m), g(m + 1), v(n_), z(n_), w(n_);
  Eigen::VectorXd best = sol_;
  double best_res = res;
  bool ok = res <= tol_;
  while (!ok) {
    const double beta = res * bnorm;
    kv_.col(0) = r / beta;
    g.setZero();
    g[0] = beta;
    H.setZero();
    int k = 0;
    while (k < m && iters < max_iterations) {
      v = kv_.col(k);
      if (pc_chol_)
        z = cholesky_apply(v);
      else
        z = lu_->solve(v);
      kz_.col(k) = z;
      multiply(z, w);
      // modified Gram-Schmidt, twice
      for (int pass = 0; pass < 2; ++pass)
        for (int i = 0; i <= k; ++i) {
          const double h = kv_.col(i).dot(w);
          H(i, k) += h;
          w -= h * kv_.col(i);
        }
      const double hn = w.norm();
      H(k + 1, k) = hn;
      for (int i = 0; i < k; ++i) {  // previous rotations
        const double t = cs[i] * H(i, k) + sn[i] * H(i + 1, k);
        H(i + 1, k) = -sn[i] * H(i, k) + cs[i] * H(i + 1, k);
        H(i, k) = t;
      }
      const double d = std::hypot(H(k, k), H(k + 1, k));
      cs[k] = d > 0 ? H(k, k) / d : 1.0;
      sn[k] = d > 0 ? H(k + 1, k) / d : 0.0;
      H(k, k) = d;
      H(k + 1, k) = 0.0;
      g[k + 1] = -sn[k] * g[k];
      g[k] = cs[k] * g[k];
      ++k;
      ++iters;
      if (std::abs(g[k]) <= 0.5 * tol_ * bnorm || hn <= 1e-300) break;
      if (hn > 0) kv_.col(k) = w / hn;
    }
    // x += Z y, H y = g (upper triangular)
    const Eigen::VectorXd y =
        H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    sol_.noalias() += kz_.leftCols(k) * y;
    r = rhs_;
    multiply(sol_, w);
    r -= w;
    const double prev = res;
    res = r.norm() / bnorm;
    if (!std::isfinite(res)) break;
    if (res < best_res) best_res = res, best = sol_;
    if (res <= tol_) {
      ok = true;
      break;
    }
    if (iters >= max_iterations) break;
    if (res > 0.5 * prev) break;  // stagnation (round-off floor of this preconditioner)
  }
  if (!ok) sol_ = best;
  relres = best_res;
  // With the LU of the current system, stagnation is the floor of that factorisation: accepted.
  return ok || (fresh && std::isfinite(best_res) && best_res < 1e-6);
}

void FittedStokes::solve(const Eigen::Matrix3Xd& F, Eigen::Matrix3Xd& U,
                         const std::function<Eigen::Vector2d(double x, double r)>* body, int guess) {
  if (!factored_) throw std::logic_error("FittedStokes::solve before a successful factor()");
  if (guess < -1 || guess >= kGuessSlots)
    throw std::invalid_argument("FittedStokes::solve: warm-start slot " + std::to_string(guess) + " not in [-1, " +
                                std::to_string(kGuessSlots - 1) + "]");
  const Eigen::VectorXd* x0 = guess >= 0 ? &guess_[std::size_t(guess)] : nullptr;
  const int nm = mesh_->membrane_nodes();
  if (F.cols() != nm)
    throw std::invalid_argument("FittedStokes::solve: F has " + std::to_string(F.cols()) + " columns, expected " +
                                std::to_string(nm));
  const auto t0 = Clock::now();
  const double factor_before = timing_.factor;  // a refactorisation inside is accounted as such
  rhs_.setZero();
  for (int k = 0; k < nm; ++k)
    for (int s = 0; s < 5; ++s) {
      const int nd = gnode_[k][s];
      if (nd < 0) continue;
      rhs_[dof_x_[nd]] += gw_[k][s] * F(0, k);
      rhs_[dof_r_[nd]] += gw_[k][s] * F(1, k);
    }
  const int E = mesh_->elements();
  Geometry g;
  if (body && *body) {
    for (int e = 0; e < E; ++e) {
      element_geometry(e, g);
      const int* L = &loc_[std::size_t(e) * kLoc];
      for (int q = 0; q < 9; ++q) {
        const Eigen::Vector2d f = (*body)(g.x[q], g.r[q]);
        const double W = g.wdet[q] * g.r[q];
        for (int a = 0; a < 9; ++a) {
          if (L[2 * a] >= 0) rhs_[L[2 * a]] += W * f[0] * g.N(q, a);
          if (L[2 * a + 1] >= 0) rhs_[L[2 * a + 1]] += W * f[1] * g.N(q, a);
        }
      }
    }
  }
  if (!reuse_) {
    lu_->umfpackControl()(UMFPACK_IRSTEP) = 1;
    sol_ = lu_->solve(rhs_);
    last_iters_ = 0;
    last_res_ = -1.0;
  } else {
    // This system's second solve uses its own background factorisation; the previous solve
    // needed too many iterations: factor the current system first.
    if (++solves_on_system_ > 1 && worker_.joinable()) join_background(true);
    if (!lu_current_ && last_iters_ > refactor_after_) refactor_now();
    if (!lu_valid_) numeric_factor(true);  // a background Cholesky failed: the LU now
    int it = 0;
    double res = 0.0;
    bool fresh = lu_current_;
    bool ok = gmres(fresh ? 40 : 20, fresh, it, res, x0);
    timing_.krylov_iterations += it;
    if (!ok && !fresh) {  // the old factorisation is no longer good enough: refactor, solve again
      refactor_now();
      int it2 = 0;
      ok = gmres(40, true, it2, res, x0);
      timing_.krylov_iterations += it2;
      it = it2;
      fresh = true;
    }
    if (!ok && pc_chol_) {  // a fresh Cholesky that does not converge: UMFPACK's LU from now on
      give_up_cholesky();
      numeric_factor(false);
      int it3 = 0;
      ok = gmres(40, true, it3, res, x0);
      timing_.krylov_iterations += it3;
      it = it3;
    }
    if (!ok)
      throw NumericalError("the fitted Stokes solve did not converge (relative residual " + significant(res) +
                               " with a fresh factorisation)",
                           "check the wall's shape and the stiffness term; change axi.fitted.cells_inner or "
                           "axi.fitted.cells_outer");
    if (!fresh) ++timing_.reused;
    last_iters_ = it;
    last_res_ = res;
    if (guess >= 0) guess_[std::size_t(guess)] = sol_;
  }
  if (!sol_.allFinite())
    throw NumericalError("the fitted Stokes solve returned a non-finite velocity",
                         "check the forces; change axi.fitted.cells_inner or axi.fitted.cells_outer");
  solved_ = true;
  pressure_gauge();
  U.setZero(3, nm);
  for (int k = 0; k < nm; ++k)
    for (int s = 0; s < 5; ++s) {
      const int nd = gnode_[k][s];
      if (nd < 0) continue;
      U(0, k) += gw_[k][s] * sol_[dof_x_[nd]];
      U(1, k) += gw_[k][s] * sol_[dof_r_[nd]];
    }
  timing_.solve += seconds_since(t0) - (timing_.factor - factor_before);
  ++timing_.solves;
}

void FittedStokes::pressure_gauge() {
  // Volume mean of the raw pressure (the gauge of the queries).
  p_mean_ = 0.0;
  Geometry g;
  double pv = 0.0, vol = 0.0;
  for (int e = 0; e < mesh_->elements(); ++e) {
    element_geometry(e, g);
    for (int q = 0; q < 9; ++q) {
      const double W = g.wdet[q] * g.r[q];
      pv += W * eval_pressure(e, g.x[q], g.r[q]);
      vol += W;
    }
  }
  p_mean_ = pv / vol;
}

FittedStokes::PrescribedWall FittedStokes::prescribed_wall_velocity(const Eigen::Matrix3Xd& X,
                                                                    const Eigen::Matrix3Xd& V) {
  const int nm = mesh_->membrane_nodes();
  if (V.cols() != nm || !V.topRows(2).allFinite())
    throw std::invalid_argument("FittedStokes::prescribed_wall_velocity: V must be 3 x " + std::to_string(nm) +
                                " and finite");
  join_background(false);  // its worker reads A_, which is about to change
  factored_ = solved_ = false;
  lu_valid_ = lu_current_ = false;  // the stored LU will be of the constrained system
  auto t0 = Clock::now();
  mesh_->fit(X);
  transfer_weights();
  assemble(nullptr, 0.0);
  // The wall line's nodes: the rings (I = 2k) and the segments' midpoints (I = 2k + 1) between
  // the rims (closed test mode: the whole line). Their values: V interpolated linearly (a), 1
  // axial (b).
  const bool closed = mesh_->closed();
  const int last = closed ? 2 * nm - 1 : 2 * (nm - 1);
  std::vector<signed char> fixed(n_, 0);  // 1: axial, 2: radial wall unknown
  Eigen::VectorXd ga = Eigen::VectorXd::Zero(n_), gb = Eigen::VectorXd::Zero(n_);
  for (int I = 0; I <= last; ++I) {
    const int k = I / 2, l = (k + 1) % nm;
    const int nd = I % 2 == 0 ? mesh_->wall_node(k) : mesh_->wall_midside_node(k);
    const Eigen::Vector2d v = I % 2 == 0 ? Eigen::Vector2d(V(0, k), V(1, k))
                                         : Eigen::Vector2d(0.5 * (V(0, k) + V(0, l)), 0.5 * (V(1, k) + V(1, l)));
    fixed[dof_x_[nd]] = 1;
    fixed[dof_r_[nd]] = 2;
    ga[dof_x_[nd]] = v[0];
    ga[dof_r_[nd]] = v[1];
    gb[dof_x_[nd]] = 1.0;
  }
  // Constrained rows: keep the axial ones' entries for the reaction, then replace every such row
  // by its diagonal (the row's own scale) times the prescribed value. Column-major storage: a
  // row's entries are spread over the columns.
  double* val = A_.valuePtr();
  const int* inner = A_.innerIndexPtr();
  const int* outer = A_.outerIndexPtr();
  std::vector<std::pair<int, double>> reaction;  // (column, value) of the axial rows, summed over them
  Eigen::VectorXd diag = Eigen::VectorXd::Zero(n_);
  for (int c = 0; c < n_; ++c)
    for (int q = outer[c]; q < outer[c + 1]; ++q) {
      const int row = inner[q];
      if (!fixed[row]) continue;
      if (fixed[row] == 1) reaction.emplace_back(c, val[q]);
      if (row == c)
        diag[row] = val[q];
      else
        val[q] = 0.0;
    }
  for (int i = 0; i < n_; ++i)
    if (fixed[i] && !(diag[i] > 0.0))
      throw NumericalError("a wall unknown of the fitted Stokes system has no positive diagonal",
                           "check the wall's shape; change axi.grid");
  timing_.assemble += seconds_since(t0);
  numeric_factor(false);
  lu_current_ = false;  // A_ is not the traction system any more
  lu_valid_ = false;
  const auto t1 = Clock::now();
  lu_->umfpackControl()(UMFPACK_IRSTEP) = 1;
  auto solve_one = [&](const Eigen::VectorXd& g, Eigen::VectorXd& x) {
    rhs_.setZero();
    for (int i = 0; i < n_; ++i)
      if (fixed[i]) rhs_[i] = diag[i] * g[i];
    x = lu_->solve(rhs_);
    if (!x.allFinite())
      throw NumericalError("the fitted Stokes solve of the prescribed wall returned a non-finite velocity",
                           "check the wave's shape; change axi.grid");
    double f = 0.0;
    for (const auto& [c, v] : reaction) f += v * x[c];
    return f;
  };
  Eigen::VectorXd xa, xb;
  PrescribedWall res;
  res.force = solve_one(ga, xa);
  res.drag = solve_one(gb, xb);
  if (!(std::isfinite(res.drag) && res.drag > 0.0) || !std::isfinite(res.force))
    throw NumericalError("the towed tube's drag is not positive (" + significant(res.drag) + " N s/m)",
                         "check the wall's shape; change axi.grid");
  res.velocity = -res.force / res.drag;
  sol_ = xb;
  solved_ = true;
  res.towed_lumen_flux = end_disc_flux(0, 1.0);
  sol_ = xa + res.velocity * xb;
  solved_ = true;
  last_iters_ = 0;
  last_res_ = -1.0;
  pressure_gauge();
  timing_.solve += seconds_since(t1);
  timing_.solves += 2;
  return res;
}

Eigen::Vector2d FittedStokes::eval_velocity(int e, double xi, double eta) const {
  const int* L = &loc_[std::size_t(e) * kLoc];
  Eigen::Vector2d u(0.0, 0.0);
  if (triangles_) {
    double N[9], Nxi[9], Neta[9];
    p2plus(xi, eta, N, Nxi, Neta);
    for (int a = 0; a < 7; ++a) {
      u[0] += N[a] * dof_value(L[2 * a]);
      u[1] += N[a] * dof_value(L[2 * a + 1]);
    }
    return u;
  }
  for (int b = 0; b < 3; ++b)
    for (int i = 0; i < 3; ++i) {
      const int a = 3 * b + i;
      const double N = lag(i, xi) * lag(b, eta);
      u[0] += N * dof_value(L[2 * a]);
      u[1] += N * dof_value(L[2 * a + 1]);
    }
  return u;
}

double FittedStokes::eval_pressure(int e, double x, double r) const {
  double cx[4], cr[4];
  mesh_->corners(e, cx, cr);
  double xc, rc, hx, hr;
  if (triangles_)
    triangle_pressure_scales(cx, cr, xc, rc, hx, hr);
  else
    pressure_scales(cx, cr, xc, rc, hx, hr);
  const int* L = &loc_[std::size_t(e) * kLoc];
  return ps_ * (dof_value(L[18]) + dof_value(L[19]) * (x - xc) / hx + dof_value(L[20]) * (r - rc) / hr) - p_mean_;
}

Eigen::Vector2d FittedStokes::velocity(double x, double r) const {
  if (!solved_) throw std::logic_error("FittedStokes::velocity before solve()");
  double xi, eta;
  const int e = mesh_->locate(x, r, xi, eta);
  return eval_velocity(e, xi, eta);
}

double FittedStokes::pressure(double x, double r) const {
  if (!solved_) throw std::logic_error("FittedStokes::pressure before solve()");
  double xi, eta;
  const int e = mesh_->locate(x, r, xi, eta);
  return eval_pressure(e, x, r);
}

double FittedStokes::end_disc_flux(int end, double frame_velocity) const {
  if (!solved_) throw std::logic_error("FittedStokes::end_disc_flux before solve()");
  if (end != 0 && end != 1) throw std::invalid_argument("FittedStokes::end_disc_flux: end must be 0 or 1");
  // Flux through the vertex column's line from the axis to the rim, relative to the frame:
  // int 2 pi r (u_x dr - u_r dx) along the line minus U pi r_rim^2 (the frame's flux through any
  // surface spanning the rim circle). Each edge is straight and u is quadratic along it: 3-point
  // Gauss is exact.
  mesh_->rim_path(end, path_);
  double s = 0.0;
  for (const RimPathEdge& edge : path_) {
    const double r0 = edge.r0, r1 = edge.r1;
    const double dx = edge.x1 - edge.x0;
    double ux[3], ur[3];
    for (int m = 0; m < 3; ++m) {
      const int node = edge.node[m];
      ux[m] = dof_value(dof_x_[node]);
      ur[m] = dx != 0.0 ? dof_value(dof_r_[node]) : 0.0;
    }
    for (int q = 0; q < 3; ++q) {
      const double t = kGp[q], r = 0.5 * (r0 * (1 - t) + r1 * (1 + t));
      const double vx = lag(0, t) * ux[0] + lag(1, t) * ux[1] + lag(2, t) * ux[2];
      const double vr = lag(0, t) * ur[0] + lag(1, t) * ur[1] + lag(2, t) * ur[2];
      s += kGw[q] * kTwoPi * r * (vx * 0.5 * (r1 - r0) - vr * 0.5 * dx);
    }
  }
  const double rim = path_.back().r1;
  return s - frame_velocity * std::numbers::pi * rim * rim;
}

double FittedStokes::element_divergence(int e) const {
  if (!solved_) throw std::logic_error("FittedStokes::element_divergence before solve()");
  Geometry g;
  element_geometry(e, g);
  const int* L = &loc_[std::size_t(e) * kLoc];
  double s = 0.0;
  for (int q = 0; q < 9; ++q) {
    double ur = 0, drur = 0, dxux = 0;
    for (int a = 0; a < 9; ++a) {
      const double vx = dof_value(L[2 * a]), vr = dof_value(L[2 * a + 1]);
      ur += g.N(q, a) * vr;
      drur += g.gr(q, a) * vr;
      dxux += g.gx(q, a) * vx;
    }
    s += g.wdet[q] * (g.r[q] * (drur + dxux) + ur);
  }
  return s;
}

double FittedStokes::lumen_divergence_residual() const {
  if (!solved_) throw std::logic_error("FittedStokes::lumen_divergence_residual before solve()");
  const double umax = sol_.head(n_vel_).cwiseAbs().maxCoeff();
  if (umax == 0.0) return 0.0;
  Geometry g;
  double worst = 0.0;
  for (int e = 0; e < mesh_->elements(); ++e) {
    element_geometry(e, g);
    double vol = 0.0, area = 0.0;
    for (int q = 0; q < 9; ++q) {
      vol += g.wdet[q] * g.r[q];
      area += g.wdet[q] / kTwoPi;
    }
    worst = std::max(worst, std::abs(element_divergence(e)) / (vol * umax / std::sqrt(area)));
  }
  return worst;
}

double FittedStokes::dissipation() const {
  if (!solved_) throw std::logic_error("FittedStokes::dissipation before solve()");
  Geometry g;
  double s = 0.0;
  for (int e = 0; e < mesh_->elements(); ++e) {
    element_geometry(e, g);
    const int* L = &loc_[std::size_t(e) * kLoc];
    for (int q = 0; q < 9; ++q) {
      double ur = 0, drur = 0, dxur = 0, dxux = 0, drux = 0;
      for (int a = 0; a < 9; ++a) {
        const double vx = dof_value(L[2 * a]), vr = dof_value(L[2 * a + 1]);
        ur += g.N(q, a) * vr;
        drur += g.gr(q, a) * vr;
        dxur += g.gx(q, a) * vr;
        dxux += g.gx(q, a) * vx;
        drux += g.gr(q, a) * vx;
      }
      const double r = g.r[q], sh = dxur + drux;
      s += 2.0 * mu_ * g.wdet[q] * r * (drur * drur + (ur / r) * (ur / r) + dxux * dxux + 0.5 * sh * sh);
    }
  }
  return s;
}

}  // namespace swim::axi
