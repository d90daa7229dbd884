// The open ends' flow of the confined force-free model (reduced1d/outer_flow.hpp EndEffects,
// `model1d.end_effects`, docs/outer-flow-1d.md §2b): each end is a rigid extension of the lumen
// and of the annulus. Checked: the towed tube against the closed form of the extended channels,
// the correction's limit on long tubes, mirror symmetry and the scallop theorem with the ends on,
// and the scene key's refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "common/scene.hpp"
#include "reduced1d/outer_flow.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"
#include "tests/support/quadrature.hpp"

using namespace swim::reduced1d::outer;
using swim::scene::json;

namespace {

constexpr double kR0 = 0.125e-6, kL = 0.4e-6, kMu = 1.2e-3, kRc = 0.25e-6, kP = 2e-6;

std::vector<double> intervals(int N, double L) {
  std::vector<double> d(N + 1, L / N);
  d[0] = d[N] = 0.5 * L / N;
  return d;
}

/// Displacement over one transit of a prescribed wave on the 1D tier (confined force-free model).
double transit_displacement(const std::string& kind, double L_um, double lambda_um, const std::string& ends) {
  auto um = [](double v) { return std::to_string(v) + " um"; };
  json sc = {{"name", "ends"},
             {"swimmer", {{"radius", "0.125 um"}, {"length", um(L_um)}}},
             {"container", {{"kind", "cylinder"}, {"radius", "0.25 um"}, {"period", um(5 * L_um)}}},
             {"wave", {{"kind", kind}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}}},
             {"model1d", {{"end_effects", ends}}},
             {"numerics1d", {{"cells", 400}}}};
  if (kind == "step") sc["wave"]["width"] = um(lambda_um);
  if (kind == "sine") sc["wave"]["wavelength"] = um(lambda_um);
  json resolved;
  const auto r = swim::reduced1d::solve(swim::reduced1d::read_scene(sc, resolved));
  EXPECT_FALSE(r.failure.has_value());
  return r.series.back().X;
}

}  // namespace

// A rigid straight tube towed by a force F: with end effects it is the closed form of the
// three channels with the lumen longer by 2 c_l R_i and the annulus (resistance, Couette flux,
// force weight and drag) longer by 2 c_a (Rc - R), the free pipe unchanged:
//   dp [1 + (G_l / L_l + G_a / L_a)(P - L) / G_c] = U S (P - L) / G_c,  F = S dp + 2 pi mu U L_a / lambda,
// and the lumen flux relative to the tube is -G_l dp / L_l.
TEST(EndEffects, TowedTubeIsTheClosedFormOfTheExtendedChannels) {
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

// The correction is an end effect: at a fixed wave shape (a sine of wavelength 0.4 um, a whole
// number of wavelengths on the tube) its relative change of the displacement per transit falls
// as 1/L, halving with each doubling of the tube, and vanishes as L/Rc grows.
TEST(EndEffects, CorrectionVanishesAsOneOverTheTubeLength) {
  double prev = 0.0;
  for (double L : {0.8, 1.6, 3.2, 6.4}) {
    const double off = transit_displacement("sine", L, 0.4, "none");
    const double on = transit_displacement("sine", L, 0.4, "open_ends");
    const double rel = on / off - 1.0;
    std::printf("L = %.1f um (L/Rc = %.1f): displacement %.4e -> %.4e m, relative change %+.4f, times L/Rc %.3f\n", L,
                L / 0.25, off, on, rel, rel * L / 0.25);
    EXPECT_GT(std::abs(rel), 0.0);
    if (prev != 0.0) {
      EXPECT_GT(rel / prev, 0.4) << "L = " << L;
      EXPECT_LT(rel / prev, 0.6) << "L = " << L;
    }
    prev = rel;
  }
  EXPECT_LT(std::abs(prev), 0.02);
}

// Mirror z -> L - z with the ends on: the mirrored shape and wall velocities swim the other way.
TEST(EndEffects, MirroredProfilesSwimTheOtherWay) {
  std::mt19937 g(13);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.5, 1.3);
  for (int N : {8, 33}) {
    const auto d = intervals(N, kL);
    std::vector<double> R(N + 2);
    for (auto& r : R) r = u(g) * kR0;
    std::vector<double> Rm(R.rbegin(), R.rend());
    ConfinedSystem a(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL), b(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL);
    a.ends = b.ends = kOpenEnds;
    ASSERT_TRUE(a.geometry(R.data()));
    ASSERT_TRUE(b.geometry(Rm.data()));
    std::vector<double> s(N + 1), sm(N + 1);
    const double h = kL / N;
    for (int j = 0; j < N; ++j) s[j + 1] = s[j] + h * 1e-15 * n(g);
    for (int j = 0; j <= N; ++j) sm[j] = s[N] - s[N - j];
    a.kinematic(s.data());
    b.kinematic(sm.data());
    EXPECT_GT(std::abs(a.U), 0.0);
    EXPECT_NEAR(b.U, -a.U, 1e-11 * std::abs(a.U));
    // and the ends change the answer (asymmetric end radii)
    ConfinedSystem c(N + 2, d, kMu, 1e-9, 2e-9, kRc, kP, kL);
    ASSERT_TRUE(c.geometry(R.data()));
    c.kinematic(s.data());
    EXPECT_GT(std::abs(c.U - a.U), 1e-6 * std::abs(a.U));
  }
}

