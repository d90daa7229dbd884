// Coupled IB time step (ib_solver.hpp): observed time order of the paper's
// first-order scheme (eq. 21) and of the midpoint predictor-corrector on an
// elastic membrane relaxing in a periodic box; guards raise NumericalError.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "common/errors.hpp"
#include "full3d/ib_solver.hpp"

using namespace swim::full3d;

namespace {
constexpr double kR0 = 0.125e-6, kL = 0.4e-6, kBox = 0.5e-6;
constexpr int kN = 16;

struct Problem {
  MacGrid grid{kN, kN, kN, kBox / kN, GridBoundary::PeriodicBox};
  CylinderMesh mesh = make_cylinder_for_grid(kR0, kL, kBox / kN, Eigen::Vector3d(0.05e-6, 0.25e-6, 0.25e-6));
};

IbSolver make_solver(const Problem& p, IbScheme scheme) {
  IbOptions o;
  o.scheme = scheme;
  return IbSolver(p.grid, FluidParams{1.0e3, 1.2e-3}, p.mesh, MembraneParams{}, Eigen::VectorXd::Zero(p.mesh.nodes()),
                  o);
}

// Elliptic (cos 2 phi) radial perturbation of 5 % of R0.
IbState perturbed_state(const Problem& p, const IbSolver& s) {
  IbState st = s.initial_state();
  const Eigen::Matrix3Xd er = radial_directions(p.mesh, st.X);
  for (int i = 0; i < p.mesh.nodes(); ++i) {
    const double phi = std::atan2(er(2, i), er(1, i));
    st.X.col(i) += 0.05 * kR0 * std::cos(2 * phi) * er.col(i);
  }
  return st;
}

Eigen::Matrix3Xd run(const Problem& p, IbScheme scheme, double T, int steps) {
  IbSolver s = make_solver(p, scheme);
  IbState st = perturbed_state(p, s);
  for (int k = 0; k < steps; ++k) s.step(st, T / steps);
  return st.X;
}
}  // namespace

TEST(IbSolver, ObservedTimeOrders) {
  const Problem p;
  const double T = 2e-3;  // s; the elliptic mode relaxes by ~5 % of its amplitude
  const Eigen::Matrix3Xd X0 = perturbed_state(p, make_solver(p, IbScheme::ForwardEuler)).X;
  const Eigen::Matrix3Xd ref = run(p, IbScheme::Midpoint, T, 128);
  const double moved = (ref - X0).cwiseAbs().maxCoeff();
  for (auto scheme : {IbScheme::ForwardEuler, IbScheme::Midpoint}) {
    double e[3];
    const int steps[3] = {8, 16, 32};
    for (int r = 0; r < 3; ++r) e[r] = (run(p, scheme, T, steps[r]) - ref).cwiseAbs().maxCoeff();
    const double o1 = std::log2(e[0] / e[1]), o2 = std::log2(e[1] / e[2]);
    std::printf("%s: max node displacement %.3e m; errors %.3e %.3e %.3e m (dt = T/8..T/32); orders %.3f %.3f\n",
                scheme == IbScheme::Midpoint ? "midpoint" : "forward Euler (eq. 21)", moved, e[0], e[1], e[2], o1,
                o2);
    if (scheme == IbScheme::ForwardEuler) {
      EXPECT_GT(o2, 0.9);
      EXPECT_LT(o2, 1.2);
    } else {
      EXPECT_GT(o2, 1.8);
    }
    EXPECT_LT(e[2], 1e-2 * moved);
  }
}

TEST(IbSolver, TooLargeTimeStepIsCaught) {
  const Problem p;
  for (auto scheme : {IbScheme::ForwardEuler, IbScheme::Midpoint}) {
    IbSolver s = make_solver(p, scheme);
    IbState st = perturbed_state(p, s);
    const Eigen::Matrix3Xd X = st.X;
    try {
      s.step(st, 5e-2);  // 25x the relaxation run's horizon in one step
      FAIL() << "expected a NumericalError";
    } catch (const swim::NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("reduce the time step dt"), std::string::npos) << e.what();
    }
    EXPECT_EQ((st.X - X).norm(), 0.0);  // state left at the last good step
  }
}

