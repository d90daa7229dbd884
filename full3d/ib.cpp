#include "full3d/ib.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "full3d/kernel.hpp"
#include "full3d/parallel.hpp"

namespace swim::full3d {

namespace {

/// i mod n in [0, n).
inline int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

// The 4 stencil indices and weights phi(.) of one node along one direction;
// invalid points (outside the fluid or on a fixed wall face) get weight 0 and index 0.
// The valid points are m = m0 .. m1-1 (contiguous: the invalid ones sit at the ends).
struct Stencil1d {
  int idx[4];
  double w[4];
  int m0, m1;
};

// Stencil along `dir` for the grid nodes of a component with staggering offset 0 along dir
// (normal = true: the component normal to the dir-faces, e.g. v along y) or 1/2 (normal =
// false). Same as MacGrid::offset/dims/on_wall for a component c with (c == dir) == normal.
// xh = x / h (node coordinate in cells).
inline Stencil1d stencil(const MacGrid& g, int dir, bool normal, double xh) {
  Stencil1d s;
  const double r = normal ? xh : xh - 0.5;
  const double fl = std::floor(r);
  peskin_4pt_weights(r - fl, s.w);  // points i0 .. i0+3 at distances 1+t, t, 1-t, 2-t
  const int i0 = int(fl) - 1;
  const int n = g.n(dir);
  if (g.periodic(dir)) {
    int i = wrap(i0, n);
    for (int m = 0; m < 4; ++m) {
      s.idx[m] = i;
      if (++i == n) i = 0;
    }
    s.m0 = 0;
    s.m1 = 4;
  } else {
    const int nstore = normal ? n + 1 : n;  // the wall-normal component has faces 0..n
    for (int m = 0; m < 4; ++m) {
      const int i = i0 + m;
      if (i < 0 || i >= nstore || (normal && (i == 0 || i == n))) {  // outside, or a no-slip wall face
        s.idx[m] = 0;
        s.w[m] = 0.0;
      } else {
        s.idx[m] = i;
      }
    }
    // valid: i in [normal ? 1 : 0, n - 1]
    s.m0 = std::clamp((normal ? 1 : 0) - i0, 0, 4);
    s.m1 = std::clamp(n - i0, s.m0, 4);
  }
  return s;
}

// The y and z stencils of one node: [dir - 1][normal]. Component c uses [d-1][c == d].
struct NodeStencilsYZ {
  Stencil1d s[2][2];
};

inline NodeStencilsYZ stencils_yz(const MacGrid& g, double y, double z) {
  NodeStencilsYZ n;
  const double yh = y / g.h(), zh = z / g.h();
  n.s[0][0] = stencil(g, 1, false, yh);
  n.s[0][1] = stencil(g, 1, true, yh);
  n.s[1][0] = stencil(g, 2, false, zh);
  n.s[1][1] = stencil(g, 2, true, zh);
  return n;
}

}  // namespace

namespace {

/// The support of a spread from the nodes X: the cells within 3 of a node's cell in every
/// direction (a stencil reaches 2 cells either way, the staggered components half a cell
/// more), the whole direction where that covers it, where it crosses a periodic y or z seam,
/// or where a node is not finite.
SpreadSupport support_of(const MacGrid& g, const Eigen::Matrix3Xd& X) {
  SpreadSupport s;
  s.valid = true;
  constexpr int kMargin = 3;
  for (int d = 0; d < 3; ++d) {
    const int n = g.n(d);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (Eigen::Index k = 0; k < X.cols(); ++k) {
      const double v = X(d, k) / g.h();
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    s.whole[d] = true;
    if (!(std::isfinite(lo) && std::isfinite(hi)) || hi - lo > 4.0 * n) continue;
    s.lo[d] = int(std::floor(lo)) - kMargin;
    s.hi[d] = int(std::floor(hi)) + kMargin;
    if (s.hi[d] - s.lo[d] + 1 >= n) continue;
    if (d > 0 && g.periodic(d) && (s.lo[d] < 0 || s.hi[d] >= n)) continue;
    s.whole[d] = false;
  }
  return s;
}

// f (+)= spread(F); with zero_first, each thread first zeroes its own z planes of f within
// `zero`'s box (whole in every direction by default).
void spread_impl(const MacGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, VectorField& f,
                 int threads, bool zero_first, const SpreadSupport& zero = SpreadSupport{}) {
  const long N = long(X.cols());
  if (N == 0 && !zero_first) return;
  const double ih3 = 1.0 / (g.h() * g.h() * g.h());
  const int nx = g.nx(), nz = g.nz();
  const bool zper = g.periodic(2);
  const std::array<int, 3> dims[3] = {g.dims(0), g.dims(1), g.dims(2)};
  const int T = block_count(nz, threads);

  // Ownership of the z planes (z is the slowest index: each thread's planes are one
  // contiguous block of every component, so no cache line is written by two threads):
  // thread t adds only to planes [bound[t], bound[t+1]) (the last block also holds the
  // wall plane nz of w in the duct). The block edges sit at quantiles of the nodes' z
  // cells so that every thread gets about as many nodes; the result does not depend on
  // where they sit (see ib.hpp).
  std::vector<int> bound(T + 1, 0), cell;
  bound[T] = nz + 1;
  if (T > 1) {
    cell.resize(N);
    std::vector<long> count(nz + 1, 0);  // count[p] = nodes in cells < p after the prefix sum
    for (long k = 0; k < N; ++k) {
      const int cz = int(std::floor(X(2, k) / g.h()));
      cell[k] = zper ? wrap(cz, nz) : std::clamp(cz, -8, nz + 8);  // clamped far outside the duct
      ++count[std::clamp(cell[k], 0, nz - 1) + 1];
    }
    for (int p = 0; p < nz; ++p) count[p + 1] += count[p];
    for (int t = 1; t < T; ++t)
      bound[t] = int(std::lower_bound(count.begin(), count.end(), N * t / T) - count.begin());
    for (int t = 1; t < T; ++t) bound[t] = std::clamp(bound[t], bound[t - 1], nz);
  }

  parallel_blocks(T, T, [&](long tb, long, int) {
    const int t = int(tb), lo = bound[t], hi = bound[t + 1];
    if (hi <= lo) return;
    if (zero_first)  // the support's box of the thread's planes (all of them for an unknown support)
      for (int c = 0; c < 3; ++c) {
        const auto& d = dims[c];
        // y and z: clamped (a periodic seam crossing makes the support whole there); x: up to
        // two runs across the periodic seam
        const int z0 = std::max(lo, zero.whole[2] ? 0 : std::max(0, zero.lo[2]));
        const int z1 = std::min({hi, d[2], zero.whole[2] ? d[2] : zero.hi[2] + 1});
        const int y0 = zero.whole[1] ? 0 : std::max(0, zero.lo[1]);
        const int y1 = zero.whole[1] ? d[1] : std::min(d[1], zero.hi[1] + 1);
        int runs[2][2] = {{0, d[0]}, {0, 0}};
        if (!zero.whole[0]) {
          const int a = wrap(zero.lo[0], d[0]), len = zero.hi[0] - zero.lo[0] + 1;
          runs[0][0] = a;
          runs[0][1] = std::min(d[0], a + len);
          runs[1][1] = a + len - runs[0][1];  // the part past the seam, from 0
        }
        double* out = f.c[c].data();
        for (int zz = z0; zz < z1; ++zz)
          for (int yy = y0; yy < y1; ++yy) {
            double* row = out + (std::size_t(zz) * d[1] + yy) * d[0];
            for (const auto& r : runs)
              if (r[1] > r[0]) std::fill(row + r[0], row + r[1], 0.0);
          }
      }
    for (long k = 0; k < N; ++k) {
      if (T > 1) {
        // the z stencils of a node in cell cz = floor(z/h) lie within planes cz-2 .. cz+2
        // (i0 = floor(z/h) - 1 for w, floor(z/h - 1/2) - 1 >= cz - 2 for u, v)
        if (zper) {
          const int s = wrap(cell[k] - 2 - lo, nz);  // planes lo + s .. lo + s + 4 (mod nz)
          if (!(s < hi - lo || s + 4 >= nz)) continue;
        } else if (cell[k] + 2 < lo || cell[k] - 2 >= hi) {
          continue;
        }
      }
      // x stencils (x is periodic): [0] staggered (v, w), [1] normal (u)
      const Stencil1d sx[2] = {stencil(g, 0, false, X(0, k) / g.h()), stencil(g, 0, true, X(0, k) / g.h())};
      const NodeStencilsYZ yz = stencils_yz(g, X(1, k), X(2, k));
      for (int c = 0; c < 3; ++c) {
        const double Fc = F(c, k) * ih3;
        if (Fc == 0.0) continue;
        const Stencil1d& sxc = sx[c == 0];
        const Stencil1d& sy = yz.s[0][c == 1];
        const Stencil1d& sz = yz.s[1][c == 2];
        const auto& d = dims[c];
        // the x weights are kept in registers (copies), so that the compiler need not
        // reload them after every store into the field
        const double w0 = sxc.w[0], w1 = sxc.w[1], w2 = sxc.w[2], w3 = sxc.w[3];
        const int i0 = sxc.idx[0];
        const bool contiguous = i0 + 3 < nx;  // not wrapping across the periodic seam
        const std::size_t nx0 = std::size_t(d[0]), ny0 = std::size_t(d[1]);
        double* out = f.c[c].data();
        // x offsets of the 4 points (contiguous unless wrapping across the periodic seam)
        const int j0 = contiguous ? i0 : sxc.idx[0], j1 = contiguous ? i0 + 1 : sxc.idx[1],
                  j2 = contiguous ? i0 + 2 : sxc.idx[2], j3 = contiguous ? i0 + 3 : sxc.idx[3];
        for (int a = sz.m0; a < sz.m1; ++a) {
          if (sz.idx[a] < lo || sz.idx[a] >= hi) continue;  // another thread's plane
          const double wz = sz.w[a];
          double* plane = out + std::size_t(sz.idx[a]) * ny0 * nx0;
          for (int b = sy.m0; b < sy.m1; ++b) {
            const double q = wz * sy.w[b] * Fc;  // same products as the serial formula
            double* r = plane + std::size_t(sy.idx[b]) * nx0;
            if (contiguous) {
              r += i0;
              r[0] += q * w0;
              r[1] += q * w1;
              r[2] += q * w2;
              r[3] += q * w3;
            } else {
              r[j0] += q * w0;
              r[j1] += q * w1;
              r[j2] += q * w2;
              r[j3] += q * w3;
            }
          }
        }
      }
    }
  });
}

}  // namespace

void spread_add(const MacGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, VectorField& f,
                int threads) {
  spread_impl(g, X, F, f, threads, false);
}

void spread(const MacGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, VectorField& f,
            int threads, SpreadSupport* support) {
  SpreadSupport zero;  // invalid: the whole field
  if (f.c[0].size() != g.size(0) || f.c[1].size() != g.size(1) || f.c[2].size() != g.size(2))
    f = VectorField(g);
  else if (support)
    zero = *support;
  spread_impl(g, X, F, f, threads, true, zero);
  if (support) *support = support_of(g, X);
}

void interpolate(const MacGrid& g, const VectorField& u, const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd& U,
                 int threads) {
  U.resize(3, X.cols());
  const std::array<int, 3> dims[3] = {g.dims(0), g.dims(1), g.dims(2)};
  parallel_blocks(long(X.cols()), threads, [&](long kb, long ke, int) {
    for (long k = kb; k < ke; ++k) {
      const Stencil1d sx[2] = {stencil(g, 0, false, X(0, k) / g.h()), stencil(g, 0, true, X(0, k) / g.h())};
      const NodeStencilsYZ yz = stencils_yz(g, X(1, k), X(2, k));
      for (int c = 0; c < 3; ++c) {
        const Stencil1d& sxc = sx[c == 0];
        const Stencil1d& sy = yz.s[0][c == 1];
        const Stencil1d& sz = yz.s[1][c == 2];
        const auto& d = dims[c];
        const double* in = u.c[c].data();
        const double w0 = sxc.w[0], w1 = sxc.w[1], w2 = sxc.w[2], w3 = sxc.w[3];
        const int i0 = sxc.idx[0];
        const bool contiguous = sxc.idx[3] == i0 + 3;  // not wrapping across the periodic seam
        double acc = 0.0;
        for (int a = sz.m0; a < sz.m1; ++a) {
          for (int b = sy.m0; b < sy.m1; ++b) {
            const double wzy = sz.w[a] * sy.w[b];
            const double* row = in + (std::size_t(sz.idx[a]) * d[1] + sy.idx[b]) * d[0];
            double accx;
            if (contiguous) {
              const double* r = row + i0;
              accx = w0 * r[0] + w1 * r[1] + w2 * r[2] + w3 * r[3];
            } else {
              accx = w0 * row[sxc.idx[0]] + w1 * row[sxc.idx[1]] + w2 * row[sxc.idx[2]] + w3 * row[sxc.idx[3]];
            }
            acc += wzy * accx;
          }
        }
        U(c, k) = acc;  // h^3 * (1/h^3) weights cancel
      }
    }
  });
}

}  // namespace swim::full3d
