// Outer flows of the force-free 1D swimmer (reduced1d/outer_flow.hpp), checked against
// closed forms and exact properties: the lumen force cancellation, the rigid tube towed
// through the confined container, mirror symmetry, flux balance per channel, and the
// scallop theorem for a reciprocal stroke; the open ends' extensions (EndEffects): the towed tube
// against the closed form of the extended channels, mirror symmetry and the scallop theorem.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "tests/support/quadrature.hpp"
#include "reduced1d/outer_flow.hpp"

using namespace swim::reduced1d::outer;

namespace {

constexpr double kR0 = 0.125e-6, kL = 0.4e-6, kMu = 1.2e-3, kRc = 0.25e-6, kP = 2e-6;

/// Interval lengths of the solver's point set (half cells at both ends).
std::vector<double> intervals(int N, double L) {
  std::vector<double> d(N + 1, L / N);
  d[0] = d[N] = 0.5 * L / N;
  return d;
}

std::vector<double> random_radii(std::mt19937& g, int np, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> R(np);
  for (auto& r : R) r = u(g) * kR0;
  return R;
}

}  // namespace

// Lubrication order: the wall shear -pi int R^2 p' and the pressure on the tapered wall
// -pi int p (R^2)' cancel when both ends are at one pressure; otherwise their sum is the
// control-volume force pi [R(0)^2 p(0) - R(L)^2 p(L)].
TEST(OuterFlow, LumenShearAndTaperPressureCancelWithEqualEndPressures) {
  std::mt19937 g(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int np = 5 + trial * 7;
    const auto R = random_radii(g, np, 0.3, 1.2);
    std::vector<double> p(np);
    for (auto& v : p) v = n(g);
    p.front() = p.back() = 0.0;  // both ends open to the same (gauge) pressure
    auto f = lumen_wall_force(R.data(), p.data(), np);
    EXPECT_GT(std::abs(f.shear), 1e-3 * kR0 * kR0) << "a non-trivial profile";
    EXPECT_NEAR(f.shear + f.taper, 0.0, 1e-13 * std::abs(f.shear)) << trial;
    p.front() = -0.4, p.back() = 0.7;
    f = lumen_wall_force(R.data(), p.data(), np);
    const double cv = pi * (R.front() * R.front() * p.front() - R.back() * R.back() * p.back());
    EXPECT_NEAR(f.shear + f.taper, cv, 1e-13 * (std::abs(f.shear) + std::abs(cv))) << trial;
  }
}

// A rigid straight tube (no wave: Pi = 0) pulled by a force F through the periodic
// container: lumen (carried along), Poiseuille-Couette annulus and free pipe. The closed form
// is written here from the textbook annulus formulas, independently of the solver.
TEST(OuterFlow, RigidTubeTowedThroughTheContainerMatchesTheClosedForm) {
  for (double R : {0.5 * kR0, kR0, 1.6 * kR0})
    for (double a_out : {0.0, 0.01e-6})
      for (int N : {1, 4, 37}) {
        const double a_in = 0.005e-6, F = 1e-15;
        const double Ri = R - a_in, Ro = R + a_out, lam = std::log(kRc / Ro);
        const double Gl = pi * Ri * Ri * Ri * Ri / (8 * kMu);
        const double Ga = pi / (8 * kMu) * (std::pow(kRc, 4) - std::pow(Ro, 4) - std::pow(kRc * kRc - Ro * Ro, 2) / lam);
        const double Gc = pi * std::pow(kRc, 4) / (8 * kMu);
        const double S = pi * (kRc * kRc - Ro * Ro) / (2 * lam);
        // unknowns (dp = p(L) - p(0), U): total flux Q = -(Gl + Ga) dp / L - U K with
        // K = Ac - S, Ac = pi Rc^2; free pipe dp = (Q + U Ac) (P - L) / Gc; force
        // F = S dp + 2 pi mu U L / lambda.
        // => dp [1 + (Gl + Ga)(P - L)/(Gc L)] = U (Ac - K)(P - L)/Gc = U S (P - L) / Gc
        const double a = 1 + (Gl + Ga) * (kP - kL) / (Gc * kL), b = S * (kP - kL) / Gc;
        const double U_exact = F / (S * b / a + 2 * pi * kMu * kL / lam);

        ConfinedSystem sys(N + 2, intervals(N, kL), kMu, a_in, a_out, kRc, kP, kL);
        const std::vector<double> Rp(N + 2, R), Pi(N + 2, 0.0);
        ASSERT_TRUE(sys.geometry(Rp.data()));
        sys.transmural(Pi.data(), F);
        EXPECT_NEAR(sys.U, U_exact, 1e-12 * U_exact) << "R/R0 " << R / kR0 << " N " << N;
        EXPECT_NEAR(sys.drag_coefficient(), F / U_exact, 1e-12 * F / U_exact);
        EXPECT_NEAR(sys.dp_tube, U_exact * b / a, 1e-11 * std::abs(U_exact * b / a));
        if (N == 4 && a_out == 0.0 && R == kR0) {
          EXPECT_NEAR(confined_drag_coefficient(R, kL, a_in, a_out, kRc, kP, kMu), F / U_exact, 1e-12 * F / U_exact);
        }
      }
}

