// The stabilised wall update (wall_stabilizer.hpp): its operator in the rings' azimuthal modes
// is the graph Laplacian's cube on the mesh, its solve inverts I + dt B, it leaves rigid
// translations alone and is symmetric positive semi-definite; coupled through the fluid, a
// bending-dominated wall steps stably beyond forward Euler's limit, with first-order error.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "common/errors.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/wall_stabilizer.hpp"

using namespace swim::full3d;

namespace {
constexpr double kR0 = 0.125e-6, kL = 0.4e-6, kBox = 0.5e-6, kMu = 1.2e-3;

Eigen::Matrix3Xd random_field(int n, unsigned seed) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3Xd x(3, n);
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = u(g);
  return x;
}

Eigen::SparseMatrix<double> graph_laplacian(const CylinderMesh& mesh) {
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd deg = Eigen::VectorXd::Zero(mesh.nodes());
  for (const auto& e : mesh.edges) {
    t.emplace_back(e[0], e[1], -1.0);
    t.emplace_back(e[1], e[0], -1.0);
    deg[e[0]] += 1.0;
    deg[e[1]] += 1.0;
  }
  for (int i = 0; i < mesh.nodes(); ++i) t.emplace_back(i, i, deg[i]);
  Eigen::SparseMatrix<double> L(mesh.nodes(), mesh.nodes());
  L.setFromTriplets(t.begin(), t.end());
  return L;
}

// Meshes with an even and an odd node count per ring, and one seeded with lobes (the seed moves
// nodes radially: the connectivity and the node angles stay).
std::vector<CylinderMesh> meshes() {
  const Eigen::Vector3d start(0.05e-6, 0.25e-6, 0.25e-6);
  std::vector<CylinderMesh> v{make_cylinder(kR0, 0.2e-6, 24, start), make_cylinder(kR0, 0.1e-6, 19, start),
                              make_cylinder_for_grid(kR0, kL, kBox / 16, start)};
  CylinderMesh seeded = make_cylinder(kR0, 0.2e-6, 40, start);
  seed_ring_mode(seeded, 8, 0.01);
  v.push_back(seeded);
  return v;
}
}  // namespace

// S^T Lt S with S the graph Laplacian's rows of the nodes off the end rings and Lt its block on
// them, assembled from the mesh's edges, against the operator in the azimuthal modes; on a
// field linear along the axis (the free ends' null space) it is zero.
TEST(WallStabilizer, ItsOperatorIsTheCubedGraphLaplacianWithFreeEnds) {
  for (const CylinderMesh& mesh : meshes()) {
    const WallStabilizer st(mesh, kBox / 16, kMu, 1e-24, WallStabilization::Bending);
    const Eigen::SparseMatrix<double> L = graph_laplacian(mesh);
    const int n_in = mesh.nodes() - 2 * mesh.n_theta;  // nodes off the end rings
    Eigen::SparseMatrix<double> P(n_in, mesh.nodes());  // selects them
    for (int i = 0; i < n_in; ++i) P.insert(i, mesh.n_theta + i) = 1.0;
    const Eigen::SparseMatrix<double> S = P * L;
    const Eigen::SparseMatrix<double> Lt = S * Eigen::SparseMatrix<double>(P.transpose());
    const double scale = st.mobility() * st.kappa_bending() / st.laplacian_at_h();
    const Eigen::Matrix3Xd x = random_field(mesh.nodes(), 7);
    const Eigen::MatrixXd xt = x.transpose();
    // the filter P = (I + Lg / (8 l_h))^8: B = P^{-1} K
    Eigen::SparseMatrix<double> I(mesh.nodes(), mesh.nodes());
    I.setIdentity();
    const Eigen::SparseMatrix<double> one = I + (1.0 / (8.0 * st.laplacian_at_h())) * L;
    Eigen::SparseMatrix<double> Pf = one;
    for (int k = 1; k < 8; ++k) Pf = Eigen::SparseMatrix<double>(Pf * one);
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> Pinv(Pf);
    const Eigen::MatrixXd expect =
        Pinv.solve(Eigen::MatrixXd(scale * (Eigen::SparseMatrix<double>(S.transpose()) * (Lt * (S * xt)))));
    const Eigen::Matrix3Xd got = st.rate(x);
    EXPECT_LT((got.transpose() - expect).norm(), 1e-11 * expect.norm())
        << mesh.n_theta << " nodes per ring, " << mesh.n_rings << " rings";
    // linear along the axis: every component a + b x (the node's axial coordinate)
    Eigen::Matrix3Xd lin(3, mesh.nodes());
    for (int k = 0; k < mesh.nodes(); ++k)
      lin.col(k) = Eigen::Vector3d(1.0, -0.5, 2.0) * 1e-9 + Eigen::Vector3d(0.3, 1.0, -0.7) * (mesh.X0(0, k) - mesh.axis_start(0)) * 1e-2;
    const double norm_B = scale * 729.0;  // |Lg| <= 9
    EXPECT_LT(st.rate(lin).norm(), 1e-12 * norm_B * lin.norm()) << mesh.n_theta << " nodes per ring";
  }
}

