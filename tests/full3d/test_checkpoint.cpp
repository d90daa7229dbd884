// Checkpoint integrity (full3d/checkpoint.hpp, full3d/run3d_checkpoint.hpp): the file
// format refuses truncated, changed and foreign files; a failed write keeps the previous
// checkpoint; on a real run, damaged values (positions, time, step count) and a
// checkpoint of another scene are refused as bad input naming the file and the remedy,
// before anything is restored.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/checksum.hpp"
#include "common/errors.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/run3d.hpp"
#include "run3d_scenes.hpp"

using namespace swim;
using namespace swim::full3d;
namespace fs = std::filesystem;

namespace {

// header: magic 8, version 4 bytes, scene hash 8, payload bytes 8, payload checksum 8
constexpr std::size_t kSumAt = 28, kPayloadAt = 36;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
void spit(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
}

/// File offset of the value of record `name` (after the count of a text or array record).
std::size_t value_at(const std::string& all, const std::string& name) {
  std::size_t pos = kPayloadAt;
  while (pos + 5 <= all.size() - 4) {
    const char kind = all[pos];
    std::uint32_t len;
    std::memcpy(&len, all.data() + pos + 1, 4);
    const std::string got = all.substr(pos + 5, len);
    pos += 5 + len;
    std::uint64_t n = 1;
    if (kind == 's' || kind == 'a') {
      std::memcpy(&n, all.data() + pos, 8);
      pos += 8;
    }
    if (got == name) return pos;
    pos += kind == 's' ? n : 8 * n;
  }
  ADD_FAILURE() << "no record " << name;
  return 0;
}

/// Recomputes the payload checksum: a file with the given values that only the value checks can catch.
void reseal(std::string& all) {
  const std::uint64_t sum = fnv1a64(all.data() + kPayloadAt, all.size() - kPayloadAt - 4);
  std::memcpy(all.data() + kSumAt, &sum, 8);
}

template <class T>
void patch(std::string& all, const std::string& name, T v) {
  std::memcpy(all.data() + value_at(all, name), &v, sizeof v);
  reseal(all);
}

/// The message of the InputError thrown by f, "" when none.
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "--resume");
    return e.what();
  }
  return "";
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string fresh(const std::string& name) { return run3d_test::fresh_dir("out_checkpoint", name); }

CheckpointWriter sample(std::uint64_t hash) {
  CheckpointWriter w(hash);
  w.put("t", 0.25);
  w.put("step", std::int64_t(250));
  w.put("name", std::string("tiny"));
  w.put("X", std::vector<double>{1.0, 2.0, 3.0, 4.0, 5.0, 6.0});
  w.put("empty", std::vector<double>{});
  return w;
}

}  // namespace

TEST(CheckpointFile, RecordsAreReadBackByName) {
  const std::string d = fresh("format_roundtrip"), path = d + "/checkpoint.bin";
  sample(42).save(path);
  const CheckpointReader r(path, 42);
  EXPECT_EQ(r.get_vector("X"), (std::vector<double>{1, 2, 3, 4, 5, 6}));  // any order
  EXPECT_EQ(r.get_int("step"), 250);
  EXPECT_EQ(r.get_double("t"), 0.25);
  EXPECT_EQ(r.get_string("name"), "tiny");
  EXPECT_TRUE(r.get_vector("empty").empty());
  EXPECT_EQ(r.first_non_finite(), "");
  EXPECT_TRUE(has(refusal([&] { r.get_double("missing"); }), "no record 'missing'"));
  EXPECT_TRUE(has(refusal([&] { r.get_int("t"); }), "record 't' is a number, expected an integer"));
  double three[3];
  EXPECT_TRUE(has(refusal([&] { r.get_into("X", three, 3); }), "different grid or mesh"));
}

