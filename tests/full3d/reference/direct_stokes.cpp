#include "tests/full3d/reference/direct_stokes.hpp"

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <complex>
#include <exception>
#include <mutex>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "common/errors.hpp"

namespace swim::full3d::reference {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Lu = Eigen::SparseLU<SpMat, Eigen::COLAMDOrdering<int>>;

// Runs f(m) for m = 0..n-1 on `threads` threads (the caller's included); the first
// exception thrown by a worker is rethrown after all have joined.
template <class F>
void parallel_for(int n, int threads, F&& f) {
  std::atomic<int> next{0};
  std::exception_ptr err;
  std::mutex err_mutex;
  auto work = [&] {
    try {
      for (int m = next++; m < n; m = next++) f(m);
    } catch (...) {
      std::lock_guard<std::mutex> lock(err_mutex);
      if (!err) err = std::current_exception();
      next = n;
    }
  };
  const int extra = std::max(0, std::min(threads, n) - 1);
  std::vector<std::thread> pool;
  pool.reserve(std::size_t(extra));
  for (int t = 0; t < extra; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (err) std::rethrow_exception(err);
}

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

}  // namespace

struct DirectStokes::Impl {
  MacGrid grid;
  double mu;
  // the pressure unknown is p / sigma, sigma = mu / h: the G entries then have the size
  // mu/h^2 of the viscous entries, which keeps partial pivoting accurate
  double sigma;
  int threads;
  int nx, nxh;
  std::array<std::array<int, 3>, 4> dims;
  std::array<int, 5> off{};  // cross-section row offsets: u, v, w, p, end
  int rtot = 0;

  // unknown numbering of one mode
  std::array<std::vector<int>, 3> vel_id;  // per component, per cross-section row: unknown or -1
  std::vector<int> p_id;                   // per cell: unknown or -1
  std::vector<int> unk_row;                // unknown -> global cross-section row (velocity and pressure)
  std::vector<char> unk_comp;              // unknown -> 0,1,2 velocity, 3 pressure
  int nvel = 0, nunk = 0;
  std::vector<char> pin0, pin1;  // per cell: pinned for kx = 0 / kx > 0

  // transforms
  FftwBuffer real_v, real_p, spec;
  std::array<FftwPlan, 3> fwd;
  std::array<FftwPlan, 4> bwd;

  struct Factors {
    double alpha = 0.0;
    std::vector<std::unique_ptr<Lu>> lu;
    std::size_t bytes = 0;
  };
  std::array<Factors, 2> cache;
  int next_slot = 0;
  double factor_seconds = 0.0;
  bool factorized_last = false;

