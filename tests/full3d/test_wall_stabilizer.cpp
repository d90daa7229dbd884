// The stabilised wall update (wall_stabilizer.hpp): its operator in the rings' azimuthal modes
// is the filtered cube of the graph Laplacian on the mesh, symmetric positive semi-definite, zero
// on rigid translations and fields linear along the axis; its filter is (I + dt B)^{-1/2}.
// Coupled through the fluid, the update's rates are real, and a bending-dominated wall steps
// stably beyond forward Euler's limit, with first-order error.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
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

// B = P^{-1/2} K P^{-1/2} with K = S^T Lt S + E^3 (S the graph Laplacian's rows of the nodes off
// the end rings, Lt its block on them, E (3/2) the graph Laplacian of the end rings' own edges)
// and the filter P = (I + Lf / (8 l_h))^8, Lf = (S^T S + E^2)^{1/2},
// assembled densely from the mesh's edges, against the operator in the azimuthal modes; it is
// symmetric, and zero on a field linear along the axis (the free ends' null space).
TEST(WallStabilizer, ItsOperatorIsTheFilteredCubedGraphLaplacianWithFreeEnds) {
  for (const CylinderMesh& mesh : meshes()) {
    const WallStabilizer st(mesh, kBox / 16, kMu, 1e-24, WallStabilization::Bending);
    const Eigen::MatrixXd L = Eigen::MatrixXd(graph_laplacian(mesh));
    const int n_in = mesh.nodes() - 2 * mesh.n_theta;  // nodes off the end rings
    const Eigen::MatrixXd S = L.middleRows(mesh.n_theta, n_in);
    const Eigen::MatrixXd Lt = S.middleCols(mesh.n_theta, n_in);
    // E: (3/2) the graph Laplacian of the end rings' own edges
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(mesh.nodes(), mesh.nodes());
    const int last = mesh.nodes() - mesh.n_theta;
    for (const auto& e : mesh.edges) {
      const bool first_ring = e[0] < mesh.n_theta && e[1] < mesh.n_theta;
      const bool last_ring = e[0] >= last && e[1] >= last;
      if (!first_ring && !last_ring) continue;
      E(e[0], e[0]) += 1.5;
      E(e[1], e[1]) += 1.5;
      E(e[0], e[1]) -= 1.5;
      E(e[1], e[0]) -= 1.5;
    }
    const double scale = st.mobility() * st.kappa_bending() / st.laplacian_at_h();
    const Eigen::MatrixXd K = scale * (S.transpose() * Lt * S + E * E * E);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(S.transpose() * S + E * E);
    const Eigen::VectorXd g =
        (1.0 + es.eigenvalues().cwiseMax(0.0).cwiseSqrt().array() / (8.0 * st.laplacian_at_h())).pow(-4.0).matrix();
    const Eigen::MatrixXd Ph = es.eigenvectors() * g.asDiagonal() * es.eigenvectors().transpose();
    const Eigen::MatrixXd B = Ph * K * Ph;
    const Eigen::Matrix3Xd x = random_field(mesh.nodes(), 7), y = random_field(mesh.nodes(), 8);
    const Eigen::MatrixXd expect = B * Eigen::MatrixXd(x.transpose());
    const Eigen::Matrix3Xd got = st.rate(x);
    EXPECT_LT((got.transpose() - expect).norm(), 1e-10 * expect.norm())
        << mesh.n_theta << " nodes per ring, " << mesh.n_rings << " rings";
    const double xBy = (x.array() * st.rate(y).array()).sum(), yBx = (y.array() * got.array()).sum();
    EXPECT_LT(std::abs(xBy - yBx), 1e-10 * std::abs(xBy)) << "B is symmetric";
    EXPECT_NEAR(st.largest_rate(), Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(B).eigenvalues().maxCoeff(),
                1e-10 * st.largest_rate());
    // linear along the axis: every component a + b x (the node's axial coordinate)
    Eigen::Matrix3Xd lin(3, mesh.nodes());
    for (int k = 0; k < mesh.nodes(); ++k)
      lin.col(k) = Eigen::Vector3d(1.0, -0.5, 2.0) * 1e-9 + Eigen::Vector3d(0.3, 1.0, -0.7) * (mesh.X0(0, k) - mesh.axis_start(0)) * 1e-2;
    EXPECT_LT(st.rate(lin).norm(), 1e-12 * st.largest_rate() * lin.norm()) << mesh.n_theta << " nodes per ring";
    Eigen::Matrix3Xd kept = lin;
    st.apply_root(1.0, kept);
    EXPECT_LT((kept - lin).norm(), 1e-11 * lin.norm()) << "G leaves a field linear along the axis alone";
  }
}

