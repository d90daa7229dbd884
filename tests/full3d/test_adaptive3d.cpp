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

// The run of s in dir stopped after `steps` steps and resumed to its end.
RunOutcome stopped_and_resumed(const Scene& s, const std::string& dir, long steps) {
  RunControl stop = quiet();
  stop.stop_after_steps = steps;
  EXPECT_TRUE(run3d(s.p, s.resolved, dir, stop).interrupted);
  RunControl res = quiet();
  res.resume = true;
  return run3d(s.p, s.resolved, dir, res);
}

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
  const RunOutcome rc = stopped_and_resumed(s, b, ra.steps / 2);
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
  // Chebyshev stages: chosen by the adaptive step, not with the lagged node inertia, and the
  // stage bound only with that scheme
  EXPECT_THROW(cycle({"full3d.scheme=\"chebyshev\""}), InputError);
  EXPECT_THROW(cycle({"full3d.adaptive.enabled=true", "full3d.scheme=\"chebyshev\"", "full3d.wall_inertia=true"}),
               InputError);
  EXPECT_THROW(cycle({"full3d.adaptive.enabled=true", "full3d.adaptive.max_stages=4"}), InputError);
  EXPECT_THROW(cycle({"full3d.adaptive.enabled=true", "full3d.scheme=\"chebyshev\"", "full3d.adaptive.max_stages=0"}),
               InputError);
  EXPECT_NO_THROW(
      cycle({"full3d.adaptive.enabled=true", "full3d.scheme=\"chebyshev\"", "full3d.adaptive.max_stages=4"}));
}

// Chebyshev stages (full3d.scheme = chebyshev, docs/full3d.md "Chebyshev stages") on the tiny
// cycle at h = 20 nm with a loose tolerance, where forward Euler spends most steps on its
// stability bound: the stages take fewer fluid solves for the same accuracy. Measured: 177
// against 225 solves; displacement 4.536 against 4.540 nm (forward Euler at the default
// tolerance: 4.609 nm), cycle 0.691 against 0.689 s (0.708 s).
TEST(Adaptive3d, ChebyshevStagesTakeFewerFluidSolvesWhereStabilityBinds) {
  const std::vector<std::string> fine = {"full3d.adaptive.enabled=true", "full3d.grid.cell_size=\"0.02 um\""};
  auto with = [&](std::vector<std::string> more) {
    more.insert(more.begin(), fine.begin(), fine.end());
    return cycle(more);
  };
  struct Result {
    double d, t;
    long solves;
    int stages;
    long stability;
  };
  auto run = [&](const Scene& s, const std::string& name) {
    const std::string dir = fresh_dir(name);
    const RunOutcome r = run3d(s.p, s.resolved, dir, quiet());
    EXPECT_FALSE(r.failed) << r.message;
    std::ifstream in(fs::path(dir) / "solver_stats.json");
    const scene::json ts = scene::json::parse(in)["time_step"];
    return Result{r.summary["displacement_m"].get<double>(), r.summary["cycle_times_s"][0].get<double>(),
                  ts["fluid_solves_this_process"].get<long>(), ts["stages_max_used"].get<int>(),
                  ts["steps_by_bound"]["stability"].get<long>()};
  };
  const Result ref = run(with({}), "cheb_reference");
  const Result fe = run(with({"full3d.adaptive.tolerance=0.02"}), "cheb_fe");
  const Result ch = run(with({"full3d.adaptive.tolerance=0.02", "full3d.scheme=\"chebyshev\""}), "cheb");
  std::printf("tolerance 1e-3, forward Euler: %.5g m, %.5g s, %ld solves\n", ref.d, ref.t, ref.solves);
  std::printf("tolerance 2e-2, forward Euler: %.5g m, %.5g s, %ld solves (%ld stability-bound steps)\n", fe.d, fe.t,
              fe.solves, fe.stability);
  std::printf("tolerance 2e-2, Chebyshev: %.5g m, %.5g s, %ld solves, up to %d stages\n", ch.d, ch.t, ch.solves,
              ch.stages);
  EXPECT_GT(fe.stability, fe.solves / 3) << "the case must be stability-bound for forward Euler";
  EXPECT_EQ(fe.stages, 1);
  EXPECT_GE(ch.stages, 2);
  EXPECT_LT(ch.solves, 0.85 * fe.solves);
  // the same accuracy: within the loose tolerance's own error of the tight run
  EXPECT_NEAR(ch.d, ref.d, 0.03 * ref.d);
  EXPECT_NEAR(ch.t, ref.t, 0.04 * ref.t);
  EXPECT_LT(std::abs(ch.d - fe.d), 0.01 * fe.d);
}