TEST(CheckpointFile, AnyChangedByteIsRefused) {
  const std::string d = fresh("format_flip"), path = d + "/checkpoint.bin";
  sample(42).save(path);
  const std::string good = slurp(path);
  for (std::size_t at = 0; at < good.size(); ++at) {
    std::string bad = good;
    bad[at] = char(bad[at] ^ 0x10);
    spit(path, bad);
    const std::string m = refusal([&] { CheckpointReader(path, 42); });
    EXPECT_TRUE(has(m, path)) << "byte " << at << ": " << m;
    EXPECT_TRUE(has(m, "--overwrite") || has(m, "different scene")) << "byte " << at << ": " << m;
  }
  std::string bad = good;
  bad[value_at(good, "X") + 3] ^= 0x01;  // a low bit of a position
  spit(path, bad);
  EXPECT_TRUE(has(refusal([&] { CheckpointReader(path, 42); }), "checksum does not match"));
}

TEST(CheckpointFile, TruncatedFileIsRefused) {
  const std::string d = fresh("format_truncated"), path = d + "/checkpoint.bin";
  sample(42).save(path);
  const std::string good = slurp(path);
  for (std::size_t n : {std::size_t(0), std::size_t(7), kPayloadAt, good.size() / 2, good.size() - 4, good.size() - 1}) {
    spit(path, good.substr(0, n));
    const std::string m = refusal([&] { CheckpointReader(path, 42); });
    EXPECT_TRUE(has(m, "truncated")) << n << " bytes: " << m;
  }
}

TEST(CheckpointFile, AnotherScenesCheckpointIsRefused) {
  const std::string d = fresh("format_scene"), path = d + "/checkpoint.bin";
  sample(42).save(path);
  EXPECT_TRUE(has(refusal([&] { CheckpointReader(path, 43); }), "written for a different scene"));
}

// A failed write (a directory where the temporary file goes, an injected full disk) is an
// OutputError naming checkpoint.bin, and the previous checkpoint stays as it was.
TEST(CheckpointFile, AFailedWriteKeepsThePreviousCheckpoint) {
  const std::string d = fresh("format_write_failure"), path = d + "/checkpoint.bin";
  sample(42).save(path);
  const std::string before = slurp(path);
  CheckpointWriter next(42);
  next.put("t", 0.5);
  const fs::path tmp = fs::path(d) / (".checkpoint.bin.tmp-" + std::to_string(::getpid()));
  fs::create_directory(tmp);
  try {
    next.save(path);
    ADD_FAILURE() << "no error";
  } catch (const OutputError& e) {
    EXPECT_EQ(e.file(), "checkpoint.bin") << e.what();
  }
  fs::remove(tmp);
  EXPECT_EQ(slurp(path), before);
  ::setenv("SWIM_TEST_FAIL_WRITE", "checkpoint.bin:20", 1);
  try {
    next.save(path);
    ADD_FAILURE() << "no error";
  } catch (const OutputError& e) {
    EXPECT_TRUE(has(e.what(), "disk full while writing checkpoint.bin")) << e.what();
  }
  ::unsetenv("SWIM_TEST_FAIL_WRITE");
  EXPECT_EQ(slurp(path), before);
  for (const auto& e : fs::directory_iterator(d)) EXPECT_EQ(e.path().filename(), "checkpoint.bin");  // no temporaries
  next.save(path);
  EXPECT_EQ(CheckpointReader(path, 42).get_double("t"), 0.5);
}

// ---- on a real run --------------------------------------------------------------------

namespace {

// 1 ms steps, a checkpoint every 2 ms; "killed" after 3 steps: the checkpoint is at step 2.
run3d_test::Scene short_run(const std::string& dt = "1 ms") {
  return run3d_test::shipped_scene("tiny_3d.json", {"full3d.dt=\"" + dt + "\"", "time.duration=\"6 ms\"",
                                                    "full3d.checkpoint_interval=\"2 ms\""});
}

std::string interrupted_run(const std::string& name, const run3d_test::Scene& s) {
  const std::string d = fresh(name);
  RunControl stop = run3d_test::quiet_control();
  stop.stop_after_steps = 3;
  EXPECT_TRUE(run3d(s.p, s.resolved, d, stop).interrupted);
  return d;
}

}  // namespace

