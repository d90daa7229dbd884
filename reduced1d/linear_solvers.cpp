// Direct linear solvers of the 1D tier's Newton systems: band LU with partial pivoting,
// block-tridiagonal LU over the cells, and the Sherman-Morrison-Woodbury correction of a
// low-rank term, behind one SUNLinearSolver (equations in linear_solvers.hpp).
#include "reduced1d/linear_solvers.hpp"

#include <sunmatrix/sunmatrix_band.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "common/dot.hpp"
#include "reduced1d/v4.hpp"

namespace swim::reduced1d::sun {

namespace {

// The block kernels below update whole padded rows and columns as V4 (v4.hpp); with blocks of
// 8, the default model at N = 50, the results are those of scalar code bit for bit; other
// block sizes differ in the last bits (docs/performance-1d.md).
using v4::V4;
using v4::load4;
using v4::store4;

// Band LU with partial pivoting (LAPACK dgbtf2 layout: A(i, j) at ab[j * ldab + kv + i - j],
// kv = ku + kl, ldab = 2 kl + ku + 1), compiled with the project's flags (the distribution's
// SUNDIALS band kernels are unoptimised, see serial_kernels.hpp).
struct BandLU {
  long n = 0;
  int kl = 0, ku = 0, kv = 0, ldab = 0;
  std::vector<double> ab;
  std::vector<long> piv;
  std::vector<double> dinv;  // 1 / U(j, j)
  double& at(long i, long j) { return ab[std::size_t(j) * ldab + kv + i - j]; }
  double at(long i, long j) const { return ab[std::size_t(j) * ldab + kv + i - j]; }
  void resize(long n_, int kl_, int ku_) {
    n = n_, kl = kl_, ku = ku_, kv = kl + ku, ldab = 2 * kl + ku + 1;
    ab.assign(std::size_t(n) * ldab, 0.0);
    piv.assign(n, 0);
    dinv.assign(n, 0.0);
  }
  void load(SUNMatrix M) {
    std::fill(ab.begin(), ab.end(), 0.0);
    const long mu = SM_UBAND_B(M), ml = SM_LBAND_B(M);
    for (long j = 0; j < n; ++j) {
      const long i0 = std::max(0L, j - mu), i1 = std::min(n - 1, j + ml);
      for (long i = i0; i <= i1; ++i) at(i, j) = SM_ELEMENT_B(M, i, j);
    }
  }
  bool factor() {
    long ju = 0;
    for (long j = 0; j < n; ++j) {
      const long km = std::min<long>(kl, n - 1 - j);
      long p = 0;
      double best = std::abs(at(j, j));
      for (long r = 1; r <= km; ++r)
        if (std::abs(at(j + r, j)) > best) best = std::abs(at(j + r, j)), p = r;
      piv[j] = j + p;
      if (best == 0.0) return false;
      ju = std::max(ju, std::min(j + ku + p, n - 1));
      if (p != 0)
        for (long c = j; c <= ju; ++c) std::swap(at(j, c), at(j + p, c));
      const double inv = 1.0 / at(j, j);
      dinv[j] = inv;
      for (long r = 1; r <= km; ++r) at(j + r, j) *= inv;
      for (long c = j + 1; c <= ju; ++c) {
        const double ajc = at(j, c);
        if (ajc == 0.0) continue;
        for (long r = 1; r <= km; ++r) at(j + r, c) -= at(j + r, j) * ajc;
      }
    }
    return true;
  }
  void solve(double* b) const {
    for (long j = 0; j < n; ++j) {
      const long km = std::min<long>(kl, n - 1 - j);
      if (piv[j] != j) std::swap(b[j], b[piv[j]]);
      const double bj = b[j];
      for (long r = 1; r <= km; ++r) b[j + r] -= at(j + r, j) * bj;
    }
    if (kv == 2 && n >= 2) {  // tridiagonal with pivoting: U has two superdiagonals
      const double* a = ab.data();
      b[n - 1] *= dinv[n - 1];
      b[n - 2] = (b[n - 2] - a[std::size_t(n - 1) * ldab + 1] * b[n - 1]) * dinv[n - 2];
      for (long j = n - 3; j >= 0; --j) {
        const double* c1 = a + std::size_t(j + 1) * ldab;  // column j + 1, row j at offset kv - 1
        const double* c2 = a + std::size_t(j + 2) * ldab;  // column j + 2, row j at offset kv - 2
        b[j] = (b[j] - c1[1] * b[j + 1] - c2[0] * b[j + 2]) * dinv[j];
      }
      return;
    }
    for (long j = n - 1; j >= 0; --j) {
      b[j] *= dinv[j];
      const double bj = b[j];
      for (long i = std::max(0L, j - kv); i < j; ++i) b[i] -= at(i, j) * bj;
    }
  }
};

// LU with partial pivoting of a small dense column-major matrix; returns false if singular.
bool small_lu(std::vector<double>& a, std::vector<int>& piv, int r) {
  for (int k = 0; k < r; ++k) {
    int p = k;
    for (int i = k + 1; i < r; ++i)
      if (std::abs(a[k * r + i]) > std::abs(a[k * r + p])) p = i;
    piv[k] = p;
    if (a[k * r + p] == 0.0) return false;
    if (p != k)
      for (int j = 0; j < r; ++j) std::swap(a[j * r + k], a[j * r + p]);
    for (int i = k + 1; i < r; ++i) {
      a[k * r + i] /= a[k * r + k];
      for (int j = k + 1; j < r; ++j) a[j * r + i] -= a[k * r + i] * a[j * r + k];
    }
  }
  return true;
}
void small_solve(const std::vector<double>& a, const std::vector<int>& piv, int r, double* b) {
  // small_lu swaps whole rows (the multipliers of earlier columns included, as LAPACK's
  // dgetf2 does), so all the row interchanges apply to b before the forward substitution.
  for (int k = 0; k < r; ++k) std::swap(b[k], b[piv[k]]);
  for (int k = 0; k < r; ++k)
    for (int i = k + 1; i < r; ++i) b[i] -= a[k * r + i] * b[k];
  for (int k = r - 1; k >= 0; --k) {
    for (int j = k + 1; j < r; ++j) b[k] -= a[j * r + k] * b[j];
    b[k] /= a[k * r + k];
  }
}

// Block LU of a band matrix whose cells form a block tridiagonal matrix (CellBlocks), with a
// border of unknowns that no cell row references: A = [T 0; F G]. T = Lt Ut with Lt block
// lower bidiagonal (diagonal blocks D_k, subdiagonal blocks the matrix's own L_k) and Ut unit
// block upper bidiagonal (Up_k = D_k^{-1} U_k); D_k = A_kk - L_k Up_{k-1} is inverted
// explicitly (Gauss-Jordan with partial pivoting), so that both sweeps of a solve are dense
// S x S products per cell, independent across rows. The border follows from G x_B = b_B - F x_T.
struct BlockTri {
  long n = 0, o = 0, N = 0;
  int S = 0, nb = 0;
  std::vector<int> bpos;          // unknown -> position in the border, or -1
  std::vector<long> border;       // border unknowns
  // per cell, S x S column-major (entry (r, c) at [c S + r]): D_k^{-1}, Up_k = D_k^{-1} U_k
  std::vector<double> Dinv, Up;
  // the nonzeros of each L_k (about one per column): position r + c s and value, cell k's
  // from lbeg[k] to lbeg[k + 1]
  std::vector<int> lpos, lbeg;
  std::vector<double> lval;
  // D_k^{-1} L_k dense (S x S column-major, stride lead(S)), for the solves' forward sweep
  // y_k = D_k^{-1} b_k - (D_k^{-1} L_k) y_{k-1}: one dense product of whole vectors on the
  // chain from cell to cell (D_k^{-1} b_k does not wait for y_{k-1}) instead of two
  std::vector<double> DL;
  struct Entry {
    int row;
    long col;
    double v;
  };
  std::vector<Entry> F;       // the border rows' entries in cell columns
  std::vector<double> G;      // nb x nb, column-major, LU-factored in place
  std::vector<int> gpiv;
  std::vector<double> bt;  // workspace
  double growth = 0;          // largest ||D_k||_max ||D_k^{-1}||_max S of the last factor()

