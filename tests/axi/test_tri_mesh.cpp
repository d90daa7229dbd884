// The fitted method's triangular mesh (axi/tri_mesh.hpp) and the P2+ element of its Stokes solver
// (axi/fe_stokes_axi.hpp, "Triangles"). What each test expects, and why, is stated at the test.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numbers>
#include <random>
#include <string>

#include "axi/fe_stokes_axi.hpp"
#include "axi/fitted_mesh.hpp"
#include "axi/tri_mesh.hpp"
#include "common/errors.hpp"
#include "tests/support/axi_fixture.hpp"

using swim::axi::FittedStokes;
using swim::axi::TriMesh;
using swim::axi::TriMeshParams;

namespace {

using namespace swim::test::fitted_tube;
constexpr double kPi = std::numbers::pi;
using Body = std::function<Eigen::Vector2d(double, double)>;

TriMeshParams tri_params(double h, double gap_size = 1.0) {
  TriMeshParams p;
  p.Rc = kRc;
  p.period = kP;
  p.size = h;
  p.gap_size = gap_size;
  return p;
}

// An open tube of n rings from x0 over L, radius kA (1 + amp sin(2 pi s)).
Eigen::Matrix3Xd tube(int n, double amp = 0.0, double x0 = 0.3e-6) {
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Zero(3, n);
  for (int k = 0; k < n; ++k) {
    const double s = double(k) / (n - 1);
    X(0, k) = x0 + s * kL;
    X(1, k) = kA * (1.0 + amp * std::sin(2 * kPi * s));
  }
  return X;
}

// A tube of n rings of equal spacing whose tangent turns by theta_end over the last 20 % of its
// arc length (positive: the rim curls outwards and back over the tube; negative: inwards and back
// over the lumen, the hook of the round wall's front rim, docs/axi.md).
Eigen::Matrix3Xd hooked(int n, double theta_end) {
  Eigen::Matrix3Xd X = Eigen::Matrix3Xd::Zero(3, n);
  const double ds = kL / (n - 1);
  X(0, 0) = 0.3e-6;
  X(1, 0) = kA;
  for (int k = 1; k < n; ++k) {
    const double s = (k - 0.5) / (n - 1), u = std::clamp((s - 0.8) / 0.2, 0.0, 1.0);
    const double th = theta_end * u * u * (3 - 2 * u);
    X(0, k) = X(0, k - 1) + ds * std::cos(th);
    X(1, k) = X(1, k - 1) + ds * std::sin(th);
  }
  return X;
}

std::unique_ptr<FittedStokes> tri_solver(double h, const Eigen::Matrix3Xd& X, double gap_size = 1.0) {
  return std::make_unique<FittedStokes>(std::make_unique<TriMesh>(tri_params(h, gap_size), X), kMu);
}

const TriMesh& tri_of(const FittedStokes& s) { return dynamic_cast<const TriMesh&>(s.meridian_mesh()); }

Eigen::Matrix3Xd random_forces(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, n);
  for (int k = 0; k < n; ++k) F(0, k) = 1e-12 * d(rng), F(1, k) = 1e-12 * d(rng);
  return F;
}

double triangle_area(const TriMesh& m, int e) {
  double x[4], r[4];
  m.corners(e, x, r);
  return 0.5 * ((x[1] - x[0]) * (r[2] - r[0]) - (x[2] - x[0]) * (r[1] - r[0]));
}

}  // namespace