TEST(IbSolver, CflAndNonFiniteGuards) {
  const Problem p;
  IbSolver s = make_solver(p, IbScheme::ForwardEuler);
  IbState st = s.initial_state();
  // a huge uniform push: every node moves several cells in one step
  s.set_external_force([](double, const Eigen::Matrix3Xd& X) {
    Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, X.cols());
    F.row(0).setConstant(1e-9);
    return F;
  });
  try {
    s.step(st, 1e-3);
    FAIL() << "expected a NumericalError";
  } catch (const swim::NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("CFL"), std::string::npos) << e.what();
    EXPECT_EQ(e.remedy(), "reduce the time step dt");
  }
  s.set_external_force([](double, const Eigen::Matrix3Xd& X) {
    return Eigen::Matrix3Xd::Constant(3, X.cols(), std::nan(""));
  });
  EXPECT_THROW(s.step(st, 1e-6), swim::NumericalError);
}

TEST(IbSolver, WallEnergyBetweenStepsChangesNothingAndIsTheMembraneEnergy) {
  // the solver keeps the elastic pass of the last state asked for: asking the energy of each
  // new state (as a run's guard does) leaves the trajectory bit for bit, for both schemes, and
  // the energy is the membrane's (to the last bits: the same formula, which FMA code may round
  // differently in the last place in its two inlined copies)
  const Problem p;
  for (IbScheme scheme : {IbScheme::ForwardEuler, IbScheme::Midpoint}) {
    IbSolver a = make_solver(p, scheme), b = make_solver(p, scheme);
    IbState sa = perturbed_state(p, a), sb = perturbed_state(p, b);
    double e_first = 0.0, e_last = 0.0;
    for (int k = 0; k < 6; ++k) {
      a.step(sa, 2e-5);
      b.step(sb, 2e-5);
      const auto e = b.elastic_energy_parts(sb.X);
      EXPECT_DOUBLE_EQ(e[0] + e[1], elastic_energy(p.mesh, sb.X, MembraneParams{}));  // within 4 ulps
      if (k == 0) e_first = e[0] + e[1];
      e_last = e[0] + e[1];
    }
    EXPECT_EQ(sa.X, sb.X);
    EXPECT_EQ(sa.V, sb.V);
    EXPECT_LT(e_last, e_first) << "the perturbed tube relaxes";
  }
}

namespace {
// R(z) of the Chebyshev stages on y' = lambda y, z = dt lambda, by the stages' own recurrence
double chebyshev_amplification(const ChebyshevStages& c, double z) {
  double y2 = 1.0, y1 = 1.0 + c.mut[1] * z;
  for (int j = 2; j <= c.s; ++j) {
    const double yj = c.mu[j] * y1 + c.nu[j] * y2 + c.mut[j] * z * y1;
    y2 = y1;
    y1 = yj;
  }
  return y1;
}
}  // namespace

TEST(ChebyshevStages, FirstOrderAndStableOnTheirRealInterval) {
  for (int s = 1; s <= 12; ++s) {
    const ChebyshevStages c = chebyshev_stages(s);
    const double beta = c.stability_interval();
    // consistency and first order: R(z) = 1 + z + O(z^2); the last stage sits at t + dt
    const double z = 1e-5;
    EXPECT_NEAR(chebyshev_amplification(c, 0.0), 1.0, 1e-14) << s;
    EXPECT_NEAR((chebyshev_amplification(c, z) - chebyshev_amplification(c, -z)) / (2 * z), 1.0, 1e-8) << s;
    EXPECT_NEAR(c.c[s], 1.0, 1e-12) << s;
    if (s == 1) {
      EXPECT_EQ(beta, 2.0);  // forward Euler
    } else {
      // the damped interval (2 - 4 eps / 3) s^2 with eps = 0.05, to its O(1/s^2) term
      EXPECT_GT(beta, 1.90 * s * s) << s;
      EXPECT_LT(beta, 2.0 * s * s) << s;
    }
    // stable on [-beta, 0], damped inside, unstable just beyond
    double worst = 0.0;
    for (int k = 0; k <= 4000; ++k) worst = std::max(worst, std::abs(chebyshev_amplification(c, -beta * k / 4000.0)));
    EXPECT_LE(worst, 1.0 + 1e-12) << s;
    EXPECT_GT(std::abs(chebyshev_amplification(c, -1.05 * beta)), 1.0) << s;
    // the stage count for a step: the fewest stages whose (fraction of the) interval holds dt lambda
    EXPECT_EQ(chebyshev_stages_for(0.5 * beta * 0.999, 1.0, 0.5, 32), s) << s;
  }
  EXPECT_EQ(chebyshev_stages_for(1.0, 0.0, 0.5, 8), 1);     // no estimate yet: forward Euler
  EXPECT_EQ(chebyshev_stages_for(1e6, 1.0, 0.5, 8), 8);     // capped
}