  /// Block sizes with a compiled kernel (3: wall inertia alone; 3 + J with the traction's J
  /// fields, J = 5 to 10 from the |k| quadrature).
  static constexpr int kMinBlock = 3, kMaxBlock = 14;
  static bool supported(int s) { return s >= kMinBlock && s <= kMaxBlock; }
  /// Calls f(std::integral_constant<int, S>) for a supported S; false otherwise.
  template <int s = kMinBlock, class F>
  static bool with_block_size(int S_, F&& f) {
    if constexpr (s > kMaxBlock) {
      return false;
    } else {
      if (S_ == s) {
        f(std::integral_constant<int, s>{});
        return true;
      }
      return with_block_size<s + 1>(S_, f);
    }
  }

  /// Leading dimension of a block of size s: s rounded up to whole 4-wide vectors. Blocks are
  /// stored column-major with this stride and zero padding rows, so that every column update
  /// and every Gauss-Jordan row operation is whole vectors.
  static constexpr int lead(int s) { return (s + 3) / 4 * 4; }

  void resize(long n_, const CellBlocks& c) {
    n = n_, o = c.offset, S = c.block, N = c.count;
    bpos.assign(n, -1);
    border.clear();
    for (long i = 0; i < n; ++i)
      if (i < o || i >= o + S * N) bpos[i] = int(border.size()), border.push_back(i);
    nb = int(border.size());
    const std::size_t blk = std::size_t(S) * lead(S) * N;
    Dinv.assign(blk, 0.0), Up.assign(blk, 0.0), DL.assign(blk, 0.0);
    lpos.clear(), lval.clear(), lbeg.assign(N + 1, 0);
    G.assign(std::size_t(nb) * nb, 0.0);
    gpiv.assign(nb, 0);
    bt.assign(nb, 0.0);
  }

