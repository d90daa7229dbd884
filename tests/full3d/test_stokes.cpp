// Backward-Euler unsteady Stokes step on the MAC grid (stokes.hpp):
//  * discrete divergence after the step at round-off, both containers, for the product step,
//    the test reference's PCG and the bench's pressure-correction step;
//  * observed spatial order on manufactured solutions, both containers (product step), and
//    in the duct for the test reference's PCG.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "full3d/operators.hpp"
#include "full3d/reference/duct_fft.hpp"
#include "full3d/stokes.hpp"
#include "tests/full3d/reference/reference_stokes.hpp"
#include "tests/full3d/test_support.hpp"

using namespace swim::full3d;
using namespace swim::full3d::testing;

namespace {
constexpr double kPi = std::numbers::pi;

// A * prod_d sin(k_d x_d + a_d): an exact eigenfunction of the Laplacian.
struct Term {
  double A;
  std::array<double, 3> k, a;
  double operator()(const std::array<double, 3>& x) const {
    return A * std::sin(k[0] * x[0] + a[0]) * std::sin(k[1] * x[1] + a[1]) * std::sin(k[2] * x[2] + a[2]);
  }
  double lap(const std::array<double, 3>& x) const { return -(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]) * (*this)(x); }
  Term d(int dir) const {
    Term t = *this;
    t.A *= k[dir];
    t.a[dir] += kPi / 2;
    return t;
  }
};
using Fn = std::vector<Term>;
double eval(const Fn& f, const std::array<double, 3>& x) {
  double s = 0;
  for (const auto& t : f) s += t(x);
  return s;
}
double eval_lap(const Fn& f, const std::array<double, 3>& x) {
  double s = 0;
  for (const auto& t : f) s += t.lap(x);
  return s;
}
double eval_d(const Fn& f, int dir, const std::array<double, 3>& x) {
  double s = 0;
  for (const auto& t : f) s += t.d(dir)(x);
  return s;
}

struct Manufactured {
  std::array<Fn, 3> u;
  Fn p;
};

constexpr double h2 = kPi / 2;  // phase turning sin into cos
// Periodic box [0,1)^3: solenoidal trigonometric field.
Manufactured box_solution() {
  const double k = 2 * kPi;
  Manufactured m;
  m.u[0] = {{1.0, {k, k, k}, {0, h2, h2}}, {0.5, {0, k, k}, {h2, h2 + 0.3, 0}}};
  m.u[1] = {{1.0, {k, k, k}, {h2, 0, h2}}};
  m.u[2] = {{-2.0, {k, k, k}, {h2, h2, 0}}};
  m.p = {{1.0, {k, k, 2 * k}, {0.4, h2, 0}}};
  return m;
}
// Square duct [0,1)x[0,1]^2, no slip at y, z in {0,1}: u = curl(0, psi_y, psi_z) + axial flow,
//   psi_z = sin(2 pi x) sin^2(pi y) sin(pi z),  psi_y = cos(2 pi x) sin(pi y) sin^2(pi z).
Manufactured duct_solution() {
  const double k = 2 * kPi, q = kPi;
  Manufactured m;
  // u = d psi_z/dy - d psi_y/dz + sin(pi y) sin(pi z)
  m.u[0] = {{q, {k, k, q}, {0, 0, 0}},               // pi sin(2pi x) sin(2pi y) sin(pi z)
            {-q, {k, q, k}, {h2, 0, 0}},             // -pi cos(2pi x) sin(pi y) sin(2pi z)
            {1.0, {0, q, q}, {h2, 0, 0}}};           // sin(pi y) sin(pi z)
  // v = -d psi_z/dx = -2pi cos(2pi x) (1 - cos 2pi y)/2 sin(pi z)
  m.u[1] = {{-q, {k, 0, q}, {h2, h2, 0}}, {q, {k, k, q}, {h2, h2, 0}}};
  // w = d psi_y/dx = -2pi sin(2pi x) sin(pi y) (1 - cos 2pi z)/2
  m.u[2] = {{-q, {k, q, 0}, {0, 0, h2}}, {q, {k, q, k}, {0, 0, h2}}};
  m.p = {{1.0, {k, q, q}, {0.2, h2, 0}}};
  return m;
}

