// Richardson extrapolation, U(t) comparison and suite-file checks of the validation layer.
#include <unistd.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"
#include "validation/compare.hpp"
#include "validation/richardson.hpp"
#include "validation/suite.hpp"
#include "validation/suite_phases.hpp"
#include "validation/suite_file.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/scene1d.hpp"
#include "common/scene.hpp"

using namespace swim;
using namespace swim::validation;

// f(h) = f0 + C h^p exactly: the observed order and the limit are recovered, for a constant
// and for a varying refinement ratio.
TEST(Richardson, RecoversOrderAndLimitOfAnExactPowerLaw) {
  for (double p : {0.5, 1.0, 1.5}) {
    for (const std::vector<double>& h : {std::vector<double>{0.04, 0.02, 0.01}, std::vector<double>{15.6, 12.5, 10.4}}) {
      std::vector<double> f;
      for (double x : h) f.push_back(29.0 - 3.0 * std::pow(x / h.front(), p));  // corrections below 3
      const Extrapolation e = richardson(h, f);
      EXPECT_TRUE(e.asymptotic);
      EXPECT_NEAR(e.order, p, 1e-9);
      EXPECT_NEAR(e.value, 29.0, 1e-9);
      // a second-order scheme's range takes order 2 as well
      std::vector<double> g;
      for (double x : h) g.push_back(29.0 - 3.0 * std::pow(x / h.front(), p + 1.0));
      const Extrapolation s = richardson(h, g, 1.0, OrderRange{0.5, 3.0});
      EXPECT_TRUE(s.asymptotic);
      EXPECT_NEAR(s.value, 29.0, 1e-9);
    }
  }
}

// The grids may come in any order.
TEST(Richardson, OrderOfTheGridsDoesNotMatter) {
  const Extrapolation a = richardson({0.01, 0.04, 0.02}, {29.0 - 0.03, 29.0 - 0.12, 29.0 - 0.06});
  EXPECT_NEAR(a.value, 29.0, 1e-9);
  EXPECT_NEAR(a.order, 1.0, 1e-9);
}

// Differences of opposite sign: not asymptotic, the finest value with the spread as error.
TEST(Richardson, NonMonotoneSequenceIsReportedNotExtrapolated) {
  const Extrapolation e = richardson({3, 2, 1}, {10.0, 12.0, 11.0});
  EXPECT_FALSE(e.asymptotic);
  EXPECT_DOUBLE_EQ(e.value, 11.0);
  EXPECT_DOUBLE_EQ(e.error, 2.0);
}

// A first-order method before its asymptotic range, f = f0 + a h + b h^2 with b h comparable
// to a (the immersed boundary's smeared wall on the affordable grids): the three finest grids
// show an order outside [0.5, 1.5], so Richardson gives the finest value; the error-expansion fit
// over five grids recovers f0 exactly, with zero leave-one-out change; its error bar is the
// distance to the finest pair's extrapolation at order 1 and 0.5, which covers f0.
TEST(ExpansionFit, RecoversTheLimitOfAFirstOrderSeriesBeforeItsAsymptoticRange) {
  const std::vector<double> h = {15.625, 12.5, 10.4167, 8.92857, 7.8125};
  std::vector<double> f;
  for (double x : h) f.push_back(40.0 - 1.8 * x + 0.05 * x * x);
  const Extrapolation r = richardson(h, f);
  EXPECT_FALSE(r.asymptotic);
  const Extrapolation e = extrapolate_series(h, f, 1.0, kImmersedBoundaryOrders);
  EXPECT_EQ(e.method, "expansion_fit");
  EXPECT_FALSE(e.asymptotic);
  EXPECT_NEAR(e.value, 40.0, 1e-9);
  const double r1 = f[4] + (f[4] - f[3]) / (h[3] / h[4] - 1.0);
  const double rh = f[4] + (f[4] - f[3]) / (std::sqrt(h[3] / h[4]) - 1.0);
  EXPECT_NEAR(e.error, std::max(std::abs(r1 - 40.0), std::abs(rh - 40.0)), 1e-9);
  EXPECT_DOUBLE_EQ(e.order, 1.0);
  // the fitted coefficients, which the report's convergence figure draws (report.json "expansion")
  EXPECT_NEAR(e.expansion_a, -1.8, 1e-9);
  EXPECT_NEAR(e.expansion_b, 0.05, 1e-9);
  EXPECT_TRUE(std::isnan(r.expansion_a));
  // noise on one grid: the fit moves, and the leave-one-out error covers the move
  f[2] += 0.3;
  const Extrapolation n = expansion_fit(h, f);
  EXPECT_GT(std::abs(n.value - 40.0), 0.05);
  EXPECT_GE(n.error, std::abs(n.value - 40.0));
}