  /// Band entry (i, j), zero outside the band.
  static double band_at(SUNMatrix M, long i, long j) {
    const long d = i - j;
    return (d > SM_LBAND_B(M) || -d > SM_UBAND_B(M)) ? 0.0 : SM_COLUMN_B(M, j)[d];
  }

  /// Rows [r0, r0 + s) of band column j into dst (zero outside the band): a contiguous run
  /// of the column's storage.
  template <int s>
  static void column_run(SUNMatrix M, long j, long r0, double* dst) {
    const long mu = SM_UBAND_B(M), ml = SM_LBAND_B(M);
    const double* col = SM_COLUMN_B(M, j);
    // rows r with -mu <= r0 + r - j <= ml; the others are zero (a fixed-length loop with a
    // clamped index: no library copy with its start-up cost for 3 to 14 entries)
    for (int r = 0; r < s; ++r) {
      const long d = r0 + r - j;
      const double v = col[std::clamp(d, -mu, ml)];
      dst[r] = (d >= -mu && d <= ml) ? v : 0.0;
    }
  }

  /// Copy the three blocks of cell k's rows (columns of cells k - 1, k, k + 1) into L, A, U
  /// (column-major, stride lead(s)); false if a band entry of these rows lies outside them.
  /// The entries of L and U outside the band and the padding rows are never written: the
  /// caller zeroes them once.
  template <int s>
  bool gather(SUNMatrix M, long k, double* L, double* A, double* Uk) const {
    constexpr int ld = lead(s);
    const long mu = SM_UBAND_B(M), ml = SM_LBAND_B(M);
    const long e = o + s * N, r0 = o + s * k;
    for (int c = 0; c < s; ++c) {
      // block column c of L (band column r0 - s + c) holds rows r with s + r - c <= ml;
      // of A, all rows when s - 1 <= min(mu, ml); of U (column r0 + s + c), rows with
      // s + c - r <= mu
      if (k > 0) {
        const double* col = SM_COLUMN_B(M, r0 - s + c) + (s - c);
        const int hi = int(std::min<long>(s, ml - s + c + 1));
        for (int r = 0; r < hi; ++r) L[c * ld + r] = col[r];
      }
      if (s - 1 <= mu && s - 1 <= ml) {
        const double* col = SM_COLUMN_B(M, r0 + c) - c;
        for (int r = 0; r < s; ++r) A[c * ld + r] = col[r];
      } else {
        column_run<s>(M, r0 + c, r0, A + c * ld);
      }
      if (k + 1 < N) {
        const double* col = SM_COLUMN_B(M, r0 + s + c) - (s + c);
        for (int r = int(std::max<long>(0, s + c - mu)); r < s; ++r) Uk[c * ld + r] = col[r];
      } else {
        std::fill(Uk + c * ld, Uk + c * ld + s, 0.0);
      }
    }
    // the rest of these rows' band must be zero: columns left of cell k - 1 (or of the
    // cells) and right of cell k + 1 (or of the cells) that the band reaches
    const long lo = std::max(o, r0 - (k > 0 ? s : 0)), hi = std::min(e, r0 + (k + 1 < N ? 2 * s : s));
    double run[s];
    for (long j = std::max(0L, r0 - ml); j < lo; ++j) {
      column_run<s>(M, j, r0, run);
      for (int r = 0; r < s; ++r)
        if (run[r] != 0.0) return false;
    }
    for (long j = hi; j <= std::min(n - 1, r0 + s - 1 + mu); ++j) {
      column_run<s>(M, j, r0, run);
      for (int r = 0; r < s; ++r)
        if (run[r] != 0.0) return false;
    }
    return true;
  }

