// The two test references of the duct and cylinder step against each other
// (tests/full3d/reference/reference_stokes.hpp): the per-axial-mode sparse LU
// (reference::DirectStokes)
//  * equals the converged PCG solution, duct and staircase cylinder, even and odd nx
//    (relative 1e-9 in u, pressure up to its constant);
//  * discrete divergence at round-off, masked and wall faces exactly zero;
//  * refactorises when dt changes and reuses the factors of the two last dt values;
//  * the recovered multiplier matches the PCG's; the sparse LU takes the staircase wall only;
//  * 1 and 2 threads give bit-identical results.
// And the product's StokesSolver::set_pressure.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "common/errors.hpp"
#include "full3d/operators.hpp"
#include "full3d/stokes.hpp"
#include "tests/full3d/reference/reference_stokes.hpp"
#include "tests/full3d/test_support.hpp"

using namespace swim::full3d;
using namespace swim::full3d::testing;

namespace {

constexpr double kRc = 0.25e-6;

struct Case {
  MacGrid grid;
  bool cylinder;
};

reference::Options options(bool cylinder, reference::Method method, int threads = 1) {
  reference::Options o;
  o.method = method;
  o.threads = threads;
  o.cg_rtol = 1e-13;
  o.cg_max_iterations = 2000;
  if (cylinder) {
    o.cylinder.enabled = true;
    o.cylinder.radius = kRc;
  }
  return o;
}

// random u^n (masked faces zeroed for the cylinder) and a random force
void random_state(const MacGrid& g, bool cylinder, VectorField& u, VectorField& f, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1, 1);
  for_each_face(g, [&](const Face& q) {
    const bool out = cylinder && cylinder_outside(g, kRc, q.c, q.j, q.k);
    u.c[q.c][q.id] = out ? 0.0 : 1e-6 * U(rng);
    f.c[q.c][q.id] = 1e3 * U(rng);
  });
  zero_wall_faces(g, u);
}

double rel_diff(const VectorField& a, const VectorField& b) {
  double d = 0, m = 0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < a.c[c].size(); ++i) {
      d = std::max(d, std::abs(a.c[c][i] - b.c[c][i]));
      m = std::max(m, std::abs(b.c[c][i]));
    }
  return d / m;
}

// max |pa - pb - const| / max |pb| over the cells where `use` holds (const: the mean difference)
template <class Use>
double rel_pressure_diff(const ScalarField& pa, const ScalarField& pb, Use use) {
  double mean = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < pa.v.size(); ++i)
    if (use(i)) {
      mean += pa.v[i] - pb.v[i];
      ++n;
    }
  mean /= double(n);
  double d = 0, m = 0;
  for (std::size_t i = 0; i < pa.v.size(); ++i)
    if (use(i)) {
      d = std::max(d, std::abs(pa.v[i] - pb.v[i] - mean));
      m = std::max(m, std::abs(pb.v[i]));
    }
  return d / m;
}

void compare_with_iterative(const MacGrid& g, bool cylinder, double dt) {
  const FluidParams water{1.0e3, 1.2e-3};
  reference::ReferenceStokes direct(g, water, options(cylinder, reference::Method::SparseLu));
  reference::ReferenceStokes iter(g, water, options(cylinder, reference::Method::Pcg));
  VectorField u(g), f(g);
  random_state(g, cylinder, u, f, 3);
  VectorField ud = u, ui = u;
  for (int s = 0; s < 2; ++s) {
    const StokesStats sd = direct.step(ud, f, dt);
    const StokesStats si = iter.step(ui, f, dt);
    EXPECT_EQ(sd.iterations, 0);
    const double du = rel_diff(ud, ui);
    const int ny = g.ny(), nx = g.nx();
    const reference::ReferenceStokes& mask = direct;
    const double dp = rel_pressure_diff(direct.pressure(), iter.pressure(), [&](std::size_t id) {
      const std::size_t cell = id / std::size_t(nx);
      return mask.has_pressure(int(cell % std::size_t(ny)), int(cell / std::size_t(ny)));
    });
    const double div = sd.max_divergence / (ud.max_abs() / g.h());
    std::printf("[%s %dx%dx%d dt=%.0e step %d] |u_d - u_i|/|u| = %.2e  |p_d - p_i|/|p| = %.2e  PCG it=%d  div=%.1e\n",
                cylinder ? "cylinder" : "duct", g.nx(), g.ny(), g.nz(), dt, s, du, dp, si.iterations, div);
    EXPECT_LT(du, 1e-9);
    EXPECT_LT(dp, 1e-9);
    EXPECT_LT(div, 1e-12);
    if (cylinder) {
      EXPECT_EQ(sd.max_constraint, 0.0);
      for (int c = 0; c < 3; ++c) {
        const auto d = g.dims(c);
        for (int k = 0; k < d[2]; ++k)
          for (int j = 0; j < d[1]; ++j)
            if (cylinder_outside(g, kRc, c, j, k))
              for (int i = 0; i < d[0]; ++i) {
                ASSERT_EQ(ud.c[c][MacGrid::index(d, i, j, k)], 0.0);
              }
      }
      // multiplier recovered from the direct solution against the PCG's multiplier. Only
      // lambda + E G p is unique (the pressure of fully masked cells trades off with lambda).
      auto total = [&](const reference::ReferenceStokes& solver) {
        VectorField gp(g);
        gradient(g, solver.pressure(), gp);
        std::vector<double> egp;
        solver.constraints()->gather(gp, egp);
        std::vector<double> l = solver.multiplier();
        for (std::size_t r = 0; r < l.size(); ++r) l[r] += egp[r];
        return l;
      };
      const auto ld = total(direct);
      const auto li = total(iter);
      ASSERT_EQ(ld.size(), li.size());
      double dl = 0, ml = 0;
      for (std::size_t r = 0; r < ld.size(); ++r) {
        dl = std::max(dl, std::abs(ld[r] - li[r]));
        ml = std::max(ml, std::abs(li[r]));
      }
      std::printf("    multiplier: |(l + E G p)_d - (l + E G p)_i|/|l + E G p| = %.2e\n", dl / ml);
      EXPECT_LT(dl / ml, 1e-7);
    }
  }
}

}  // namespace