// The fit is refused, with the finest value and the spread of the finest three, where it has
// no footing: three grids, a second-order scheme (no h term), or a correction larger than half
// of the finest value.
TEST(ExpansionFit, IsRefusedWhereItHasNoFooting) {
  const std::vector<double> h4 = {4, 3, 2, 1};
  const std::vector<double> f4 = {6.0, 7.0, 9.0, 8.5};
  const Extrapolation three = expansion_fit({3, 2, 1}, {7.0, 9.0, 8.5});
  EXPECT_EQ(three.method, "finest_grid");
  EXPECT_DOUBLE_EQ(three.value, 8.5);
  EXPECT_DOUBLE_EQ(three.error, 2.0);
  EXPECT_EQ(expansion_fit(h4, f4, kSharpInterfaceOrders).method, "finest_grid");
  // f0 = 100 from a finest value of 10: refused
  std::vector<double> f;
  for (double x : h4) f.push_back(100.0 - 90.0 * x + 0.5 * x * x);
  const Extrapolation big = expansion_fit(h4, f);
  EXPECT_EQ(big.method, "finest_grid");
  EXPECT_DOUBLE_EQ(big.value, f.back());
  // an asymptotic series keeps Richardson
  std::vector<double> g;
  for (double x : h4) g.push_back(29.0 - 0.3 * x);
  EXPECT_EQ(extrapolate_series(h4, g, 1.0, kImmersedBoundaryOrders).method, "richardson");
}

// The round R_f = 0.82 R0 wall's displacement per cycle on the 3D tier's five grids (32 to 64
// cells across, nm; the converged suite's runs), whose axisymmetric reference is 19.451 nm
// ± 0.2 %. The finest three show an order of 1.98: a first-order method's grids there are not
// asymptotic (the axisymmetric immersed boundary on the same scene shows 0.7–0.85 down to
// h = 1.95 nm), and Richardson at that order would give 15.67 nm, 19 % short, with an error bar
// (1.64 nm) that misses the reference. Expected: the immersed boundary's range refuses the
// order, the series goes to the error expansion, whose f0 (19.48 nm) lies within 0.2 % of the
// reference and whose error bar covers it; a range up to 2 shows the miss.
TEST(ExpansionFit, TakesTheRoundWallsSeriesWhoseFinestGridsShowOrderTwo) {
  const std::vector<double> h = {15.625, 12.5, 10.416666666666666, 8.928571428571429, 7.8125};
  const std::vector<double> f = {10.437463075546646, 11.562043571301572, 12.771365027330898, 13.532160111626174,
                                 14.027643995126283};
  const double reference = 19.451;
  const Extrapolation wide = extrapolate_series(h, f, 1.0, OrderRange{0.5, 2.0});
  EXPECT_EQ(wide.method, "richardson");
  EXPECT_NEAR(wide.order, 1.976, 0.005);
  EXPECT_GT(std::abs(wide.value - reference), wide.error + 0.1);  // the error bar misses it
  const Extrapolation e = extrapolate_series(h, f, 1.0, kImmersedBoundaryOrders);
  EXPECT_EQ(e.method, "expansion_fit");
  EXPECT_FALSE(e.asymptotic);
  EXPECT_NEAR(e.observed_order, 1.976, 0.005);
  EXPECT_NE(e.note.find("outside the range [0.5, 1.5]"), std::string::npos) << e.note;
  EXPECT_NEAR(e.value, 19.476, 0.001);
  EXPECT_LT(std::abs(e.value - reference), 0.005 * reference);
  EXPECT_GT(e.error, std::abs(e.value - reference));
  EXPECT_NEAR(e.error, 3.429, 0.001);  // the largest change with one grid left out
}

