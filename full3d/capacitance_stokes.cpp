// The capacitance Stokes solver (capacitance_stokes.hpp): the spectral free-slip base
// (transforms, per-mode projection), the symmetry-adapted dense factors and their cache,
// and the driver of a solve. The no-slip duct correction is in capacitance_duct.cpp, the
// staircase cylinder in capacitance_cylinder.cpp (shared state: capacitance_impl.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include "full3d/capacitance_impl.hpp"
#include "full3d/parallel.hpp"

namespace swim::full3d {

namespace capacitance {

Dir1d::Dir1d(int n_, double h)
    : n(n_), cf(std::size_t(n_) * n_), cft(std::size_t(n_) * n_), ci(std::size_t(n_) * n_), sn(std::size_t(n_) * n_), g(n_) {
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const double c = std::cos(kPi * a * (b + 0.5) / n);
      cf[std::size_t(a) * n + b] = 2.0 * c;
      cft[std::size_t(b) * n + a] = 2.0 * c;
      ci[std::size_t(b) * n + a] = (a ? 2.0 : 1.0) * c;
      sn[std::size_t(a) * n + b] = 2.0 * std::sin(kPi * a * b / n);
    }
  for (int m = 0; m < n; ++m) g[m] = -2.0 * std::sin(kPi * m / (2.0 * n)) / h;
}

}  // namespace capacitance

CapacitanceStokes::Impl::Impl(const MacGrid& g, double mu_, const CylinderOptions* cylopt, int thr,
                              const FftOptions& fft_in)
    : grid(g), mu(mu_), threads(std::max(1, thr)), nx(g.nx()), ny(g.ny()), nz(g.nz()), nxh(g.nx() / 2 + 1),
      dy(g.ny(), g.h()), dz(g.nz(), g.h()) {
  if (g.boundary() != GridBoundary::SquareDuct)
    throw InputError("container", to_string(g.boundary()), "the capacitance Stokes solver needs a square_duct grid");
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
  // the inverse per component and thread block, executed straight into the output arrays
  for (int c = 0; c < 4; ++c) {
    const int rows = off[c + 1] - off[c], T = block_count(rows, threads);
    for (int t = 0; t < T; ++t) {
      const long b = off[c] + long(rows) * t / T, e = off[c] + long(rows) * (t + 1) / T;
      const int n[1] = {nx};
      const fftw_r2r_kind k = FFTW_HC2R;
      xbwd[c].push_back(plan_many_r2r(1, n, int(e - b), planes.data() + b, nullptr, int(P), 1,
                                      real.data() + std::size_t(b) * nx, nullptr, 1, nx, &k, fft));
      xbwd_rows[c].push_back({b, e});
    }
  }

  // cross-section transforms (dense, applied to every plane)
  yz_at = {std::size_t(off[0]), std::size_t(off[1]) + 1, std::size_t(off[2]) + ny, std::size_t(off[3])};
  y10 = LineTransform(R2rKind::Redft10, ny);
  y01 = LineTransform(R2rKind::Redft01, ny);
  y00 = LineTransform(R2rKind::Rodft00, ny - 1);
  z10 = LineTransform(R2rKind::Redft10, nz);
  z01 = LineTransform(R2rKind::Redft01, nz);
  z00 = LineTransform(R2rKind::Rodft00, nz - 1);
  for (int c = 0; c < 4; ++c) {
    YzLayout& l = yz[c];
    l.ly = c == 1 ? ny - 1 : ny;
    l.lz = c == 2 ? nz - 1 : nz;
    l.row = c == 1 ? ny + 1 : ny;
    l.fy = c == 1 ? &y00 : &y10;
    l.iy = c == 1 ? &y00 : &y01;
    l.fz = c == 2 ? &z00 : &z10;
    l.iz = c == 2 ? &z00 : &z01;
  }
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
    s.tb.assign(P, 0.0);
    if (cyl) {
      s.fb.assign(P, 0.0);
      s.u0b.resize(u0_n);
      s.u0x.resize(u0_n);
    }
  }
}