TEST(IbSolver, ChebyshevStagesAreStableBeyondTheForwardEulerLimitAndFirstOrder) {
  const Problem p;
  IbSolver probe = make_solver(p, IbScheme::ForwardEuler);
  const IbState st0 = perturbed_state(p, probe);
  const double lambda = probe.explicit_rate(st0, 1e-4, 30);
  ASSERT_GT(lambda, 0.0);
  // the elliptic mode relaxes at about 25 /s, the stiffest mode at lambda: a horizon of many
  // forward-Euler limits, 4 steps of dt lambda > 4
  const double T = 0.16;
  const Eigen::Matrix3Xd ref = run(p, IbScheme::Midpoint, T, 512);
  const double moved = (ref - st0.X).cwiseAbs().maxCoeff();
  const int n = 4;
  const double dt = T / n;
  std::printf("explicit rate %.4g /s, dt lambda = %.3g\n", lambda, dt * lambda);
  ASSERT_GT(dt * lambda, 4.0) << "the test needs a step beyond forward Euler's limit";
  const int s = chebyshev_stages_for(dt, lambda, 0.5, 32);
  ASSERT_GT(s, 2);
  auto error_with_stages = [&](int steps, int stages) {
    IbSolver solver = make_solver(p, IbScheme::Chebyshev);
    IbState st = perturbed_state(p, solver);
    int solves = 0;
    for (int k = 0; k < steps; ++k) solves += solver.step(st, T / steps, stages).fluid_solves;
    EXPECT_EQ(solves, steps * stages);
    return (st.X - ref).cwiseAbs().maxCoeff();
  };
  // forward Euler at that step: the stiffest modes grow until a guard stops it
  {
    IbSolver fe = make_solver(p, IbScheme::ForwardEuler);
    IbState st = perturbed_state(p, fe);
    bool failed = false;
    double err = 0.0;
    try {
      for (int k = 0; k < n; ++k) fe.step(st, dt);
      err = (st.X - ref).cwiseAbs().maxCoeff();
    } catch (const swim::NumericalError&) {
      failed = true;
    }
    EXPECT_TRUE(failed || err > moved) << "forward Euler beyond its limit: error " << err << " m";
  }
  // the stages at the same step stay bounded; with the stages held, the error falls at
  // order 1 as dt does
  const double e[4] = {error_with_stages(n, s), error_with_stages(2 * n, s), error_with_stages(4 * n, s),
                       error_with_stages(8 * n, s)};
  std::printf("Chebyshev, %d stages: errors %.3e %.3e %.3e %.3e m (moved %.3e m), orders %.2f %.2f %.2f\n", s, e[0],
              e[1], e[2], e[3], moved, std::log2(e[0] / e[1]), std::log2(e[1] / e[2]), std::log2(e[2] / e[3]));
  EXPECT_LT(e[0], moved);
  EXPECT_GT(std::log2(e[2] / e[3]), 0.8);
  EXPECT_LT(std::log2(e[2] / e[3]), 1.3);
  // one stage is the forward Euler step, to the bit
  IbSolver a = make_solver(p, IbScheme::Chebyshev), b = make_solver(p, IbScheme::ForwardEuler);
  IbState sa = perturbed_state(p, a), sb = perturbed_state(p, b);
  a.step(sa, 1e-5, 1);
  b.step(sb, 1e-5);
  EXPECT_EQ(sa.X, sb.X);
  EXPECT_EQ(sa.V, sb.V);
}