// The cycle time of an immersed boundary whose smearing narrows the lumen by a h: an exact
// T0 (1 - a h)^-4 on the converged suite's five 3D grids (h = 15.6 to 7.8 nm, a h = 0.27 on
// the coarsest, as the round L = 0.2 um tube's fit). Expected: Richardson on the finest three
// finds an order of 1.93, which a range up to 2 would take, and then misses T0 by 21 %: the
// series is not a power law in h (the immersed boundary's range, [0.5, 1.5], refuses it). The lumen fit recovers T0 to 1e-12 and a to 1e-12, its error is a
// quarter of the correction (every refit and the finest pair's line give T0 exactly: the
// model's own share), the order is 1 and the value not asymptotic;
// with one grid perturbed the error covers the move. Refused (the finest value, method
// finest_grid): two grids, a time that falls towards the coarse grids, a lumen that closes
// within the grids, a non-positive time, a correction above half the finest value.
TEST(LumenFit, RecoversTheLimitOfASmearedLumensCycleTime) {
  const std::vector<double> h = {15.625, 12.5, 10.4167, 8.92857, 7.8125};
  const double T0 = 0.32, a = 0.0173;
  std::vector<double> T;
  for (double x : h) T.push_back(T0 * std::pow(1.0 - a * x, -4.0));
  EXPECT_FALSE(richardson(h, T).asymptotic);
  const Extrapolation r = richardson(h, T, 1.0, OrderRange{0.5, 2.0});
  EXPECT_TRUE(r.asymptotic);
  EXPECT_NEAR(r.observed_order, 1.93, 0.01);
  EXPECT_NEAR(r.value / T0 - 1.0, 0.21, 0.01);
  const Extrapolation e = lumen_fit(h, T);
  EXPECT_EQ(e.method, "lumen_fit");
  EXPECT_NEAR(e.value, T0, 1e-12);
  EXPECT_NEAR(e.lumen_a, a, 1e-12);
  // every refit and the finest pair's line give T0: the error is the model's share of the correction
  EXPECT_NEAR(e.error, kLumenModelShare * (T.back() - T0), 1e-12);
  EXPECT_DOUBLE_EQ(e.order, 1.0);
  EXPECT_FALSE(e.asymptotic);
  // the same on three grids, in any order
  const Extrapolation e3 = lumen_fit({h[4], h[0], h[2]}, {T[4], T[0], T[2]});
  EXPECT_NEAR(e3.value, T0, 1e-12);
  std::vector<double> Tn = T;
  Tn[2] *= 1.05;
  const Extrapolation n = lumen_fit(h, Tn);
  EXPECT_GT(std::abs(n.value - T0), 1e-3);
  EXPECT_GE(n.error, std::abs(n.value - T0));

  EXPECT_EQ(lumen_fit({2, 1}, {0.5, 0.4}).method, "finest_grid");
  EXPECT_EQ(lumen_fit({3, 2, 1}, {0.3, 0.4, 0.5}).method, "finest_grid");  // shorter on coarser grids
  std::vector<double> closing;
  for (double x : {30.0, 20.0, 10.0}) closing.push_back(std::pow(1.0 - x / 25.0, -4.0) * 1e-3 + (x > 25 ? 1.0 : 0.0));
  EXPECT_EQ(lumen_fit({30, 20, 10}, closing).method, "finest_grid");  // not a line with a h < 1
  EXPECT_EQ(lumen_fit({3, 2, 1}, {0.6, -0.5, 0.4}).method, "finest_grid");
  std::vector<double> big;
  for (double x : {3.0, 2.0, 1.0}) big.push_back(1.0 * std::pow(1.0 - 0.3 * x, -4.0));
  const Extrapolation b = lumen_fit({3, 2, 1}, big);  // T0 = 1 from a finest value of 4.2
  EXPECT_EQ(b.method, "finest_grid");
  EXPECT_DOUBLE_EQ(b.value, big.back());
}