// The confined lubrication drag of the paper's geometry is several times the unbounded
// slender-body drag (confinement matters): Rc = 2 R0, L = 0.4 um.
TEST(OuterFlow, ConfinementRaisesTheDragAboveTheSlenderBodyValue) {
  const double conf = confined_drag_coefficient(kR0, kL, 0, 0, kRc, kP, kMu);
  const double free = slender_drag_per_length(kL, kR0, kMu) * kL;
  EXPECT_GT(conf / free, 3.0);
  EXPECT_LT(conf / free, 10.0);
  // and it falls towards the unbounded value as the container widens
  const double wide = confined_drag_coefficient(kR0, kL, 0, 0, 20 * kR0, 40 * kL, kMu);
  EXPECT_LT(wide, conf / 3.0);
}

// Mirror z -> L - z: every radius profile, transmural pressure and wall velocity mirrored
// gives the opposite swimming velocity and total flux (both closures of the confined system
// and the slender body).
TEST(OuterFlow, MirroredProfilesSwimTheOtherWay) {
  std::mt19937 g(11);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int N : {8, 33}) {
    const auto d = intervals(N, kL);
    auto R = random_radii(g, N + 2, 0.4, 1.3);
    std::vector<double> Pi(N + 2);
    for (auto& v : Pi) v = n(g);
    Pi.front() = Pi.back() = 0;
    std::vector<double> Rm(R.rbegin(), R.rend()), Pim(Pi.rbegin(), Pi.rend());
    ConfinedSystem a(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL), b(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL);
    ASSERT_TRUE(a.geometry(R.data()));
    ASSERT_TRUE(b.geometry(Rm.data()));
    a.transmural(Pi.data());
    b.transmural(Pim.data());
    EXPECT_GT(std::abs(a.U), 0.0);
    EXPECT_NEAR(b.U, -a.U, 1e-12 * std::abs(a.U));
    EXPECT_NEAR(b.Q_tot, -a.Q_tot, 1e-11 * std::abs(a.Q_tot));
    // kinematic closure: cell area rates At_i, cumulative s_j = h sum_{i<j} At_i
    std::vector<double> At(N), s(N + 1), sm(N + 1);
    for (auto& v : At) v = 1e-15 * n(g);
    const double h = kL / N;
    for (int j = 0; j < N; ++j) s[j + 1] = s[j] + h * At[j];
    for (int j = 0; j <= N; ++j) sm[j] = s[N] - s[N - j];  // mirrored rates summed from the other end
    a.kinematic(s.data());
    b.kinematic(sm.data());
    EXPECT_GT(std::abs(a.U), 0.0);
    EXPECT_NEAR(b.U, -a.U, 1e-11 * std::abs(a.U));
    // slender body: mirrored line sources, the two end point sources exchanged
    std::vector<double> zc(N), faces(N + 1), rho(N), rhom(N), u;
    for (int i = 0; i < N; ++i) zc[i] = (i + 0.5) * h, rho[i] = R[i + 1], rhom[i] = R[N - i];
    for (int j = 0; j <= N; ++j) faces[j] = j * h;
    std::vector<double> Atm(At.rbegin(), At.rend());
    const double Ua = slender_velocity(zc, faces, At, 1e-16, -3e-16, rho, kL, kMu, u);
    const double Ub = slender_velocity(zc, faces, Atm, -3e-16, 1e-16, rhom, kL, kMu, u);
    EXPECT_NEAR(Ub, -Ua, 1e-12 * std::abs(Ua));
  }
}

