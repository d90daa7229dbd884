// The output samples of a force-driven run on a second thread (numerics1d.threads = 2): the
// pipe that carries them keeps their order, stops at a failed one and hands the consumer's
// exception back; a run with the second thread gives the same result bit for bit as one
// without it, on every path of the event loop (IDA and CVODE, the confined and the unbounded
// outer flow, the junction and the axial bending, several cycles, a run stopped midway).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "common/run_record.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/sample_pipe.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"

using namespace swim::reduced1d;
using swim::reduced1d::detail::SamplePipe;
using json = swim::scene::json;

TEST(SamplePipe, DeliversEveryRecordInOrderThroughAFullRing) {
  // Two slots for 5 000 records: the producer waits for the consumer most of the time.
  std::vector<double> seen;
  {
    SamplePipe pipe(3, [&](const double* r) {
      seen.push_back(r[0]);
      EXPECT_EQ(r[1], 2.0 * r[0]);
      EXPECT_EQ(r[2], -r[0]);
      return true;
    }, 2);
    for (int k = 0; k < 5000; ++k) {
      double* r = pipe.slot();
      r[0] = k, r[1] = 2.0 * k, r[2] = -k;
      pipe.commit();
      if (k == 2500) {
        pipe.drain();
        EXPECT_EQ(seen.size(), 2501u);
      }
    }
    pipe.drain();
    EXPECT_FALSE(pipe.failed());
  }
  ASSERT_EQ(seen.size(), 5000u);
  for (int k = 0; k < 5000; ++k) ASSERT_EQ(seen[k], double(k)) << k;
}

TEST(SamplePipe, AFailedRecordStopsTheRestAndAnExceptionReachesTheProducer) {
  std::vector<double> seen;
  SamplePipe pipe(1, [&](const double* r) {
    seen.push_back(r[0]);
    return r[0] != 7.0;
  });
  for (int k = 0; k < 20; ++k) {
    *pipe.slot() = k;
    pipe.commit();
  }
  pipe.drain();
  EXPECT_TRUE(pipe.failed());
  EXPECT_EQ(seen.size(), 8u);  // 0 ... 7; 8 ... 19 skipped

  SamplePipe throwing(1, [](const double* r) -> bool {
    if (r[0] == 3.0) throw std::runtime_error("sample 3");
    return true;
  });
  for (int k = 0; k < 10; ++k) {
    *throwing.slot() = k;
    throwing.commit();
  }
  try {
    throwing.drain();
    ADD_FAILURE() << "drain() did not rethrow the consumer's exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "sample 3");
  }
  EXPECT_TRUE(throwing.failed());
}

namespace {

Result run(json scene, int threads) {
  scene["numerics1d"]["threads"] = threads;
  json resolved;
  const Params p = read_scene(scene, resolved);
  EXPECT_EQ(p.numerics.threads, threads);
  return solve(p);
}

// Every figure of the two results, bit for bit.
void expect_identical(const Result& a, const Result& b, const std::string& what) {
  ASSERT_EQ(a.series.size(), b.series.size()) << what;
  EXPECT_GT(a.series.size(), 10u) << what;
  for (std::size_t k = 0; k < a.series.size(); ++k) {
    const std::vector<double> ra = series_row(a.series[k]), rb = series_row(b.series[k]);
    ASSERT_EQ(0, std::memcmp(ra.data(), rb.data(), ra.size() * sizeof(double))) << what << ": sample " << k;
  }
  EXPECT_EQ(a.radius, b.radius) << what;
  EXPECT_EQ(a.radius_times, b.radius_times) << what;
  EXPECT_EQ(a.cycle_start, b.cycle_start) << what;
  EXPECT_EQ(a.cycle_end, b.cycle_end) << what;
  EXPECT_EQ(a.switches, b.switches) << what;
  EXPECT_EQ(a.stats, b.stats) << what;  // the integration itself is the same
  EXPECT_EQ(a.record.series.rows(), b.record.series.rows()) << what;
  ASSERT_EQ(bool(a.failure), bool(b.failure)) << what;
  if (a.failure) {
    EXPECT_STREQ(a.failure->what(), b.failure->what()) << what;
    EXPECT_EQ(a.failure->time(), b.failure->time()) << what;
  }
}

}  // namespace

TEST(SampleThread, GivesTheSameRunBitForBitOnEveryPath) {
  const std::vector<std::pair<std::string, json>> scenes = {
      {"default (IDA, short-wave traction, confined)", json::object()},
      {"lubrication-only wall (CVODE, one unknown per cell)", {{"model1d", {{"short_wave_traction", false}}}}},
      {"unbounded outer flow (velocity quadrature)", {{"model1d", {{"outer_flow", "unbounded"}}}}},
      {"calibrated junction", {{"model1d", {{"end_effects", "junction"}}}}},
      {"axial bending (curvature unknowns)",
       {{"model1d", {{"axial_bending", {{"source", "scene"}, {"rigidity", "5e-25 J"}}}}}}},
      {"two cycles", {{"protocol", {{"cycles", 2}}}}},
  };
  for (const auto& [what, scene] : scenes) {
    const Result one = run(scene, 1), two = run(scene, 2);
    EXPECT_FALSE(one.failure) << what << ": " << (one.failure ? one.failure->what() : "");
    EXPECT_FALSE(one.cycle_end.empty()) << what;
    expect_identical(one, two, what);
  }
}