  /// invert() for blocks of at most 8 (two 4-wide vectors per row): the same elimination in
  /// the same order, with the rows held in vector registers throughout (every loop unrolled
  /// at compile time) and the pivot's row chosen by selects instead of branches. The
  /// elimination is a chain of s dependent pivot steps; through memory each step waited on
  /// its stores and on the branches of the pivot search, which the data decide
  /// (docs/performance-1d.md: 2.7 times faster per block of 8).
  template <int s>
  static bool invert_in_registers(const double* src, double* Dm) {
    constexpr int ld = lead(s);
    constexpr int nv = ld / 4;
    V4 a[s][nv];
#pragma GCC unroll 16
    for (int r = 0; r < s; ++r)
#pragma GCC unroll 4
      for (int v = 0; v < nv; ++v) a[r][v] = load4(src + r * ld + 4 * v);
    int perm[s];
#pragma GCC unroll 16
    for (int k = 0; k < s; ++k) {
      // pivot: the first row of largest |entry| in column k (as invert's strict comparison)
      int p = k;
      double best = std::abs(a[k][k / 4][k % 4]);
#pragma GCC unroll 16
      for (int r = k + 1; r < s; ++r) {
        const double v = std::abs(a[r][k / 4][k % 4]);
        const bool g = v > best;
        best = g ? v : best;
        p = g ? r : p;
      }
      perm[k] = p;
      if (best == 0.0) return false;
      // pr = row p; row p takes row k. The Newton matrices' blocks pivot on their diagonal
      // (the demo cycle at N = 50: no interchange in 65 600 pivot steps), so the interchange
      // is a branch that is not taken rather than selects on every row.
      if (p != k) {
#pragma GCC unroll 4
        for (int v = 0; v < nv; ++v) {
          V4 rp = a[k][v];
#pragma GCC unroll 16
          for (int r = k + 1; r < s; ++r) rp = (r == p) ? a[r][v] : rp;
#pragma GCC unroll 16
          for (int r = k + 1; r < s; ++r) a[r][v] = (r == p) ? a[k][v] : a[r][v];
          a[k][v] = rp;
        }
      }
      V4 pr[nv];
#pragma GCC unroll 4
      for (int v = 0; v < nv; ++v) pr[v] = a[k][v];
      const double inv = 1.0 / pr[k / 4][k % 4];
#pragma GCC unroll 4
      for (int v = 0; v < nv; ++v) pr[v] *= inv;
      pr[k / 4][k % 4] = inv;
      // entry k of every other row is cleared by a product with a constant 0/1 vector: a
      // lane write or a mask compiles to a register form of vmovq that valgrind (3.19)
      // cannot decode, which would end every callgrind measurement of the tier
      const V4 keep = {double(k % 4 != 0), double(k % 4 != 1), double(k % 4 != 2), double(k % 4 != 3)};
#pragma GCC unroll 16
      for (int r = 0; r < s; ++r) {
        if (r == k) continue;
        const double f = a[r][k / 4][k % 4];
        a[r][k / 4] *= keep;
#pragma GCC unroll 4
        for (int v = 0; v < nv; ++v) a[r][v] -= f * pr[v];
      }
#pragma GCC unroll 4
      for (int v = 0; v < nv; ++v) a[k][v] = pr[v];
    }
#pragma GCC unroll 16
    for (int r = 0; r < s; ++r)
#pragma GCC unroll 4
      for (int v = 0; v < nv; ++v) store4(Dm + r * ld + 4 * v, a[r][v]);
    for (int k = s - 1; k >= 0; --k)
      if (perm[k] != k)
        for (int r = 0; r < s; ++r) std::swap(Dm[r * ld + k], Dm[r * ld + perm[k]]);
    return true;
  }

  /// Gauss-Jordan inverse with partial pivoting of the column-major s x s matrix src (stride
  /// lead(s), padding rows zero) into Dm (which may be src). Row-major elimination on a column-major buffer
  /// inverts the transpose, whose inverse read column-major is D^{-1}; its pivots are D's
  /// columns. In place: each step leaves the inverse's column k where the eliminated column
  /// was (s^3 multiply-adds instead of 2 s^3 with a separate identity), and the row
  /// interchanges are undone as column interchanges at the end.
  template <int s>
  static bool invert(const double* src, double* Dm) {
    if constexpr (lead(s) <= 8) return invert_in_registers<s>(src, Dm);
    constexpr int ld = lead(s);
    copy_block<std::size_t(s) * ld>(src, Dm);
    int perm[s];
    for (int k = 0; k < s; ++k) {
      int p = k;
      for (int r = k + 1; r < s; ++r)
        if (std::abs(Dm[r * ld + k]) > std::abs(Dm[p * ld + k])) p = r;
      perm[k] = p;
      if (Dm[p * ld + k] == 0.0) return false;
      // the pivot row, scaled, in a local copy: the row updates then read memory they do not
      // write, and vectorise
      alignas(32) double pk[ld];
      const double inv = 1.0 / Dm[p * ld + k];
      for (int c = 0; c < ld; ++c) pk[c] = Dm[p * ld + c] * inv;
      pk[k] = inv;
      if (p != k)
        for (int c = 0; c < ld; ++c) Dm[p * ld + c] = Dm[k * ld + c];
      for (int r = 0; r < s; ++r) {
        if (r == k) continue;
        const double f = Dm[r * ld + k];
        Dm[r * ld + k] = 0.0;
        for (int c = 0; c < ld; c += 4) store4(Dm + r * ld + c, load4(Dm + r * ld + c) - f * load4(pk + c));
      }
      for (int c = 0; c < ld; ++c) Dm[k * ld + c] = pk[c];
    }
    for (int k = s - 1; k >= 0; --k)
      if (perm[k] != k)
        for (int r = 0; r < s; ++r) std::swap(Dm[r * ld + k], Dm[r * ld + perm[k]]);
    return true;
  }

