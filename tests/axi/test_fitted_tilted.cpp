// The fitted mesh on walls that are not graphs over the axis (axi/fitted_mesh.hpp): a segment that
// stands radially (the wall between a contracted and a relaxed segment) or turns back (a curling
// rim). What each test expects, and why, is stated at the test.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <iterator>
#include <numbers>
#include <random>
#include <vector>

#include "axi/fe_stokes_axi.hpp"
#include "axi/fitted_mesh.hpp"
#include "common/errors.hpp"
#include "tests/support/axi_fixture.hpp"

using swim::axi::FittedMesh;
using swim::axi::FittedMeshParams;
using swim::axi::FittedStokes;

namespace {

using namespace swim::test::fitted_tube;

constexpr double kPi = std::numbers::pi;

using Body = std::function<Eigen::Vector2d(double, double)>;

FittedMeshParams params(int ci, int co, int gap, double aspect = 0.0) {
  FittedMeshParams p = swim::test::fitted_mesh_params(kRc, kP, ci, co, gap, 1.2);
  p.wall_row_aspect = aspect;
  return p;
}

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// A meridian of n rings spaced ds along its arc length from (x0, r0), its tangent's angle with
// the axis theta(s) (s = arc length / total, in [0, 1]).
Eigen::Matrix3Xd by_angle(int n, double ds, double x0, double r0, const std::function<double(double)>& theta) {
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Zero(3, n);
  X(0, 0) = x0;
  X(1, 0) = r0;
  for (int k = 1; k < n; ++k) {
    const double th = theta((k - 0.5) / (n - 1));  // midpoint rule per segment
    X(0, k) = X(0, k - 1) + ds * std::cos(th);
    X(1, k) = X(1, k - 1) + ds * std::sin(th);
  }
  return X;
}

// The wall between a contracted (0.35 a) and a relaxed segment: the tangent turns smoothly from
// the axis's direction to theta_max (pi/2: a radially standing stretch; more: turned back) and
// back, rising 0.65 a over the arc length between s = 0.35 and 0.65 (about 30 % of the rings).
Eigen::Matrix3Xd step_wall(int n, double theta_max) {
  const double L = 0.5e-6, ds = L / (n - 1);
  auto bump = [](double s) { return smoothstep((s - 0.35) / 0.05) * smoothstep((0.65 - s) / 0.05); };
  // scale the arc so that the rise is 0.65 a
  double rise = 0.0;
  for (int k = 1; k < n; ++k) rise += ds * std::sin(theta_max * bump((k - 0.5) / (n - 1)));
  const double scale = 0.65 * kA / rise;
  return by_angle(n, ds * scale, 0.3e-6, 0.35 * kA, [&](double s) { return theta_max * bump(s); });
}

// A straight tube of radius a whose front rim curls outwards: the tangent turns from the axis's
// direction to theta_end over the last 15 % of the arc length.
Eigen::Matrix3Xd curled_rim(int n, double theta_end) {
  const double L = 0.4e-6, ds = L / (n - 1);
  return by_angle(n, ds, 0.3e-6, kA, [&](double s) { return theta_end * smoothstep((s - 0.85) / 0.15); });
}

// The mesh is valid and its lines' feet (axis and container rows) strictly ordered.
void expect_valid(const FittedMesh& m, const char* what) {
  EXPECT_GT(m.min_jacobian(), 0.0) << what;
  for (int c = 0; c < m.columns(); ++c) {
    EXPECT_LT(m.vertex_x(c, 0), m.vertex_x(c + 1, 0)) << what << ": axis feet " << c;
    EXPECT_LT(m.vertex_x(c, m.rows()), m.vertex_x(c + 1, m.rows())) << what << ": container feet " << c;
    for (int j = 0; j < m.rows(); ++j) EXPECT_LT(m.vertex_r(c, j), m.vertex_r(c, j + 1));
  }
  int tilted = 0;
  for (int c = 0; c < m.columns(); ++c) tilted += !m.column_vertical(c);
  EXPECT_GT(tilted, 0) << what;
  std::printf("  %s: %d of %d columns tilted, smallest corner Jacobian %.3e m^2\n", what, tilted, m.columns(),
              m.min_jacobian());
}

// Physical point of element e at reference (xi, eta) (the bilinear map).
Eigen::Vector2d map_point(const FittedMesh& m, int e, double xi, double eta) {
  double x[4], r[4];
  m.corners(e, x, r);
  static constexpr double cs[4] = {-1, 1, 1, -1}, ct[4] = {-1, -1, 1, 1};
  Eigen::Vector2d p(0, 0);
  for (int i = 0; i < 4; ++i) {
    const double w = 0.25 * (1 + cs[i] * xi) * (1 + ct[i] * eta);
    p += w * Eigen::Vector2d(x[i], r[i]);
  }
  return p;
}

}  // namespace