// The triangulation keeps every ring as a vertex and every wall segment as an edge (the solver's
// wall nodes sit at the rings and the segments' midpoints), its triangles are positively
// oriented and tile the periodic strip exactly (their areas add up to P Rc), and its angles stay
// above 10 degrees. Fails if the mesher split a wall segment or a cut, or a periodic image is
// placed at the wrong x.
TEST(TriMesh, KeepsTheRingsAsVerticesAndTilesThePeriodicStrip) {
  const double h = kRc / 16;
  const int n = int(kL / (0.5 * h)) + 1;
  const Eigen::Matrix3Xd X = tube(n, 0.2);
  const TriMesh m(tri_params(h), X);
  double area = 0.0;
  for (int e = 0; e < m.elements(); ++e) {
    const double a = triangle_area(m, e);
    EXPECT_GT(a, 0.0) << "triangle " << e;
    area += a;
  }
  std::printf("  %d rings: %d vertices, %d triangles, %d P2+ nodes; smallest angle %.1f deg; area / (P Rc) - 1 = %.1e\n",
              n, m.vertices(), m.elements(), m.nodes(), m.min_angle() * 180 / kPi, area / (kP * kRc) - 1);
  EXPECT_NEAR(area, kP * kRc, 1e-12 * kP * kRc);
  EXPECT_GT(m.min_angle(), 10.0 * kPi / 180);
  for (int k = 0; k < n; ++k) {
    EXPECT_EQ(m.wall_point(k).x(), X(0, k));
    EXPECT_EQ(m.wall_point(k).y(), X(1, k));
    EXPECT_EQ(m.node_kind(m.wall_node(k)), swim::axi::NodeKind::interior);
  }
  std::vector<swim::axi::RimPathEdge> path;
  for (int end = 0; end < 2; ++end) {
    m.rim_path(end, path);
    ASSERT_FALSE(path.empty());
    EXPECT_EQ(path.front().r0, 0.0);                       // starts on the axis
    EXPECT_EQ(path.back().node[2], m.wall_node(end ? n - 1 : 0));  // ends at the rim
    for (std::size_t i = 1; i < path.size(); ++i) EXPECT_EQ(path[i].node[0], path[i - 1].node[2]);
  }
}

// Poiseuille flow (f_x = G, u_x = G (Rc^2 - r^2) / (4 mu)) lies in the P2 velocity space and the
// constant pressure in P1: the solver reproduces it to round-off at every node of the unstructured
// mesh around a wavy wall (no membrane force). Fails for a wrong P2+ basis, quadrature,
// axisymmetric weight or periodic identification.
TEST(TriStokes, PoiseuilleFlowIsExact) {
  for (const double gap_size : {1.0, 3.0}) {
  SCOPED_TRACE("axi.gap_size = " + std::to_string(gap_size));
  const double G = 1.0e9, h = kRc / 8;
  const int n = int(kL / (0.5 * h)) + 1;
  auto s = tri_solver(h, tube(n, 0.3), gap_size);
  s->factor(tube(n, 0.3));
  Eigen::Matrix3Xd U;
  const Body f = [&](double, double) { return Eigen::Vector2d(G, 0.0); };
  s->solve(Eigen::Matrix3Xd::Zero(3, n), U, &f);
  const TriMesh& m = tri_of(*s);
  const double wmax = G * kRc * kRc / (4 * kMu);
  double err = 0.0, perr = 0.0;
  for (int e = 0; e < m.elements(); ++e)
    for (int a = 0; a < 7; ++a) {
      const Eigen::Vector2d Y = m.slot_position(e, a);
      const Eigen::Vector2d u = s->velocity(Y.x(), Y.y());
      err = std::max({err, std::abs(u.x() - G * (kRc * kRc - Y.y() * Y.y()) / (4 * kMu)), std::abs(u.y())});
      perr = std::max(perr, std::abs(s->pressure(Y.x(), Y.y())));
    }
  std::printf("  gap size %g h: nodal velocity error %.2e of u_max, pressure %.2e of G Rc\n", gap_size, err / wmax,
              perr / (G * kRc));
  EXPECT_LT(err, 1e-9 * wmax);
  EXPECT_LT(perr, 1e-9 * G * kRc);
  }
}