TEST(SampleThread, KeepsTheSamplesAndTheFailureOfARunStoppedMidway) {
  // The step budget runs out in the first contraction: the samples up to there and the same
  // failure, at the same time.
  const json scene = {{"numerics1d", {{"max_steps", 150}}}};
  const Result one = run(scene, 1), two = run(scene, 2);
  ASSERT_TRUE(one.failure);
  EXPECT_NE(std::string(one.failure->what()).find("numerics1d.max_steps"), std::string::npos) << one.failure->what();
  EXPECT_GT(one.failure->time(), 0.0);
  expect_identical(one, two, "stopped by the step budget");
}

TEST(SampleThread, ThreadsOtherThanOneOrTwoAreRefusedNamingTheKey) {
  for (const json& v : {json(0), json(3), json("two")}) {
    json resolved;
    try {
      read_scene(json{{"numerics1d", {{"threads", v}}}}, resolved);
      ADD_FAILURE() << "numerics1d.threads = " << v.dump() << " was accepted";
    } catch (const swim::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("numerics1d.threads"), std::string::npos) << e.what();
    }
  }
}

// A sample that fails just before a protocol switch: one thread stops there; two threads have
// gone through the switch (its events, the machine's state, the restart) while the sample was
// on the second, and take the switch back. Both give the same samples, events, segment times and
// failure (fault injected by detail::Output::reject_sample, at the last sample before the
// second switch; then at the cycle's end, where the switch also ends the cycle).
TEST(SampleThread, AFailedSampleBeforeASwitchStopsTheRunThere) {
  json sc = json::object();
  json resolved;
  Params p = read_scene(sc, resolved);
  p.numerics.threads = 1;
  const Result plain = solve(p);
  ASSERT_FALSE(plain.failure);
  ASSERT_GE(plain.segment_reached.size(), 3u);
  // the segments are reached from the last to the first: the second switch is the one before last
  std::vector<double> reached = plain.segment_reached;
  std::sort(reached.begin(), reached.end());
  const double second_switch = reached[1];
  const double cycle_end = plain.cycle_end.at(0);
  for (const double at : {second_switch, cycle_end}) {
    double last = -1;  // the last sample strictly before the switch
    for (const auto& smp : plain.series)
      if (smp.t < at) last = smp.t;
    ASSERT_GT(last, 0.0);
    Result r[2];
    for (int threads : {1, 2}) {
      p.numerics.threads = threads;
      detail::Output out;
      out.reject_sample = [last](double t) { return t == last; };
      r[threads - 1] = detail::solve_force_driven(p, out);
    }
    const Result &one = r[0], &two = r[1];
    ASSERT_TRUE(one.failure) << at;
    EXPECT_NE(std::string(one.failure->what()).find("non-finite state"), std::string::npos) << one.failure->what();
    EXPECT_EQ(one.failure->time(), last);
    ASSERT_TRUE(two.failure) << at;
    EXPECT_STREQ(one.failure->what(), two.failure->what());
    ASSERT_EQ(one.series.size(), two.series.size()) << at;
    EXPECT_EQ(one.series.back().t, two.series.back().t);
    EXPECT_LT(one.series.back().t, last);
    EXPECT_EQ(one.radius, two.radius) << at;
    EXPECT_EQ(one.cycle_start, two.cycle_start) << at;
    EXPECT_EQ(one.cycle_end, two.cycle_end) << at;
    EXPECT_TRUE(one.cycle_end.empty()) << at;
    EXPECT_EQ(one.switches, two.switches) << at;
    EXPECT_EQ(one.segment_reached, two.segment_reached) << at;
  }
}

// The output limit is checked as the second thread writes the rows: the run stops at the same
// row with the same failure as on one thread (the limit's, not a non-finite state), and a
// switch made meanwhile is taken back (a limit that falls after the first switch).
TEST(SampleThread, TheOutputLimitStopsTheRunAtTheSameRow) {
  json sc = json::object();
  json resolved;
  Params p = read_scene(sc, resolved);
  for (const std::uintmax_t limit : {30000u, 1500000u}) {
    Result r[2];
    for (int threads : {1, 2}) {
      p.numerics.threads = threads;
      const std::string dir = testing::TempDir() + "/sample_thread_limit_" + std::to_string(threads);
      std::filesystem::remove_all(dir);
      std::filesystem::create_directories(dir);
      swim::record::RunStream stream(dir, series_columns());
      stream.limit(limit);
      SolveOptions so;
      so.stream = &stream;
      r[threads - 1] = solve(p, so);
      std::filesystem::remove_all(dir);
    }
    const Result &one = r[0], &two = r[1];
    ASSERT_TRUE(one.failure) << limit;
    EXPECT_NE(std::string(one.failure->what()).find("output.max_bytes"), std::string::npos) << one.failure->what();
    ASSERT_TRUE(two.failure) << limit;
    EXPECT_STREQ(one.failure->what(), two.failure->what()) << limit;
    EXPECT_EQ(one.failure->time(), two.failure->time()) << limit;
    EXPECT_EQ(one.series.size(), two.series.size()) << limit;
    EXPECT_EQ(one.cycle_start, two.cycle_start) << limit;
    EXPECT_EQ(one.switches, two.switches) << limit;
    EXPECT_EQ(one.segment_reached, two.segment_reached) << limit;
    if (limit > 100000u) {
      EXPECT_GT(one.switches, 0) << "the larger limit falls after a switch";
    }
  }
}
