// A screen design's outcome sent between MPI ranks as JSON comes back bit for bit: every double
// of the metrics (and the lists of per-cycle figures) of real force-driven designs, a failed
// design's message, and non-finite numbers, which JSON cannot write as numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "common/scene.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"

using namespace swim;
using namespace swim::reduced1d;

namespace {
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_identical(const DesignOutcome& a, const DesignOutcome& b) {
  EXPECT_EQ(a.ok, b.ok);
  EXPECT_EQ(a.message, b.message);
  EXPECT_TRUE(same_bits(a.wall_time_s, b.wall_time_s));
  const Metrics &x = a.metrics, &y = b.metrics;
  for (const auto& [u, v] : {std::pair{x.t_end_s, y.t_end_s}, {x.displacement_m, y.displacement_m},
                             {x.max_displacement_m, y.max_displacement_m}, {x.mean_velocity_m_per_s, y.mean_velocity_m_per_s},
                             {x.body_lengths_per_s, y.body_lengths_per_s}, {x.final_velocity_m_per_s, y.final_velocity_m_per_s},
                             {x.max_velocity_m_per_s, y.max_velocity_m_per_s}, {x.pumped_volume_m3, y.pumped_volume_m3},
                             {x.mean_cycle_time_s, y.mean_cycle_time_s}, {x.min_radius_m, y.min_radius_m},
                             {x.displacement_per_cycle_m, y.displacement_per_cycle_m},
                             {x.mean_velocity_per_cycle_m_per_s, y.mean_velocity_per_cycle_m_per_s},
                             {x.pumped_volume_lab_m3, y.pumped_volume_lab_m3},
                             {x.drag_coefficient_N_s_per_m, y.drag_coefficient_N_s_per_m},
                             {x.thermal_rms_displacement_m, y.thermal_rms_displacement_m},
                             {x.directed_to_diffusive, y.directed_to_diffusive}})
    EXPECT_TRUE(same_bits(u, v)) << u << " vs " << v;
  EXPECT_EQ(x.cycles_completed, y.cycles_completed);
  EXPECT_EQ(x.switches, y.switches);
  EXPECT_EQ(x.has_cycle, y.has_cycle);
  EXPECT_EQ(x.no_cycle_reason, y.no_cycle_reason);
  EXPECT_EQ(x.implausible, y.implausible);
  ASSERT_EQ(x.cycle_times_s.size(), y.cycle_times_s.size());
  for (std::size_t i = 0; i < x.cycle_times_s.size(); ++i) EXPECT_TRUE(same_bits(x.cycle_times_s[i], y.cycle_times_s[i]));
  ASSERT_EQ(x.cycle_displacements_m.size(), y.cycle_displacements_m.size());
  for (std::size_t i = 0; i < x.cycle_displacements_m.size(); ++i)
    EXPECT_TRUE(same_bits(x.cycle_displacements_m[i], y.cycle_displacements_m[i]));
}

DesignOutcome through_text(const DesignOutcome& o) {
  return outcome_from_json(scene::json::parse(outcome_to_json(o).dump()));
}
}  // namespace

TEST(OutcomeJson, ForceDrivenDesignsComeBackBitForBit) {
  for (double ratio : {0.45, 0.7}) {
    scene::json s = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/demo.json");
    s["wave"]["contracted_ratio"] = ratio;
    s["protocol"]["cycles"] = 2;
    scene::json resolved;
    const DesignOutcome o = run_design(read_scene(s, resolved, SWIM_SOURCE_DIR "/data/scenes"));
    ASSERT_TRUE(o.ok) << o.message;
    ASSERT_TRUE(o.metrics.has_cycle);
    ASSERT_GE(o.metrics.cycle_times_s.size(), 1u);
    expect_identical(o, through_text(o));
  }
}

TEST(OutcomeJson, FailuresAndNonFiniteNumbersSurvive) {
  DesignOutcome o;
  o.ok = false;
  o.message = "numerical failure: \"CVODE\" step\nfailed";
  o.metrics.displacement_m = std::numeric_limits<double>::quiet_NaN();
  o.metrics.max_velocity_m_per_s = std::numeric_limits<double>::infinity();
  o.metrics.min_radius_m = -std::numeric_limits<double>::infinity();
  o.metrics.cycle_times_s = {0.1 + 0.2, std::nextafter(1.0, 2.0), 5e-324};
  o.metrics.implausible = {"a", "b"};
  DesignOutcome b = through_text(o);
  EXPECT_TRUE(std::isnan(b.metrics.displacement_m));
  EXPECT_EQ(b.metrics.max_velocity_m_per_s, std::numeric_limits<double>::infinity());
  EXPECT_EQ(b.metrics.min_radius_m, -std::numeric_limits<double>::infinity());
  o.metrics.displacement_m = b.metrics.displacement_m = 0;  // NaN != NaN: compared above
  expect_identical(o, b);
}
