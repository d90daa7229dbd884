// The two-grid error estimate of a single 3D run (validation/error_estimate.hpp): the
// arithmetic on exact power laws, and the measured pair of grids of the round-wall
// paper_aspect_L0.2 case against its converged axisymmetric reference.
#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.hpp"
#include "validation/error_estimate.hpp"

using namespace swim;
using namespace swim::validation;

// f(h) = f0 + C h^p exactly, p anywhere in the immersed boundary's range [0.5, 2]: the
// extrapolation at the true order gives f0, and the interval [min, max] of E_0.5, E_1, E_2
// holds f0 (E_p is monotone in p); at p = 1 the order-1 value is f0 itself.
TEST(ErrorEstimate, ExactPowerLawsRecoverTheLimitAndTheIntervalHoldsIt) {
  const double f0 = 40.2, h = 7.8125, H = 10.4167;
  for (double p : {0.5, 0.75, 1.0, 1.3, 1.7, 2.0}) {
    for (double C : {-0.8, 0.05, 1.3}) {
      const double f = f0 + C * std::pow(h, p), F = f0 + C * std::pow(H, p);
      EXPECT_NEAR(extrapolate_two_grids(f, F, h, H, p), f0, 1e-9 * f0) << "p = " << p << ", C = " << C;
      const TwoGridEstimate e = two_grid_estimate(f, F, h, H, false);
      EXPECT_LE(e.interval_low, f0 + 1e-9) << "p = " << p << ", C = " << C;
      EXPECT_GE(e.interval_high, f0 - 1e-9) << "p = " << p << ", C = " << C;
      EXPECT_LE(e.interval_low, e.extrapolated_order1);
      EXPECT_GE(e.interval_high, e.extrapolated_order1);
      // the error reaches f0 from E_1
      EXPECT_GE(e.error, std::abs(e.extrapolated_order1 - f0) - 1e-9);
      if (p == 1.0) {
        EXPECT_NEAR(e.extrapolated_order1, f0, 1e-9 * f0);
      }
      EXPECT_FALSE(e.clipped);
    }
  }
  // equal figures on both grids: a zero-width interval at that figure
  const TwoGridEstimate same = two_grid_estimate(3.0, 3.0, h, H, true);
  EXPECT_EQ(same.interval_low, 3.0);
  EXPECT_EQ(same.interval_high, 3.0);
  EXPECT_EQ(same.error, 0.0);
}

// Measured (docs/full3d.md): paper_aspect_L0.2 under 0.5 Pa, 23.68 nm per cycle on 48 cells
// across and 26.39 nm on 64 (h = 10.42 and 7.81 nm). E_1 = 34.5 nm, E_0.5 = 43.9 nm: the
// interval holds the converged axisymmetric reference, 40.2 nm.
TEST(ErrorEstimate, TheMeasuredPairOfTheRoundWallBracketsTheAxisymmetricReference) {
  const double h = 0.5e-6 / 64, H = 0.5e-6 / 48;
  const TwoGridEstimate d = two_grid_estimate(26.39e-9, 23.68e-9, h, H, false);
  EXPECT_NEAR(d.extrapolated_order1, 34.5e-9, 0.05e-9);
  EXPECT_NEAR(d.extrapolated[0], 43.9e-9, 0.05e-9);
  EXPECT_NEAR(d.extrapolated[2], 29.9e-9, 0.05e-9);
  EXPECT_LT(d.interval_low, 40.2e-9);
  EXPECT_GT(d.interval_high, 40.2e-9);
  EXPECT_NEAR(d.interval_low, d.extrapolated[2], 1e-18);
  EXPECT_NEAR(d.interval_high, d.extrapolated[0], 1e-18);
  EXPECT_NEAR(d.error, 43.9e-9 - 34.5e-9, 0.1e-9);
}