TEST(WallStabilizer, ItsFilterIsTheInverseSquareRootOfIPlusDtB) {
  for (const CylinderMesh& mesh : meshes()) {
    const WallStabilizer st(mesh, kBox / 16, kMu, 1e-24, WallStabilization::Bending);
    const Eigen::Matrix3Xd y = random_field(mesh.nodes(), 11), z = random_field(mesh.nodes(), 13);
    for (double dt : {1e-4, 1e-2, 1.0}) {
      Eigen::Matrix3Xd b = y + dt * st.rate(y);
      Eigen::Matrix3Xd c = b;
      st.apply_root(dt, b);
      st.apply_root(dt, b);
      EXPECT_LT((b - y).norm(), 1e-9 * y.norm()) << "dt " << dt << ", " << mesh.n_theta << " per ring";
      st.apply(dt, c);
      EXPECT_LT((c - y).norm(), 1e-9 * y.norm()) << "dt " << dt << ", " << mesh.n_theta << " per ring";
      // G is symmetric, and a contraction
      Eigen::Matrix3Xd gy = y, gz = z;
      st.apply_root(dt, gy);
      st.apply_root(dt, gz);
      const double zgy = (z.array() * gy.array()).sum(), ygz = (y.array() * gz.array()).sum();
      EXPECT_LT(std::abs(zgy - ygz), 1e-10 * std::abs(zgy));
      EXPECT_LE(gy.norm(), y.norm() * (1.0 + 1e-12));
    }
    // damping (a positive Rayleigh quotient); a uniform translation is in its null space
    EXPECT_GT((y.array() * st.rate(y).array()).sum(), 0.0);
    EXPECT_GT((z.array() * st.rate(z).array()).sum(), 0.0);
    Eigen::Matrix3Xd shift(3, mesh.nodes());
    shift.colwise() = Eigen::Vector3d(1e-9, -2e-9, 0.5e-9);
    EXPECT_LT(st.rate(shift).norm(), 1e-13 * st.largest_rate() * shift.norm());
    Eigen::Matrix3Xd moved = shift;
    st.apply_root(1.0, moved);
    EXPECT_LT((moved - shift).norm(), 1e-10 * shift.norm());
  }
}

// A wall 100 times stiffer in bending than the paper's, on a 16-cell box: its stiffest coupled
// mode is a bending mode. The stabilised update's rate at a step dt, lambda(dt), falls as dt
// grows while dt lambda(dt) grows; at a step of 3 / lambda (forward Euler's limit is 2 /
// lambda) forward Euler fails and the stabilised update (437 /s there, dt lambda(dt) = 0.88)
// follows the reference, with its error falling at first order in dt.
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

// The stabilised update's linearisation G M G H is similar to a symmetric matrix (G M G is
// symmetric positive semi-definite, H the wall's symmetric stiffness), so its rates are real
// and the power iteration's largest magnitude is its stability limit. Arnoldi's converged Ritz
// values on the stiff lobed wall, forward Euler's and the stabilised update's at a step beyond
// forward Euler's limit, have no imaginary part; the one-sided update (I + dt B)^{-1} M F had
// converged pairs such as (301 +- 26i) /s here.
TEST(WallStabilizer, ItsLinearisationHasRealRates) {
  const MacGrid grid{16, 16, 16, kBox / 16, GridBoundary::PeriodicBox};
  const CylinderMesh mesh = make_cylinder_for_grid(kR0, kL, kBox / 16, Eigen::Vector3d(0.05e-6, 0.25e-6, 0.25e-6));
  MembraneParams wall;
  wall.kb = 1e-13;
  for (WallStabilization w : {WallStabilization::None, WallStabilization::Bending}) {
    IbOptions o;
    o.wall_stabilization = w;
    IbSolver solver(grid, FluidParams{1.0e3, kMu}, mesh, wall, Eigen::VectorXd::Zero(mesh.nodes()), o);
    IbState s0 = solver.initial_state();
    s0.X = inextensional_lobes(mesh, s0.X, 3, 0.03 * kR0);
    const double dt = 3.0 / 1495.0;  // forward Euler's rate here: 1 495 /s
    const IbSolver::RateSpectrum sp = solver.explicit_spectrum(s0, dt, 40);
    ASSERT_EQ(sp.ritz.size(), 40u);
    int converged = 0;
    double worst = 0.0, top = 0.0;
    for (std::size_t i = 0; i < sp.ritz.size(); ++i) {
      if (!(sp.residual[i] < 0.05)) continue;
      ++converged;
      worst = std::max(worst, std::abs(sp.ritz[i].imag()) / std::abs(sp.ritz[i]));
      top = std::max(top, std::abs(sp.ritz[i]));
    }
    std::printf("%s: %d converged Ritz values, largest %.1f /s, largest |Im mu| / |mu| %.2e\n", to_string(w).c_str(),
                converged, top, worst);
    EXPECT_GE(converged, 10) << to_string(w);
    EXPECT_LT(worst, 1e-6) << to_string(w);
    EXPECT_NEAR(top, solver.explicit_rate(s0, dt, 40), 0.02 * top) << "power iteration against Arnoldi, " << to_string(w);
  }
}