// A wall with a radially standing stretch (tangent at 90 degrees over about 20 % of the rings,
// the shape between a segment contracted to 0.35 a and a relaxed one) is meshed:
// every element's Jacobian is positive at its four corners, the lines' feet are strictly ordered
// at the axis and at the container, the rings are the mesh's wall vertices. On the product's mesh
// parameters (rows graded to the wall, 16 + 16 rows) and on a coarse uniform one. Fails with
// vertical lines (fit throws: the lines of the radial stretch's rings coincide) or with tilts
// that cross (a non-positive Jacobian).
TEST(FittedMeshTilted, MeshesAWallThatStandsRadially) {
  for (double th : {0.5 * kPi}) {
    for (int level = 0; level < 2; ++level) {
      const int n = level ? 129 : 65;
      const FittedMeshParams p = level ? params(16, 16, 40, 2.0) : params(6, 6, 16);
      const Eigen::Matrix3Xd X = step_wall(n, th);
      FittedMesh m(p, n);
      char what[80];
      std::snprintf(what, sizeof what, "step at %.0f deg, %d rings", th * 180 / kPi, n);
      ASSERT_NO_THROW(m.fit(X)) << what;
      expect_valid(m, what);
      for (int k = 0; k < n; ++k) {
        EXPECT_EQ(m.vertex_x(k, p.cells_inner), X(0, k));
        EXPECT_EQ(m.vertex_r(k, p.cells_inner), X(1, k));
      }
    }
  }
}

// A front rim that curls until its last segment stands radially (90 degrees) and beyond (110
// degrees: the meridian turns back over its last 5 % of the rings) is meshed validly, on the
// product's mesh parameters and on a coarser one. Fails as above.
TEST(FittedMeshTilted, MeshesARimThatCurlsBack) {
  for (double th : {0.5 * kPi, 105.0 / 180.0 * kPi, 110.0 / 180.0 * kPi}) {
   for (int level = 0; level < 2; ++level) {
    const int n = level ? 101 : 81;
    const FittedMeshParams p = level ? params(16, 16, 40, 2.0) : params(8, 8, 24, 2.0);
    const Eigen::Matrix3Xd X = curled_rim(n, th);
    FittedMesh m(p, n);
    char what[80];
    std::snprintf(what, sizeof what, "rim curled to %.0f deg, %d rings", th * 180 / kPi, n);
    ASSERT_NO_THROW(m.fit(X)) << what;
    expect_valid(m, what);
    EXPECT_FALSE(m.column_vertical(n - 1));
   }
  }
}

// Where the wall is a gentle graph (slope below 0.7 everywhere) every line is exactly vertical
// (x = the ring's x on every row, to the bit), so the vertical-line mesh's measured convergence
// stays valid. Fails if the tilt or the far-position shift leaks into gentle walls.
TEST(FittedMeshTilted, KeepsVerticalLinesOnAGentleWall) {
  const int n = 65;
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Zero(3, n);
  for (int k = 0; k < n; ++k) {
    const double s = double(k) / (n - 1);
    X(0, k) = 0.3e-6 + 0.4e-6 * s;
    X(1, k) = kA * (1.0 - 0.3 * std::pow(std::sin(kPi * s), 2));  // slope <= 0.3 a pi / L = 0.29
  }
  FittedMesh m(params(8, 8, 16, 2.0), n);
  m.fit(X);
  for (int c = 0; c <= m.columns(); ++c) {
    EXPECT_TRUE(m.column_vertical(c));
    for (int j = 0; j <= m.rows(); ++j) EXPECT_EQ(m.vertex_x(c, j), m.column_x(c));
  }
}