// Out of sample: the quarter of the correction (kLumenModelShare) was set on the 3D tier's
// round walls; here it meets the axisymmetric immersed boundary's cycle times of the round
// paper_aspect_L0.2 under 0.5 Pa, 32 to 256 cells across (docs/axi.md, "The immersed
// boundary's grid convergence"; h = 250 nm / cells), whose converged reference is 0.320 s. Every
// window of three, four and five neighbouring grids gives a fit whose error bar holds the
// reference (measured: within 0.021 s of it, bars 0.012 to 0.064 s). Without the model's share
// five of the twelve windows would miss it (the 64-96-128 fit, 0.341 s, by 0.021 s against
// 0.007 s from its refits and the finest pair's line).
TEST(LumenFit, ItsErrorBarHoldsTheReferenceOnTheAxisymmetricImmersedBoundarysSeries) {
  const std::vector<std::pair<int, double>> series = {{32, 1.183}, {48, 0.749}, {64, 0.578}, {96, 0.483},
                                                      {128, 0.439}, {192, 0.396}, {256, 0.373}};
  const double ref = 0.320;
  int windows = 0;
  for (std::size_t w = 3; w <= 5; ++w)
    for (std::size_t i = 0; i + w <= series.size(); ++i) {
      std::vector<double> h, T;
      for (std::size_t k = i; k < i + w; ++k) {
        h.push_back(250.0 / series[k].first);
        T.push_back(series[k].second);
      }
      const Extrapolation e = lumen_fit(h, T);
      const std::string at = std::to_string(series[i].first) + " to " + std::to_string(series[i + w - 1].first) + " cells";
      ASSERT_EQ(e.method, "lumen_fit") << at;
      EXPECT_LE(std::abs(e.value - ref), e.error) << at << ": " << e.value << " +- " << e.error;
      EXPECT_LT(std::abs(e.value - ref), 0.025) << at;
      EXPECT_GE(e.error, kLumenModelShare * std::abs(e.value - T.back()) - 1e-15) << at;
      ++windows;
    }
  EXPECT_EQ(windows, 12);
  // the window that needs the share: its refits and the finest pair's line stay within 0.01 s
  const Extrapolation m = lumen_fit({250.0 / 64, 250.0 / 96, 250.0 / 128}, {0.578, 0.483, 0.439});
  EXPECT_NEAR(m.value, 0.341, 0.001);
  EXPECT_NEAR(m.error, kLumenModelShare * (0.439 - m.value), 1e-12);
  EXPECT_GT(std::abs(m.value - ref), 0.01);
}

// A sum of two parts with errors of opposite sign and different orders (order 1.5 from below,
// 3 from above, as a first contraction and the rest of a cycle): the sum's own series shows no
// order, the parts extrapolated apart recover the limit and both orders.
TEST(Richardson, ASumOfPartsIsExtrapolatedPartByPart) {
  const std::vector<double> h = {0.06, 0.04, 0.03};
  std::vector<std::vector<double>> parts;
  std::vector<double> sum;
  for (double x : h) {
    parts.push_back({0.110 - 0.2 * std::pow(x, 1.5), 0.211 + 10.0 * std::pow(x, 3.0)});
    sum.push_back(parts.back()[0] + parts.back()[1]);
  }
  EXPECT_FALSE(richardson(h, sum, 1.0, kSharpInterfaceOrders).asymptotic);
  const SumExtrapolation s = richardson_sum(h, parts, 1.0, kSharpInterfaceOrders, 0.01);
  ASSERT_EQ(s.parts.size(), 2u);
  EXPECT_NEAR(s.parts[0].order, 1.5, 1e-8);
  EXPECT_NEAR(s.parts[1].order, 3.0, 1e-8);
  EXPECT_NEAR(s.value, 0.321, 1e-12);
  EXPECT_NEAR(s.error, std::abs(s.parts[0].value - parts[2][0]) + std::abs(s.parts[1].value - parts[2][1]), 1e-15);
  EXPECT_TRUE(s.asymptotic);
  EXPECT_TRUE(s.converged);                                   // 0.41 % <= 1 %
  EXPECT_FALSE(richardson_sum(h, parts, 1.0, kSharpInterfaceOrders, 0.003).converged);  // > 0.3 %
  // a third part without an order: harmless when its spread is below a tenth of the target,
  // fatal when it is not
  auto with_third = [&](std::vector<double> third) {
    auto p = parts;
    for (std::size_t g = 0; g < p.size(); ++g) p[g].push_back(third[g]);
    return richardson_sum(h, p, 1.0, kSharpInterfaceOrders, 0.01);
  };
  const SumExtrapolation tiny = with_third({0.001, 0.001001, 0.0010005});
  EXPECT_FALSE(tiny.asymptotic);
  EXPECT_TRUE(tiny.converged);
  EXPECT_FALSE(with_third({0.001, 0.002, 0.0015}).converged);
  // parts that differ in number from grid to grid are refused
  auto bad = parts;
  bad[1].push_back(0.0);
  EXPECT_THROW(richardson_sum(h, bad, 1.0, kSharpInterfaceOrders, 0.01), InputError);
}