// Mass balance per channel: the annulus flux reconstructed from its own law,
// Q_out = -(dp_out + c U) / r_out with dp_out = dp_in - dPi, adds to the lumen flux to the
// same total at every face; the pressure is periodic over the container period.
TEST(OuterFlow, ChannelFluxesAddToOneTotalAndThePressureIsPeriodic) {
  std::mt19937 g(5);
  std::normal_distribution<double> n(0.0, 1.0);
  const int N = 40;
  const auto d = intervals(N, kL);
  auto R = random_radii(g, N + 2, 0.5, 1.1);
  std::vector<double> Pi(N + 2);
  for (auto& v : Pi) v = n(g);
  Pi.front() = Pi.back() = 0;
  ConfinedSystem sys(N + 2, d, kMu, 0.0, 0.0, kRc, kP, kL);
  ASSERT_TRUE(sys.geometry(R.data()));
  sys.transmural(Pi.data());
  double drop = 0;
  for (int j = 0; j <= N; ++j) {
    const auto& k = sys.k[j];
    const double dp_in = -k.rl * sys.Q_in[j];
    const double Q_out = -((dp_in - (Pi[j + 1] - Pi[j])) + k.c * sys.U) / k.ra;
    EXPECT_NEAR(sys.Q_in[j] + Q_out, sys.Q_tot, 1e-10 * (std::abs(sys.Q_in[j]) + std::abs(Q_out))) << j;
    drop += dp_in;
  }
  const double free_drop = -(sys.Q_tot + sys.U * pi * kRc * kRc) * (kP - kL) * 8 * kMu / (pi * std::pow(kRc, 4));
  EXPECT_NEAR(drop + free_drop, 0.0, 1e-10 * std::abs(drop));
}

// Square duct of half-width a: the circular pipe with the same Poiseuille conductance has
// R = 1.0939 a (conductance 0.5623 a^4 / mu of the square duct).
TEST(OuterFlow, DuctEquivalentRadius) { EXPECT_NEAR(duct_equivalent_radius(1.0), 1.09391, 2e-5); }