  /// Copies and zeroes of whole blocks as 4-wide vectors (a library call's start-up costs
  /// more than the 16 stores of a block of 8).
  template <std::size_t m>
  static void copy_block(const double* src, double* dst) {
    static_assert(m % 4 == 0);
#pragma GCC unroll 16
    for (std::size_t e = 0; e < m; e += 4) store4(dst + e, load4(src + e));
  }
  template <std::size_t m>
  static void zero_block(double* dst) {
    static_assert(m % 4 == 0);
#pragma GCC unroll 16
    for (std::size_t e = 0; e < m; e += 4) store4(dst + e, V4{});
  }

  /// Largest |x_e| of m entries, in four independent chains.
  template <std::size_t m>
  static double max_abs(const double* x) {
    double a0 = 0, a1 = 0, a2 = 0, a3 = 0;
    std::size_t e = 0;
    for (; e + 4 <= m; e += 4) {
      a0 = std::max(a0, std::abs(x[e])), a1 = std::max(a1, std::abs(x[e + 1]));
      a2 = std::max(a2, std::abs(x[e + 2])), a3 = std::max(a3, std::abs(x[e + 3]));
    }
    if constexpr (m % 4 != 0)
      for (; e < m; ++e) a0 = std::max(a0, std::abs(x[e]));
    return std::max(std::max(a0, a1), std::max(a2, a3));
  }

  template <int s>
  bool factor_cells(SUNMatrix M) {
    constexpr int ld = lead(s);
    constexpr std::size_t SS = std::size_t(s) * ld;
    growth = 0;
    // local copies: the compiler sees that they do not alias, and vectorises the updates
    alignas(32) double L[SS] = {}, Dm[SS] = {}, Uk[SS] = {};
    lpos.clear(), lval.clear();
    for (long k = 0; k < N; ++k) {
      if (!gather<s>(M, k, L, Dm, Uk)) return false;
      lbeg[k] = int(lpos.size());
      for (int e = 0; e < int(SS); ++e)
        if (L[e] != 0.0) lpos.push_back(e), lval.push_back(L[e]);
      lbeg[k + 1] = int(lpos.size());
      if (k > 0) {  // D -= L_k Up_{k-1} over the nonzeros of L_k (about one per column)
        const double* Pp = Up.data() + (k - 1) * SS;
        for (int e = lbeg[k]; e < lbeg[k + 1]; ++e) {
          const int r = lpos[e] % ld, c = lpos[e] / ld;
          const double l = lval[e];
          for (int q = 0; q < s; ++q) Dm[q * ld + r] -= l * Pp[q * ld + c];
        }
      }
      const double dmax = max_abs<SS>(Dm);
      double* Di = Dinv.data() + k * SS;
      if (!invert<s>(Dm, Di)) return false;
      growth = std::max(growth, dmax * max_abs<SS>(Di) * s);
      if (k > 0) {  // D_k^{-1} L_k: column c takes D^{-1}'s column r times L(r, c)
        double* P = DL.data() + k * SS;
        zero_block<SS>(P);
        for (int e = lbeg[k]; e < lbeg[k + 1]; ++e) {
          const int r = lpos[e] % ld, c = lpos[e] / ld;
          const V4 l = V4{} + lval[e];
          for (int q = 0; q < ld; q += 4) store4(P + c * ld + q, load4(P + c * ld + q) + load4(Di + r * ld + q) * l);
        }
      }
      if (k + 1 < N) {  // Up_k = D_k^{-1} U_k: column c takes D^{-1}'s column r times U(r, c)
        double* P = Up.data() + k * SS;
        zero_block<SS>(P);
        for (int c = 0; c < s; ++c)
          for (int r = 0; r < s; ++r) {
            const double u = Uk[c * ld + r];
            if (u == 0.0) continue;
            for (int q = 0; q < ld; q += 4) store4(P + c * ld + q, load4(P + c * ld + q) + load4(Di + r * ld + q) * u);
          }
      }
    }
    return true;
  }