// Two grids: the assumed order is used. f = 1 + h: from h = 2, 1 the limit is 1.
TEST(Richardson, TwoGridsUseTheAssumedOrder) {
  const Extrapolation e = richardson({2, 1}, {3.0, 2.0}, 1.0);
  EXPECT_NEAR(e.value, 1.0, 1e-12);
  EXPECT_THROW(richardson({1}, {1.0}), InputError);
  EXPECT_EQ(e.note, "two grids, assumed order 1");
}

// A correction larger than half the finest value is not an extrapolation the grids support:
// two coarse grids whose values would extrapolate through zero (cycle times 3 s and 2.05 s at
// h = 20.8 and 15.6 nm, the ten-cycle paper swimmer) give the finest value and the
// difference as its error; so do three grids whose observed order is very low.
TEST(Richardson, ACorrectionLargerThanHalfTheFinestValueIsNotTrusted) {
  const Extrapolation e = richardson({20.8, 15.6}, {3.0, 2.05}, 1.0);
  EXPECT_FALSE(e.asymptotic);
  EXPECT_DOUBLE_EQ(e.value, 2.05);
  EXPECT_NEAR(e.error, 0.95, 1e-12);
  EXPECT_GT(e.value, 0.0);
  // f = 1 + 3 h^0.3 on h = 4, 2, 1: order 0.3 in range, limit 1, correction 3 / (1.0) > half of 4
  std::vector<double> h{4, 2, 1}, f;
  for (double x : h) f.push_back(1.0 + 3.0 * std::pow(x, 0.3));
  const Extrapolation g = richardson(h, f);
  EXPECT_FALSE(g.asymptotic);
  EXPECT_DOUBLE_EQ(g.value, f.back());
  EXPECT_THROW(richardson({1, 1}, {1.0, 2.0}), InputError);
}

namespace {
void sample(double T, double sign, std::vector<double>& t, std::vector<double>& u) {
  for (int k = 0; k <= 1000; ++k) {
    t.push_back(T * k / 1000.0);
    u.push_back(sign * std::sin(2 * M_PI * k / 1000.0) + 0.3);
  }
}
}  // namespace

// A velocity history and the same history on a cycle 4x longer: identical against phase,
// different against time. A mirrored history anticorrelates.
// Grids whose differences lie within the time integration's noise: f(h) = f0 + C h^p with p in
// the scheme's range, each value off by up to e_t (the step tolerance's error). Wherever the
// bound applies, the finest value's distance to f0 is within the error it states; over draws
// of noise and orders it applies in some and is refused in others (differences beyond 2 e_t).
// The bound is the lowest order's: with the highest order's in its place the error bars miss f0.
TEST(TimeErrorBound, CoversTheLimitWhereTheGridsDifferencesAreNoise) {
  const std::vector<double> h = {31.25, 20.8333, 15.625};
  const double f0 = 40.0, et = 0.01;
  unsigned state = 12345;
  auto uniform = [&] {  // [-1, 1), a fixed sequence
    state = state * 1664525u + 1013904223u;
    return 2.0 * (state >> 8) / double(1u << 24) - 1.0;
  };
  int applied = 0, refused = 0, missed_at_hi = 0;
  for (int draw = 0; draw < 2000; ++draw) {
    const double p = kSharpInterfaceOrders.lo + (uniform() + 1.0) / 2.0 * (kSharpInterfaceOrders.hi - kSharpInterfaceOrders.lo);
    const double E3 = (uniform() + 1.0) * 4.0 * et;  // the finest grid's error, 0 to 8 e_t
    std::vector<double> f;
    for (double x : h) f.push_back(f0 + E3 * std::pow(x / h.back(), p) + et * uniform());
    const auto b = bound_within_time_error(h, f, et, kSharpInterfaceOrders);
    if (!b) {
      ++refused;
      continue;
    }
    ++applied;
    EXPECT_TRUE(b->within_time_error);
    EXPECT_FALSE(b->asymptotic);
    EXPECT_EQ(b->method, "time_error_bound");
    EXPECT_DOUBLE_EQ(b->value, f.back());
    EXPECT_LE(std::abs(b->value - f0), b->error) << "p = " << p << ", E3 = " << E3;
    // the same bound with the highest order would claim too little
    const auto hi = bound_within_time_error(h, f, et, OrderRange{kSharpInterfaceOrders.hi - 1e-9, kSharpInterfaceOrders.hi});
    if (hi && std::abs(hi->value - f0) > hi->error) ++missed_at_hi;
  }
  EXPECT_GT(applied, 100);
  EXPECT_GT(refused, 100);
  EXPECT_GT(missed_at_hi, 0);
}