// 1/|g|^2 and 1/(alpha + mu |g|^2) of every wavevector of mode kx (symbol gx) into s.
void CapacitanceStokes::Impl::mode_tables(double gx, double alpha, Scratch& s) const {
  // (branch-free, so that the divisions vectorise; |g|^2 = 0 only at gx = my = mz = 0)
  for (int mz = 0; mz < nz; ++mz) {
    const double gz2 = gx * gx + dz.g[mz] * dz.g[mz];
    double* il = s.inv_lam.data() + std::size_t(mz) * ny;
    double* id = s.inv_den.data() + std::size_t(mz) * ny;
    for (int my = 0; my < ny; ++my) {
      const double lam = gz2 + dy.g[my] * dy.g[my];
      il[my] = 1.0 / std::max(lam, std::numeric_limits<double>::min());
      id[my] = 1.0 / (alpha + mu * lam);
    }
  }
  if (!(gx * gx + dz.g[0] * dz.g[0] + dy.g[0] * dy.g[0] > 0.0)) s.inv_lam[0] = 0.0;
}

// Spectral free-slip projection per wavevector (my, mz), the box formula with a real symbol:
//   P = g.B/|g|^2 (0 at g = 0),  X = (B - g P)/(alpha + mu |g|^2).
// B: u, v, w coefficients of a plane-shaped array; X: u, v, w, p coefficients; the tables
// of mode_tables(gx, alpha). subtract: X = scale (X - M B), else X = scale M B (B may alias X).
namespace {

// One z row (fixed mz) of apply_M over my in [m0, m1); with_v: my > 0 (v has no my = 0
// coefficient), with_w: mz > 0 (nor w an mz = 0 one). The loop vectorises: X may be B, and
// each iteration reads and writes only its own index.
template <bool subtract, bool with_v, bool with_w>
void apply_M_row(int m0, int m1, const double* bu, const double* bv, const double* bw, double* xu, double* xv,
                 double* xw, double* xp, const double* gy, double gx, double gz, const double* il,
                 const double* id, double scale) {
#pragma omp simd
  for (int my = m0; my < m1; ++my) {
    const double cu = bu[my], cv = with_v ? bv[my] : 0.0, cw = with_w ? bw[my] : 0.0;
    const double pp = (gx * cu + gy[my] * cv + gz * cw) * il[my];
    const double inv = id[my];
    const double ru = (cu - gx * pp) * inv, rv = (cv - gy[my] * pp) * inv, rw = (cw - gz * pp) * inv;
    if (subtract) {
      xu[my] = scale * (xu[my] - ru);
      xp[my] = scale * (xp[my] - pp);
      if (with_v) xv[my] = scale * (xv[my] - rv);
      if (with_w) xw[my] = scale * (xw[my] - rw);
    } else {
      xu[my] = scale * ru;
      xp[my] = scale * pp;
      if (with_v) xv[my] = scale * rv;
      if (with_w) xw[my] = scale * rw;
    }
  }
}

template <bool subtract, bool with_w>
void apply_M_z_row(int ny, const double* bu, const double* bv, const double* bw, double* xu, double* xv, double* xw,
                   double* xp, const double* gy, double gx, double gz, const double* il, const double* id,
                   double scale) {
  apply_M_row<subtract, false, with_w>(0, 1, bu, bv, bw, xu, xv, xw, xp, gy, gx, gz, il, id, scale);
  apply_M_row<subtract, true, with_w>(1, ny, bu, bv, bw, xu, xv, xw, xp, gy, gx, gz, il, id, scale);
}

}  // namespace

void CapacitanceStokes::Impl::apply_M(const double* B, double* X, double gx, const Scratch& s, double scale,
                                      bool subtract) const {
  auto* row = subtract ? (apply_M_z_row<true, true>) : (apply_M_z_row<false, true>);
  auto* row0 = subtract ? (apply_M_z_row<true, false>) : (apply_M_z_row<false, false>);
  for (int mz = 0; mz < nz; ++mz) {
    const std::size_t iu = std::size_t(mz) * ny, iv = std::size_t(mz) * (ny + 1);
    (mz ? row : row0)(ny, B + off[0] + iu, B + off[1] + iv, B + off[2] + iu, X + off[0] + iu, X + off[1] + iv,
                      X + off[2] + iu, X + off[3] + iu, dy.g.data(), gx, dz.g[mz], s.inv_lam.data() + iu,
                      s.inv_den.data() + iu, scale);
  }
}