TEST(DirectStokes, MatchesIterativeDuctEvenNx) {
  compare_with_iterative(MacGrid(12, 10, 8, 0.5e-6 / 10, GridBoundary::SquareDuct), false, 1e-5);
}

TEST(DirectStokes, MatchesIterativeDuctOddNxUnitParameters) {
  // a non-quasi-steady regime too: rho/dt comparable with mu/h^2
  compare_with_iterative(MacGrid(9, 8, 11, 0.5e-6 / 8, GridBoundary::SquareDuct), false, 1e-9);
}

TEST(DirectStokes, MatchesIterativeCylinder) {
  compare_with_iterative(MacGrid(8, 18, 18, 2.25 * kRc / 18, GridBoundary::SquareDuct), true, 1e-5);
}

TEST(DirectStokes, MatchesIterativeCylinderOddNx) {
  compare_with_iterative(MacGrid(7, 16, 16, 2.25 * kRc / 16, GridBoundary::SquareDuct), true, 1e-8);
}

TEST(DirectStokes, RefactorisesWhenDtChanges) {
  const MacGrid g(8, 12, 12, 2.25 * kRc / 12, GridBoundary::SquareDuct);
  const FluidParams water{1.0e3, 1.2e-3};
  reference::ReferenceStokes s(g, water, options(true, reference::Method::SparseLu));
  VectorField u(g), f(g);
  random_state(g, true, u, f, 7);
  const double dts[4] = {1e-5, 0.5e-5, 1e-5, 0.5e-5};
  VectorField last;
  for (int n = 0; n < 4; ++n) {
    const StokesStats st = s.step(u, f, dts[n]);
    if (n < 2)
      EXPECT_GT(st.factorization_seconds, 0.0) << n;
    else
      EXPECT_EQ(st.factorization_seconds, 0.0) << n;  // both dt values cached
    if (n == 2) last = u;
  }
  // a fresh solver on the state before step 3 gives the same step 3
  reference::ReferenceStokes fresh(g, water, options(true, reference::Method::SparseLu));
  VectorField u2(g), f2(g);
  random_state(g, true, u2, f2, 7);
  for (int n = 0; n < 4; ++n) {
    fresh.step(u2, f2, dts[n]);
    if (n == 2) {
      EXPECT_LT(rel_diff(u2, last), 1e-15);
    }
  }
  EXPECT_LT(rel_diff(u2, u), 1e-15);
  EXPECT_GT(s.factor_bytes(), 0u);
}

TEST(DirectStokes, ThreadsGiveIdenticalResults) {
  const MacGrid g(10, 12, 12, 2.25 * kRc / 12, GridBoundary::SquareDuct);
  const FluidParams water{1.0e3, 1.2e-3};
  reference::ReferenceStokes s1(g, water, options(true, reference::Method::SparseLu, 1));
  reference::ReferenceStokes s2(g, water, options(true, reference::Method::SparseLu, 2));
  VectorField u(g), f(g);
  random_state(g, true, u, f, 9);
  VectorField u1 = u, u2 = u;
  s1.step(u1, f, 1e-5);
  s2.step(u2, f, 1e-5);
  EXPECT_EQ(rel_diff(u1, u2), 0.0);
  EXPECT_EQ(s1.pressure().v, s2.pressure().v);
}

TEST(DirectStokes, StaircaseWallOnly) {
  const MacGrid duct(8, 12, 12, 2.25 * kRc / 12, GridBoundary::SquareDuct);
  reference::Options o = options(true, reference::Method::SparseLu);
  EXPECT_NO_THROW(reference::ReferenceStokes(duct, FluidParams{}, o));
  o.wall.wall = reference::CylinderWall::GhostLinear;
  EXPECT_THROW(reference::ReferenceStokes(duct, FluidParams{}, o), swim::InputError);
  o.method = reference::Method::Pcg;
  EXPECT_NO_THROW(reference::ReferenceStokes(duct, FluidParams{}, o));
  const MacGrid box(8, 8, 8, 1e-7, GridBoundary::PeriodicBox);
  EXPECT_THROW(reference::ReferenceStokes(box, FluidParams{}, reference::Options{}), swim::InputError);
}

TEST(DirectStokes, SetPressure) {
  const MacGrid g(8, 12, 12, 2.25 * kRc / 12, GridBoundary::SquareDuct);
  StokesSolver s(g, FluidParams{});
  ScalarField p(g);
  for (std::size_t i = 0; i < p.v.size(); ++i) p.v[i] = double(i);
  s.set_pressure(p);
  EXPECT_EQ(s.pressure().v, p.v);
  ScalarField bad;
  bad.v.assign(3, 0.0);
  EXPECT_THROW(s.set_pressure(bad), swim::InputError);
}
