// Checkpoints of the axisymmetric tier: a run stopped part way and resumed from its last
// checkpoint repeats the uninterrupted run bit for bit (the fitted solvers drop their
// factorisations at every checkpoint, as a resumed run's new solvers start without one), and
// a damaged or foreign checkpoint is refused before anything is restored.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "axi/run_axi.hpp"
#include "axi/scene_axi.hpp"
#include "axi_test_support.hpp"
#include "common/errors.hpp"
#include "common/scene.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/run3d_checkpoint.hpp"

namespace {

using swim::scene::json;
using swim::axi::testing::TempDir;

/// The round-wall amplitude scene on the coarsest fitted grid, for part of its cycle.
json short_round_wall(const std::string& duration) {
  json sc = swim::scene::load_file(std::string(SWIM_SOURCE_DIR) + "/data/scenes/paper_amplitude_0.82.json");
  sc["full3d"]["membrane"]["axisymmetric"] = true;
  sc["full3d"]["recovery_end"] = "shape";
  sc["axi"]["method"] = "fitted";
  sc["axi"]["grid"]["cells_across"] = 8;
  sc["axi"]["checkpoint_interval"] = "10 ms";
  sc["time"]["duration"] = duration;
  return sc;
}

swim::axi::RunControlAxi quiet() {
  swim::axi::RunControlAxi c;
  c.progress = 0;
  c.keep_rows = true;
  return c;
}

std::string read_all(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(AxiCheckpoint, AResumedRunRepeatsTheUninterruptedOneBitForBit) {
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(short_round_wall("60 ms"), resolved);
  TempDir a("swim-axi-ckpt-a"), b("swim-axi-ckpt-b");
  const swim::axi::RunOutcomeAxi ra = swim::axi::run_axi(p, resolved, a.path.string(), quiet());
  ASSERT_FALSE(ra.failed) << ra.message;
  ASSERT_GT(ra.steps, 20);
  swim::axi::RunControlAxi stop = quiet();
  stop.stop_after_steps = ra.steps / 2;  // "killed" between two checkpoints
  ASSERT_TRUE(swim::axi::run_axi(p, resolved, b.path.string(), stop).interrupted);
  swim::axi::RunControlAxi res = quiet();
  res.resume = true;
  const swim::axi::RunOutcomeAxi rb = swim::axi::run_axi(p, resolved, b.path.string(), res);
  ASSERT_FALSE(rb.failed) << rb.message;
  EXPECT_EQ(rb.steps, ra.steps);
  EXPECT_EQ(rb.summary["t_end_s"].get<double>(), ra.summary["t_end_s"].get<double>());
  EXPECT_EQ(rb.summary["displacement_m"].get<double>(), ra.summary["displacement_m"].get<double>());
  EXPECT_NE(ra.summary["displacement_m"].get<double>(), 0.0);
  EXPECT_EQ(rb.summary["segment_reached_s"], ra.summary["segment_reached_s"]);
  // the streamed results continue where the checkpoint left them: the same files
  EXPECT_EQ(read_all(b.path / "series.csv"), read_all(a.path / "series.csv"));
  EXPECT_EQ(read_all(b.path / "radius.csv"), read_all(a.path / "radius.csv"));
}

// The same with the triangulation (axi.mesh = triangles) on a deep contraction (R_f = 0.35 R0
// under 0.8 Pa), whose first segment degrades the mesh made on the straight tube: the run makes
// it again on its way (counted in solver_stats.json), the checkpoint keeps the current mesh's
// reference shape, and the resumed run makes the same mesh and repeats the uninterrupted one bit
// for bit. Fails if the mesh a resumed run starts from is not the one the checkpoint was taken on.
TEST(AxiCheckpoint, AResumedRunOnTrianglesRepeatsTheUninterruptedOneBitForBit) {
  json sc = short_round_wall("50 ms");
  sc["axi"]["mesh"] = "triangles";
  sc["wave"]["contracted_ratio"] = 0.35;
  sc["protocol"]["pressure"] = "0.8 Pa";
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(sc, resolved);
  TempDir a("swim-axi-ckpt-tri-a"), b("swim-axi-ckpt-tri-b");
  const swim::axi::RunOutcomeAxi ra = swim::axi::run_axi(p, resolved, a.path.string(), quiet());
  ASSERT_FALSE(ra.failed) << ra.message;
  const json stats = json::parse(read_all(a.path / "solver_stats.json"));
  EXPECT_EQ(stats["mesh"], "triangles");
  EXPECT_GT(stats["remeshes"].get<long>(), 0);
  std::printf("  %ld steps, %ld triangulations made after the first\n", ra.steps, stats["remeshes"].get<long>());
  swim::axi::RunControlAxi stop = quiet();
  stop.stop_after_steps = ra.steps * 3 / 4;
  ASSERT_TRUE(swim::axi::run_axi(p, resolved, b.path.string(), stop).interrupted);
  {  // the checkpoint resumed from holds a mesh made on a contracted shape, not on the straight tube
    const swim::full3d::CheckpointReader r = swim::full3d::CheckpointReader(
        (b.path / "checkpoint.bin").string(), swim::full3d::RunCheckpoint::scene_hash(resolved));
    const std::vector<double> ref = r.get_vector("mesh_reference");
    double deepest = p.base.R0;
    for (std::size_t k = 1; k < ref.size(); k += 3) deepest = std::min(deepest, ref[k]);
    EXPECT_LT(deepest, 0.9 * p.base.R0);
  }
  swim::axi::RunControlAxi res = quiet();
  res.resume = true;
  const swim::axi::RunOutcomeAxi rb = swim::axi::run_axi(p, resolved, b.path.string(), res);
  ASSERT_FALSE(rb.failed) << rb.message;
  EXPECT_EQ(rb.steps, ra.steps);
  EXPECT_EQ(rb.summary["displacement_m"].get<double>(), ra.summary["displacement_m"].get<double>());
  EXPECT_EQ(read_all(b.path / "series.csv"), read_all(a.path / "series.csv"));
  EXPECT_EQ(read_all(b.path / "radius.csv"), read_all(a.path / "radius.csv"));
  const json stats_b = json::parse(read_all(b.path / "solver_stats.json"));
  EXPECT_EQ(stats_b["remeshes"], stats["remeshes"]);
  EXPECT_EQ(stats_b["remesh_times_s"], stats["remesh_times_s"]);
}

// The scheduled remeshes (axi.remesh_interval, 10 ms by default on triangles) are made at the
// multiples of the interval whatever the step tolerance, so the shapes the meshes are made on move
// with the tolerance only by the time integration's error, and the figures converge with it. On
// the deep contraction above, at the default tolerance and at a quarter of it: the same remesh
// times, every one a multiple of 10 ms, and the displacement within 1 % (its time error); with
// the remeshes made whenever the mesh degrades (interval 0), the mesh is made again on other
// shapes and at times off that clock.
TEST(AxiCheckpoint, ScheduledRemeshesDoNotMoveWithTheStepTolerance) {
  json sc = short_round_wall("50 ms");
  sc["axi"]["mesh"] = "triangles";
  sc["wave"]["contracted_ratio"] = 0.35;
  sc["protocol"]["pressure"] = "0.8 Pa";
  auto run = [&](double tolerance_factor, const char* interval, const std::string& tag) {
    json s = sc;
    json resolved;
    swim::axi::ParamsAxi p = swim::axi::read_scene_axi(s, resolved);
    s["axi"]["tolerance"] = p.tolerance * tolerance_factor;
    if (interval) s["axi"]["remesh_interval"] = interval;
    p = swim::axi::read_scene_axi(s, resolved);
    TempDir d("swim-axi-remesh-" + tag);
    const swim::axi::RunOutcomeAxi r = swim::axi::run_axi(p, resolved, d.path.string(), quiet());
    EXPECT_FALSE(r.failed) << r.message;
    const json st = json::parse(read_all(d.path / "solver_stats.json"));
    return std::pair{st["remesh_times_s"].get<std::vector<double>>(), r.summary["displacement_m"].get<double>()};
  };
  const auto [times, x] = run(1.0, nullptr, "a");
  const auto [times_fine, x_fine] = run(0.25, nullptr, "b");
  ASSERT_FALSE(times.empty());
  EXPECT_EQ(times, times_fine);
  for (const double t : times) EXPECT_NEAR(t / 0.01, std::round(t / 0.01), 1e-6) << t;
  EXPECT_NEAR(x_fine, x, 0.01 * std::abs(x));
  const auto [times_any, x_any] = run(1.0, "0 s", "c");
  ASSERT_FALSE(times_any.empty());
  long off_clock = 0;
  for (const double t : times_any) off_clock += std::abs(t / 0.01 - std::round(t / 0.01)) > 1e-6;
  EXPECT_GT(off_clock, 0);
  std::printf("  scheduled: %zu remeshes, displacement %.6g / %.6g nm; whenever degraded: %zu remeshes, %ld off the "
              "10 ms clock, %.6g nm\n",
              times.size(), 1e9 * x, 1e9 * x_fine, times_any.size(), off_clock, 1e9 * x_any);
}

TEST(AxiCheckpoint, ADamagedOrForeignCheckpointIsRefusedNamingResume) {
  json resolved;
  const swim::axi::ParamsAxi p = swim::axi::read_scene_axi(short_round_wall("30 ms"), resolved);
  TempDir a("swim-axi-ckpt-bad");
  swim::axi::RunControlAxi stop = quiet();
  stop.stop_after_steps = 15;
  ASSERT_TRUE(swim::axi::run_axi(p, resolved, a.path.string(), stop).interrupted);
  EXPECT_NO_THROW(swim::axi::check_resumable_axi(p, resolved, a.path.string()));
  // another scene (another load): refused by the scene hash
  json other = short_round_wall("30 ms"), other_resolved;
  other["protocol"]["pressure"] = "0.4 Pa";
  const swim::axi::ParamsAxi q = swim::axi::read_scene_axi(other, other_resolved);
  try {
    swim::axi::check_resumable_axi(q, other_resolved, a.path.string());
    ADD_FAILURE() << "a checkpoint of another scene was accepted";
  } catch (const swim::InputError& e) {
    EXPECT_EQ(e.key(), "--resume");
  }
  // one changed byte in the payload: refused by the checksum
  const auto ck = a.path / "checkpoint.bin";
  std::string bytes = read_all(ck);
  bytes[bytes.size() / 2] ^= 0x20;
  std::ofstream(ck, std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_THROW(swim::axi::check_resumable_axi(p, resolved, a.path.string()), swim::InputError);
}