void sample(const MacGrid& g, const std::array<Fn, 3>& fn, VectorField& out) {
  for_each_face(g, [&](const Face& q) { out.c[q.c][q.id] = eval(fn[q.c], q.x); });
}

struct Errors {
  double u_max, u_l2, p_max;
};

// The product step (StokesSolver), or, in the duct, the test reference's PCG or the bench's
// pressure-correction step.
enum class Path { Product, ReferencePcg, PressureCorrection };
struct AnySolver {
  std::unique_ptr<StokesSolver> product;
  std::unique_ptr<reference::ReferenceStokes> pcg;
  std::unique_ptr<reference::PressureCorrectionStep> bare;
  AnySolver(const MacGrid& g, const FluidParams& fl, Path path) {
    if (path == Path::Product) product = std::make_unique<StokesSolver>(g, fl);
    if (path == Path::ReferencePcg) pcg = std::make_unique<reference::ReferenceStokes>(g, fl, reference::Options{});
    if (path == Path::PressureCorrection) bare = std::make_unique<reference::PressureCorrectionStep>(g, fl, FftOptions{});
  }
  StokesStats step(VectorField& u, const VectorField& f, double dt) {
    return product ? product->step(u, f, dt) : pcg ? pcg->step(u, f, dt) : bare->step(u, f, dt);
  }
  const ScalarField& pressure() const {
    return product ? product->pressure() : pcg ? pcg->pressure() : bare->pressure();
  }
};

// One step from u^n = 0.3 u_e to the exact u_e with forcing
// f = rho (u_e - u^n)/dt - mu Lap u_e + grad p_e, evaluated at the faces.
Errors run_manufactured(GridBoundary kind, int n, const Manufactured& m, StokesStats* stats = nullptr,
                        Path path = Path::Product) {
  MacGrid g(n, n, n, 1.0 / n, kind);
  const FluidParams fl{1.0, 1.0};
  const double dt = 0.05, alpha = fl.rho / dt;
  AnySolver solver(g, fl, path);
  VectorField u(g), f(g), ue(g);
  sample(g, m.u, ue);
  for_each_face(g, [&](const Face& q) {
    u.c[q.c][q.id] = 0.3 * ue.c[q.c][q.id];
    f.c[q.c][q.id] = alpha * 0.7 * ue.c[q.c][q.id] - fl.mu * eval_lap(m.u[q.c], q.x) + eval_d(m.p, q.c, q.x);
  });
  zero_wall_faces(g, f);
  const StokesStats st = solver.step(u, f, dt);
  if (stats) *stats = st;
  Errors e{0, 0, 0};
  std::size_t count = 0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t id = 0; id < u.c[c].size(); ++id) {
      const double err = std::abs(u.c[c][id] - ue.c[c][id]);
      e.u_max = std::max(e.u_max, err);
      e.u_l2 += err * err;
      ++count;
    }
  e.u_l2 = std::sqrt(e.u_l2 / double(count));
  // pressure up to a constant
  const auto dp = g.dims(3);
  std::vector<double> dpv(g.cells());
  double mean = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const std::size_t id = MacGrid::index(dp, i, j, k);
        dpv[id] = solver.pressure().v[id] - eval(m.p, g.position(3, i, j, k));
        mean += dpv[id];
      }
  mean /= double(g.cells());
  for (double x : dpv) e.p_max = std::max(e.p_max, std::abs(x - mean));
  return e;
}