// The bound's arithmetic on one series, and where it is refused: a difference beyond 2 e_t, two
// grids, a time error that is zero or not finite.
TEST(TimeErrorBound, IsTheLowestOrdersBoundAndIsRefusedBeyondTheNoise) {
  // grids 3, 2, 1 (ratios 1.5 and 2), differences 0.01 and 0.015, e_t = 0.01, order range [1, 3.5]
  const auto b = bound_within_time_error({3, 2, 1}, {10.0, 10.01, 9.995}, 0.01, kSharpInterfaceOrders);
  ASSERT_TRUE(b.has_value());
  // pairs: (0.01 + 0.02) / (1.5 - 1) = 0.06 and (0.015 + 0.02) / (2 - 1) = 0.035; the larger, plus e_t
  EXPECT_NEAR(b->error, 0.06 + 0.01, 1e-12);
  EXPECT_DOUBLE_EQ(b->value, 9.995);
  EXPECT_FALSE(bound_within_time_error({3, 2, 1}, {10.0, 10.03, 10.02}, 0.01, kSharpInterfaceOrders).has_value());
  EXPECT_FALSE(bound_within_time_error({2, 1}, {10.0, 10.001}, 0.01, kSharpInterfaceOrders).has_value());
  EXPECT_FALSE(bound_within_time_error({3, 2, 1}, {10.0, 10.0, 10.0}, 0.0, kSharpInterfaceOrders).has_value());
  EXPECT_FALSE(bound_within_time_error({3, 2, 1}, {10.0, 10.0, 10.0}, std::nan(""), kSharpInterfaceOrders).has_value());
  EXPECT_THROW(bound_within_time_error({3, 2}, {10.0, 10.0, 10.0}, 0.01, kSharpInterfaceOrders), InputError);
}

TEST(CompareSeries, PhaseNormalisationAndCorrelation) {
  std::vector<double> t1, u1, t2, u2, t3, u3;
  sample(1.0, 1.0, t1, u1);
  sample(4.0, 1.0, t2, u2);
  sample(1.0, -1.0, t3, u3);
  const SeriesComparison ph = compare_series(t1, u1, 1.0, t2, u2, 4.0, true);
  EXPECT_LT(ph.l2_relative, 1e-5);
  EXPECT_NEAR(ph.correlation, 1.0, 1e-9);
  const SeriesComparison ab = compare_series(t1, u1, 1.0, t2, u2, 4.0, false);
  EXPECT_GT(ab.l2_relative, 0.5);
  const SeriesComparison mir = compare_series(t3, u3, 1.0, t1, u1, 1.0, true);
  EXPECT_NEAR(mir.correlation, -1.0, 1e-9);
  EXPECT_THROW(compare_series({0.0}, {1.0}, 1.0, t1, u1, 1.0, true), InputError);
}

namespace {
/// U(t) = sin(2 pi t / T + shift) + 0.3 over one cycle of T, 1001 samples.
Series shifted(double T, double shift) {
  Series s;
  for (int k = 0; k <= 1000; ++k) {
    s.t.push_back(T * k / 1000.0);
    s.x.push_back(0.0);
    s.u.push_back(std::sin(2 * M_PI * k / 1000.0 + shift) + 0.3);
  }
  return s;
}
}  // namespace

