// Navier-Stokes advection module (28) (advection.hpp):
//  * the centred MAC advective term (u.grad)u is second order in space
//    (periodic box, max norm, against the analytic term at the faces);
//  * the time integrators have their order on the advection sub-problem alone
//    (RK2: 2, SSP-RK3: 3, against a fine-step reference);
//  * 2D Taylor-Green vortex through the full Lie step (advection, then the
//    backward-Euler Stokes step), dt proportional to h: first order overall,
//    as the splitting and backward Euler are;
//  * with advection off (the default) the Stokes step is bit-for-bit the same,
//    and the CFL guard raises swim::NumericalError leaving u unchanged.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "common/errors.hpp"
#include "full3d/advection.hpp"
#include "full3d/stokes.hpp"
#include "tests/full3d/test_support.hpp"

using namespace swim::full3d;
using namespace swim::full3d::testing;

namespace {
constexpr double kPi = std::numbers::pi;

// A smooth periodic 3D field on [0,1)^3 (not divergence-free: the advective term
// is tested as an operator).
double field(int c, const std::array<double, 3>& x) {
  const double k = 2 * kPi;
  switch (c) {
    case 0: return std::sin(k * x[0]) * std::cos(k * x[1]) + 0.3 * std::cos(k * x[2]);
    case 1: return std::cos(k * x[0] + 0.2) * std::sin(k * x[2]) + 0.5;
    default: return std::sin(k * (x[0] + x[1])) - 0.2 * std::cos(k * x[2]);
  }
}
// analytic (u.grad) u_c by central differences of tiny step (exact to ~1e-10)
double exact_term(int c, const std::array<double, 3>& x) {
  const double e = 1e-5;
  double s = 0;
  for (int d = 0; d < 3; ++d) {
    auto xp = x, xm = x;
    xp[d] += e;
    xm[d] -= e;
    s += field(d, x) * (field(c, xp) - field(c, xm)) / (2 * e);
  }
  return s;
}

void sample(const MacGrid& g, VectorField& u, double (*fn)(int, const std::array<double, 3>&)) {
  for_each_face(g, [&](const Face& q) { u.c[q.c][q.id] = fn(q.c, q.x); });
}

double max_diff(const VectorField& a, const VectorField& b) { return max_abs_diff(a, b); }
}  // namespace

TEST(Advection, SecondOrderInSpace) {
  double prev = 0;
  for (int n : {16, 32, 64}) {
    MacGrid g(n, n, n, 1.0 / n, GridBoundary::PeriodicBox);
    VectorField u(g), N(g), ex(g);
    sample(g, u, field);
    sample(g, ex, exact_term);
    advective_term(g, u, N);
    const double e = max_diff(N, ex);
    if (prev > 0) {
      std::printf("advective term n=%d: max error %.3e, order %.3f\n", n, e, std::log2(prev / e));
      EXPECT_GT(std::log2(prev / e), 1.9);
    } else {
      std::printf("advective term n=%d: max error %.3e\n", n, e);
    }
    prev = e;
  }
}

TEST(Advection, TimeOrderOfTheIntegrators) {
  MacGrid g(16, 16, 16, 1.0 / 16, GridBoundary::PeriodicBox);
  VectorField u0(g);
  sample(g, u0, field);
  const double T = 0.05;  // max|u| ~ 1.3: CFL sum ~ 3.5 dt/h
  auto run = [&](AdvectionScheme s, int steps) {
    AdvectionOptions opt{true, s, 0.9};
    VectorField u = u0;
    for (int i = 0; i < steps; ++i) advect(g, u, T / steps, opt);
    return u;
  };
  for (auto [scheme, expected, label] : {std::tuple{AdvectionScheme::Rk2, 2.0, "RK2"},
                                         std::tuple{AdvectionScheme::SspRk3, 3.0, "SSP-RK3"}}) {
    const VectorField ref = run(AdvectionScheme::SspRk3, 256);
    const double e1 = max_diff(run(scheme, 8), ref), e2 = max_diff(run(scheme, 16), ref),
                 e3 = max_diff(run(scheme, 32), ref);
    std::printf("%s: errors %.3e %.3e %.3e, orders %.2f %.2f\n", label, e1, e2, e3, std::log2(e1 / e2),
                std::log2(e2 / e3));
    EXPECT_GT(std::log2(e2 / e3), expected - 0.15);
  }
}