TEST(Checkpoint3d, DamagedOrForeignCheckpointsAreRefusedNamingTheFile) {
  const run3d_test::Scene s = short_run();
  const std::string d = interrupted_run("refused", s), path = checkpoint_path(d);
  const std::string good = slurp(path);
  auto refused = [&](const std::string& bytes, const std::string& expect, const char* what) {
    spit(path, bytes);
    const std::string m = refusal([&] { check_resumable(s.p, s.resolved, d); });
    std::printf("%s:\n  %s\n", what, m.c_str());
    EXPECT_TRUE(has(m, path)) << m;
    EXPECT_TRUE(has(m, expect)) << m;
    EXPECT_TRUE(has(m, "--overwrite") || has(m, "--resume")) << m;
    RunControl res = run3d_test::quiet_control();
    res.resume = true;
    EXPECT_THROW(run3d(s.p, s.resolved, d, res), InputError) << what;
  };
  EXPECT_NO_THROW(check_resumable(s.p, s.resolved, d));
  {  // a flipped byte in the node positions: the checksum
    std::string bad = good;
    bad[value_at(good, "X") + 8 * 100 + 7] ^= 0x40;
    refused(bad, "checksum does not match", "flipped byte in the positions");
    reseal(bad);  // the same damage behind a valid checksum: the position check
    refused(bad, "outside the container", "flipped byte in the positions, checksum recomputed");
  }
  {
    std::string bad = good;
    patch(bad, "t", std::numeric_limits<double>::quiet_NaN());
    refused(bad, "not a finite number", "NaN time");
  }
  {
    std::string bad = good;
    patch(bad, "t", -1.0);
    refused(bad, "negative", "negative time");
  }
  {
    std::string bad = good;
    patch(bad, "t", 1.0);
    refused(bad, "beyond the end of this run", "time beyond the end");
  }
  {
    std::string bad = good;
    patch(bad, "step", std::int64_t(-3));
    refused(bad, "step count", "negative step count");
    patch(bad, "step", std::int64_t(5));
    refused(bad, "does not match its time", "step count inconsistent with the time");
  }
  {
    std::string bad = good;
    patch(bad, "V", std::numeric_limits<double>::infinity());
    refused(bad, "record 'V' holds a NaN or infinite value", "infinite velocity");
  }
  refused(good.substr(0, good.size() / 3), "truncated", "truncated file");
  {  // another scene (another time step) may not continue this run
    spit(path, good);
    const run3d_test::Scene other = short_run("0.5 ms");
    const std::string m = refusal([&] { check_resumable(other.p, other.resolved, d); });
    EXPECT_TRUE(has(m, "different scene")) << m;
  }
  // the intact checkpoint still resumes
  spit(path, good);
  RunControl res = run3d_test::quiet_control();
  res.resume = true;
  const RunOutcome r = run3d(s.p, s.resolved, d, res);
  EXPECT_FALSE(r.failed) << r.message;
  EXPECT_EQ(r.steps, 6);
}

// A checkpoint that cannot be written ends the run with an OutputError naming
// checkpoint.bin; the previous checkpoint is intact and the run resumes from it.
TEST(Checkpoint3d, AFailedCheckpointWriteKeepsThePreviousCheckpoint) {
  const run3d_test::Scene s = short_run();
  const std::string d = interrupted_run("write_failure", s), path = checkpoint_path(d);
  const std::string before = slurp(path);
  const fs::path tmp = fs::path(d) / (".checkpoint.bin.tmp-" + std::to_string(::getpid()));
  fs::create_directory(tmp);
  RunControl res = run3d_test::quiet_control();
  res.resume = true;
  try {
    run3d(s.p, s.resolved, d, res);
    ADD_FAILURE() << "the checkpoint write did not fail";
  } catch (const OutputError& e) {
    EXPECT_EQ(e.file(), "checkpoint.bin") << e.what();
  }
  fs::remove(tmp);
  EXPECT_EQ(slurp(path), before);
  output::reset_ledger(d);  // as a new run's RunFolder does (the ledger holds the failure)
  const RunOutcome r = run3d(s.p, s.resolved, d, res);
  EXPECT_FALSE(r.failed) << r.message;
  EXPECT_EQ(r.steps, 6);
}