TEST(WallStabilizer, TheSolveInvertsIPlusDtBAndLeavesTranslationsAlone) {
  for (const CylinderMesh& mesh : meshes()) {
    const WallStabilizer st(mesh, kBox / 16, kMu, 1e-24, WallStabilization::Bending);
    const Eigen::Matrix3Xd y = random_field(mesh.nodes(), 11), z = random_field(mesh.nodes(), 13);
    for (double dt : {1e-4, 1e-2, 1.0}) {
      Eigen::Matrix3Xd b = y + dt * st.rate(y);
      st.apply(dt, b);
      EXPECT_LT((b - y).norm(), 1e-9 * y.norm()) << "dt " << dt << ", " << mesh.n_theta << " per ring";
    }
    // damping (a positive Rayleigh quotient); a uniform translation is in its null space
    EXPECT_GT((y.array() * st.rate(y).array()).sum(), 0.0);
    EXPECT_GT((z.array() * st.rate(z).array()).sum(), 0.0);
    Eigen::Matrix3Xd shift(3, mesh.nodes());
    shift.colwise() = Eigen::Vector3d(1e-9, -2e-9, 0.5e-9);
    const double norm_B = st.mobility() * st.kappa_bending() / st.laplacian_at_h() * 729.0;  // |Lg| <= 9
    EXPECT_LT(st.rate(shift).norm(), 1e-13 * norm_B * shift.norm());
    Eigen::Matrix3Xd moved = shift;
    st.apply(1.0, moved);
    EXPECT_LT((moved - shift).norm(), 1e-10 * shift.norm());
  }
  EXPECT_EQ(WallStabilizer(meshes()[0], kBox / 16, kMu, 1e-24, WallStabilization::Bending).factorizations(), 0);
}