TEST(Advection, TaylorGreenThroughTheLieStep) {
  // u = sin x cos y F, v = -cos x sin y F, F = exp(-2 nu t), on [0, 2pi)^2 (nz = 1), nu = 0.1.
  const double nu = 0.1, T = 0.5;
  double prev = 0;
  for (int n : {16, 32, 64}) {
    const double h = 2 * kPi / n;
    MacGrid g(n, n, 1, h, GridBoundary::PeriodicBox);
    StokesOptions opt;
    opt.advection.enabled = true;
    StokesSolver solver(g, FluidParams{1.0, nu}, opt);
    auto tg = [&](VectorField& u, double t) {
      const double F = std::exp(-2 * nu * t);
      for (int c = 0; c < 2; ++c) {
        const auto d = g.dims(c);
        for (int j = 0; j < d[1]; ++j)
          for (int i = 0; i < d[0]; ++i) {
            const auto x = g.position(c, i, j, 0);
            u.c[c][MacGrid::index(d, i, j, 0)] =
                c == 0 ? std::sin(x[0]) * std::cos(x[1]) * F : -std::cos(x[0]) * std::sin(x[1]) * F;
          }
      }
    };
    VectorField u(g), f(g), ex(g);
    tg(u, 0);
    const int steps = n / 2;  // dt = T/steps, proportional to h (CFL ~ 0.3)
    double cfl = 0;
    for (int s = 0; s < steps; ++s) cfl = std::max(cfl, solver.step(u, f, T / steps).advection_cfl);
    tg(ex, T);
    const double e = max_diff(u, ex);
    if (prev > 0) {
      std::printf("Taylor-Green n=%d steps=%d: max error %.3e, order %.2f (CFL %.2f)\n", n, steps, e,
                  std::log2(prev / e), cfl);
      if (n == 64) {
        EXPECT_GT(std::log2(prev / e), 0.85);
      }  // measured 0.75, 0.92: O(dt) + O(h^2)
      EXPECT_LT(e, prev);
    } else {
      std::printf("Taylor-Green n=%d steps=%d: max error %.3e (CFL %.2f)\n", n, steps, e, cfl);
    }
    prev = e;
  }
}

TEST(Advection, OffIsTheStokesStepAndGuardThrows) {
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    MacGrid g(12, 8, 10, 0.1, kind);
    StokesOptions off;  // default: advection off
    StokesOptions off2;
    off2.advection.scheme = AdvectionScheme::Rk2;  // unused while disabled
    off2.advection.max_cfl = 1e-9;
    StokesSolver a(g, FluidParams{1.0, 1.0}, off), b(g, FluidParams{1.0, 1.0}, off2);
    VectorField ua(g), f(g);
    sample(g, ua, field);
    for (auto& x : f.c[1]) x = 1.0;
    if (kind == GridBoundary::SquareDuct) {
      for (int c = 1; c < 3; ++c) {  // zero wall faces
        const auto d = g.dims(c);
        for (int k = 0; k < d[2]; ++k)
          for (int j = 0; j < d[1]; ++j)
            for (int i = 0; i < d[0]; ++i)
              if (g.on_wall(c, c, c == 1 ? j : k)) ua.c[c][MacGrid::index(d, i, j, k)] = f.c[c][MacGrid::index(d, i, j, k)] = 0;
      }
    }
    VectorField ub = ua;
    a.step(ua, f, 0.01);
    b.step(ub, f, 0.01);
    EXPECT_EQ(max_diff(ua, ub), 0.0);
    // guard
    StokesOptions on;
    on.advection.enabled = true;
    on.advection.max_cfl = 0.5;
    StokesSolver c(g, FluidParams{1.0, 1.0}, on);
    VectorField uc = ub;
    EXPECT_THROW(c.step(uc, f, 10.0), swim::NumericalError);
    EXPECT_EQ(max_diff(uc, ub), 0.0);
  }
}