  /// Factor; false if the matrix leaves the block structure or a diagonal block is singular.
  bool factor(SUNMatrix M) {
    // border rows: G (border columns) and F (cell columns)
    std::fill(G.begin(), G.end(), 0.0);
    F.clear();
    for (int q = 0; q < nb; ++q) {
      const long i = border[q];
      for (long j = std::max(0L, i - long(SM_LBAND_B(M))); j <= std::min(n - 1, i + long(SM_UBAND_B(M))); ++j) {
        const double v = band_at(M, i, j);
        if (v == 0.0) continue;
        if (bpos[j] >= 0)
          G[std::size_t(bpos[j]) * nb + q] = v;
        else
          F.push_back({q, j, v});
      }
    }
    bool ok = false;
    if (!with_block_size(S, [&](auto c) { ok = factor_cells<decltype(c)::value>(M); })) return false;
    return ok && (nb == 0 || small_lu(G, gpiv, nb));
  }

  /// y = A x for the column-major s x s matrix A (stride ld, padding rows zero), in two
  /// independent chains of whole-vector column updates.
  template <int s>
  static void matvec(const double* A, const double* x, double* y) {
    constexpr int ld = lead(s);
    constexpr int nv = ld / 4;
    V4 y0[nv] = {}, y1[nv] = {};
    int c = 0;
    for (; c + 1 < s; c += 2)
      for (int i = 0; i < nv; ++i)
        y0[i] += load4(A + c * ld + 4 * i) * x[c], y1[i] += load4(A + (c + 1) * ld + 4 * i) * x[c + 1];
    if constexpr (s % 2 == 1)
      for (int i = 0; i < nv; ++i) y0[i] += load4(A + (s - 1) * ld + 4 * i) * x[s - 1];
    for (int i = 0; i < nv; ++i) store4(y + 4 * i, y0[i] + y1[i]);
  }

  /// y = a - A x for the column-major s x s matrix A (stride ld, padding rows zero), in four
  /// independent chains: the sweeps' step from cell to cell, whose latency (x arrives, the
  /// products, their sum) is the solve's critical path. y may alias a, not x.
  template <int s>
  static void matvec_sub(const double* A, const double* x, const double* a, double* y) {
    constexpr int ld = lead(s);
    constexpr int nv = ld / 4;
    V4 y0[nv], y1[nv] = {}, y2[nv] = {}, y3[nv] = {};
    for (int i = 0; i < nv; ++i) y0[i] = load4(a + 4 * i);
    int c = 0;
    for (; c + 3 < s; c += 4)
      for (int i = 0; i < nv; ++i) {
        y0[i] -= load4(A + c * ld + 4 * i) * x[c];
        y1[i] -= load4(A + (c + 1) * ld + 4 * i) * x[c + 1];
        y2[i] -= load4(A + (c + 2) * ld + 4 * i) * x[c + 2];
        y3[i] -= load4(A + (c + 3) * ld + 4 * i) * x[c + 3];
      }
    for (; c < s; ++c)
      for (int i = 0; i < nv; ++i) y1[i] -= load4(A + c * ld + 4 * i) * x[c];
    for (int i = 0; i < nv; ++i) store4(y + 4 * i, (y0[i] + y1[i]) + (y2[i] + y3[i]));
  }

  template <int s>
  void solve_cells(double* b) {
    constexpr int ld = lead(s);
    constexpr std::size_t SS = std::size_t(s) * ld;
    if constexpr (s == ld) {  // whole vectors in place, no copies (blocks of 4, 8, 12)
      constexpr int nv = ld / 4;
      alignas(32) double Ly[ld] = {};
      for (long k = 0; k < N; ++k) {  // y_k = D_k^{-1} b_k - (D_k^{-1} L_k) y_{k-1}
        double* bk = b + o + k * s;
        matvec<s>(Dinv.data() + k * SS, bk, Ly);
        if (k > 0)
          matvec_sub<s>(DL.data() + k * SS, bk - s, Ly, bk);
        else
          for (int v = 0; v < nv; ++v) store4(bk + 4 * v, load4(Ly + 4 * v));
      }
      const double* x = b + o + (N - 1) * s;
      for (long k = N - 2; k >= 0; --k) {  // x_k = y_k - Up_k x_{k+1}
        double* xk = b + o + k * s;
        matvec_sub<s>(Up.data() + k * SS, x, xk, xk);
        x = xk;
      }
      return;
    }
    alignas(32) double T[ld] = {}, y[ld] = {}, x[ld] = {}, Ly[ld] = {};
    for (long k = 0; k < N; ++k) {  // y_k = D_k^{-1} b_k - (D_k^{-1} L_k) y_{k-1}
      double* bk = b + o + k * s;
      for (int i = 0; i < s; ++i) T[i] = bk[i];
      matvec<s>(Dinv.data() + k * SS, T, Ly);
      if (k > 0) {
        matvec<s>(DL.data() + k * SS, y, T);
        for (int i = 0; i < s; ++i) y[i] = Ly[i] - T[i];
      } else {
        for (int i = 0; i < s; ++i) y[i] = Ly[i];
      }
      for (int i = 0; i < s; ++i) bk[i] = y[i];
    }
    for (int i = 0; i < ld; ++i) x[i] = y[i];  // x_{N-1} = y_{N-1}
    for (long k = N - 2; k >= 0; --k) {        // x_k = y_k - Up_k x_{k+1}
      double* xk = b + o + k * s;
      matvec<s>(Up.data() + k * SS, x, T);
      for (int i = 0; i < s; ++i) x[i] = xk[i] - T[i], xk[i] = x[i];
    }
  }