// The membrane's power F . U equals the viscous dissipation a(u, u), every element conserves mass,
// and the wall's mobility F -> U is symmetric and positive: the load and the read-out are the same
// transfer on the triangles' wall edges. Fails for a load not adjoint to the read-out, a wrong
// divergence form or a wrong midside node of a wall segment.
TEST(TriStokes, PowerIsDissipatedMassIsConservedAndTheMobilityIsSymmetric) {
  const double h = kRc / 4;
  const int n = 17;
  const Eigen::Matrix3Xd X = tube(n, 0.3);
  auto s = tri_solver(h, X);
  s->factor(X);
  std::mt19937 rng(7);
  for (int t = 0; t < 2; ++t) {
    const Eigen::Matrix3Xd F = random_forces(n, rng);
    Eigen::Matrix3Xd U;
    s->solve(F, U);
    const double P = (F.topRows(2).array() * U.topRows(2).array()).sum(), D = s->dissipation();
    std::printf("  power %.6e W, dissipation %.6e W, mass residual %.1e\n", P, D, s->lumen_divergence_residual());
    EXPECT_GT(P, 0.0);
    EXPECT_NEAR(D, P, 1e-10 * P);
    EXPECT_LT(s->lumen_divergence_residual(), 1e-10);
  }
  const int m = 2 * n;
  Eigen::MatrixXd M(m, m);
  Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, n), U;
  for (int j = 0; j < m; ++j) {
    F.setZero();
    F(j % 2, j / 2) = 1.0;
    s->solve(F, U);
    for (int i = 0; i < m; ++i) M(i, j) = U(i % 2, i / 2);
  }
  EXPECT_LT((M - M.transpose()).cwiseAbs().maxCoeff(), 1e-10 * M.cwiseAbs().maxCoeff());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (M + M.transpose()));
  EXPECT_GT(es.eigenvalues().minCoeff(), 0.0);
}

// The mesh moves with the wall by the harmonic extension of the rings' displacement: a wall
// translated along the axis (here by more than a tenth of the period) moves every vertex by the
// same amount, so the wall's velocities under the same forces do not change (to round-off); a
// contraction of the middle of the tube to 0.55 of its radius keeps every triangle valid. Fails
// if the motion does not reproduce a translation, or the periodic images move apart.
TEST(TriMesh, MovesWithTheWall) {
  const double h = kRc / 8;
  const int n = int(kL / (0.5 * h)) + 1;
  const Eigen::Matrix3Xd X = tube(n, 0.0);
  auto s = tri_solver(h, X);
  std::mt19937 rng(3);
  const Eigen::Matrix3Xd F = random_forces(n, rng);
  Eigen::Matrix3Xd U0, U1;
  s->factor(X);
  s->solve(F, U0);
  Eigen::Matrix3Xd Xs = X;
  Xs.row(0).array() += 0.2371e-6;
  s->factor(Xs);
  s->solve(F, U1);
  const double e = (U1 - U0).cwiseAbs().maxCoeff() / U0.cwiseAbs().maxCoeff();
  std::printf("  translated by 0.237 um: relative change of the wall velocities %.2e\n", e);
  EXPECT_LT(e, 1e-9);
  Eigen::Matrix3Xd Xc = X;
  for (int k = 0; k < n; ++k) {
    const double s01 = double(k) / (n - 1);
    Xc(1, k) = kA * (1.0 - 0.45 * std::exp(-std::pow((s01 - 0.5) / 0.2, 2)));
  }
  const TriMesh& m = tri_of(*s);
  EXPECT_TRUE(m.follows(Xc));
  s->factor(Xc);
  std::printf("  contracted to 0.55 R0: smallest angle %.1f deg\n", m.min_angle() * 180 / kPi);
  EXPECT_GT(m.min_angle(), 5.0 * kPi / 180);
}

// The degradation threshold of a run's remeshing (TriMesh::remesh_threshold). The mesher's bound
// is asin(sqrt(0.125)) = 20.705 degrees. A smooth tube is meshed above it, so the nominal
// threshold (12 degrees) stands. A wall with a spike whose two segments meet at about 9.5 degrees
// caps the smallest angle of any triangulation that keeps the rings at that apex angle: the made
// mesh falls short of the bound, and the threshold falls with it (12 degrees times the made
// mesh's smallest angle over the bound), so a fit of the mesh as made does not count as
// degraded. Fails if the bound is computed from the wrong relation (NaN or 90 degrees for the
// default b), or the threshold does not scale, which makes a run mesh again at every step while
// the wall keeps such a corner.
TEST(TriMesh, ScalesItsRemeshThresholdByTheAngleTheMadeMeshReached) {
  const double h = kRc / 16, deg = kPi / 180;
  const int n = int(kL / (0.5 * h)) + 1;
  const TriMesh smooth(tri_params(h), tube(n, 0.2));
  EXPECT_NEAR(smooth.bound_angle() / deg, 20.7048, 1e-3);
  ASSERT_GE(smooth.min_angle(), smooth.bound_angle());
  EXPECT_EQ(smooth.remesh_threshold(12 * deg), 12 * deg);
  Eigen::Matrix3Xd X = tube(n);
  const double ds = kL / (n - 1);
  X(1, n / 2) += 12 * ds;  // its neighbours ds either side: apex angle 2 atan(1 / 12) = 9.53 degrees
  const TriMesh spiked(tri_params(h), X);
  std::printf("  spike of apex angle 9.53 deg: the made mesh's smallest angle %.2f deg, threshold %.2f deg\n",
              spiked.min_angle() / deg, spiked.remesh_threshold(12 * deg) / deg);
  EXPECT_LE(spiked.min_angle(), 9.54 * deg);
  EXPECT_GT(spiked.min_angle(), 1 * deg);
  EXPECT_NEAR(spiked.remesh_threshold(12 * deg), 12 * deg * spiked.min_angle() / spiked.bound_angle(), 1e-15);
  EXPECT_LT(spiked.remesh_threshold(12 * deg), spiked.min_angle());
}

