#include "full3d/ib.hpp"

#include <cmath>

#include "full3d/kernel.hpp"

namespace swim::full3d {

namespace {

// The 4 stencil indices and weights phi(.) of one node along one direction for
// component c; invalid (outside the fluid or on a fixed wall face) get weight 0.
struct Stencil1d {
  int idx[4];
  double w[4];
};

Stencil1d stencil(const MacGrid& g, int c, int dir, double x) {
  Stencil1d s;
  const double r = x / g.h() - MacGrid::offset(c, dir);
  const int i0 = int(std::floor(r)) - 1;
  const int n = g.n(dir);
  const int nstore = g.dims(c)[dir];
  for (int m = 0; m < 4; ++m) {
    const int i = i0 + m;
    s.w[m] = peskin_4pt(r - i);
    if (g.periodic(dir)) {
      s.idx[m] = ((i % n) + n) % n;
    } else if (i < 0 || i >= nstore || g.on_wall(c, dir, i)) {
      s.idx[m] = 0;
      s.w[m] = 0.0;
    } else {
      s.idx[m] = i;
    }
  }
  return s;
}

}  // namespace

void spread_add(const MacGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, VectorField& f) {
  const double ih3 = 1.0 / (g.h() * g.h() * g.h());
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    auto& out = f.c[c];
    for (Eigen::Index k = 0; k < X.cols(); ++k) {
      const double Fc = F(c, k) * ih3;
      if (Fc == 0.0) continue;
      const Stencil1d sx = stencil(g, c, 0, X(0, k)), sy = stencil(g, c, 1, X(1, k)), sz = stencil(g, c, 2, X(2, k));
      for (int a = 0; a < 4; ++a) {
        if (sz.w[a] == 0.0) continue;
        for (int b = 0; b < 4; ++b) {
          const double wzy = sz.w[a] * sy.w[b] * Fc;
          if (wzy == 0.0) continue;
          const std::size_t row = (std::size_t(sz.idx[a]) * d[1] + sy.idx[b]) * d[0];
          for (int e = 0; e < 4; ++e) out[row + sx.idx[e]] += wzy * sx.w[e];
        }
      }
    }
  }
}

void spread(const MacGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, VectorField& f) {
  if (f.c[0].size() != g.size(0)) f = VectorField(g);
  f.fill(0.0);
  spread_add(g, X, F, f);
}

void interpolate(const MacGrid& g, const VectorField& u, const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd& U) {
  U.resize(3, X.cols());
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    const auto& in = u.c[c];
    for (Eigen::Index k = 0; k < X.cols(); ++k) {
      const Stencil1d sx = stencil(g, c, 0, X(0, k)), sy = stencil(g, c, 1, X(1, k)), sz = stencil(g, c, 2, X(2, k));
      double acc = 0.0;
      for (int a = 0; a < 4; ++a) {
        if (sz.w[a] == 0.0) continue;
        for (int b = 0; b < 4; ++b) {
          const double wzy = sz.w[a] * sy.w[b];
          if (wzy == 0.0) continue;
          const std::size_t row = (std::size_t(sz.idx[a]) * d[1] + sy.idx[b]) * d[0];
          double accx = 0.0;
          for (int e = 0; e < 4; ++e) accx += sx.w[e] * in[row + sx.idx[e]];
          acc += wzy * accx;
        }
      }
      U(c, k) = acc;  // h^3 * (1/h^3) weights cancel
    }
  }
}

}  // namespace swim::full3d