  Impl(const MacGrid& g, double mu_, const CylinderOptions* cyl, int thr, const FftOptions& fft)
      : grid(g), mu(mu_), sigma(mu_ / g.h()), threads(std::max(1, thr)), nx(g.nx()), nxh(g.nx() / 2 + 1) {
    if (g.boundary() != GridBoundary::SquareDuct)
      throw InputError("container", to_string(g.boundary()), "the direct Stokes solver needs a square_duct grid");
    const int ny = g.ny(), nz = g.nz();
    for (int c = 0; c < 4; ++c) dims[c] = g.dims(c);
    off[0] = 0;
    for (int c = 0; c < 4; ++c) off[c + 1] = off[c] + dims[c][1] * dims[c][2];
    rtot = off[4];

    // free faces
    auto free_face = [&](int c, int j, int k) {
      if (g.on_wall(c, 1, j) || g.on_wall(c, 2, k)) return false;
      return !(cyl && cylinder_outside(g, cyl->radius, c, j, k));
    };
    for (int c = 0; c < 3; ++c) {
      vel_id[c].assign(std::size_t(dims[c][1]) * dims[c][2], -1);
      for (int k = 0; k < dims[c][2]; ++k)
        for (int j = 0; j < dims[c][1]; ++j)
          if (free_face(c, j, k)) {
            vel_id[c][std::size_t(k) * dims[c][1] + j] = nunk++;
            unk_row.push_back(off[c] + k * dims[c][1] + j);
            unk_comp.push_back(char(c));
          }
    }
    nvel = nunk;
    auto vid = [&](int c, int j, int k) { return vel_id[c][std::size_t(k) * dims[c][1] + j]; };
    p_id.assign(std::size_t(ny) * nz, -1);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j) {
        const bool any = vid(0, j, k) >= 0 || vid(1, j, k) >= 0 || vid(1, j + 1, k) >= 0 || vid(2, j, k) >= 0 ||
                         vid(2, j, k + 1) >= 0;
        if (!any) continue;
        p_id[std::size_t(k) * ny + j] = nunk++;
        unk_row.push_back(off[3] + k * ny + j);
        unk_comp.push_back(char(3));
      }
    // pressure null space: groups of cells connected through free y/z faces
    std::vector<int> parent(std::size_t(ny) * nz);
    for (std::size_t m = 0; m < parent.size(); ++m) parent[m] = int(m);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j) {
        const int cell = k * ny + j;
        if (j > 0 && vid(1, j, k) >= 0) parent[find_root(parent, cell)] = find_root(parent, cell - 1);
        if (k > 0 && vid(2, j, k) >= 0) parent[find_root(parent, cell)] = find_root(parent, cell - ny);
      }
    std::vector<int> first(parent.size(), -1);
    std::vector<char> has_q(parent.size(), 0);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j) {
        const int cell = k * ny + j;
        if (p_id[cell] < 0) continue;
        const int r = find_root(parent, cell);
        if (first[r] < 0) first[r] = cell;
        if (vid(0, j, k) >= 0) has_q[r] = 1;
      }
    pin0.assign(parent.size(), 0);
    pin1.assign(parent.size(), 0);
    for (std::size_t r = 0; r < parent.size(); ++r)
      if (first[r] >= 0) {
        pin0[first[r]] = 1;
        if (!has_q[r]) pin1[first[r]] = 1;
      }

    // batched x transforms, spectral layout [kx][cross-section row]
    real_v = FftwBuffer(std::size_t(off[3]) * nx);
    real_p = FftwBuffer(std::size_t(ny) * nz * nx);
    spec = FftwBuffer(2 * std::size_t(nxh) * rtot);
    fftw_complex* sp = spec.complex();
    for (int c = 0; c < 3; ++c) {
      const int rows = off[c + 1] - off[c];
      fwd[c] = plan_many_r2c_1d(nx, rows, real_v.data() + std::size_t(off[c]) * nx, 1, nx, sp + off[c], rtot, 1, fft);
      bwd[c] = plan_many_c2r_1d(nx, rows, sp + off[c], rtot, 1, real_v.data() + std::size_t(off[c]) * nx, 1, nx, fft);
    }
    bwd[3] = plan_many_c2r_1d(nx, ny * nz, sp + off[3], rtot, 1, real_p.data(), 1, nx, fft);
  }

  // s = 2 sin(theta/2)/h, theta = 2 pi kx / nx
  double s_of(int kx) const { return 2.0 * std::sin(std::numbers::pi * kx / nx) / grid.h(); }

  SpMat mode_matrix(int kx, double alpha) const {
    const double h = grid.h(), ih = 1.0 / h, ih2 = ih * ih;
    const double s = s_of(kx);
    const std::vector<char>& pin = kx == 0 ? pin0 : pin1;
    const int ny = grid.ny();
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(std::size_t(nunk) * 9);
    auto pcol = [&](int j, int k) {  // pressure unknown of cell (j,k), -1 if none or pinned
      const std::size_t cell = std::size_t(k) * ny + j;
      return pin[cell] ? -1 : p_id[cell];
    };
    auto couple = [&](int row, int col, double v) {  // G entry (row, col) and its transpose
      if (col < 0 || v == 0.0) return;
      v *= sigma;
      t.emplace_back(row, col, v);
      t.emplace_back(col, row, v);
    };
    for (int c = 0; c < 3; ++c) {
      const auto& d = dims[c];
      for (int k = 0; k < d[2]; ++k)
        for (int j = 0; j < d[1]; ++j) {
          const int m = vel_id[c][std::size_t(k) * d[1] + j];
          if (m < 0) continue;
          double diag = alpha + mu * (s * s + 4.0 * ih2);
          const int idx[3] = {0, j, k};
          for (int dir = 1; dir <= 2; ++dir)
            for (int sg = -1; sg <= 1; sg += 2) {
              const int tt = idx[dir] + sg;
              if (tt < 0 || tt >= d[dir]) {
                diag += mu * ih2;  // ghost value -u
                continue;
              }
              const int jj = dir == 1 ? tt : j, kk = dir == 2 ? tt : k;
              const int nb = vel_id[c][std::size_t(kk) * d[1] + jj];
              if (nb >= 0) t.emplace_back(m, nb, -mu * ih2);  // masked / wall neighbours hold zero
            }
          t.emplace_back(m, m, diag);
          if (c == 0) {
            couple(m, pcol(j, k), -s);
          } else if (c == 1) {
            couple(m, pcol(j, k), ih);
            couple(m, pcol(j - 1, k), -ih);
          } else {
            couple(m, pcol(j, k), ih);
            couple(m, pcol(j, k - 1), -ih);
          }
        }
    }
    for (std::size_t cell = 0; cell < pin.size(); ++cell)
      if (pin[cell] && p_id[cell] >= 0) t.emplace_back(p_id[cell], p_id[cell], mu * ih2);
    SpMat A(nunk, nunk);
    A.setFromTriplets(t.begin(), t.end());
    A.makeCompressed();
    return A;
  }

  Factors& factors(double alpha) {
    for (auto& f : cache)
      if (!f.lu.empty() && f.alpha == alpha) {
        factorized_last = false;
        return f;
      }
    Factors& f = cache[next_slot];
    next_slot = 1 - next_slot;
    f.lu.clear();
    f.bytes = 0;
    f.alpha = alpha;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::unique_ptr<Lu>> lu(static_cast<std::size_t>(nxh));
    std::vector<std::size_t> bytes(static_cast<std::size_t>(nxh), 0);
    parallel_for(nxh, threads, [&](int kx) {
      auto l = std::make_unique<Lu>();
      l->compute(mode_matrix(kx, alpha));
      if (l->info() != Eigen::Success)
        throw NumericalError("sparse LU of the direct Stokes solver failed for axial mode " + std::to_string(kx) +
                                 ": " + l->lastErrorMessage(),
                             "change the grid of the test");
      bytes[kx] = std::size_t(l->nnzL() + l->nnzU()) * (sizeof(double) + sizeof(int));
      lu[kx] = std::move(l);
    });
    f.lu = std::move(lu);
    for (auto b : bytes) f.bytes += b;
    factor_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    factorized_last = true;
    return f;
  }

  void solve(const VectorField& b, VectorField& u, ScalarField& p, double alpha) {
    Factors& fac = factors(alpha);
    for (int c = 0; c < 3; ++c) {
      std::copy(b.c[c].begin(), b.c[c].end(), real_v.data() + std::size_t(off[c]) * nx);
      fwd[c].execute();
    }
    auto* sp = reinterpret_cast<std::complex<double>*>(spec.complex());
    const double inv_n = 1.0 / nx;
    parallel_for(nxh, threads, [&](int kx) {
      const double th2 = std::numbers::pi * kx / nx;  // theta / 2
      const double cs = std::cos(th2), sn = std::sin(th2);
      std::complex<double>* row = sp + std::size_t(kx) * rtot;
      Eigen::MatrixXd B = Eigen::MatrixXd::Zero(nunk, 2);
      for (int m = 0; m < nvel; ++m) {
        const std::complex<double> v = row[unk_row[m]];
        if (unk_comp[m] == 0) {  // q = i e^{i theta/2} b^
          B(m, 0) = -(cs * v.imag() + sn * v.real());
          B(m, 1) = cs * v.real() - sn * v.imag();
        } else {
          B(m, 0) = v.real();
          B(m, 1) = v.imag();
        }
      }
      const Eigen::MatrixXd X = fac.lu[kx]->solve(B);
      std::fill(row, row + rtot, std::complex<double>(0.0, 0.0));
      for (int m = 0; m < nunk; ++m) {
        const double xr = X(m, 0), xi = X(m, 1);
        if (unk_comp[m] == 0)  // u^ = -i e^{-i theta/2} q
          row[unk_row[m]] = inv_n * std::complex<double>(cs * xi - sn * xr, -(cs * xr + sn * xi));
        else if (unk_comp[m] < 3)
          row[unk_row[m]] = inv_n * std::complex<double>(xr, xi);
        else
          row[unk_row[m]] = (inv_n * sigma) * std::complex<double>(xr, xi);
      }
    });
    for (int c = 0; c < 3; ++c) {
      bwd[c].execute();
      const double* src = real_v.data() + std::size_t(off[c]) * nx;
      u.c[c].assign(src, src + grid.size(c));
    }
    bwd[3].execute();
    p.v.assign(real_p.data(), real_p.data() + grid.cells());
    // zero mean over the cells carrying a pressure, zero elsewhere
    double sum = 0.0;
    std::size_t count = 0;
    const int ny = grid.ny();
    for (std::size_t cell = 0; cell < p_id.size(); ++cell)
      if (p_id[cell] >= 0) {
        for (int i = 0; i < nx; ++i) sum += p.v[cell * nx + i];
        count += nx;
      }
    const double mean = count ? sum / double(count) : 0.0;
    for (std::size_t cell = 0; cell < p_id.size(); ++cell) {
      double* pc = p.v.data() + cell * nx;
      if (p_id[cell] >= 0)
        for (int i = 0; i < nx; ++i) pc[i] -= mean;
      else
        std::fill(pc, pc + nx, 0.0);
    }
    (void)ny;
  }
};