// Scallop theorem: in Stokes flow U is linear in the wall velocity for a given shape, so a
// reciprocal stroke (the same shapes forward, then backward at another pace) gives zero net
// displacement, while the swimmer does move during each half. A travelling wave does not
// retrace its shapes and gives a net displacement. Integrated with Gauss-Legendre in time.
TEST(OuterFlow, ReciprocalStrokesGiveNoNetDisplacement) {
  const int N = 60;
  const double h = kL / N, a = 0.35 * kR0;
  const auto d = intervals(N, kL);
  std::vector<double> zpt(N + 2);
  zpt[0] = 0, zpt[N + 1] = kL;
  for (int i = 0; i < N; ++i) zpt[i + 1] = (i + 0.5) * h;
  // shape: an asymmetric contraction near the rear, amplitude s in [0, 1]
  auto shape = [&](double z) { return std::exp(-std::pow((z - 0.3 * kL) / (0.12 * kL), 2)); };
  ConfinedSystem sys(N + 2, d, kMu, 0, 0, kRc, kP, kL);
  std::vector<double> R(N + 2), s(N + 1);
  // U at time t of a stroke with amplitude s(t), rate sd(t), or of a travelling wave
  auto velocity = [&](double amp, double rate, bool travelling, double t) {
    for (int k = 0; k < N + 2; ++k) {
      const double ph = travelling ? 2 * pi * (zpt[k] + 1e-5 * t) / kL : 0.0;
      R[k] = kR0 - a * (travelling ? 0.5 * (1 - std::cos(ph)) : amp * shape(zpt[k]));
    }
    double cum = 0;
    for (int i = 0; i < N; ++i) {
      s[i] = cum;
      const double z = zpt[i + 1];
      const double Rt = travelling ? -a * 0.5 * std::sin(2 * pi * (z + 1e-5 * t) / kL) * 2 * pi * 1e-5 / kL
                                   : -a * rate * shape(z);
      cum += h * 2 * pi * R[i + 1] * Rt;
    }
    s[N] = cum;
    if (!sys.geometry(R.data())) ADD_FAILURE();
    sys.kinematic(s.data());
    return sys.U;
  };
  const auto integrate = [](auto f, double t0, double t1, int pieces) {
    return ::swim::test::gauss_legendre10(f, t0, t1, pieces);
  };
  const double T1 = 0.1, T2 = 0.3;  // contract in 0.1 s, release in 0.3 s
  const double forward = integrate([&](double t) {
    const double x = pi * t / (2 * T1);
    return velocity(std::sin(x) * std::sin(x), 2 * std::sin(x) * std::cos(x) * pi / (2 * T1), false, t);
  }, 0.0, T1, 20);
  const double back = integrate([&](double t) {
    const double x = pi * (t - T1) / (2 * T2);
    return velocity(std::cos(x) * std::cos(x), -2 * std::sin(x) * std::cos(x) * pi / (2 * T2), false, t);
  }, T1, T1 + T2, 20);
  EXPECT_GT(std::abs(forward), 1e-3 * kR0) << "the asymmetric contraction moves the tube";
  EXPECT_NEAR(forward + back, 0.0, 1e-10 * std::abs(forward));
  // uniform contraction and release: front-back symmetric at every instant, so U = 0 throughout
  double umax = 0;
  for (double t : {0.01, 0.05, 0.09}) {
    const double x = pi * t / (2 * T1);
    for (int k = 0; k < N + 2; ++k) R[k] = kR0 - a * std::sin(x) * std::sin(x);
    double cum = 0;
    for (int i = 0; i < N; ++i) {
      s[i] = cum;
      cum += h * 2 * pi * R[i + 1] * (-a * 2 * std::sin(x) * std::cos(x) * pi / (2 * T1));
    }
    s[N] = cum;
    ASSERT_TRUE(sys.geometry(R.data()));
    sys.kinematic(s.data());
    umax = std::max(umax, std::abs(sys.U));
  }
  EXPECT_LT(umax, 1e-12 * std::abs(forward) / T1) << "uniform contraction: no motion at any instant";
  // the travelling wave over one period L / s
  const double wave = integrate([&](double t) { return velocity(0, 0, true, t); }, 0.0, kL / 1e-5, 40);
  EXPECT_GT(std::abs(wave), 1e-4 * std::abs(forward));
  EXPECT_GT(wave, 0.0) << "confined: the tube swims against its wave (the wave here travels in -z)";
}

