#include "full3d/operators.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "full3d/parallel.hpp"

namespace swim::full3d {

namespace {
inline int wrap(int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); }
}  // namespace

void divergence(const MacGrid& g, const VectorField& u, ScalarField& div) {
  const int nx = g.nx(), ny = g.ny(), nz = g.nz();
  const double ih = 1.0 / g.h();
  const auto du = g.dims(0), dv = g.dims(1), dw = g.dims(2), dp = g.dims(3);
  const bool py = g.periodic(1), pz = g.periodic(2);
  div.v.assign(g.cells(), 0.0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int ip = wrap(i + 1, nx);
        const int jp = py ? wrap(j + 1, ny) : j + 1;
        const int kp = pz ? wrap(k + 1, nz) : k + 1;
        div.v[MacGrid::index(dp, i, j, k)] =
            ih * (u.c[0][MacGrid::index(du, ip, j, k)] - u.c[0][MacGrid::index(du, i, j, k)] +
                  u.c[1][MacGrid::index(dv, i, jp, k)] - u.c[1][MacGrid::index(dv, i, j, k)] +
                  u.c[2][MacGrid::index(dw, i, j, kp)] - u.c[2][MacGrid::index(dw, i, j, k)]);
      }
}

double max_abs_divergence(const MacGrid& g, const VectorField& u, int threads) {
  const int nx = g.nx(), ny = g.ny(), nz = g.nz();
  const double ih = 1.0 / g.h();
  const auto du = g.dims(0), dv = g.dims(1), dw = g.dims(2);
  const bool py = g.periodic(1), pz = g.periodic(2);
  const int T = block_count(nz, threads);
  std::vector<double> part(std::size_t(T), 0.0);
  parallel_blocks(nz, T, [&](long kb, long ke, int t) {
    double m = 0.0;
    bool finite = true;
    for (int k = int(kb); k < int(ke); ++k)
      for (int j = 0; j < ny; ++j) {
        const int jp = py ? wrap(j + 1, ny) : j + 1;
        const int kp = pz ? wrap(k + 1, nz) : k + 1;
        const double* u0 = &u.c[0][MacGrid::index(du, 0, j, k)];
        const double* v0 = &u.c[1][MacGrid::index(dv, 0, j, k)];
        const double* v1 = &u.c[1][MacGrid::index(dv, 0, jp, k)];
        const double* w0 = &u.c[2][MacGrid::index(dw, 0, j, k)];
        const double* w1 = &u.c[2][MacGrid::index(dw, 0, j, kp)];
        for (int i = 0; i < nx; ++i) {
          const int ip = i + 1 < nx ? i + 1 : 0;
          const double d = std::abs(u0[ip] - u0[i] + v1[i] - v0[i] + w1[i] - w0[i]);
          finite = finite && std::isfinite(d);
          m = std::max(m, d);
        }
      }
    part[std::size_t(t)] = finite ? m : std::numeric_limits<double>::quiet_NaN();
  });
  double m = 0.0;
  for (double x : part) {
    if (!std::isfinite(x)) return std::numeric_limits<double>::quiet_NaN();
    m = std::max(m, x);
  }
  return ih * m;
}

void gradient(const MacGrid& g, const ScalarField& p, VectorField& grad) {
  const double ih = 1.0 / g.h();
  const auto dp = g.dims(3);
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    auto& out = grad.c[c];
    out.assign(g.size(c), 0.0);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          const int idx[3] = {i, j, k};
          if (g.on_wall(c, c, idx[c])) continue;
          int m[3] = {i, j, k};
          m[c] = g.periodic(c) ? wrap(idx[c] - 1, g.n(c)) : idx[c] - 1;
          out[MacGrid::index(d, i, j, k)] =
              ih * (p.v[MacGrid::index(dp, i, j, k)] - p.v[MacGrid::index(dp, m[0], m[1], m[2])]);
        }
  }
}

void laplacian(const MacGrid& g, const VectorField& u, VectorField& lap) {
  const double ih2 = 1.0 / (g.h() * g.h());
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    const auto& in = u.c[c];
    auto& out = lap.c[c];
    out.assign(g.size(c), 0.0);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          const int idx[3] = {i, j, k};
          bool wall = false;
          for (int dir = 0; dir < 3; ++dir) wall = wall || g.on_wall(c, dir, idx[dir]);
          if (wall) continue;
          const double uc = in[MacGrid::index(d, i, j, k)];
          double acc = 0.0;
          for (int dir = 0; dir < 3; ++dir) {
            for (int s = -1; s <= 1; s += 2) {
              int m[3] = {i, j, k};
              const int t = idx[dir] + s;
              double val;
              if (g.periodic(dir)) {
                m[dir] = wrap(t, g.n(dir));
                val = in[MacGrid::index(d, m[0], m[1], m[2])];
              } else if (t < 0 || t >= d[dir]) {
                val = -uc;  // ghost cell of a tangential component: zero on the wall
              } else {
                m[dir] = t;
                val = in[MacGrid::index(d, m[0], m[1], m[2])];  // wall faces hold zero
              }
              acc += val;
            }
            acc -= 2.0 * uc;
          }
          out[MacGrid::index(d, i, j, k)] = ih2 * acc;
        }
  }
}

void zero_wall_faces(const MacGrid& g, VectorField& u) {
  for (int c = 1; c < 3; ++c) {
    if (g.periodic(c)) continue;
    const auto d = g.dims(c);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          const int idx[3] = {i, j, k};
          if (g.on_wall(c, c, idx[c])) u.c[c][MacGrid::index(d, i, j, k)] = 0.0;
        }
  }
}

}  // namespace swim::full3d