// A ring pushed through its neighbours' triangles inverts them: fit refuses the shape with a
// swim::NumericalError naming the triangle and the ring, follows() says so without changing the
// mesh, and the mesh still fits the good shape afterwards.
TEST(TriMesh, RefusesAShapeItCannotFollow) {
  const double h = kRc / 8;
  const int n = int(kL / (0.5 * h)) + 1;
  const Eigen::Matrix3Xd X = tube(n);
  TriMesh m(tri_params(h), X);
  Eigen::Matrix3Xd B = X;
  B(0, n / 2) += 3 * kL / (n - 1);  // past two neighbours along the axis
  std::string cause;
  EXPECT_FALSE(m.follows(B, &cause));
  EXPECT_NE(cause.find("non-positive Jacobian"), std::string::npos) << cause;
  EXPECT_THROW(m.fit(B), swim::NumericalError);
  B = X;
  B(1, 3) = kRc;
  EXPECT_FALSE(m.follows(B, &cause));
  EXPECT_NE(cause.find("outside (0, Rc)"), std::string::npos) << cause;
  EXPECT_NO_THROW(m.fit(X));
}

// A mesh made on a shape the strip cannot hold (a ring on the container, a tube as long as the
// period) is a numerical failure of the run that asked for it, naming the ring and a scene key.
TEST(TriMesh, RefusesToMeshAShapeTheStripCannotHold) {
  const double h = kRc / 8;
  const int n = int(kL / (0.5 * h)) + 1;
  Eigen::Matrix3Xd X = tube(n);
  X(1, 5) = kRc;
  try {
    TriMesh m(tri_params(h), X);
    ADD_FAILURE() << "a ring on the container was meshed";
  } catch (const swim::NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("wall ring 5"), std::string::npos) << e.what();
    EXPECT_NE(e.remedy().find("protocol.pressure"), std::string::npos) << e.remedy();
  }
  X = tube(n);
  X(0, n - 1) = X(0, 0) + kP;
  EXPECT_THROW(TriMesh(tri_params(h), X), swim::NumericalError);
}

// The hook the structured mesh cannot follow (docs/axi.md, "What the mesh cannot follow"): a rim
// curled through 200 degrees, inwards over a wedge of lumen and outwards over the tube. The
// structured mesh refuses both; the triangulation meshes them and its solve conserves mass and
// dissipates the power put in. Fails if a hooked wall cannot be triangulated or its wedge's
// elements are inverted.
TEST(TriMesh, MeshesAHookedRimTheStructuredMeshCannot) {
  const double h = kRc / 16;
  const int n = int(kL / (0.5 * h)) + 1;
  for (double theta : {-200.0, 200.0}) {
    const Eigen::Matrix3Xd X = hooked(n, theta * kPi / 180);
    const double ci = std::lround(kA / h), co = std::lround((kRc - kA) / h);
    FittedStokes quad(swim::test::fitted_mesh_params(kRc, kP, int(ci), int(co), 32, 1.2), kMu, n);
    EXPECT_THROW(quad.factor(X), swim::NumericalError) << theta;
    auto s = tri_solver(h, X);
    s->factor(X);
    std::mt19937 rng(5);
    const Eigen::Matrix3Xd F = random_forces(n, rng);
    Eigen::Matrix3Xd U;
    s->solve(F, U);
    const double P = (F.topRows(2).array() * U.topRows(2).array()).sum();
    std::printf("  rim curled by %.0f deg: %d triangles, smallest angle %.1f deg, power/dissipation - 1 = %.1e\n", theta,
                s->meridian_mesh().elements(), tri_of(*s).min_angle() * 180 / kPi, s->dissipation() / P - 1);
    EXPECT_NEAR(s->dissipation(), P, 1e-10 * P);
    EXPECT_LT(s->lumen_divergence_residual(), 1e-10);
  }
}

