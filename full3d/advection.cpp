#include "full3d/advection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "full3d/operators.hpp"

namespace swim::full3d {

namespace {
inline int wrap(int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); }
}  // namespace

void advective_term(const MacGrid& g, const VectorField& u, VectorField& N) {
  const double i2h = 0.5 / g.h();
  for (int c = 0; c < 3; ++c) {
    const auto dc = g.dims(c);
    auto& out = N.c[c];
    out.assign(g.size(c), 0.0);
    const auto& uc = u.c[c];
    for (int k = 0; k < dc[2]; ++k)
      for (int j = 0; j < dc[1]; ++j)
        for (int i = 0; i < dc[0]; ++i) {
          const int I[3] = {i, j, k};
          if (g.on_wall(c, c, I[c])) continue;
          const double self = uc[MacGrid::index(dc, i, j, k)];
          double acc = 0.0;
          for (int d = 0; d < 3; ++d) {
            // advecting velocity u_d at this u_c node
            double ud;
            if (d == c) {
              ud = self;
            } else {
              const auto dd = g.dims(d);
              int lo[3] = {i, j, k}, hi[3] = {i, j, k};
              // along c: u_d nodes at I_c - 1 and I_c ; along d: at I_d and I_d + 1
              lo[c] = g.periodic(c) ? wrap(I[c] - 1, g.n(c)) : I[c] - 1;
              hi[d] = g.periodic(d) ? wrap(I[d] + 1, g.n(d)) : I[d] + 1;
              int a[3] = {lo[0], lo[1], lo[2]}, b[3] = {i, j, k}, e[3] = {lo[0], lo[1], lo[2]}, f[3] = {i, j, k};
              a[d] = I[d];
              e[d] = hi[d];
              b[d] = I[d];
              f[d] = hi[d];
              const auto& vd = u.c[d];
              ud = 0.25 * (vd[MacGrid::index(dd, a[0], a[1], a[2])] + vd[MacGrid::index(dd, b[0], b[1], b[2])] +
                           vd[MacGrid::index(dd, e[0], e[1], e[2])] + vd[MacGrid::index(dd, f[0], f[1], f[2])]);
            }
            if (ud == 0.0) continue;
            // centred derivative of u_c along d
            double vals[2];
            for (int s = 0; s < 2; ++s) {
              int m[3] = {i, j, k};
              const int t = I[d] + (s ? 1 : -1);
              if (g.periodic(d)) {
                m[d] = wrap(t, g.n(d));
                vals[s] = uc[MacGrid::index(dc, m[0], m[1], m[2])];
              } else if (t < 0 || t >= dc[d]) {
                vals[s] = -self;  // ghost of a tangential component
              } else {
                m[d] = t;
                vals[s] = uc[MacGrid::index(dc, m[0], m[1], m[2])];  // wall faces hold zero
              }
            }
            acc += ud * (vals[1] - vals[0]) * i2h;
          }
          out[MacGrid::index(dc, i, j, k)] = acc;
        }
  }
}

double advective_cfl(const MacGrid& g, const VectorField& u, double dt) {
  double s = 0.0;
  for (int c = 0; c < 3; ++c) {
    double m = 0.0;
    for (double x : u.c[c]) m = std::max(m, std::abs(x));
    s += m;
  }
  return s * dt / g.h();
}

double advect(const MacGrid& g, VectorField& u, double dt, const AdvectionOptions& opt) {
  const double cfl = advective_cfl(g, u, dt);
  if (!(cfl <= opt.max_cfl))
    throw NumericalError("fluid advection CFL number " + significant(cfl, 4) + " exceeds " + significant(opt.max_cfl, 4) +
                             " (sum_d max|u_d| dt/h of the Navier-Stokes advection sub-step)",
                         "reduce the time step full3d.dt (or raise StokesOptions::advection.max_cfl through the API)");
  VectorField N(g);
  if (opt.scheme == AdvectionScheme::Rk2) {
    // Heun: u1 = u - dt N(u);  u <- (u + u1 - dt N(u1)) / 2
    advective_term(g, u, N);
    VectorField u1 = u;
    u1.axpy(-dt, N);
    advective_term(g, u1, N);
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < u.c[c].size(); ++m) u.c[c][m] = 0.5 * (u.c[c][m] + u1.c[c][m] - dt * N.c[c][m]);
  } else {
    // Shu-Osher SSP-RK3
    advective_term(g, u, N);
    VectorField u1 = u;
    u1.axpy(-dt, N);
    advective_term(g, u1, N);
    VectorField u2 = u1;
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < u.c[c].size(); ++m)
        u2.c[c][m] = 0.75 * u.c[c][m] + 0.25 * (u1.c[c][m] - dt * N.c[c][m]);
    advective_term(g, u2, N);
    for (int c = 0; c < 3; ++c)
      for (std::size_t m = 0; m < u.c[c].size(); ++m)
        u.c[c][m] = u.c[c][m] / 3.0 + 2.0 / 3.0 * (u2.c[c][m] - dt * N.c[c][m]);
  }
  zero_wall_faces(g, u);
  return cfl;
}

}  // namespace swim::full3d