const CapacitanceStokes::Impl::Factors& CapacitanceStokes::Impl::factors(double alpha) {
  for (int k = 0; k < slots; ++k)
    if (!cache[k].chol.empty() && cache[k].alpha == alpha) {
      used_at[k] = ++use_clock;
      factorized_last = false;
      return cache[k];
    }
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::array<PackedCholesky, 4>> chol(static_cast<std::size_t>(nxh));
  parallel_blocks(nxh, threads, [&](long b, long e, int t) {
    for (long kx = b; kx < e; ++kx) {
      const double gx = gx_of(int(kx));
      mode_tables(gx, alpha, scratch[t]);
      const Eigen::MatrixXd C = cyl ? capacitance_cyl(int(kx), gx, scratch[t]) : capacitance(int(kx), gx, scratch[t]);
      factor_blocks(C, chol[kx], kx, alpha, cyl ? "cylinder" : "duct");
    }
  });
  auto u0llt = cyl ? factor_mean_x(alpha) : nullptr;
  Factors& f = free_slot();  // taken only when every factorisation succeeded
  f.alpha = alpha;
  f.chol = std::move(chol);
  f.u0llt = std::move(u0llt);
  f.bytes = std::size_t(nxh) * factor_doubles * sizeof(double);
  if (f.u0llt)
    f.bytes += std::size_t(f.u0llt->matrixL().nestedExpression().nonZeros()) * (sizeof(double) + sizeof(int));
  factor_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  factor_seconds_total += factor_seconds;
  ++factorizations;
  factorized_last = true;
  return f;
}

// Cholesky factors of the symmetry blocks Q_c^T C Q_c (LAPACK packed lower storage).
void CapacitanceStokes::Impl::factor_blocks(const Eigen::MatrixXd& C, std::array<PackedCholesky, 4>& l, long kx,
                                            double alpha, const char* what) const {
  for (int cl = 0; cl < 4; ++cl) {
    const int o = cls_off[cl], n = cls_off[cl + 1] - o;
    std::vector<double> b(PackedCholesky::packed_size(n));  // lower triangle of Q_c^T C Q_c
    for (int jb = 0; jb < n; ++jb)
      for (int ib = jb; ib < n; ++ib) {
        const SymVec &vi = sym[o + ib], &vj = sym[o + jb];
        double acc = 0.0;
        for (int p = 0; p < vi.n; ++p)
          for (int q = 0; q < vj.n; ++q) acc += vi.w[p] * vj.w[q] * C(vi.node[p], vj.node[q]);
        b[PackedCholesky::column(jb, n) + std::size_t(ib - jb)] = acc;
      }
    try {
      l[cl] = PackedCholesky(std::move(b), n);
    } catch (const LapackError& e) {
      throw NumericalError(std::string("capacitance matrix of the ") + what +
                               " Stokes solver is not positive definite for axial mode " + std::to_string(kx) +
                               " (rho/dt = " + std::to_string(alpha) + "; " + e.what() + ")",
                           "change the time step or the grid (full3d.grid.cells_across)");
    }
  }
}

// The whole cross-section solve of axial mode kx on its one or two planes: to the spectral
// frame, the free-slip solution Y = M T b, the correction of the duct walls or of the
// cylinder's ring, back to real space, and the exactly solved axial mean of u (kx = 0).
void CapacitanceStokes::Impl::solve_mode(int kx, const Factors& fac, double alpha, Scratch& s) {
  const int np = paired(kx) ? 2 : 1;
  double* const F[2] = {plane(kx), np == 2 ? plane(nx - kx) : nullptr};
  mode_to_spectral(kx, F, np, s);
  const double gx = gx_of(kx);
  mode_tables(gx, alpha, s);
  for (int q = 0; q < np; ++q) apply_M(F[q], F[q], gx, s, 1.0, false);
  if (cyl)
    correct_ring(kx, F, np, gx, fac, s);
  else
    correct_walls(kx, F, np, gx, fac, s);
  mode_from_spectral(kx, F, np, pressure_wanted, s);
  if (kx == 0) {
    if (cyl) {
      mean_x_ring(F[0] + off[0], fac, s);
    } else {
      std::copy_n(s.y.data(), std::size_t(ny) * nz, F[0] + off[0]);
      solve_mean_x(F[0] + off[0], alpha);
    }
  }
}

// Forward yz transforms of the np planes F of mode kx and, for a paired mode, the rotation
// into the real frame; kx = 0: the axial-mean x part of b is kept in s.y first.
void CapacitanceStokes::Impl::mode_to_spectral(int kx, double* const F[2], int np, Scratch& s) {
  if (kx == 0) std::copy_n(F[0] + off[0], std::size_t(ny) * nz, s.y.data());  // b of the axial mean u
  for (int q = 0; q < np; ++q)
    for (int c = 0; c < 3; ++c) yz_transform(c, F[q], s.tb.data(), false);
  if (np == 2) rotate(F[0], F[1], kx, +1);
}

