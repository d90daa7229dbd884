// MAC grid layout and staggered operators: D = -G^T, symbols of D G.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "common/errors.hpp"
#include "full3d/grid.hpp"
#include "full3d/operators.hpp"

using namespace swim::full3d;

namespace {
double inner(const VectorField& a, const VectorField& b) {
  double s = 0;
  for (int c = 0; c < 3; ++c)
    for (std::size_t m = 0; m < a.c[c].size(); ++m) s += a.c[c][m] * b.c[c][m];
  return s;
}
void randomise(const MacGrid& g, VectorField& u, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  for (auto& a : u.c)
    for (double& x : a) x = U(rng);
  zero_wall_faces(g, u);
}
}  // namespace

TEST(MacGrid, LayoutAndValidation) {
  MacGrid box(8, 6, 4, 0.1, GridBoundary::PeriodicBox);
  EXPECT_EQ(box.size(0), 8u * 6 * 4);
  EXPECT_EQ(box.size(1), 8u * 6 * 4);
  MacGrid duct(8, 6, 4, 0.1, GridBoundary::SquareDuct);
  EXPECT_EQ(duct.size(0), 8u * 6 * 4);
  EXPECT_EQ(duct.size(1), 8u * 7 * 4);
  EXPECT_EQ(duct.size(2), 8u * 6 * 5);
  const auto x = duct.position(1, 2, 0, 1);
  EXPECT_DOUBLE_EQ(x[0], 0.25);
  EXPECT_DOUBLE_EQ(x[1], 0.0);
  EXPECT_DOUBLE_EQ(x[2], 0.15);
  EXPECT_THROW(MacGrid(8, 1, 4, 0.1, GridBoundary::SquareDuct), swim::InputError);
  EXPECT_THROW(MacGrid(8, 4, 4, -1.0, GridBoundary::PeriodicBox), swim::InputError);
  EXPECT_THROW(grid_boundary_from_string("container", "cylinder?"), swim::InputError);
}

TEST(MacOperators, DivergenceIsMinusGradientTranspose) {
  std::mt19937 rng(3);
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    MacGrid g(6, 5, 4, 0.3, kind);
    VectorField u(g), gp(g);
    ScalarField p(g), du(g);
    randomise(g, u, rng);
    std::uniform_real_distribution<double> U(-1, 1);
    for (double& x : p.v) x = U(rng);
    divergence(g, u, du);
    gradient(g, p, gp);
    double lhs = 0;
    for (std::size_t m = 0; m < p.v.size(); ++m) lhs += p.v[m] * du.v[m];
    EXPECT_NEAR(lhs, -inner(u, gp), 1e-11 * std::abs(lhs) + 1e-11) << to_string(kind);
  }
}

TEST(MacOperators, LaplacianIsSymmetricNegative) {
  std::mt19937 rng(5);
  for (auto kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    MacGrid g(5, 4, 6, 0.2, kind);
    VectorField a(g), b(g), La(g), Lb(g);
    randomise(g, a, rng);
    randomise(g, b, rng);
    laplacian(g, a, La);
    laplacian(g, b, Lb);
    EXPECT_NEAR(inner(a, Lb), inner(La, b), 1e-10 * std::abs(inner(a, Lb)));
    EXPECT_LT(inner(a, La), 0.0);
  }
}

TEST(MacOperators, PeriodicLaplacianSymbol) {
  // L e^{i k x} = -(4/h^2) sin^2(k h / 2) e^{i k x}: check on a cosine mode of u.
  MacGrid g(16, 8, 8, 0.5, GridBoundary::PeriodicBox);
  VectorField u(g), Lu(g);
  const auto d = g.dims(0);
  const double k = 2 * std::numbers::pi * 3 / g.length(0);
  for (int kk = 0; kk < d[2]; ++kk)
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i) u.c[0][MacGrid::index(d, i, j, kk)] = std::cos(k * g.position(0, i, j, kk)[0]);
  laplacian(g, u, Lu);
  const double sym = -4.0 / (g.h() * g.h()) * std::pow(std::sin(k * g.h() / 2), 2);
  for (std::size_t m = 0; m < u.c[0].size(); ++m) EXPECT_NEAR(Lu.c[0][m], sym * u.c[0][m], 1e-12);
}

TEST(MacOperators, DivergenceMaximumIsNaNForAnyNonFiniteVelocity) {
  // max |D u| without storing D u: equal to the stored divergence's maximum on 1 and 3 threads,
  // and NaN when any one face value (interior, wall or seam face) is NaN or infinite
  std::mt19937 rng(5);
  for (GridBoundary kind : {GridBoundary::PeriodicBox, GridBoundary::SquareDuct}) {
    const MacGrid g(8, 6, 5, 0.1, kind);
    VectorField u(g);
    randomise(g, u, rng);
    ScalarField div(g);
    divergence(g, u, div);
    EXPECT_EQ(max_abs_divergence(g, u, 1), div.max_abs());
    EXPECT_EQ(max_abs_divergence(g, u, 3), div.max_abs());
    for (int c = 0; c < 3; ++c)
      for (std::size_t at : {std::size_t(0), u.c[c].size() / 2, u.c[c].size() - 1})
        for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
          VectorField v = u;
          v.c[c][at] = bad;
          EXPECT_TRUE(std::isnan(max_abs_divergence(g, v, 2))) << c << " " << at;
        }
  }
}