// locate() finds points on the tilted mesh: for random reference points of every element, the
// returned element and reference coordinates map back to the point (to 1e-12 of the element
// size), xi and eta in [-1, 1]; and a point shifted by a period is found at the same place.
// Fails with the vertical-line search (wrong column where the lines lean).
TEST(FittedMeshTilted, LocateFindsPointsOnTiltedLines) {
  const int n = 65;
  FittedMesh m(params(6, 6, 16), n);
  m.fit(step_wall(n, 0.5 * kPi));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.95, 0.95);
  double worst = 0.0;
  for (int e = 0; e < m.elements(); ++e) {
    const double xi0 = u(rng), eta0 = u(rng);
    const Eigen::Vector2d Y = map_point(m, e, xi0, eta0);
    double x = Y[0] + (e % 3 - 1) * kP, xi, eta;
    const int f = m.locate(x, Y[1], xi, eta);
    EXPECT_LE(std::abs(xi), 1.0);
    EXPECT_LE(std::abs(eta), 1.0);
    const Eigen::Vector2d Z = map_point(m, f, xi, eta);
    double cx[4], cr[4];
    m.corners(e, cx, cr);
    const double h = std::hypot(cx[2] - cx[0], cr[2] - cr[0]);
    double dx = Z[0] - Y[0];
    dx -= kP * std::round(dx / kP);
    worst = std::max(worst, std::hypot(dx, Z[1] - Y[1]) / h);
  }
  std::printf("  locate: worst mapped-back distance / element size %.2e\n", worst);
  EXPECT_LT(worst, 1e-12);
}

// Poiseuille flow (f_x = G, w = G (Rc^2 - r^2) / 4 mu) across the unloaded step wall is exact on
// the tilted mesh too: w is biquadratic on any bilinear element (r is bilinear in the reference
// coordinates), and every integrand of a(w, v) and the load is a polynomial of degree <= 5 per
// direction (w's gradient is polynomial in r, det J times v's physical gradient is the cofactor
// matrix times reference derivatives). So the Galerkin solution is the exact one to round-off.
// Fails if the general bilinear geometry (Jacobian, gradient transform, node placement) or the
// pressure scales on tilted elements are wrong. Also: every element conserves mass to
// round-off (lumen_divergence_residual).
TEST(FittedMeshTilted, PoiseuilleAcrossAStepWallIsExactOnTiltedLines) {
  const int n = 65;
  FittedStokes s(params(6, 6, 16), kMu, n);
  s.factor(step_wall(n, 0.5 * kPi));
  int tilted = 0;
  for (int c = 0; c < s.mesh().columns(); ++c) tilted += !s.mesh().column_vertical(c);
  ASSERT_GT(tilted, 5);
  const double G = 1.0e9;
  auto w = [&](double r) { return G * (kRc * kRc - r * r) / (4 * kMu); };
  Eigen::Matrix3Xd U;
  const Body f = [&](double, double) { return Eigen::Vector2d(G, 0.0); };
  s.solve(Eigen::Matrix3Xd::Zero(3, n), U, &f);
  double eu = 0.0, ep = 0.0;
  for (int I = 0; I < s.mesh().node_columns(); ++I)
    for (int J = 0; J < s.mesh().node_rows(); ++J) {
      const Eigen::Vector2d Y = s.mesh().node_position(I, J);
      const Eigen::Vector2d v = s.velocity(Y[0], Y[1]);
      eu = std::max({eu, std::abs(v[0] - w(Y[1])), std::abs(v[1])});
      ep = std::max(ep, std::abs(s.pressure(Y[0], Y[1])));
    }
  std::printf("  tilted Poiseuille: rel. nodal velocity error %.2e, pressure %.2e, divergence %.2e\n", eu / w(0),
              ep / (G * kRc), s.lumen_divergence_residual());
  EXPECT_LT(eu / w(0), 1e-10);
  EXPECT_LT(ep / (G * kRc), 1e-9);
  EXPECT_LT(s.lumen_divergence_residual(), 1e-9);
}