// A rigid straight tube towed by a force F: with end effects it is the closed form of the
// three channels with the lumen longer by 2 c_l R_i and the annulus (resistance, Couette flux,
// force weight and drag) longer by 2 c_a (Rc - R), the free pipe unchanged:
//   dp [1 + (G_l / L_l + G_a / L_a)(P - L) / G_c] = U S (P - L) / G_c,  F = S dp + 2 pi mu U L_a / lambda,
// and the lumen flux relative to the tube is -G_l dp / L_l.
TEST(OuterFlowEnds, TowedTubeIsTheClosedFormOfTheExtendedChannels) {
  for (double R : {0.6 * kR0, kR0, 1.5 * kR0})
    for (const EndEffects e : {EndEffects{}, kOpenEnds, EndEffects{0.9, 0.05}}) {
      const double lam = std::log(kRc / R);
      const double Gl = pi * std::pow(R, 4) / (8 * kMu);
      const double Ga = pi / (8 * kMu) * (std::pow(kRc, 4) - std::pow(R, 4) - std::pow(kRc * kRc - R * R, 2) / lam);
      const double Gc = pi * std::pow(kRc, 4) / (8 * kMu);
      const double S = pi * (kRc * kRc - R * R) / (2 * lam);
      const double Ll = kL + 2 * e.lumen * R, La = kL + 2 * e.annulus * (kRc - R);
      const double dp_per_U = S * (kP - kL) / Gc / (1 + (Gl / Ll + Ga / La) * (kP - kL) / Gc);
      const double drag = S * dp_per_U + 2 * pi * kMu * La / lam;
      const TowedTube t = confined_tow(R, kL, 0.0, 0.0, kRc, kP, kMu, e);
      EXPECT_NEAR(t.drag, drag, 1e-11 * drag) << "R/R0 " << R / kR0 << " ends " << e.lumen << ", " << e.annulus;
      EXPECT_NEAR(t.lumen_flux, -Gl * dp_per_U / Ll, 1e-10 * Gl * dp_per_U / Ll);
    }
  // the ends add drag: the open ends' extra drag of the paper's geometry is a few per cent
  const double d0 = confined_tow(kR0, kL, 0, 0, kRc, kP, kMu, {}).drag;
  const double d1 = confined_tow(kR0, kL, 0, 0, kRc, kP, kMu, kOpenEnds).drag;
  EXPECT_GT(d1, d0);
  EXPECT_LT(d1, 1.2 * d0);
}