// The two meshes discretise the same problem: the towed rigid tube's drag and the lumen flux it
// carries (the prescribed wall's steady flows, FittedStokes::prescribed_wall_velocity) on the
// triangles and on the structured quadrilaterals approach each other as h falls, and agree within
// 1 % at h = Rc/32. Fails for a wrong rim path (the flux), a wrong wall line on the triangles, or
// a discretisation that converges to something else.
TEST(TriStokes, TheTowedTubeAgreesWithTheStructuredMeshAsBothRefine) {
  double prev_drag = 0, prev_flux = 0;
  for (int level = 0; level < 3; ++level) {
    const int cells = 8 << level;
    const double h = kRc / cells;
    const int n = int(kL / (0.5 * h)) + 1;
    const Eigen::Matrix3Xd X = tube(n);
    const Eigen::Matrix3Xd V = Eigen::Matrix3Xd::Zero(3, n);
    auto t = tri_solver(h, X);
    const auto wt = t->prescribed_wall_velocity(X, V);
    FittedStokes q(swim::test::fitted_mesh_params(kRc, kP, cells / 2, cells / 2, 4 * cells, 1.2), kMu, n);
    const auto wq = q.prescribed_wall_velocity(X, V);
    const double dd = wt.drag / wq.drag - 1, df = wt.towed_lumen_flux / wq.towed_lumen_flux - 1;
    std::printf("  h = Rc/%d: drag %.6e / %.6e N s/m (%.2e), lumen flux %.6e / %.6e m^3/s per m/s (%.2e); %d / %d unknowns\n",
                cells, wt.drag, wq.drag, dd, wt.towed_lumen_flux, wq.towed_lumen_flux, df, t->unknowns(), q.unknowns());
    if (level > 0) {
      EXPECT_LT(std::abs(dd), std::abs(prev_drag) + 1e-3);
      EXPECT_LT(std::abs(df), std::abs(prev_flux) + 1e-3);
    }
    prev_drag = dd;
    prev_flux = df;
  }
  EXPECT_LT(std::abs(prev_drag), 0.01);
  EXPECT_LT(std::abs(prev_flux), 0.01);
}