// With at most one stage the Chebyshev run is the forward-Euler run, to the bit.
TEST(Adaptive3d, OneChebyshevStageIsForwardEuler) {
  const std::vector<std::string> base = {"full3d.adaptive.enabled=true", "full3d.grid.cell_size=\"0.02 um\"",
                                         "time.duration=\"40 ms\""};
  std::vector<std::string> ch = base;
  ch.push_back("full3d.scheme=\"chebyshev\"");
  ch.push_back("full3d.adaptive.max_stages=1");
  const Scene a = cycle(base), b = cycle(ch);
  const RunOutcome ra = run3d(a.p, a.resolved, fresh_dir("one_stage_fe"), quiet());
  const RunOutcome rb = run3d(b.p, b.resolved, fresh_dir("one_stage_cheb"), quiet());
  ASSERT_FALSE(ra.failed) << ra.message;
  ASSERT_FALSE(rb.failed) << rb.message;
  EXPECT_EQ(ra.steps, rb.steps);
  EXPECT_EQ(ra.summary["displacement_m"].get<double>(), rb.summary["displacement_m"].get<double>());
}

// A Chebyshev run killed and resumed: the stage counts follow from the checkpointed step and
// rate estimate, so the resumed run repeats the uninterrupted one to the last bit.
TEST(Adaptive3d, ChebyshevResumeEqualsUninterruptedRun) {
  const Scene s = cycle({"full3d.adaptive.enabled=true", "full3d.grid.cell_size=\"0.02 um\"",
                         "full3d.adaptive.tolerance=0.02", "full3d.scheme=\"chebyshev\"", "time.duration=\"0.3 s\"",
                         "full3d.checkpoint_interval=\"20 ms\""});
  const std::string a = fresh_dir("cheb_resume_a"), b = fresh_dir("cheb_resume_b");
  const RunOutcome ra = run3d(s.p, s.resolved, a, quiet());
  ASSERT_FALSE(ra.failed) << ra.message;
  std::ifstream in(fs::path(a) / "solver_stats.json");
  ASSERT_GE(scene::json::parse(in)["time_step"]["stages_max_used"].get<int>(), 2) << "the run must use the stages";
  const RunOutcome rc = stopped_and_resumed(s, b, ra.steps / 2);
  ASSERT_FALSE(rc.failed) << rc.message;
  EXPECT_EQ(rc.steps, ra.steps);
  EXPECT_EQ(rc.summary["displacement_m"].get<double>(), ra.summary["displacement_m"].get<double>());
}

// The stabilised wall step (full3d.wall_stabilization = bending, docs/full3d.md "The stabilised
// wall step") on the tiny cycle at h = 20 nm: the keys are validated, the run follows the
// forward-Euler run (the same displacement and cycle time within 2 %: the stabilisation changes
// a mode's motion by dt sigma, small on the modes this wall moves in), and a run killed and
// resumed repeats the uninterrupted one to the last bit (the model's decomposition depends on
// the mesh alone, and the rate estimates follow from the checkpointed state).
TEST(Adaptive3d, StabilisedWallStepFollowsForwardEulerAndResumesExactly) {
  EXPECT_THROW(cycle({"full3d.adaptive.enabled=true", "full3d.scheme=\"midpoint\"", "full3d.wall_stabilization=\"bending\""}),
               InputError);
  EXPECT_THROW(cycle({"full3d.wall_stabilization=\"elastic\""}), InputError);
  EXPECT_THROW(cycle({"full3d.memory_limit_gib=0"}), InputError);
  EXPECT_THROW(cycle({"full3d.wall_stabilization=\"bending\"", "full3d.stabilization_factor=0"}), InputError);
  const std::vector<std::string> base = {"full3d.adaptive.enabled=true", "full3d.grid.cell_size=\"0.02 um\"",
                                         "full3d.checkpoint_interval=\"20 ms\""};
  std::vector<std::string> stab = base;
  stab.push_back("full3d.wall_stabilization=\"bending\"");
  const Scene fe = cycle(base), st = cycle(stab);
  const std::string a = fresh_dir("stab_a"), b = fresh_dir("stab_b");
  const RunOutcome rf = run3d(fe.p, fe.resolved, fresh_dir("stab_fe"), quiet());
  const RunOutcome rs = run3d(st.p, st.resolved, a, quiet());
  ASSERT_FALSE(rf.failed) << rf.message;
  ASSERT_FALSE(rs.failed) << rs.message;
  const double df = rf.summary["displacement_m"].get<double>(), ds = rs.summary["displacement_m"].get<double>();
  const double tf = rf.summary["cycle_times_s"][0].get<double>(), ts = rs.summary["cycle_times_s"][0].get<double>();
  std::printf("forward Euler %.5g m, %.5g s, %ld steps; stabilised %.5g m, %.5g s, %ld steps\n", df, tf, rf.steps, ds,
              ts, rs.steps);
  EXPECT_NEAR(ds, df, 0.02 * df);
  EXPECT_NEAR(ts, tf, 0.02 * tf);
  const RunOutcome rc = stopped_and_resumed(st, b, rs.steps / 2);
  ASSERT_FALSE(rc.failed) << rc.message;
  EXPECT_EQ(rc.steps, rs.steps);
  EXPECT_EQ(rc.summary["displacement_m"].get<double>(), ds);
}