void CapacitanceStokes::Impl::yz_transform(int c, double* f, double* tmp, bool inverse) const {
  const YzLayout& l = yz[c];
  double* a = f + yz_at[c];
  double* t = tmp + yz_at[c];
  (inverse ? l.iy : l.fy)->along(a, l.row, t, l.row, l.lz);
  (inverse ? l.iz : l.fz)->across(t, l.row, a, l.row, l.ly);
}

// The way back: rotation of a paired mode, the wall faces (not transformed) set to zero,
// the inverse yz transforms of u, v, w and (pressure) p.
void CapacitanceStokes::Impl::mode_from_spectral(int kx, double* const F[2], int np, bool pressure, Scratch& s) {
  if (np == 2) rotate(F[0], F[1], kx, -1);
  for (int q = 0; q < np; ++q) {
    double* f = F[q];
    zero_wall_slots(f);
    for (int c = 0; c < (pressure ? 4 : 3); ++c) yz_transform(c, f, s.tb.data(), true);
  }
}

void CapacitanceStokes::Impl::zero_wall_slots(double* f) const {
  for (int k = 0; k < nz; ++k) {
    f[off[1] + std::size_t(k) * (ny + 1)] = 0.0;
    f[off[1] + std::size_t(k) * (ny + 1) + ny] = 0.0;
  }
  std::fill(f + off[2], f + off[2] + ny, 0.0);
  std::fill(f + off[2] + std::size_t(nz) * ny, f + off[2] + std::size_t(nz + 1) * ny, 0.0);
}

// Rotation of the x component of a paired mode into the real frame, q = i e^{i theta/2} u^
// (dir = +1), and back, u^ = -i e^{-i theta/2} q (dir = -1); re / im: the two planes.
void CapacitanceStokes::Impl::rotate(double* re, double* im, int kx, int dir) const {
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
// the four block solves with the factors l, and back.
void CapacitanceStokes::Impl::block_solve(const std::array<PackedCholesky, 4>& l, int np, Scratch& s) const {
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
    l[cl].solve(s.e.data() + o, np, m);  // the np columns of s.e, leading dimension m
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

// b = beta * un + f (un == nullptr: b = f), fused into the copy into the transform rows.
// u may alias un: every row is read before any output is written.
void CapacitanceStokes::Impl::solve(const VectorField* un, double beta, const VectorField& f, VectorField& u,
                                    ScalarField& p, double alpha) {
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
    for (long kx = kb; kx < ke; ++kx) solve_mode(int(kx), fac, alpha, scratch[t]);
  });
  const bool with_p = pressure_wanted;
  // Inverse along x from the planes into the output rows (u, v, w, and p when wanted); into
  // the transform rows and copied when an output array is not aligned like them (FFTW's
  // new-array execution keeps the planned alignment).
  parallel_blocks(threads, threads, [&](long tb, long te, int) {
    for (long t = tb; t < te; ++t)
      for (int c = 0; c < (with_p ? 4 : 3); ++c) {
        if (t >= long(xbwd[c].size())) continue;
        const auto [b, e] = xbwd_rows[c][std::size_t(t)];
        double* rows = real.data() + std::size_t(b) * nx;
        double* dst = (c < 3 ? u.c[c].data() : p.v.data()) + std::size_t(b - off[c]) * nx;
        if (fftw_alignment_of(dst) == fftw_alignment_of(rows)) {
          xbwd[c][std::size_t(t)].execute_r2r(planes.data() + b, dst);
        } else {
          xbwd[c][std::size_t(t)].execute();
          std::memcpy(dst, rows, sizeof(double) * std::size_t(e - b) * nx);
        }
      }
  });
  // Sums and maxima below: per static block, combined in block order (reproducible for a
  // given thread count, parallel.hpp).
  const int T = block_count(long(grid.cells() / std::size_t(nx)), threads);
  if (cyl) {
    // masked faces: zero in exact arithmetic (ring: the constraint; outer: the homogeneous
    // outside problem); record their round-off and set them to 0. Pressure: zero mean over
    // the fluid cells, 0 in the others.
    std::vector<double> res(std::size_t(T), 0.0), psum(std::size_t(T), 0.0);
    std::vector<std::size_t> cnt(std::size_t(T), 0);
    parallel_blocks(off[3], T, [&](long rb, long re, int t) {
      rows_of(rb, re, [&](int c, long lo, long hi) {
        for (long r = lo; r < hi; ++r)
          if (row_masked[r]) {
            double* x = u.c[c].data() + std::size_t(r - off[c]) * nx;
            for (int i = 0; i < nx; ++i) res[std::size_t(t)] = std::max(res[std::size_t(t)], std::abs(x[i]));
            std::fill_n(x, nx, 0.0);
          }
      });
    });
    mask_residual = *std::max_element(res.begin(), res.end());
    if (!with_p) return;
    parallel_blocks(long(cell_fluid.size()), T, [&](long cb, long ce, int t) {
      for (long cell = cb; cell < ce; ++cell)
        if (cell_fluid[std::size_t(cell)]) {
          const double* pc = p.v.data() + std::size_t(cell) * nx;
          for (int i = 0; i < nx; ++i) psum[std::size_t(t)] += pc[i];
          cnt[std::size_t(t)] += std::size_t(nx);
        }
    });
    double ps = 0.0;
    std::size_t n = 0;
    for (int t = 0; t < T; ++t) ps += psum[std::size_t(t)], n += cnt[std::size_t(t)];
    const double pm = n ? ps / double(n) : 0.0;
    parallel_blocks(long(cell_fluid.size()), T, [&](long cb, long ce, int) {
      for (long cell = cb; cell < ce; ++cell) {
        double* pc = p.v.data() + std::size_t(cell) * nx;
        if (cell_fluid[std::size_t(cell)])
          for (int i = 0; i < nx; ++i) pc[i] -= pm;
        else
          std::fill_n(pc, nx, 0.0);
      }
    });
    return;
  }
  if (!with_p) return;
  // the pressure's zero mode is the gauge (0); remove its round-off mean
  std::vector<double> part(std::size_t(T), 0.0);
  const long rows = long(p.v.size() / std::size_t(nx));
  parallel_blocks(rows, T, [&](long rb, long re, int t) {
    for (std::size_t i = std::size_t(rb) * nx; i < std::size_t(re) * nx; ++i) part[std::size_t(t)] += p.v[i];
  });
  double sum = 0.0;
  for (double x : part) sum += x;
  const double mean = sum / double(p.v.size());
  parallel_blocks(rows, T, [&](long rb, long re, int) {
    for (std::size_t i = std::size_t(rb) * nx; i < std::size_t(re) * nx; ++i) p.v[i] -= mean;
  });
}