// A wall 100 times stiffer in bending than the paper's, on a 16-cell box: its stiffest coupled
// mode is a bending mode. The stabilised update's rate at a step dt, lambda(dt), falls as dt
// grows while dt lambda(dt) grows; at a step of 3 / lambda (forward Euler's limit is 2 /
// lambda) forward Euler fails and the stabilised update follows the reference, with its error
// falling at first order in dt.
TEST(WallStabilizer, ABendingWallStepsStablyBeyondForwardEulersLimit) {
  const MacGrid grid{16, 16, 16, kBox / 16, GridBoundary::PeriodicBox};
  const CylinderMesh mesh = make_cylinder_for_grid(kR0, kL, kBox / 16, Eigen::Vector3d(0.05e-6, 0.25e-6, 0.25e-6));
  MembraneParams wall;
  wall.kb = 1e-13;
  auto solver = [&](WallStabilization w, IbScheme scheme = IbScheme::ForwardEuler) {
    IbOptions o;
    o.scheme = scheme;
    o.wall_stabilization = w;
    return std::make_unique<IbSolver>(grid, FluidParams{1.0e3, kMu}, mesh, wall, Eigen::VectorXd::Zero(mesh.nodes()), o);
  };
  auto start = [&](const IbSolver& s) {  // lobes of mode 3, 3 % of R0
    IbState st = s.initial_state();
    st.X = inextensional_lobes(mesh, st.X, 3, 0.03 * kR0);
    return st;
  };
  auto plain = solver(WallStabilization::None), stab = solver(WallStabilization::Bending);
  const IbState s0 = start(*plain);
  const double lambda = plain->explicit_rate(s0, 1e-5, 40);
  const double dt = 3.0 / lambda;
  const double l_small = stab->explicit_rate(s0, 0.1 * dt, 40), l_dt = stab->explicit_rate(s0, dt, 40);
  std::printf("explicit rate %.4g /s; stabilised %.4g /s at dt = %.3g s, %.4g /s at dt / 10\n", lambda, l_dt, dt,
              l_small);
  EXPECT_LT(l_dt, l_small);
  EXPECT_LT(l_small, lambda);
  EXPECT_GT(dt * l_dt, 0.1 * dt * l_small);
  EXPECT_LT(dt * l_dt, 2.0) << "the stabilised update holds dt = 3 / lambda";
  // the reference: the midpoint rule far inside the limit
  const double T = 8 * dt;
  auto ref_solver = solver(WallStabilization::None, IbScheme::Midpoint);
  IbState ref = start(*ref_solver);
  for (int k = 0; k < 2048; ++k) ref_solver->step(ref, T / 2048);
  const double moved = (ref.X - s0.X).cwiseAbs().maxCoeff();
  {
    IbState st = start(*plain);
    bool failed = false;
    double err = 0.0;
    try {
      for (int k = 0; k < 8; ++k) plain->step(st, dt);
      err = (st.X - ref.X).cwiseAbs().maxCoeff();
    } catch (const swim::NumericalError&) {
      failed = true;
    }
    EXPECT_TRUE(failed || err > moved) << "forward Euler beyond its limit: error " << err << " m";
  }
  // at dt = 3 / lambda the stabilised update stays bounded; its error falls at first order as
  // dt does (from about dt sigma = 0.1 on the lobes, which at 16 cells across sit at the grid
  // scale, k h = 0.75, where the model is as stiff as the bending)
  const int steps[4] = {8, 32, 128, 512};
  double e[4];
  for (int r = 0; r < 4; ++r) {
    auto s = solver(WallStabilization::Bending);
    IbState st = start(*s);
    for (int k = 0; k < steps[r]; ++k) s->step(st, T / steps[r]);
    e[r] = (st.X - ref.X).cwiseAbs().maxCoeff();
  }
  std::printf("stabilised: errors %.3e %.3e %.3e %.3e m (moved %.3e m) with 8, 32, 128, 512 steps; orders %.2f %.2f %.2f\n",
              e[0], e[1], e[2], e[3], moved, std::log(e[0] / e[1]) / std::log(4.0), std::log(e[1] / e[2]) / std::log(4.0),
              std::log(e[2] / e[3]) / std::log(4.0));
  EXPECT_LT(e[0], moved);
  EXPECT_GT(std::log(e[2] / e[3]) / std::log(4.0), 0.8);
  EXPECT_LT(std::log(e[2] / e[3]) / std::log(4.0), 1.2);
}

TEST(WallStabilizer, OnlyWithForwardEuler) {
  const MacGrid grid{16, 16, 16, kBox / 16, GridBoundary::PeriodicBox};
  const CylinderMesh mesh = make_cylinder_for_grid(kR0, kL, kBox / 16, Eigen::Vector3d(0.05e-6, 0.25e-6, 0.25e-6));
  IbOptions o;
  o.scheme = IbScheme::Midpoint;
  o.wall_stabilization = WallStabilization::Bending;
  try {
    IbSolver s(grid, FluidParams{1.0e3, kMu}, mesh, MembraneParams{}, Eigen::VectorXd::Zero(mesh.nodes()), o);
    FAIL() << "expected an InputError";
  } catch (const swim::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("full3d.wall_stabilization"), std::string::npos) << e.what();
  }
  EXPECT_THROW(wall_stabilization_from("elastic"), swim::InputError);
  EXPECT_EQ(to_string(wall_stabilization_from("bending")), "bending");
}