// A history correlates with itself exactly (correlation 1, no L2 difference); a copy shifted
// in phase by phi correlates by cos(phi) over the cycle, below 1, and the larger the shift the
// lower the correlation.
TEST(CompareSeries, SelfCorrelationIsOneAndAPhaseShiftLowersIt) {
  const Series a = shifted(1.0, 0.0);
  const SeriesComparison self = compare_series(a.t, a.u, 1.0, a.t, a.u, 1.0, true);
  EXPECT_NEAR(self.correlation, 1.0, 1e-12);
  EXPECT_NEAR(self.l2_relative, 0.0, 1e-12);
  double previous = 1.0;
  for (double phi : {0.1, 0.3, 0.6, 1.0}) {
    const Series b = shifted(1.0, phi);
    const SeriesComparison c = compare_series(a.t, a.u, 1.0, b.t, b.u, 1.0, true);
    EXPECT_NEAR(c.correlation, std::cos(phi), 1e-4) << "shift " << phi;
    EXPECT_LT(c.correlation, previous - 1e-3) << "shift " << phi;
    EXPECT_GT(c.l2_relative, 0.0);
    previous = c.correlation;
  }
}

// The U(t) comparison against a grid series (velocity_vs_runs: the 1D models against the
// finest 3D run, and against the finest axisymmetric run) takes the finest run that completed
// a cycle as the reference and the spread of the phase correlation over the three finest such
// runs as its uncertainty: here runs shifted by 1.0, 0.6, 0.3 and 0.1 rad (coarse to fine),
// then a finest run without a cycle, which is passed over.
TEST(CompareSeries, VelocityAgainstAGridSeriesTakesItsFinestRunWithACycle) {
  const Series one_d = shifted(1.0, 0.0);
  const std::vector<double> shifts = {1.0, 0.6, 0.3, 0.1, 0.0};
  std::vector<Series> series;
  for (double phi : shifts) series.push_back(shifted(2.0, phi));  // the reference's cycle is twice as long
  std::vector<VelocityRun> runs;
  for (std::size_t k = 0; k < shifts.size(); ++k)
    runs.push_back({&series[k], k + 1 < shifts.size(), 2.0, 40e-9 / double(k + 1)});
  const json v = velocity_vs_runs(one_d, 1.0, runs);
  ASSERT_TRUE(v.contains("phase_correlation")) << v.dump(1);
  EXPECT_NEAR(v["phase_correlation"].get<double>(), std::cos(0.1), 1e-4);
  EXPECT_NEAR(v["reference_cell_size_m"].get<double>(), 10e-9, 1e-18);
  EXPECT_NEAR(v["phase_correlation_grid_spread"].get<double>(), std::cos(0.1) - std::cos(0.6), 1e-4);
  EXPECT_EQ(v["phase_correlation_grids"], 3);
  // against time the two cycles differ (1 s against 2 s): not the phase figure
  EXPECT_LT(v["time_correlation"].get<double>(), v["phase_correlation"].get<double>() - 0.1);
  // one run with a cycle: a correlation without an uncertainty; none: no comparison
  const json single = velocity_vs_runs(one_d, 1.0, {runs[3], runs[4]});
  EXPECT_NEAR(single["phase_correlation"].get<double>(), std::cos(0.1), 1e-4);
  EXPECT_FALSE(single.contains("phase_correlation_grid_spread"));
  EXPECT_TRUE(velocity_vs_runs(one_d, 1.0, {runs[4]}).empty());
}