namespace {

/// Mirror z -> L - z on random shapes and wall velocities (N = 8 and 33 cells): the mirrored
/// problem swims the other way, and the end model `configure` sets changes the answer.
void expect_mirrored_profiles_swim_the_other_way(unsigned seed, double a_in, double a_out,
                                                 const std::function<void(ConfinedSystem&)>& configure) {
  std::mt19937 g(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.5, 1.3);
  for (int N : {8, 33}) {
    const auto d = intervals(N, kL);
    std::vector<double> R(N + 2);
    for (auto& r : R) r = u(g) * kR0;
    std::vector<double> Rm(R.rbegin(), R.rend());
    ConfinedSystem a(N + 2, d, kMu, a_in, a_out, kRc, kP, kL), b(N + 2, d, kMu, a_in, a_out, kRc, kP, kL),
        c(N + 2, d, kMu, a_in, a_out, kRc, kP, kL);
    configure(a);
    configure(b);
    ASSERT_TRUE(a.geometry(R.data()));
    ASSERT_TRUE(b.geometry(Rm.data()));
    ASSERT_TRUE(c.geometry(R.data()));
    std::vector<double> s(N + 1), sm(N + 1);
    const double h = kL / N;
    for (int j = 0; j < N; ++j) s[j + 1] = s[j] + h * 1e-15 * n(g);
    for (int j = 0; j <= N; ++j) sm[j] = s[N] - s[N - j];
    a.kinematic(s.data());
    b.kinematic(sm.data());
    c.kinematic(s.data());  // the plain junction
    EXPECT_GT(std::abs(a.U), 0.0);
    EXPECT_NEAR(b.U, -a.U, 1e-11 * std::abs(a.U));
    EXPECT_GT(std::abs(c.U - a.U), 1e-6 * std::abs(a.U)) << "the end model changes the answer";
  }
}

/// A reciprocal stroke (an asymmetric contraction that reaches the rear end, so the end radius
/// changes: forward in 0.1 s and back in 0.3 s) returns the tube to its start with the end
/// model `configure` sets: U stays linear in the wall velocity at a given shape.
void expect_reciprocal_stroke_returns(const std::function<void(ConfinedSystem&)>& configure) {
  const int N = 60;
  const double h = kL / N, a = 0.35 * kR0;
  ConfinedSystem sys(N + 2, intervals(N, kL), kMu, 0, 0, kRc, kP, kL);
  configure(sys);
  std::vector<double> zpt(N + 2), R(N + 2), s(N + 1);
  zpt[0] = 0, zpt[N + 1] = kL;
  for (int i = 0; i < N; ++i) zpt[i + 1] = (i + 0.5) * h;
  auto shape = [&](double z) { return std::exp(-std::pow((z - 0.1 * kL) / (0.15 * kL), 2)); };
  auto velocity = [&](double amp, double rate) {
    for (int k = 0; k < N + 2; ++k) R[k] = kR0 - a * amp * shape(zpt[k]);
    double cum = 0;
    for (int i = 0; i < N; ++i) {
      s[i] = cum;
      cum += h * 2 * pi * R[i + 1] * (-a * rate * shape(zpt[i + 1]));
    }
    s[N] = cum;
    if (!sys.geometry(R.data())) ADD_FAILURE();
    sys.kinematic(s.data());
    return sys.U;
  };
  const double T1 = 0.1, T2 = 0.3;
  const double forward = swim::test::gauss_legendre10([&](double t) {
    const double x = pi * t / (2 * T1);
    return velocity(std::sin(x) * std::sin(x), 2 * std::sin(x) * std::cos(x) * pi / (2 * T1));
  }, 0.0, T1, 20);
  const double back = swim::test::gauss_legendre10([&](double t) {
    const double x = pi * (t - T1) / (2 * T2);
    return velocity(std::cos(x) * std::cos(x), -2 * std::sin(x) * std::cos(x) * pi / (2 * T2));
  }, T1, T1 + T2, 20);
  EXPECT_GT(std::abs(forward), 1e-3 * kR0);
  EXPECT_NEAR(forward + back, 0.0, 1e-10 * std::abs(forward));
}

}  // namespace

// Mirror z -> L - z with the ends on: the mirrored shape and wall velocities swim the other way.
TEST(OuterFlowEnds, MirroredProfilesSwimTheOtherWay) {
  expect_mirrored_profiles_swim_the_other_way(13, 1e-9, 2e-9, [](ConfinedSystem& s) { s.ends = kOpenEnds; });
}

// Scallop theorem with the ends on.
TEST(OuterFlowEnds, ReciprocalStrokeGivesNoNetDisplacement) {
  expect_reciprocal_stroke_returns([](ConfinedSystem& s) { s.ends = kOpenEnds; });
}