// Beyond the tube's ends the triangles may grow (TriMeshParams::gap_size): the size bound is
// h min(gap_size, 1 + 5 d / Rc) at an axial distance d from the nearer end. With gap_size = 3 the
// mesh tiles the strip and keeps every ring as the uniform one does, with under half its
// triangles: those in the gap's middle more than twice as large, those beside the tube no larger,
// and no triangle further above its local bound than the uniform mesh's are above h (the mesher
// does not split the constrained edges, so a triangle on one may exceed its bound a little).
// Fails if the size field is ignored (no saving, no large triangle) or misplaced (a large
// triangle beside the tube or one far above its bound).
TEST(TriMesh, GrowsItsTrianglesInTheGapBetweenTheTubesEnds) {
  const double h = kRc / 16;
  const int n = int(kL / (0.5 * h)) + 1;
  const Eigen::Matrix3Xd X = tube(n);
  const TriMesh uniform(tri_params(h), X), graded(tri_params(h, 3.0), X);
  const double x0 = X(0, 0), x1 = X(0, n - 1);
  // the longest edge of each triangle against its size bound at the centroid; the largest
  // triangle beside the tube and in the gap's middle (beyond Rc from the ends)
  struct Sizes {
    double area = 0, worst = 0, beside = 0, middle = 0;
  };
  const auto sizes = [&](const TriMesh& m, double gap_size) {
    Sizes z;
    for (int e = 0; e < m.elements(); ++e) {
      double x[4], r[4];
      m.corners(e, x, r);
      z.area += triangle_area(m, e);
      double longest = 0.0;
      for (int i = 0; i < 3; ++i) longest = std::max(longest, std::hypot(x[(i + 1) % 3] - x[i], r[(i + 1) % 3] - r[i]));
      const double xc = (x[0] + x[1] + x[2]) / 3.0, d = std::max({0.0, x0 - xc, xc - x1});
      z.worst = std::max(z.worst, longest / (h * std::min(gap_size, 1.0 + 5.0 * d / kRc)));
      if (d == 0.0) z.beside = std::max(z.beside, longest);
      if (d > kRc) z.middle = std::max(z.middle, longest);
    }
    return z;
  };
  const Sizes u = sizes(uniform, 1.0), g = sizes(graded, 3.0);
  std::printf("  h = Rc/16: %d triangles uniform, %d with gap size 3 (%.2f); longest edge over the local bound %.2f "
              "(uniform %.2f); beside the tube %.2f h (uniform %.2f h), in the gap's middle %.2f h (uniform %.2f h); "
              "smallest angle %.1f deg (uniform %.1f deg)\n",
              uniform.elements(), graded.elements(), double(graded.elements()) / uniform.elements(), g.worst, u.worst,
              g.beside / h, u.beside / h, g.middle / h, u.middle / h, graded.min_angle() * 180 / kPi,
              uniform.min_angle() * 180 / kPi);
  EXPECT_NEAR(g.area, kP * kRc, 1e-12 * kP * kRc);
  EXPECT_LT(graded.elements(), 0.5 * uniform.elements());
  EXPECT_LE(g.worst, 1.5 * u.worst);
  EXPECT_LE(g.beside, 1.05 * u.beside);
  EXPECT_GT(g.middle, 2.0 * u.middle);
  EXPECT_GT(graded.min_angle(), 20.0 * kPi / 180);
  for (int k = 0; k < n; ++k) EXPECT_EQ(graded.wall_point(k).x(), X(0, k));
}

// The larger triangles in the gap change the towed tube's drag and the lumen flux it carries by
// less than a third of the discretisation error at the same h (the change from h = Rc/8 to Rc/16
// on the uniform mesh: 2.7e-3 and 6.4e-3), with under half the unknowns. At Rc/8, where the gap's
// triangles reach 0.375 Rc, the difference is printed, not asserted. Fails if the gap's flow is
// under-resolved (the drag's return flow and the lumen's inflow pass through it) or the graded
// boundary points break the periodic identification.
TEST(TriStokes, TheGapsLargerTrianglesKeepTheTowedTubesDragAndFlux) {
  double drag8 = 0, flux8 = 0;
  for (const int cells : {8, 16}) {
    const double h = kRc / cells;
    const int n = int(kL / (0.5 * h)) + 1;
    const Eigen::Matrix3Xd X = tube(n);
    const Eigen::Matrix3Xd V = Eigen::Matrix3Xd::Zero(3, n);
    auto u = tri_solver(h, X), g = tri_solver(h, X, 3.0);
    const auto wu = u->prescribed_wall_velocity(X, V), wg = g->prescribed_wall_velocity(X, V);
    const double dd = wg.drag / wu.drag - 1, df = wg.towed_lumen_flux / wu.towed_lumen_flux - 1;
    std::printf("  h = Rc/%d: drag %.2e, lumen flux %.2e relative to the uniform mesh; %d against %d unknowns\n", cells,
                dd, df, g->unknowns(), u->unknowns());
    EXPECT_LT(g->unknowns(), 0.5 * u->unknowns());
    if (cells == 8) {
      drag8 = wu.drag, flux8 = wu.towed_lumen_flux;
      continue;
    }
    const double ed = std::abs(wu.drag / drag8 - 1), ef = std::abs(wu.towed_lumen_flux / flux8 - 1);
    std::printf("  uniform mesh from Rc/8 to Rc/16: drag %.2e, lumen flux %.2e\n", ed, ef);
    EXPECT_LT(std::abs(dd), ed / 3);
    EXPECT_LT(std::abs(df), ef / 3);
  }
}
