// A design confirmed in 3D has its 1D cycle end by its 3D run's recovery rule
// (design::match_recovery_end): the 1D default, the paper's energy rule, waits until the wall
// has relaxed far below the geometric band the 3D tier ends by, so without it the two tiers'
// cycle times and mean velocities would measure different cycles.
#include <gtest/gtest.h>

#include <string>

#include "common/scene.hpp"
#include "design/confirm.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"

using namespace swim;
using swim::scene::json;

namespace {

const std::string kDir = SWIM_SOURCE_DIR "/data/scenes";

json demo(const std::vector<std::string>& sets = {}) {
  json s = scene::load_file(kDir + "/demo.json");
  for (const auto& kv : sets) scene::apply_override(s, kv);
  return s;
}

reduced1d::Metrics run1d(const json& s) {
  json resolved;
  const reduced1d::DesignOutcome o = reduced1d::run_design(reduced1d::read_scene(s, resolved, kDir));
  EXPECT_TRUE(o.ok) << o.message;
  return o.metrics;
}

design::Candidate candidate(const json& s) {
  design::Candidate c;
  c.scene = s;
  c.metrics = run1d(s);
  return c;
}

}  // namespace

TEST(ConfirmRecoveryEnd, AForceDrivenDesignEndsItsOneDCycleByTheThreeDDefault) {
  design::Candidate c = candidate(demo());
  const reduced1d::Metrics energy = c.metrics;
  design::match_recovery_end(c, kDir);
  EXPECT_EQ(c.recovery_end_1d, "dead_band");
  ASSERT_TRUE(c.metrics_sweep.has_value());
  EXPECT_EQ(c.metrics_sweep->mean_cycle_time_s, energy.mean_cycle_time_s);
  // the figures are those of the 1D run with the 3D rule, exactly
  const reduced1d::Metrics dead_band = run1d(demo({"model1d.recovery_end=\"dead_band\""}));
  EXPECT_EQ(c.metrics.mean_cycle_time_s, dead_band.mean_cycle_time_s);
  EXPECT_EQ(c.metrics.mean_velocity_m_per_s, dead_band.mean_velocity_m_per_s);
  // the band ends the cycle earlier; the stroke itself is the same
  std::printf("demo: energy rule %.4g s, dead band %.4g s; displacement %.6g against %.6g m\n",
              energy.mean_cycle_time_s, c.metrics.mean_cycle_time_s, energy.displacement_per_cycle_m,
              c.metrics.displacement_per_cycle_m);
  // (demo, R_f = 0.55 R0: 0.528 against 0.515 s)
  EXPECT_LT(c.metrics.mean_cycle_time_s, 0.99 * energy.mean_cycle_time_s);
  EXPECT_NEAR(c.metrics.displacement_per_cycle_m, energy.displacement_per_cycle_m,
              0.01 * energy.displacement_per_cycle_m);
  // a shallow contraction stores little energy in the band: there the energy rule's wait is
  // most of the recovery
  design::Candidate shallow = candidate(demo({"wave.contracted_ratio=0.82"}));
  const double t_energy = shallow.metrics.mean_cycle_time_s;
  design::match_recovery_end(shallow, kDir);
  std::printf("R_f = 0.82 R0: energy rule %.4g s, dead band %.4g s\n", t_energy, shallow.metrics.mean_cycle_time_s);
  EXPECT_LT(shallow.metrics.mean_cycle_time_s, 0.8 * t_energy);
}

TEST(ConfirmRecoveryEnd, TheSceneOwnThreeDRuleIsFollowedAndAStatedOneDRuleIsKept) {
  design::Candidate shape = candidate(demo({"full3d.recovery_end=\"shape\""}));
  design::match_recovery_end(shape, kDir);
  EXPECT_EQ(shape.recovery_end_1d, "shape");
  EXPECT_TRUE(shape.metrics_sweep.has_value());
  EXPECT_EQ(shape.metrics.mean_cycle_time_s,
            run1d(demo({"full3d.recovery_end=\"shape\"", "model1d.recovery_end=\"shape\""})).mean_cycle_time_s);

  // the design states its 1D rule: its figures stay the sweep's
  design::Candidate own = candidate(demo({"model1d.recovery_end=\"energy\""}));
  const double t = own.metrics.mean_cycle_time_s;
  design::match_recovery_end(own, kDir);
  EXPECT_EQ(own.recovery_end_1d, "energy");
  EXPECT_FALSE(own.metrics_sweep.has_value());
  EXPECT_EQ(own.metrics.mean_cycle_time_s, t);

  // the 3D rule is the 1D's already: nothing to run again
  design::Candidate same = candidate(demo({"full3d.recovery_end=\"energy\""}));
  design::match_recovery_end(same, kDir);
  EXPECT_EQ(same.recovery_end_1d, "energy");
  EXPECT_FALSE(same.metrics_sweep.has_value());
}

TEST(ConfirmRecoveryEnd, APrescribedWaveHasNoRecoveryToMatch) {
  json s = demo({"wave.kind=\"step\"", "protocol=null"});
  design::Candidate c;
  c.scene = s;
  design::match_recovery_end(c, kDir);
  EXPECT_TRUE(c.recovery_end_1d.empty());
  EXPECT_FALSE(c.metrics_sweep.has_value());
}