// A malformed suite is rejected naming the key, before any run.
TEST(SuiteFile, MalformedSuitesNameTheKey) {
  const std::string path = testing::TempDir() + "/bad_suite_" + std::to_string(::getpid()) + ".json";
  auto expect_key = [&](const std::string& text, const std::string& key) {
    std::ofstream(path) << text;
    try {
      load_suite(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  const std::string models = R"("models1d": [{"label": "m"}])";
  const std::string th = R"("thresholds": {"displacement_per_cycle_relative": 0.2, "cycle_time_relative": 0.5,
      "mean_velocity_per_cycle_relative": 0.5, "velocity_phase_correlation": 0.8})";
  expect_key("{" + models + ", " + th + "}", "suite.cases");
  expect_key(R"({"cases": [{"scene": "x.json", "grids": [32]}], )" + models + ", " + th + "}", "grids");
  expect_key(R"({"cases": [{"scene": "x.json", "grids": [32, 40], "calibration_grid": 5}], )" + models + ", " + th + "}",
             "calibration_grid");
  expect_key(R"({"cases": [{"scene": "x.json", "grids": [32, 40]}], )" + models + "}", "thresholds");
  expect_key(R"({"cases": [{"grids": [32, 40]}], )" + models + ", " + th + "}", "scene");
  // every grid of a case, not only the first, is one the 3D tier accepts
  const std::string data = SWIM_SOURCE_DIR "/data";
  std::ofstream(path) << R"({"cases": [{"scene": "paper_amplitude_0.82.json", "grids": [32, 40, 5000]}], )" + models +
                             ", " + th + "}";
  try {
    load_suite(path, data);
    ADD_FAILURE() << "accepted a third grid of 5000 cells across";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "suite.cases[0].grids[2]") << e.what();
    EXPECT_NE(std::string(e.what()).find("full3d.grid.cells_across"), std::string::npos) << e.what();
  }
}

// A calibrated model's scene takes the calibration file in place of the scene's own stiffness,
// whichever key the scene states it by; an uncalibrated one keeps it; the model's set applies.
TEST(SuiteFile, ACalibratedModelsSceneReplacesTheScenesOwnStiffness) {
  using scene::json;
  const json model = {{"label", "m"}, {"calibrated", true}, {"set", {{"model1d.outer_flow", "unbounded"}}}};
  for (const char* key : {"C1", "spring_constant"}) {
    json s = {{"wall", {{key, "1 Pa/m"}}}};
    const json m = model_scene(s, model, "/tmp/cal.json");
    EXPECT_FALSE(m["wall"].contains(key)) << key;
    EXPECT_EQ(m["wall"]["calibration"], "/tmp/cal.json");
    EXPECT_EQ(m["model1d"]["outer_flow"], "unbounded");
    json plain = model;
    plain["calibrated"] = false;
    EXPECT_EQ(model_scene(s, plain, "/tmp/cal.json")["wall"], s["wall"]) << key;
  }
}

// A force-driven 1D model ends its recovery by its reference's rule: the case's
// full3d.recovery_end, else the 3D tier's default (the same value the 3D tier resolves); a model
// that names its own rule keeps it; a prescribed wave has no recovery and gets none. The scenes
// so made are accepted by the 1D tier.
TEST(SuiteFile, AForceDrivenModelEndsItsRecoveryByTheReferencesRule) {
  using scene::json;
  const json base = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_amplitude_0.82.json");
  {
    json resolved;
    (void)full3d::read_scene3d(base, resolved);
    EXPECT_EQ(resolved["full3d"]["recovery_end"], kRecoveryEndDefault3d);
  }
  const json plain = {{"label", "m"}};
  EXPECT_EQ(model_scene(base, plain, "")["model1d"]["recovery_end"], kRecoveryEndDefault3d);
  json shape = base;
  set_key(shape, "full3d.recovery_end", "shape");
  const json m = model_scene(shape, plain, "");
  EXPECT_EQ(m["model1d"]["recovery_end"], "shape");
  json resolved;
  EXPECT_EQ(reduced1d::read_scene(m, resolved, SWIM_SOURCE_DIR "/data/scenes").protocol.recovery_end,
            reduced1d::RecoveryEnd::Shape);
  const json own = {{"label", "m"}, {"set", {{"model1d.recovery_end", "energy"}}}};
  EXPECT_EQ(model_scene(shape, own, "")["model1d"]["recovery_end"], "energy");
  json sine = base;
  sine["wave"] = {{"kind", "sine"}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"wavelength", "0.4 um"}};
  sine.erase("protocol");
  const json ms = model_scene(sine, plain, "");
  EXPECT_FALSE(ms.contains("model1d") && ms["model1d"].contains("recovery_end"));
}

// The shipped suites are well formed.
TEST(SuiteFile, ShippedSuitesLoad) {
  for (const char* s : {"quick.json", "default.json"})
    EXPECT_NO_THROW(load_suite(std::string(SWIM_SOURCE_DIR "/data/validation/") + s, SWIM_SOURCE_DIR "/data")) << s;
}