DirectStokes::DirectStokes(const MacGrid& g, double mu, const CylinderOptions* cylinder, int threads,
                           const FftOptions& fft)
    : impl_(std::make_unique<Impl>(g, mu, cylinder, threads, fft)) {}
DirectStokes::~DirectStokes() = default;
DirectStokes::DirectStokes(DirectStokes&&) noexcept = default;
DirectStokes& DirectStokes::operator=(DirectStokes&&) noexcept = default;

void DirectStokes::solve(const VectorField& b, VectorField& u, ScalarField& p, double alpha) {
  impl_->solve(b, u, p, alpha);
}

std::size_t DirectStokes::estimate_bytes(const MacGrid& g) {
  // Fit of the measured factor size of COLAMD + SparseLU for the plain duct
  // (docs/full3d-fluid.md; the staircase cylinder needs about 0.55 of it):
  // 52 N^1.4 bytes per mode, N = 4 ny nz unknowns (n = 12, 20, 32 within 5 %).
  const double n = 4.0 * g.ny() * g.nz();
  return std::size_t(double(g.nx() / 2 + 1) * 52.0 * std::pow(n, 1.4));
}

std::size_t DirectStokes::factor_bytes() const {
  std::size_t b = 0;
  for (const auto& f : impl_->cache) b += f.bytes;
  return b;
}
double DirectStokes::last_factorization_seconds() const { return impl_->factor_seconds; }
bool DirectStokes::last_solve_factorized() const { return impl_->factorized_last; }
std::size_t DirectStokes::unknowns_per_mode() const { return std::size_t(impl_->nunk); }
bool DirectStokes::has_pressure(int j, int k) const {
  return impl_->p_id[std::size_t(k) * impl_->grid.ny() + j] >= 0;
}

}  // namespace swim::full3d::reference
