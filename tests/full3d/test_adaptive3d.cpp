// Adaptive time step of the 3D run driver (full3d.adaptive, docs/full3d.md "Adaptive time
// step") on the small cycle scene data/scenes/tiny_3d_cycle.json (32x12x12 duct, h = 40 nm):
// agreement of a whole cycle with a fine fixed-step run, far fewer steps, exact resume,
// and the guard naming a scene key that exists.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"
#include "common/scene.hpp"
#include "full3d/run3d.hpp"
#include "run3d_scenes.hpp"

using namespace swim;
using namespace swim::full3d;
namespace fs = std::filesystem;

namespace {

using run3d_test::Scene;

Scene cycle(std::vector<std::string> sets) {
  sets.insert(sets.begin(), {"full3d.output.vtk=false", "full3d.checkpoint_interval=\"50 ms\""});
  return run3d_test::shipped_scene("tiny_3d_cycle.json", sets);
}

std::string fresh_dir(const std::string& name) { return run3d_test::fresh_dir("out_adaptive3d", name); }

RunControl quiet() { return run3d_test::quiet_control(); }

}  // namespace

// One whole cycle (contraction wave, recovery, dead-band end) with the midpoint scheme: the
// adaptive step (default tolerance) against the fixed dt = 0.5 ms run. Measured: +0.84 % in
// the displacement per cycle (about 0.75 nm, the small difference of forward and backward
// strokes of about 2 nm each) and +0.73 % in the cycle time (the end event is resolved to the
// large steps of the late recovery), with 281 steps against 1 431. Tolerance: 1.5 % for both.
// (Forward Euler is first order: its fixed dt = 0.25 ms run is itself 1.5 % below these.)
TEST(Adaptive3d, CycleAgreesWithFineFixedStep) {
  const Scene fine = cycle({"full3d.scheme=\"midpoint\"", "full3d.dt=\"0.5 ms\""});
  const Scene adap = cycle({"full3d.scheme=\"midpoint\"", "full3d.adaptive.enabled=true"});
  const RunOutcome rf = run3d(fine.p, fine.resolved, fresh_dir("fixed"), quiet());
  const RunOutcome ra = run3d(adap.p, adap.resolved, fresh_dir("adaptive"), quiet());
  ASSERT_FALSE(rf.failed) << rf.message;
  ASSERT_FALSE(ra.failed) << ra.message;
  ASSERT_EQ(rf.summary["cycles_completed"].get<int>(), 1);
  ASSERT_EQ(ra.summary["cycles_completed"].get<int>(), 1);
  const double df = rf.summary["displacement_m"].get<double>(), da = ra.summary["displacement_m"].get<double>();
  const double tf = rf.summary["cycle_times_s"][0].get<double>(), ta = ra.summary["cycle_times_s"][0].get<double>();
  const long nf = rf.summary["steps_per_cycle"][0].get<long>(), na = ra.summary["steps_per_cycle"][0].get<long>();
  std::printf("fixed 0.5 ms: %.6g m in %.5g s, %ld steps; adaptive: %.6g m in %.5g s, %ld steps; difference %.3g %%, "
              "%.3g %%\n",
              df, tf, nf, da, ta, na, 100.0 * (da - df) / df, 100.0 * (ta - tf) / tf);
  EXPECT_GT(df, 0.0);
  EXPECT_NEAR(da, df, 0.015 * std::abs(df));
  EXPECT_NEAR(ta, tf, 0.015 * tf);
  EXPECT_LT(na, nf / 4);  // the point of the exercise
}

// The adaptive step moves over several ladder values, and the fluid's inertia step is fixed at
// dt_max (IbOptions::inertia_step): the duct's capacitance matrices are factorised once for the
// whole run, not once per step size (a cycle of the paper's 96-cell scene spent 2/3 of its
// first 45 steps in eight factorisations).
TEST(Adaptive3d, TheFluidIsFactorisedOncePerRun) {
  const Scene s = cycle({"full3d.adaptive.enabled=true", "time.duration=\"0.1 s\""});
  const std::string dir = fresh_dir("factorised_once");
  const RunOutcome r = run3d(s.p, s.resolved, dir, quiet());
  ASSERT_FALSE(r.failed) << r.message;
  std::ifstream in(fs::path(dir) / "solver_stats.json");
  const scene::json st = scene::json::parse(in);
  const scene::json& ts = st["time_step"];
  // at least two rungs of the ladder dt_max 2^(-k/4) were used
  EXPECT_GT(ts["dt_max_used_s"].get<double>(), 1.18 * ts["dt_min_used_s"].get<double>());
  EXPECT_EQ(st["stokes_setup"]["factorizations"].get<long>(), 1);
}

// Killed and resumed mid-run (the step-control state is in the checkpoint): the same steps,
// the same result to the last bit.
TEST(Adaptive3d, ResumeEqualsUninterruptedRun) {
  const Scene s = cycle({"full3d.adaptive.enabled=true", "time.duration=\"0.1 s\"", "full3d.checkpoint_interval=\"10 ms\""});
  const std::string a = fresh_dir("resume_a"), b = fresh_dir("resume_b");
  const RunOutcome ra = run3d(s.p, s.resolved, a, quiet());
  ASSERT_FALSE(ra.failed) << ra.message;
  RunControl stop = quiet();
  stop.stop_after_steps = ra.steps / 2;
  ASSERT_TRUE(run3d(s.p, s.resolved, b, stop).interrupted);
  RunControl res = quiet();
  res.resume = true;
  const RunOutcome rc = run3d(s.p, s.resolved, b, res);
  ASSERT_FALSE(rc.failed) << rc.message;
  EXPECT_EQ(rc.steps, ra.steps);
  EXPECT_EQ(rc.summary["t_end_s"].get<double>(), ra.summary["t_end_s"].get<double>());
  EXPECT_DOUBLE_EQ(ra.summary["t_end_s"].get<double>(), 0.1);  // the last step lands on the duration
  EXPECT_EQ(rc.summary["displacement_m"].get<double>(), ra.summary["displacement_m"].get<double>());
}

// A step forced below dt_min ends the run (exit 3) naming the key, and that key is one the
// scene reader accepts.
TEST(Adaptive3d, StepBelowMinimumNamesAnExistingKey) {
  const Scene s = cycle({"full3d.adaptive.enabled=true", "full3d.adaptive.cfl=0.0001",
                         "full3d.adaptive.dt_min=\"0.25 ms\"", "time.duration=\"50 ms\""});
  const RunOutcome r = run3d(s.p, s.resolved, fresh_dir("below_min"), quiet());
  ASSERT_TRUE(r.failed);
  std::printf("%s\n", r.message.c_str());
  EXPECT_NE(r.message.find("full3d.adaptive.dt_min"), std::string::npos);
  EXPECT_NO_THROW(cycle({"full3d.adaptive.enabled=true", "full3d.adaptive.dt_min=\"0.1 ms\""}));
}

TEST(Adaptive3d, SceneKeysAreValidated) {
  EXPECT_THROW(cycle({"full3d.adaptive.enabled=true", "full3d.adaptive.event_dt=\"1 s\""}), InputError);
  EXPECT_THROW(cycle({"full3d.adaptive.enabled=true", "full3d.adaptive.cfl=0.6"}), InputError);  // above max_cfl
  EXPECT_THROW(cycle({"full3d.adaptive.enabled=true", "full3d.dry=true"}), InputError);
  EXPECT_THROW(cycle({"full3d.adaptive.stride=2"}), InputError);  // unknown key
}
