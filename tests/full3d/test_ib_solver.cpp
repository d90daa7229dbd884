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