// The end-disc flux through the rim's tilted line. Every element conserves mass exactly, and the
// lumen (columns 0..n-1, rows below the wall) is a union of elements bounded by the axis, the two
// rims' lines and the wall: so the flux out through the rear and front lines equals the flux of
// the velocity's Q2 trace in through the wall's edges, to round-off, whatever the lines' tilt.
// With a radially standing front rim (its line tilted) under a radial load, checked to 1e-9 of
// the fluxes. And the flux through the tilted line is the flux through the vertical disc at the
// rim's x (spanning the same circle), up to the discrete field's pointwise divergence: to 1e-3
// of the flux. Fails if end_disc_flux ignores u_r along a tilted line or the line's geometry.
TEST(FittedMeshTilted, EndFluxThroughATiltedRimLineBalancesTheLumen) {
  const int n = 81;
  const Eigen::Matrix3Xd X = curled_rim(n, 0.5 * kPi);
  FittedStokes s(params(8, 8, 24, 2.0), kMu, n);
  s.factor(X);
  ASSERT_FALSE(s.mesh().column_vertical(n - 1));
  Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, n), U;
  for (int k = 0; k < n; ++k) {
    const double sk = double(k) / (n - 1);
    F(1, k) = -1e-13 * std::pow(std::sin(kPi * sk), 2) * (0.5 + sk);
  }
  s.solve(F, U);
  const double q_rear = s.end_disc_flux(0, 0.0), q_front = s.end_disc_flux(1, 0.0);
  // the Q2 trace's flux in through the wall (normal pointing into the lumen: the meridian's
  // tangent (dx, dr) turned clockwise, (dr, -dx))
  double q_wall = 0.0;
  static constexpr double gp[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
  static constexpr double gw[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  for (int k = 0; k + 1 < n; ++k) {
    const double dx = X(0, k + 1) - X(0, k), dr = X(1, k + 1) - X(1, k);
    for (int q = 0; q < 3; ++q) {
      const double t = 0.5 * (1 + gp[q]);
      const double x = X(0, k) + t * dx, r = X(1, k) + t * dr;
      const Eigen::Vector2d v = s.velocity(x, r);
      q_wall += gw[q] * 0.5 * 2 * kPi * r * (v[0] * dr - v[1] * dx);
    }
  }
  // flux through the vertical disc at the rim's x: composite Gauss on many pieces
  const double xr = X(0, n - 1), rr = X(1, n - 1);
  double q_disc = 0.0;
  const int pieces = 400;
  for (int i = 0; i < pieces; ++i)
    for (int q = 0; q < 3; ++q) {
      const double r = rr * (i + 0.5 * (1 + gp[q])) / pieces;
      q_disc += gw[q] * 0.5 * rr / pieces * 2 * kPi * r * s.velocity(xr, r)[0];
    }
  const double scale = std::max({std::abs(q_rear), std::abs(q_front), std::abs(q_wall)});
  std::printf("  lumen fluxes: rear %.6e, front %.6e (vertical disc %.6e), wall in %.6e, imbalance %.2e\n", q_rear,
              q_front, q_disc, q_wall, (q_rear - q_front + q_wall) / scale);
  EXPECT_GT(std::abs(q_front), 1e-3 * scale);
  EXPECT_LT(std::abs(q_rear - q_front + q_wall), 1e-9 * scale);
  EXPECT_LT(std::abs(q_front - q_disc), 1e-3 * std::abs(q_front));
}

// The wall of `paper_amplitude_0.35` under 1.2 Pa on 16 cells across (33 rings, the mesh
// parameters of that run) at t = 0.1245 s, where the contracted front segment's rim falls
// radially inwards over its last four rings (ring 29 at -79 deg, the last two turned back by
// tens of picometres). The rims' rings are graded (spacings 2.4 to 13 nm), so rows graded on
// each column's own width sit at heights differing by 1.5 per column there, and the lines
// leaning and fanning across them crossed them (column 30, row 12: the run ended there; with
// the rows equalised only within 3 columns of the steep segments, column 34, row 11). With the
// first rows' heights growing by at most 1.1 per column where the lines tilt, every element's
// Jacobian is positive and the rings are the wall's vertices. Fails with the per-column
// grading. And 1 ms later, the last rings turned back by 10 degrees: the rim's lean
// (lambda = 0.37) fell to 0.24 and 0.11 over the next two gap columns (2.8 and 3.9 nm wide), and
// the lines, 50 nm tall, crossed (column 33, row 11); with the lean's change per column limited
// by the column's width over the band, the mesh is valid. Fails without that limit. And 0.5 ms
// later, the wall flared at 45 degrees before the rim: the inside lines, fanning out with the
// slope 1 of a band twice the offset, ran parallel to the wall (column 25, row 7); with the band
// three times the offset the mesh is valid. Fails with the band at twice the offset.
namespace {
const double kFallingRim[][2] = {
    {9.1898358734378672e-07, 1.063346255123713e-07},
    {9.2244249099500561e-07, 1.0476022516881915e-07},
    {9.276060435413878e-07, 1.0241542831085457e-07},
    {9.3519635772018127e-07, 9.8821930167361859e-08},
    {9.4623354338489692e-07, 9.2108391651347686e-08},
    {9.5701650667112735e-07, 8.491360903462214e-08},
    {9.6807714090649971e-07, 7.7633860656162702e-08},
    {9.7983691457074308e-07, 7.1323294137291379e-08},
    {9.952608410093097e-07, 6.8103867269733413e-08},
    {1.0092666824342904e-06, 7.1416897642932914e-08},
    {1.0218345700269555e-06, 7.4782079319290866e-08},
    {1.0340264451181849e-06, 7.1441401913853004e-08},
    {1.0464892190300547e-06, 6.5723903349564481e-08},
    {1.0602433624964718e-06, 6.2479528373638154e-08},
    {1.0744379024361952e-06, 6.2131744551796915e-08},
    {1.0880690997649667e-06, 6.3256118162278316e-08},
    {1.1011769720473983e-06, 6.3961476421662761e-08},
    {1.1141741851398664e-06, 6.338297052459092e-08},
    {1.127405612761849e-06, 6.2542232470978959e-08},
    {1.1408788974791095e-06, 6.2586695849208203e-08},
    {1.1542133570696381e-06, 6.3532023286607991e-08},
    {1.1673565721764042e-06, 6.4422612073707433e-08},
    {1.1805850226823893e-06, 6.423444313023883e-08},
    {1.1942057814027013e-06, 6.3344663034540162e-08},
    {1.2083583651110623e-06, 6.4386935085268473e-08},
    {1.2217184587730077e-06, 6.9671280235234733e-08},
    {1.2333220428087261e-06, 7.7686278131685077e-08},
    {1.2443654289979717e-06, 8.216844365526992e-08},
    {1.2533001998069682e-06, 7.5037645982934456e-08},
    {1.2546339766520727e-06, 6.819842018887248e-08},
    {1.2547489895161033e-06, 6.3241742141627054e-08},
    {1.2547063462372857e-06, 5.9757974057078463e-08},
    {1.2546771590981517e-06, 5.7355931127614224e-08},
};

// The same run 1 ms later (t = 0.1255 s, meshed with the rows above): the last four rings
// turned back by 10 degrees.
const double kCurledBackRim[][2] = {
    {9.1781484415785135e-07, 1.069046472672673e-07},
    {9.2136340980707757e-07, 1.0559695597265581e-07},
    {9.2665330543787143e-07, 1.0364748639080958e-07},
    {9.3439291781587509e-07, 1.0065933712331123e-07},
    {9.4559369278877994e-07, 9.4885947538072359e-08},
    {9.5630601480900526e-07, 8.8269950069456331e-08},
    {9.6711816865660604e-07, 8.1186664574607018e-08},
    {9.7852220592026679e-07, 7.4790811869026396e-08},
    {9.9369343736034341e-07, 7.1045512506543639e-08},
    {1.0078419179924444e-06, 7.3901489191466737e-08},
    {1.0205347349131265e-06, 7.7370733319748938e-08},
    {1.0327095589611383e-06, 7.4074447744769666e-08},
    {1.0449360709935537e-06, 6.7680481044258801e-08},
    {1.0586004119158932e-06, 6.3520316768125009e-08},
    {1.07290313776619e-06, 6.277588706211853e-08},
    {1.0868259435241418e-06, 6.3741445077463838e-08},
    {1.1003469912859121e-06, 6.4438022754824171e-08},
    {1.1137583301553459e-06, 6.3838109598535097e-08},
    {1.1273238429218864e-06, 6.2952608112794602e-08},
    {1.1410544626752326e-06, 6.3052014442972277e-08},
    {1.1546884284280626e-06, 6.4188049126621246e-08},
    {1.1682147471694414e-06, 6.5236231568169975e-08},
    {1.1818948529910193e-06, 6.5163320153628532e-08},
    {1.1960059614200146e-06, 6.4842438159878825e-08},
    {1.210373387224645e-06, 6.7294933092353197e-08},
    {1.2231811874413987e-06, 7.442524478510632e-08},
    {1.2338014582511374e-06, 8.3815016922090514e-08},
    {1.244338580944939e-06, 8.8431475385986927e-08},
    {1.2516242788123751e-06, 7.9604963014291486e-08},
    {1.2516074067266621e-06, 7.2307461933711938e-08},
    {1.2508461062090661e-06, 6.7250903308778651e-08},
    {1.2502265519246192e-06, 6.3762694922961207e-08},
    {1.2498122507201686e-06, 6.1388392225197076e-08},
};

// 0.5 ms later again (t = 0.1260 s): the front segment flares outwards at 45 degrees before the
// rim turns back by 15 degrees.
const double kFlaredRim[][2] = {
    {9.1708283420084397e-07, 1.0708872928689771e-07},
    {9.2067542996653431e-07, 1.0592544532410633e-07},
    {9.2602773400844103e-07, 1.0419004068385752e-07},
    {9.3384945535555584e-07, 1.0152576130913481e-07},
    {9.4516007830318707e-07, 9.6334453594148518e-08},
    {9.5588295488108222e-07, 9.0097270195707045e-08},
    {9.6661261535460347e-07, 8.3168896070313279e-08},
    {9.7787649495735651e-07, 7.6776096392832351e-08},
    {9.9291631600771833e-07, 7.2797598192547661e-08},
    {1.0071196549161309e-06, 7.5364359610250887e-08},
    {1.0198788317315952e-06, 7.8807903622377342e-08},
    {1.0320721101167193e-06, 7.5569223189253268e-08},
    {1.0441810526232032e-06, 6.8875118311787551e-08},
    {1.0577923929064398e-06, 6.415953468630751e-08},
    {1.0722173512842594e-06, 6.3062561963581911e-08},
    {1.0863397146327636e-06, 6.3982143170111956e-08},
    {1.1000739365526362e-06, 6.4725080711548695e-08},
    {1.1136979238928517e-06, 6.4140044203012878e-08},
    {1.1274693861397997e-06, 6.3243859367124287e-08},
    {1.1413981050167128e-06, 6.340088210436176e-08},
    {1.1552343097385399e-06, 6.4665235656143375e-08},
    {1.1689825297743734e-06, 6.5823012068637922e-08},
    {1.1829173294698079e-06, 6.5906206861395702e-08},
    {1.1972814964532297e-06, 6.6074759178624558e-08},
    {1.2116844683494051e-06, 6.9444704199283436e-08},
    {1.2240872334022085e-06, 7.7580149804057826e-08},
    {1.2342075070892993e-06, 8.7571152764742789e-08},
    {1.2445329766074938e-06, 9.2098129701300637e-08},
    {1.2507780821701101e-06, 8.2311662081601163e-08},
    {1.2500062535271381e-06, 7.4877138505659201e-08},
    {1.248790911366044e-06, 6.9834101876599768e-08},
    {1.2478792187130191e-06, 6.6365299696297001e-08},
    {1.2472728765983224e-06, 6.4015905235074481e-08},
};

template <std::size_t N>
Eigen::Matrix3Xd shape_of(const double (&rings)[N][2]) {
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Zero(3, int(N));
  for (std::size_t k = 0; k < N; ++k) X(0, k) = rings[k][0], X(1, k) = rings[k][1];
  return X;
}

Eigen::Matrix3Xd falling_rim() { return shape_of(kFallingRim); }

// The run's mesh: 8 + 8 rows (4 + 4 for h = 31 nm, one more per rim level), 28 gap columns
// graded at a ratio up to 4 (axi::fitted_mesh_params).
FittedMeshParams falling_rim_params() {
  FittedMeshParams p = params(8, 8, 28, 2.0);
  p.gap_growth = 4.0;
  return p;
}

// Largest vertex displacement between two meshes of the same topology.
double largest_move(const FittedMesh& a, const FittedMesh& b) {
  double m = 0.0;
  for (int c = 0; c <= a.columns(); ++c)
    for (int j = 0; j <= a.rows(); ++j)
      m = std::max(m, std::hypot(a.vertex_x(c, j) - b.vertex_x(c, j), a.vertex_r(c, j) - b.vertex_r(c, j)));
  return m;
}
}  // namespace

TEST(FittedMeshTilted, MeshesAContractedRimThatFallsInwards) {
  for (int which = 0; which < 3; ++which) {
    const Eigen::Matrix3Xd X = which == 2 ? shape_of(kFlaredRim) : which ? shape_of(kCurledBackRim) : falling_rim();
    const int n = int(X.cols());
    FittedMesh m(falling_rim_params(), n);
    const char* what = which == 2 ? "contracted rim flared" : which ? "contracted rim curled back" : "contracted rim falling inwards";
    ASSERT_NO_THROW(m.fit(X)) << what;
    expect_valid(m, what);
    for (int k = 0; k < n; ++k) {
      EXPECT_EQ(m.vertex_x(k, m.params().cells_inner), X(0, k));
      EXPECT_EQ(m.vertex_r(k, m.params().cells_inner), X(1, k));
    }
  }
}

// The mesh is a continuous (Lipschitz) function of the shape, as the implicit stepper needs:
// on the falling rim, random perturbations of every ring by up to eps times the smallest ring
// spacing (2.4 nm) move no vertex by more than 1000 eps times that spacing, and by no more at
// eps = 1e-7 than at 1e-3 (a jump would show as a ratio growing like 1/eps; measured: 445 at
// both, the gap's graded columns, whose common ratio follows the rim segment's width). And along a one-parameter family (the
// radially standing step stretched along the axis by 1.2 to 1.6 in 400 steps, so that the walks
// that return the steep segments' room end on other donors), no step moves a
// vertex by more than 10 times the largest ring move (measured: 1.01; 64 with a donor walk
// that counts its last donor whole, whose far offsets jump by a fraction of that segment's
// room). Fails with such a jump.
TEST(FittedMeshTilted, IsContinuousInTheWallShape) {
  {
    const Eigen::Matrix3Xd X = falling_rim();
    const int n = int(X.cols());
    double dmin = INFINITY;
    for (int k = 1; k < n; ++k) dmin = std::min(dmin, std::hypot(X(0, k) - X(0, k - 1), X(1, k) - X(1, k - 1)));
    FittedMesh a(falling_rim_params(), n), b(falling_rim_params(), n);
    a.fit(X);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    double worst[2] = {0.0, 0.0};
    for (int i = 0; i < 2; ++i) {
      const double eps = i ? 1e-7 : 1e-3;
      for (int t = 0; t < 20; ++t) {
        Eigen::Matrix3Xd Y = X;
        for (int k = 0; k < n; ++k) Y(0, k) += eps * dmin * u(rng), Y(1, k) += eps * dmin * u(rng);
        b.fit(Y);
        worst[i] = std::max(worst[i], largest_move(a, b) / (eps * dmin));
      }
      std::printf("  falling rim, eps %.0e: largest vertex move / ring move bound %.1f\n", eps, worst[i]);
    }
    EXPECT_LT(worst[0], 1000.0);
    EXPECT_LT(worst[1], 2.0 * worst[0]);
  }
  {
    const int n = 65, steps = 400;
    const FittedMeshParams p = params(6, 6, 16, 2.0);
    FittedMesh a(p, n), b(p, n);
    auto shape = [&](double stretch) {
      Eigen::Matrix3Xd X = step_wall(n, 0.5 * kPi);
      const double x0 = X(0, 0);
      for (int k = 0; k < n; ++k) X(0, k) = x0 + (X(0, k) - x0) * stretch;
      return X;
    };
    Eigen::Matrix3Xd X = shape(1.2);
    a.fit(X);
    double worst = 0.0;
    for (int i = 1; i <= steps; ++i) {
      const Eigen::Matrix3Xd Y = shape(1.2 + 0.4 * i / steps);
      b.fit(Y);
      const double ring = (Y - X).colwise().norm().maxCoeff();
      worst = std::max(worst, largest_move(a, b) / ring);
      std::swap(a, b);
      X = Y;
    }
    std::printf("  stretched step: largest vertex move / ring move %.2f\n", worst);
    EXPECT_LT(worst, 10.0);
  }
}

// A wall turned back by 110 degrees over a long stretch (the step between a contracted and a
// relaxed segment leaning back: 129 rings, 16 + 16 rows graded to the wall) folds the algebraic
// lines outside the wall (the concave corner at the step's foot), and the wall line does not
// advance along the axis, so the vertical lines cannot stand in. The elliptic smoothing around
// the fold meshes it: every corner Jacobian positive, the rings the wall's vertices (to the bit),
// Poiseuille flow exact to round-off on the smoothed elements (as on any valid bilinear mesh),
// and the point location maps every element's points back. Fails without the smoothing (fit
// throws). Where the algebraic lines are valid (the radially standing step, the contracted rim
// of paper_amplitude_0.35) the smoothing changes nothing: the vertices are the same to the bit.
TEST(FittedMeshTilted, SmoothsTheLinesWhereTheAlgebraicOnesFold) {
  const int n = 129;
  FittedMeshParams p = params(16, 16, 40, 2.0);
  const Eigen::Matrix3Xd X = step_wall(n, 110.0 / 180.0 * kPi);
  {
    FittedMeshParams q = p;
    q.elliptic_smoothing = false;
    FittedMesh m(q, n);
    EXPECT_THROW(m.fit(X), swim::NumericalError) << "the algebraic lines alone mesh the overhang";
  }
  {
    FittedMesh t(p, n);
    const auto t0 = std::chrono::steady_clock::now();
    t.fit(X);
    std::printf("  smoothed fit: %.1f ms\n", std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  FittedStokes s(p, kMu, n);
  ASSERT_NO_THROW(s.factor(X));
  const FittedMesh& m = s.mesh();
  expect_valid(m, "step leaning back by 20 deg, smoothed");
  for (int k = 0; k < n; ++k) {
    EXPECT_EQ(m.vertex_x(k, p.cells_inner), X(0, k));
    EXPECT_EQ(m.vertex_r(k, p.cells_inner), X(1, k));
  }
  const double G = 1.0e9;
  auto w = [&](double r) { return G * (kRc * kRc - r * r) / (4 * kMu); };
  Eigen::Matrix3Xd U;
  const Body f = [&](double, double) { return Eigen::Vector2d(G, 0.0); };
  s.solve(Eigen::Matrix3Xd::Zero(3, n), U, &f);
  double eu = 0.0, back = 0.0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.95, 0.95);
  for (int e = 0; e < m.elements(); e += 7) {
    const Eigen::Vector2d Y = map_point(m, e, u(rng), u(rng));
    const Eigen::Vector2d v = s.velocity(Y[0], Y[1]);
    eu = std::max({eu, std::abs(v[0] - w(Y[1])), std::abs(v[1])});
    double x = Y[0], xi, eta;
    const int g = m.locate(x, Y[1], xi, eta);
    const Eigen::Vector2d Z = map_point(m, g, xi, eta);
    back = std::max(back, std::hypot(Z[0] - x, Z[1] - Y[1]));
  }
  std::printf("  smoothed overhang: Poiseuille rel. error %.2e, located points mapped back within %.2e m\n",
              eu / w(0), back);
  EXPECT_LT(eu / w(0), 1e-10);
  EXPECT_LT(back, 1e-12 * kRc);
  for (int which = 0; which < 2; ++which) {
    const Eigen::Matrix3Xd Y = which ? falling_rim() : step_wall(65, 0.5 * kPi);
    FittedMeshParams a = which ? falling_rim_params() : params(6, 6, 16), b = a;
    b.elliptic_smoothing = false;
    FittedMesh ma(a, int(Y.cols())), mb(b, int(Y.cols()));
    ma.fit(Y);
    mb.fit(Y);
    EXPECT_EQ(largest_move(ma, mb), 0.0) << (which ? "contracted rim" : "radial step");
  }
}