  /// One right-hand side: per cell, dense s x s products as column updates (vectorised
  /// across the block's rows).
  void solve(double* b) {
    with_block_size(S, [&](auto c) { solve_cells<decltype(c)::value>(b); });
    if (nb == 0) return;
    for (int q = 0; q < nb; ++q) bt[q] = b[border[q]];  // G x_B = b_B - F x_T
    for (const Entry& e : F) bt[e.row] -= e.v * b[e.col];
    small_solve(G, gpiv, nb, bt.data());
    for (int q = 0; q < nb; ++q) b[border[q]] = bt[q];
  }
};

// Above this bound on a diagonal block's condition (max-norm estimate), a setup factors the
// band with partial pivoting across cells instead.
constexpr double kBlockGrowthLimit = 1e14;

struct LowRankContent {
  BandLU lu;
  BlockTri bt;
  bool blocks = false;     // the block structure is known (make_low_rank_block_solver)
  bool block_now = false;  // the last setup factored by blocks
  LowRankTerm* term = nullptr;
  int rank = 0;     // rank used at the last setup
  double s = 1.0;   // scale at the last setup
  long n = 0;
  std::vector<double> Qc;  // Q, column-major n x rank (U = Q R, Q orthonormal); setup workspace
  std::vector<double> Z;   // M^{-1} Q, column-major n x rank
  std::vector<double> W;   // V R^T, column-major n x rank: U V^T = Q W^T
  std::vector<double> R;   // rank x rank, column-major
  std::vector<double> S;   // I + s W^T Z, LU-factored in place (rank x rank)
  std::vector<int> piv;
  std::vector<double> w;   // rank workspace
  int last = 0;
  bool factored = false;  // the last setup completed (a kept factorisation is usable)
};
LowRankContent* lr(SUNLinearSolver S) { return static_cast<LowRankContent*>(S->content); }

SUNLinearSolver_Type lr_type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID lr_id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int lr_init(SUNLinearSolver) { return 0; }
sunindextype lr_lastflag(SUNLinearSolver S) { return lr(S)->last; }

int lr_setup(SUNLinearSolver S, SUNMatrix A) {
  LowRankContent* c = lr(S);
  if (c->term->keep_factorisation && c->factored) return 0;
  c->factored = false;
  c->block_now = c->blocks && c->bt.factor(A) && c->bt.growth < kBlockGrowthLimit;
  if (!c->block_now) {
    c->lu.load(A);
    if (!c->lu.factor()) return c->last = SUNLS_LUFACT_FAIL;
  }
  c->last = 0;
  const LowRankTerm& t = *c->term;
  c->rank = t.rank;
  c->s = t.scale ? t.scale(t.scale_ctx) : 1.0;
  const int r = c->rank;
  const long n = c->n;
  if (r == 0) {
    c->factored = true;
    return 0;
  }
  // Orthonormalise the columns of U (modified Gram-Schmidt, twice): U V^T = Q (V R^T)^T.
  // The terms may differ in scale by many decades and be nearly parallel; without this the
  // capacitance matrix I + s V^T M^{-1} U is numerically singular even when M + s U V^T is not.
  std::vector<double>& Q = c->Qc;
  Q.assign(t.U.begin(), t.U.begin() + n * r);
  c->R.assign(std::size_t(r) * r, 0.0);
  for (int k = 0; k < r; ++k) {
    double* qk = Q.data() + n * k;
    for (int pass = 0; pass < 2; ++pass)
      for (int j = 0; j < k; ++j) {
        const double* qj = Q.data() + n * j;
        const double d = swim::dot4(qj, qk, n);
        c->R[std::size_t(k) * r + j] += d;
        for (long i = 0; i < n; ++i) qk[i] -= d * qj[i];
      }
    const double nrm = std::sqrt(swim::dot4(qk, qk, n));
    c->R[std::size_t(k) * r + k] = nrm;
    if (nrm > 0) {
      const double inv = 1.0 / nrm;
      for (long i = 0; i < n; ++i) qk[i] *= inv;
    }
  }
  // Z = M^{-1} Q and W = V R^T, column-major (n x r): the passes of lr_solve are then r
  // contiguous dot products and r contiguous updates.
  c->Z.assign(Q.begin(), Q.begin() + n * r);
  c->W.assign(std::size_t(n) * r, 0.0);
  for (int i = 0; i < r; ++i) {  // W(:, i) = sum_{k >= i} V(:, k) R(i, k)
    double* Wi = c->W.data() + std::size_t(i) * n;
    for (int k = i; k < r; ++k) {
      const double f = c->R[std::size_t(k) * r + i];
      const double* Vk = t.V.data() + std::size_t(k) * n;
      for (long m = 0; m < n; ++m) Wi[m] += Vk[m] * f;
    }
  }
  for (int i = 0; i < r; ++i) {
    double* Zi = c->Z.data() + std::size_t(i) * n;
    if (c->block_now)
      c->bt.solve(Zi);
    else
      c->lu.solve(Zi);
  }
  // S = I + s W^T Z
  c->S.assign(std::size_t(r) * r, 0.0);
  for (int j = 0; j < r; ++j)
    for (int i = 0; i < r; ++i)
      c->S[std::size_t(j) * r + i] = swim::dot4(c->W.data() + std::size_t(i) * n, c->Z.data() + std::size_t(j) * n, n);
  for (int i = 0; i < r * r; ++i) c->S[i] *= c->s;
  for (int i = 0; i < r; ++i) c->S[std::size_t(i) * r + i] += 1.0;
  c->piv.assign(r, 0);
  c->w.assign(r, 0.0);
  if (!small_lu(c->S, c->piv, r)) return c->last = SUNLS_LUFACT_FAIL;
  c->factored = true;
  return 0;
}

int lr_solve(SUNLinearSolver S, SUNMatrix, N_Vector x, N_Vector b, realtype) {
  LowRankContent* c = lr(S);
  const long n = c->n;
  double* xd = N_VGetArrayPointer(x);
  const double* bd = N_VGetArrayPointer(b);
  if (xd != bd) std::copy(bd, bd + n, xd);
  if (c->block_now)
    c->bt.solve(xd);
  else
    c->lu.solve(xd);
  c->last = 0;
  if (c->rank == 0) return 0;
  const int r = c->rank;
  // x <- x - Z (I + s W^T Z)^{-1} s W^T x: r dot products, then r updates
  double* w = c->w.data();
  for (int i = 0; i < r; ++i) w[i] = c->s * swim::dot4(c->W.data() + std::size_t(i) * n, xd, n);
  small_solve(c->S, c->piv, r, w);
  for (int j = 0; j < r; ++j) {
    const double* Zj = c->Z.data() + std::size_t(j) * n;
    const double wj = w[j];
    for (long m = 0; m < n; ++m) xd[m] -= Zj[m] * wj;
  }
  return 0;
}

int lr_free(SUNLinearSolver S) {
  if (!S) return 0;
  if (S->content) {
    delete lr(S);
    S->content = nullptr;
  }
  SUNLinSolFreeEmpty(S);
  return 0;
}
}  // namespace

bool factored_by_blocks(SUNLinearSolver S) { return S->content && lr(S)->block_now; }

LinearSolver make_low_rank_block_solver(N_Vector y, SUNMatrix A, LowRankTerm* term, const CellBlocks& cells,
                                        SUNContext ctx) {
  LinearSolver S = make_low_rank_band_solver(y, A, term, ctx);
  LowRankContent* c = lr(S.get());
  if (BlockTri::supported(cells.block) && cells.count > 0 && cells.offset >= 0 &&
      cells.offset + cells.block * cells.count <= c->n) {
    c->bt.resize(c->n, cells);
    c->blocks = true;
  }
  return S;
}

LinearSolver make_low_rank_band_solver(N_Vector y, SUNMatrix A, LowRankTerm* term, SUNContext ctx) {
  SUNLinearSolver S = check_ptr(SUNLinSolNewEmpty(ctx), "SUNLinSolNewEmpty");
  auto* c = new LowRankContent;
  c->term = term;
  c->n = N_VGetLength(y);
  c->lu.resize(c->n, int(SM_LBAND_B(A)), int(SM_UBAND_B(A)));
  S->content = c;
  S->ops->gettype = lr_type;
  S->ops->getid = lr_id;
  S->ops->initialize = lr_init;
  S->ops->setup = lr_setup;
  S->ops->solve = lr_solve;
  S->ops->lastflag = lr_lastflag;
  S->ops->free = lr_free;
  return LinearSolver(S);
}

}  // namespace swim::reduced1d::sun