// The same pair's cycle times, 0.752 s and 0.616 s, fall with the grid: E_2 = 0.441 s,
// E_1 = 0.208 s, E_0.5 = -0.26 s. The interval holds the reference 0.322 s; its lower bound is
// negative, so for a positive figure it is clipped to 0 with a note giving the unclipped
// value, and the error keeps the unclipped spread. Nothing is NaN.
TEST(ErrorEstimate, TheMeasuredCycleTimesBracketTheReferenceAndANegativeBoundIsClippedAtZero) {
  const double h = 0.5e-6 / 64, H = 0.5e-6 / 48;
  const TwoGridEstimate t = two_grid_estimate(0.616, 0.752, h, H, true);
  EXPECT_NEAR(t.extrapolated[2], 0.441, 0.001);
  EXPECT_NEAR(t.extrapolated_order1, 0.208, 0.001);
  EXPECT_NEAR(t.extrapolated[0], -0.26, 0.005);
  EXPECT_TRUE(t.clipped);
  EXPECT_EQ(t.interval_low, 0.0);
  EXPECT_NEAR(t.interval_high, 0.441, 0.001);
  EXPECT_LT(t.interval_low, 0.322);
  EXPECT_GT(t.interval_high, 0.322);
  EXPECT_NEAR(t.error, t.extrapolated_order1 - t.extrapolated[0], 1e-12);
  EXPECT_NE(t.note.find("-0.26"), std::string::npos) << t.note;
  const scene::json j = to_json(t);
  EXPECT_EQ(j["interval_low"].get<double>(), 0.0);
  EXPECT_LT(j["extrapolated_order0_5"].get<double>(), 0.0);
  EXPECT_TRUE(j.contains("note"));
  // not a positive figure: the negative bound stays
  EXPECT_LT(two_grid_estimate(0.616, 0.752, h, H, false).interval_low, 0.0);
  // grids too coarse: the cycle time falls so fast (0.695 s on 12 cells, 1.162 s on 9, the
  // tiny cycle scene) that E_1 = -0.706 s too; it is reported as 0 with a note, the interval
  // [0, E_2 = 0.0946 s], the unclipped values in the note, the error and E_0.5
  const TwoGridEstimate c = two_grid_estimate(0.695, 1.162, 0.48e-6 / 12, 0.48e-6 / 9, true);
  EXPECT_EQ(c.extrapolated_order1, 0.0);
  EXPECT_EQ(c.interval_low, 0.0);
  EXPECT_NEAR(c.interval_high, 0.0946, 0.0001);
  EXPECT_NEAR(c.extrapolated[1], -0.706, 0.001);
  EXPECT_NEAR(c.error, 1.618, 0.001);  // |E_0.5 - E_1| = |-2.324 + 0.706| s
  EXPECT_NE(c.note.find("-0.706"), std::string::npos) << c.note;
  EXPECT_NE(c.note.find("too coarse"), std::string::npos) << c.note;
  // opposite signs on the two grids are named
  const TwoGridEstimate s = two_grid_estimate(0.53e-9, -5.76e-9, 0.48e-6 / 12, 0.48e-6 / 9, false);
  EXPECT_NE(s.note.find("opposite signs"), std::string::npos) << s.note;
  EXPECT_LE(s.interval_low, s.extrapolated_order1);
  EXPECT_LE(s.extrapolated_order1, s.interval_high);
}

// The summary object: the method, both grids, the order range [0.5, 2], an object per headline
// figure; a run without per-cycle figures gives a status that says why, and no numbers.
TEST(ErrorEstimate, TheSummaryObjectHoldsEveryFigureOrSaysWhyItCannot) {
  const scene::json fine = {{"displacement_per_cycle_m", 26.39e-9},
                            {"cycle_time_s", 0.616},
                            {"mean_velocity_per_cycle_m_per_s", 26.39e-9 / 0.616}};
  const scene::json coarse = {{"displacement_per_cycle_m", 23.68e-9},
                              {"cycle_time_s", 0.752},
                              {"mean_velocity_per_cycle_m_per_s", 23.68e-9 / 0.752}};
  const scene::json j = error_estimate_json(fine, coarse, 48, 0.5e-6 / 64, 0.5e-6 / 48);
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["coarse_cells_across"], 48);
  EXPECT_EQ(j["order_range"], scene::json({0.5, 2.0}));
  EXPECT_TRUE(j["method"].is_string());
  for (const char* k : kEstimatedFigures) {
    ASSERT_TRUE(j.contains(k)) << k;
    const auto& f = j[k];
    EXPECT_LE(f["interval_low"].get<double>(), f["extrapolated_order1"].get<double>()) << k;
    EXPECT_LE(f["extrapolated_order1"].get<double>(), f["interval_high"].get<double>()) << k;
    EXPECT_GE(f["error"].get<double>(), 0.0) << k;
  }
  EXPECT_EQ(j["mean_velocity_per_cycle_m_per_s"]["fine"].get<double>(), 26.39e-9 / 0.616);
  scene::json none = coarse;
  none["cycle_time_s"] = nullptr;
  none["per_cycle_absent_because"] = "no protocol cycle completed";
  const scene::json f = error_estimate_json(fine, none, 48, 0.5e-6 / 64, 0.5e-6 / 48);
  EXPECT_EQ(f.size(), 1u);
  EXPECT_EQ(f["status"], "failed: the coarse run has no per-cycle figures (no protocol cycle completed)");
  EXPECT_THROW(two_grid_estimate(1.0, 2.0, 1.0, 1.0, false), InputError);
  EXPECT_THROW(two_grid_estimate(NAN, 2.0, 1.0, 2.0, false), InputError);
}