CapacitanceStokes::CapacitanceStokes(const MacGrid& g, double mu, int threads, const FftOptions& fft)
    : impl_(std::make_unique<Impl>(g, mu, nullptr, threads, fft)) {}
CapacitanceStokes::CapacitanceStokes(const MacGrid& g, double mu, const CylinderOptions* cylinder, int threads,
                                     const FftOptions& fft)
    : impl_(std::make_unique<Impl>(g, mu, cylinder, threads, fft)) {}

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
void CapacitanceStokes::step(const VectorField& un, const VectorField& f, VectorField& u, ScalarField& p,
                             double alpha) {
  impl_->solve(&un, alpha, f, u, p, alpha);
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
long CapacitanceStokes::factorizations() const { return impl_->factorizations; }
double CapacitanceStokes::factorization_seconds_total() const { return impl_->factor_seconds_total; }
int CapacitanceStokes::cache_slots() const { return impl_->slots; }
void CapacitanceStokes::limit_cache(int slots) {
  if (slots < 1 || slots > kCachedAlphas)
    throw InputError("CapacitanceStokes cache slots", std::to_string(slots),
                     "1 to " + std::to_string(kCachedAlphas));
  for (int k = slots; k < Impl::kCacheSlots; ++k) impl_->cache[k] = Impl::Factors{};
  impl_->slots = slots;
}
int CapacitanceStokes::wall_nodes() const { return impl_->m; }
void CapacitanceStokes::compute_pressure(bool on) { impl_->pressure_wanted = on; }
bool CapacitanceStokes::computes_pressure() const { return impl_->pressure_wanted; }
int CapacitanceStokes::threads() const { return impl_->threads; }
int CapacitanceStokes::symmetry_blocks() const { return impl_->cyl && !impl_->sym_ok ? 1 : 4; }

}  // namespace swim::full3d