// The calibrated end junction (docs/outer-flow-1d.md §2c): its dissipation matrix is positive
// semi-definite at every end radius (so it only adds drag), and a junction whose coefficients are
// all zero is the plain junction.
TEST(OuterFlowJunction, DissipationIsNonNegativeAndOnlyAddsDrag) {
  for (double rc : {1.2, 1.5, 2.0, 3.0, 4.0, 8.0, 20.0}) {
    double M[3][3], rim;
    end_junction(kCalibratedJunction, kR0, rc * kR0, kMu, M, rim);
    // D = x^T M x / 2 >= 0 for random x (in units where each term is of order one)
    std::mt19937 g(7);
    std::normal_distribution<double> n(0.0, 1.0);
    const double q = kR0 * kR0 * 1e-6, u = 1e-6;  // a flux and a velocity of the same flow
    for (int k = 0; k < 200; ++k) {
      const double x[3] = {q * n(g), q * n(g), u * n(g)};
      double D = 0, scale = 0;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          D += x[r] * M[r][c] * x[c];
          scale += std::abs(x[r] * M[r][c] * x[c]);
        }
      EXPECT_GE(D, -1e-12 * scale) << "Rc/R " << rc;
    }
    EXPECT_EQ(M[0][1], M[1][0]);
    EXPECT_EQ(M[0][2], M[2][0]);
    EXPECT_EQ(M[1][2], M[2][1]);
  }
  // towed rigid tubes of three radii: the junction adds drag; the zero junction is the plain one
  const int N = 40;
  for (double R : {0.6 * kR0, kR0, 1.5 * kR0}) {
    std::vector<double> Rp(N + 2, R), s(N + 1, 0.0);
    const EndJunction zero{};
    double U[3];
    for (int k = 0; k < 3; ++k) {
      ConfinedSystem sys(N + 2, intervals(N, kL), kMu, 0, 0, kRc, kP, kL);
      if (k == 1) sys.junction = &zero;
      if (k == 2) sys.junction = &kCalibratedJunction;
      ASSERT_TRUE(sys.geometry(Rp.data()));
      sys.kinematic(s.data(), 1e-15);  // towed by 1 fN
      U[k] = sys.U;
    }
    EXPECT_EQ(U[1], U[0]) << "R/R0 " << R / kR0;
    EXPECT_GT(U[0], 0.0);
    EXPECT_LT(U[2], U[0]) << "R/R0 " << R / kR0 << ": the junction dissipates, the towed tube is slower";
    EXPECT_GT(U[2], 0.5 * U[0]);
  }
}

// Mirror z -> L - z with the junction (the rim's thrust included).
TEST(OuterFlowJunction, MirroredProfilesSwimTheOtherWay) {
  expect_mirrored_profiles_swim_the_other_way(17, 0.0, 0.0, [](ConfinedSystem& s) { s.junction = &kCalibratedJunction; });
}

// Scallop theorem with the junction, the rim's thrust included.
TEST(OuterFlowJunction, ReciprocalStrokeGivesNoNetDisplacement) {
  expect_reciprocal_stroke_returns([](ConfinedSystem& s) { s.junction = &kCalibratedJunction; });
}

// The force-driven closure with the junction (transmural, unknowns W, U, Pi_0, Pi_L) is the
// kinematic one's physics: the transmural pressures that the kinematic closure's solution
// implies at the cells (Pi_0 = (M_r x_r)_1 - (M_r x_r)_0 at the rear, then per interval
// dPi = -rl Q_in + ra Q_out + c U), with the same wall velocities, give back its U, fluxes,
// end transmural pressures and lumen pressures.
TEST(OuterFlowJunction, TransmuralClosureReproducesTheKinematicOne) {
  std::mt19937 g(23);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.5, 1.3);
  for (int N : {8, 33}) {
    const auto d = intervals(N, kL);
    const double h = kL / N;
    std::vector<double> R(N + 2);
    for (auto& r : R) r = u(g) * kR0;
    ConfinedSystem a(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL), b(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL);
    a.junction = b.junction = &kCalibratedJunction;
    ASSERT_TRUE(a.geometry(R.data()));
    ASSERT_TRUE(b.geometry(R.data()));
    std::vector<double> s(N + 1), Rdot(N + 2, 0.0);
    for (int j = 0; j < N; ++j) s[j + 1] = s[j] + h * 1e-15 * n(g);
    for (int i = 0; i < N; ++i) Rdot[i + 1] = (s[i + 1] - s[i]) / (2 * pi * R[i + 1] * h);
    const double F = 1e-16 * n(g);
    a.kinematic(s.data(), F);
    double M[3][3], rim;
    end_junction(kCalibratedJunction, R[0], kRc, kMu, M, rim);
    const double x[3] = {a.Q_in[0], a.Q_tot - a.Q_in[0], a.U};
    std::vector<double> Pi(N + 2);
    Pi[0] = 0;
    for (int c = 0; c < 3; ++c) Pi[0] += (M[1][c] - M[0][c]) * x[c];
    for (int j = 0; j <= N; ++j) {
      const auto& k = a.k[j];
      Pi[j + 1] = Pi[j] - k.rl * a.Q_in[j] + k.ra * (a.Q_tot - a.Q_in[j]) + k.c * a.U;
    }
    std::vector<double> Pg = Pi;
    Pg.front() = Pg.back() = 1e300;  // the end values are unknowns of the closure, not read
    b.transmural(Pg.data(), F, Rdot.data());
    EXPECT_GT(std::abs(a.U), 0.0);
    EXPECT_NEAR(b.U, a.U, 1e-9 * std::abs(a.U)) << N;
    EXPECT_NEAR(b.Q_tot, a.Q_tot, 1e-9 * std::abs(a.Q_tot)) << N;
    double scale = 0;
    for (double v : Pi) scale = std::max(scale, std::abs(v));
    EXPECT_NEAR(b.jc.Pi0, Pi.front(), 1e-9 * scale) << N;
    EXPECT_NEAR(b.jc.PiL, Pi.back(), 1e-9 * scale) << N;
    EXPECT_GT(std::abs(Pi.front()), 1e-3 * scale) << "the end transmural pressure is not zero";
    for (int j = 0; j <= N; ++j) EXPECT_NEAR(b.Q_in[j], a.Q_in[j], 1e-9 * std::abs(a.Q_tot) + 1e-9 * std::abs(a.Q_in[j])) << j;
    std::vector<double> pa, pb;
    a.lumen_pressure(pa);
    b.lumen_pressure(pb);
    double ps = 0;
    for (double v : pa) ps = std::max(ps, std::abs(v));
    for (int k = 0; k < N + 2; ++k) EXPECT_NEAR(pb[k], pa[k], 1e-9 * ps) << k;
  }
}