void check_orders(GridBoundary kind, const Manufactured& m, double min_order_u, double min_order_p,
                  Path path = Path::Product) {
  const int ns[3] = {16, 32, 64};
  Errors e[3];
  for (int r = 0; r < 3; ++r) {
    StokesStats st;
    const auto t0 = std::chrono::steady_clock::now();
    e[r] = run_manufactured(kind, ns[r], m, &st, path);
    const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[%s n=%d] |e_u|_max=%.3e |e_u|_2=%.3e |e_p|_max=%.3e  PCG it=%d  %.2fs\n",
                to_string(kind).c_str(), ns[r], e[r].u_max, e[r].u_l2, e[r].p_max, st.iterations, sec);
  }
  for (int r = 1; r < 3; ++r) {
    const double ou = std::log2(e[r - 1].u_max / e[r].u_max);
    const double o2 = std::log2(e[r - 1].u_l2 / e[r].u_l2);
    const double op = std::log2(e[r - 1].p_max / e[r].p_max);
    std::printf("[%s %d->%d] order u_max %.3f  u_l2 %.3f  p_max %.3f\n", to_string(kind).c_str(), ns[r - 1], ns[r],
                ou, o2, op);
    EXPECT_GE(ou, min_order_u);
    EXPECT_GE(o2, min_order_u);
    if (r == 2) {
      EXPECT_GE(op, min_order_p);  // pressure: asymptotic pair only
    }
  }
}

double divergence_ratio(GridBoundary kind, Path path = Path::Product) {
  MacGrid g(24, 16, 20, 0.01, kind);
  AnySolver solver(g, FluidParams{1.0e3, 1.2e-3}, path);
  VectorField u(g), f(g);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int c = 0; c < 3; ++c) {
    for (double& x : u.c[c]) x = U(rng);
    for (double& x : f.c[c]) x = 1e3 * U(rng);
  }
  zero_wall_faces(g, u);
  double worst = 0;
  for (int s = 0; s < 2; ++s) {
    const StokesStats st = solver.step(u, f, 1e-3);
    ScalarField div(g);
    divergence(g, u, div);
    EXPECT_DOUBLE_EQ(div.max_abs(), st.max_divergence);
    worst = std::max(worst, div.max_abs() / (u.max_abs() / g.h()));
  }
  return worst;
}
}  // namespace

TEST(StokesStep, DivergenceFreeToRoundOffPeriodicBox) {
  const double r = divergence_ratio(GridBoundary::PeriodicBox);
  std::printf("box: max|Du| / (max|u|/h) = %.2e\n", r);
  EXPECT_LT(r, 1e-12);
}

TEST(StokesStep, DivergenceFreeToRoundOffSquareDuct) {
  const double r = divergence_ratio(GridBoundary::SquareDuct);
  std::printf("duct (capacitance, production): max|Du| / (max|u|/h) = %.2e\n", r);
  EXPECT_LT(r, 1e-12);
  const double ri = divergence_ratio(GridBoundary::SquareDuct, Path::ReferencePcg);
  std::printf("duct (reference PCG): max|Du| / (max|u|/h) = %.2e\n", ri);
  EXPECT_LT(ri, 1e-12);
  const double rb = divergence_ratio(GridBoundary::SquareDuct, Path::PressureCorrection);
  std::printf("duct (bench's pressure-correction step): max|Du| / (max|u|/h) = %.2e\n", rb);
  EXPECT_LT(rb, 1e-12);
}

TEST(StokesStep, SecondOrderPeriodicBox) {
  // Every operator is second order and the solve is exact: order 2 in u and p.
  check_orders(GridBoundary::PeriodicBox, box_solution(), 1.9, 1.9);  // measured 1.97..2.01 (p: 1.88, 1.97)
}

TEST(StokesStep, SquareDuctOrder) {
  // Velocity: second order in max norm although the ghost-cell wall rule has an
  // O(1) local truncation error in the first cell layer (the error it induces is
  // O(h^2) globally, as for a Dirichlet problem). Pressure: measured 1.79 -> 1.91,
  // approaching 2; asserted >= 1.8 on the finest pair.
  check_orders(GridBoundary::SquareDuct, duct_solution(), 1.9, 1.8);  // capacitance (production)
}

TEST(StokesStep, SquareDuctOrderReferencePcg) {
  check_orders(GridBoundary::SquareDuct, duct_solution(), 1.9, 1.8, Path::ReferencePcg);
}