// Scallop theorem with the ends on: a reciprocal stroke (an asymmetric contraction near the
// rear, forward in 0.1 s and back in 0.3 s) returns the tube to its start; U is still linear in
// the wall velocity at a given shape.
TEST(EndEffects, ReciprocalStrokeGivesNoNetDisplacement) {
  const int N = 60;
  const double h = kL / N, a = 0.35 * kR0;
  ConfinedSystem sys(N + 2, intervals(N, kL), kMu, 0, 0, kRc, kP, kL);
  sys.ends = kOpenEnds;
  std::vector<double> zpt(N + 2), R(N + 2), s(N + 1);
  zpt[0] = 0, zpt[N + 1] = kL;
  for (int i = 0; i < N; ++i) zpt[i + 1] = (i + 0.5) * h;
  // the contraction reaches the rear end, so the end radius changes during the stroke
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

// The scene key: a value outside the choice names the key and the allowed values; the ends
// are refused with a force-driven wave and with the unbounded outer flow.
TEST(EndEffects, SceneKeyRefusesBadValuesAndOtherModels) {
  auto scene = [](json model1d, std::string wave) {
    json sc = {{"name", "ends"},
               {"swimmer", {{"radius", "0.125 um"}, {"length", "0.4 um"}}},
               {"container", {{"kind", "cylinder"}, {"radius", "0.25 um"}, {"period", "2 um"}}},
               {"model1d", model1d}};
    if (wave != "force_driven")
      sc["wave"] = {{"kind", wave}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"width", "0.05 um"}};
    return sc;
  };
  auto message = [](const json& sc) {
    json resolved;
    try {
      (void)swim::reduced1d::read_scene(sc, resolved);
    } catch (const swim::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string bad = message(scene({{"end_effects", "sampson"}}, "step"));
  EXPECT_NE(bad.find("model1d.end_effects"), std::string::npos) << bad;
  EXPECT_NE(bad.find("sampson"), std::string::npos) << bad;
  EXPECT_NE(bad.find("open_ends"), std::string::npos) << bad;
  const std::string forced = message(scene({{"end_effects", "open_ends"}}, "force_driven"));
  EXPECT_NE(forced.find("model1d.end_effects"), std::string::npos) << forced;
  const std::string unbounded = message(scene({{"end_effects", "open_ends"}, {"outer_flow", "unbounded"}}, "step"));
  EXPECT_NE(unbounded.find("model1d.end_effects"), std::string::npos) << unbounded;
  EXPECT_EQ(message(scene({{"end_effects", "open_ends"}}, "step")), "");
  json resolved;
  const auto p = swim::reduced1d::read_scene(scene({{"end_effects", "open_ends"}}, "step"), resolved);
  EXPECT_EQ(p.swimmer.end_lumen, kOpenEnds.lumen);
  EXPECT_EQ(p.swimmer.end_annulus, kOpenEnds.annulus);
  EXPECT_EQ(resolved["model1d"]["end_effects"], "open_ends");
}