// Mirror z -> L - z of the force-driven closure with the junction: mirrored radii, transmural
// pressures and wall velocities swim the other way, the two end transmural pressures exchanged;
// and the junction changes the answer of the plain closure.
TEST(OuterFlowJunction, TransmuralMirroredProfilesSwimTheOtherWay) {
  std::mt19937 g(29);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.5, 1.3);
  for (int N : {8, 33}) {
    const auto d = intervals(N, kL);
    std::vector<double> R(N + 2), Pi(N + 2), Rdot(N + 2);
    for (auto& r : R) r = u(g) * kR0;
    for (auto& v : Pi) v = n(g);
    for (auto& v : Rdot) v = 1e-6 * n(g);
    Pi.front() = Pi.back() = 0.0;
    std::vector<double> Rm(R.rbegin(), R.rend()), Pim(Pi.rbegin(), Pi.rend()), Rdm(Rdot.rbegin(), Rdot.rend());
    ConfinedSystem a(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL), b(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL),
        c(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL);
    a.junction = b.junction = &kCalibratedJunction;
    ASSERT_TRUE(a.geometry(R.data()));
    ASSERT_TRUE(b.geometry(Rm.data()));
    ASSERT_TRUE(c.geometry(R.data()));
    a.transmural(Pi.data(), 0.0, Rdot.data());
    b.transmural(Pim.data(), 0.0, Rdm.data());
    c.transmural(Pi.data());
    EXPECT_GT(std::abs(a.U), 0.0);
    EXPECT_NEAR(b.U, -a.U, 1e-11 * std::abs(a.U));
    EXPECT_NEAR(b.Q_tot, -a.Q_tot, 1e-10 * std::abs(a.Q_tot));
    EXPECT_NEAR(b.jc.Pi0, a.jc.PiL, 1e-10 * (std::abs(a.jc.Pi0) + std::abs(a.jc.PiL)));
    EXPECT_NEAR(b.jc.PiL, a.jc.Pi0, 1e-10 * (std::abs(a.jc.Pi0) + std::abs(a.jc.PiL)));
    EXPECT_GT(std::abs(c.U - a.U), 1e-3 * std::abs(a.U)) << "the junction changes the answer";
  }
}