// The free rims are stabilised too. Per azimuthal mode, the graph Laplacian's rows off the end
// rings have a null pair decaying away from each end, which the hinges bend; without the end
// rings' own term E the stabilised update's fastest mode on the stiff lobed wall at dt = 3 /
// lambda was such a rim mode (932 /s, a third of its weight on the two end rings at each end,
// B's Rayleigh quotient on it 98 /s against B's largest 5 298 /s). With E, the fastest mode is
// the wall's body mode that sets forward Euler's rate (as it does there), the stabilised rate
// is under a third of forward Euler's, and B is as stiff on it as the update is fast.
TEST(WallStabilizer, ItsRimsAreStabilisedToo) {
  const MacGrid grid{16, 16, 16, kBox / 16, GridBoundary::PeriodicBox};
  const CylinderMesh mesh = make_cylinder_for_grid(kR0, kL, kBox / 16, Eigen::Vector3d(0.05e-6, 0.25e-6, 0.25e-6));
  MembraneParams wall;
  wall.kb = 1e-13;
  // the update's fastest rate at dt and its mode v; rq: B's Rayleigh quotient on v (the
  // solver's own stabiliser), 1/s
  auto top_mode = [&](WallStabilization w, double dt, Eigen::Matrix3Xd& v, double& rq) {
    IbOptions o;
    o.wall_stabilization = w;
    IbSolver solver(grid, FluidParams{1.0e3, kMu}, mesh, wall, Eigen::VectorXd::Zero(mesh.nodes()), o);
    IbState s0 = solver.initial_state();
    s0.X = inextensional_lobes(mesh, s0.X, 3, 0.03 * kR0);
    v = random_field(mesh.nodes(), 3);
    const double rate = solver.explicit_rate(s0, dt, 300, &v);
    const WallStabilizer* st = solver.stabilizer();
    rq = st ? (v.array() * st->rate(v).array()).sum() / v.squaredNorm() : 0.0;
    return rate;
  };
  // the share of a field's weight on the two rings at each end
  auto rim_share = [&](const Eigen::Matrix3Xd& v) {
    const int nt = mesh.n_theta;
    return (v.leftCols(2 * nt).squaredNorm() + v.rightCols(2 * nt).squaredNorm()) / v.squaredNorm();
  };
  Eigen::Matrix3Xd v_fe, v_st;
  double unused = 0.0, rq = 0.0;
  const double lambda = top_mode(WallStabilization::None, 1e-5, v_fe, unused);
  const double dt = 3.0 / lambda;
  const double l_st = top_mode(WallStabilization::Bending, dt, v_st, rq);
  std::printf("forward Euler %.1f /s (rims %.3f); stabilised %.1f /s at dt = %.3g s (rims %.3f), B on it %.1f /s\n", lambda,
              rim_share(v_fe), l_st, dt, rim_share(v_st), rq);
  EXPECT_LT(rim_share(v_fe), 0.05);
  EXPECT_LT(rim_share(v_st), 0.05) << "the stabilised update's fastest mode is not a rim mode";
  EXPECT_LT(l_st, lambda / 3.0);
  EXPECT_GT(rq, 0.5 * l_st) << "B sees the update's fastest mode";
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
