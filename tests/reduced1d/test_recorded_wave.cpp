// A prescribed wave replayed from a recorded radius.csv (wave.kind = "recorded",
// wave.radius_file; docs/scenes.md, reduced1d/recorded_wave.hpp): the replay of a 1D sine run's
// own record reproduces the run, a mirrored record swims the other way, a time-reversed record
// swims back by the same distance and a reciprocal record does not swim (scallop theorem), and
// bad files are refused naming the key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/scene.hpp"
#include "reduced1d/recorded_wave.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"
#include "scene_refusal.hpp"

namespace fs = std::filesystem;
using swim::scene::json;
using namespace swim::reduced1d;

namespace {

constexpr int kCells = 100;

json base_scene(const std::string& ends) {
  return {{"name", "recorded"},
          {"swimmer", {{"radius", "0.125 um"}, {"length", "0.4 um"}}},
          {"container", {{"kind", "cylinder"}, {"radius", "0.25 um"}, {"period", "2 um"}}},
          {"model1d", {{"end_effects", ends}}},
          {"numerics1d", {{"cells", kCells}}}};
}

json sine_scene(const std::string& ends) {
  json sc = base_scene(ends);
  sc["wave"] = {{"kind", "sine"}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"wavelength", "0.4 um"}};
  return sc;
}

json recorded_scene(const std::string& ends, const std::string& file) {
  json sc = base_scene(ends);
  sc["wave"] = {{"kind", "recorded"}, {"radius_file", file}};
  return sc;
}

/// A folder of the running test's own (CTest runs the tests of this file in parallel, and two of
/// them record the same sine run).
fs::path scratch() {
  const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const fs::path d = fs::temp_directory_path() / ("swim_recorded_wave_test_" + test + "_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

/// Runs a scene; returns the result (its samples kept).
Result run(const json& sc, Params* params = nullptr) {
  json resolved;
  const Params p = read_scene(sc, resolved);
  if (params) *params = p;
  Result r = solve(p);
  EXPECT_FALSE(r.failure.has_value()) << (r.failure ? r.failure->what() : "");
  return r;
}

/// The sine run's own run folder (write_run: the product's radius.csv); returns its radius.csv.
fs::path record_sine(const std::string& ends, double* displacement) {
  const fs::path dir = scratch() / ("sine_" + ends);
  fs::remove_all(dir);
  fs::create_directories(dir);
  json resolved;
  const Params p = read_scene(sine_scene(ends), resolved);
  Result r = solve(p);
  EXPECT_FALSE(r.failure.has_value());
  *displacement = r.series.back().X;
  write_run(dir.string(), p, resolved, r, 0.0);
  return dir / "radius.csv";
}

struct Table {
  std::vector<double> t, z;
  std::vector<std::vector<double>> R;  // R[k][j]
};

Table read_table(const fs::path& f) {
  std::ifstream in(f);
  std::string line;
  std::getline(in, line);
  Table tb;
  while (std::getline(in, line)) {
    double t, z, r;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf", &t, &z, &r) != 3) continue;
    if (tb.t.empty() || t != tb.t.back()) {
      tb.t.push_back(t);
      tb.R.emplace_back();
    }
    if (tb.t.size() == 1) tb.z.push_back(z);
    tb.R.back().push_back(r);
  }
  return tb;
}

void write_table(const fs::path& f, const Table& tb) {
  std::ofstream o(f);
  o << "t_s,z_m,radius_m\n";
  char b[40];
  for (std::size_t k = 0; k < tb.t.size(); ++k)
    for (std::size_t j = 0; j < tb.z.size(); ++j) {
      o << swim::output::csv_number(tb.t[k], b) << ',';
      o << swim::output::csv_number(tb.z[j], b) << ',';
      o << swim::output::csv_number(tb.R[k][j], b) << '\n';
    }
}

}  // namespace

// The replay of a sine run's own radius.csv (200 samples per period, the same 100 cells, so the
// rings are the cells) reproduces the run's displacement per cycle to within 0.2 %: the only
// error is the interpolation, linear in time between samples Delta t = T/200 apart (the line
// integral of the displacement along the chords of the shape path: relative error of order
// (2 pi / 200)^2 ~ 1e-3), the end points extrapolated over half a cell (of order (h/lambda)^2)
// and the record's 10 significant digits. Measured: -1.6e-4 (plain junction), -0.9e-4 (the
// calibrated junction). The default duration is the record's span.
TEST(RecordedWave, ReplayOfASineRunReproducesItsDisplacement) {
  for (const std::string ends : {"none", "junction"}) {
    SCOPED_TRACE(ends);
    double X_sine = 0;
    const fs::path file = record_sine(ends, &X_sine);
    ASSERT_GT(std::abs(X_sine), 1e-9);
    Params p;
    const Result r = run(recorded_scene(ends, file.string()), &p);
    ASSERT_FALSE(r.series.empty());
    EXPECT_NEAR(r.series.back().t, 0.04, 1e-12) << "the record's span, lambda / s";
    const double X = r.series.back().X;
    std::printf("%s: sine %.6e m, replay %.6e m, relative %+.2e\n", ends.c_str(), X_sine, X, X / X_sine - 1);
    EXPECT_NEAR(X / X_sine, 1.0, 2e-3);
  }
}

// Mirror symmetry: the record mirrored in z (z -> L - z) swims the other way by the same
// distance.
TEST(RecordedWave, MirroredRecordSwimsTheOtherWay) {
  double X_sine = 0;
  const fs::path file = record_sine("junction", &X_sine);
  Table tb = read_table(file);
  const double L = 0.4e-6;
  Table m = tb;
  for (std::size_t j = 0; j < tb.z.size(); ++j) m.z[j] = L - tb.z[tb.z.size() - 1 - j];
  for (std::size_t k = 0; k < tb.t.size(); ++k) std::reverse(m.R[k].begin(), m.R[k].end());
  const fs::path mf = scratch() / "mirrored.csv";
  write_table(mf, m);
  for (const std::string ends : {"none", "junction"}) {
    SCOPED_TRACE(ends);
    const double X = run(recorded_scene(ends, file.string())).series.back().X;
    const double Xm = run(recorded_scene(ends, mf.string())).series.back().X;
    ASSERT_GT(std::abs(X), 1e-9);
    EXPECT_NEAR(Xm / X, -1.0, 1e-4);
  }
}

// Scallop theorem: the record played backwards in time swims back by the same distance, and
// the reciprocal record (forwards, then backwards) ends where it started.
TEST(RecordedWave, TimeReversedRecordSwimsBackAndAReciprocalOneStays) {
  double X_sine = 0;
  const fs::path file = record_sine("junction", &X_sine);
  const Table tb = read_table(file);
  const std::size_t n = tb.t.size();
  const double T = tb.t.back();
  Table rev = tb, recip = tb;
  for (std::size_t k = 0; k < n; ++k) {
    rev.t[k] = T - tb.t[n - 1 - k];
    rev.R[k] = tb.R[n - 1 - k];
  }
  for (std::size_t k = 1; k < n; ++k) {  // then back through the same shapes
    recip.t.push_back(T + (T - tb.t[n - 1 - k]));
    recip.R.push_back(tb.R[n - 1 - k]);
  }
  const fs::path rf = scratch() / "reversed.csv", cf = scratch() / "reciprocal.csv";
  write_table(rf, rev);
  write_table(cf, recip);
  for (const std::string ends : {"none", "junction"}) {
    SCOPED_TRACE(ends);
    const double X = run(recorded_scene(ends, file.string())).series.back().X;
    const double Xr = run(recorded_scene(ends, rf.string())).series.back().X;
    const Result rc = run(recorded_scene(ends, cf.string()));
    ASSERT_GT(std::abs(X), 1e-9);
    EXPECT_NEAR(Xr / X, -1.0, 1e-4);
    // half-way the reciprocal record has swum the forward distance, at the end it is back
    double X_half = 0;
    for (const auto& s : rc.series)
      if (std::abs(s.t - T) < 1e-9 * T) X_half = s.X;
    EXPECT_NEAR(X_half / X, 1.0, 1e-4);
    EXPECT_LT(std::abs(rc.series.back().X), 1e-4 * std::abs(X));
  }
}

// Bad files: each refused by the scene reader naming wave.radius_file, the path and what is
// allowed (the executable's exit 2 before anything is written: the malformed-scene corpus,
// tests/data/malformed/recorded_*.json); the other wave keys and the other tiers refuse too.
TEST(RecordedWave, BadFilesAreRefusedNamingTheKey) {
  const fs::path d = scratch();
  double X = 0;
  const fs::path good = record_sine("none", &X);
  const Table tb = read_table(good);
  auto message = [](const json& sc) {
    const test::Refusal r = test::refusal_of(sc);
    return r.refused ? std::make_pair(r.key, r.message) : std::make_pair(std::string(), std::string());
  };
  struct Case {
    std::string name, text, allowed;
  };
  std::vector<Case> cases;
  cases.push_back({"missing.csv", "", "not found"});
  cases.push_back({"header.csv", "t,z,r\n0,0,1e-7\n", "t_s,z_m,radius_m"});
  cases.push_back({"columns.csv", "t_s,z_m,radius_m\n0,1e-7\n", "three finite numbers"});
  cases.push_back({"text.csv", "t_s,z_m,radius_m\n0,0,abc\n", "three finite numbers"});
  cases.push_back({"nan.csv", "t_s,z_m,radius_m\n0,0,nan\n0,4e-7,1e-7\n", "three finite numbers"});
  cases.push_back({"negative.csv", "t_s,z_m,radius_m\n0,0,-1e-7\n", "positive"});
  cases.push_back({"one_time.csv", "t_s,z_m,radius_m\n0,0,1e-7\n0,4e-7,1e-7\n", "at least 2 times"});
  cases.push_back({"backwards.csv",
                   "t_s,z_m,radius_m\n0.1,0,1e-7\n0.1,4e-7,1e-7\n0.05,0,1e-7\n0.05,4e-7,1e-7\n", "must increase"});
  cases.push_back({"rings.csv", "t_s,z_m,radius_m\n0,0,1e-7\n0,4e-7,1e-7\n1,0,1e-7\n1,2e-7,1e-7\n1,4e-7,1e-7\n",
                   "same rings"});
  cases.push_back({"short.csv", "t_s,z_m,radius_m\n0,0,1e-7\n0,2e-7,1e-7\n1,0,1e-7\n1,2e-7,1e-7\n", "z span"});
  cases.push_back({"long.csv", "t_s,z_m,radius_m\n0,0,1e-7\n0,8e-7,1e-7\n1,0,1e-7\n1,8e-7,1e-7\n", "z span"});
  cases.push_back({"empty.csv", "", "empty"});
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path f = d / c.name;
    fs::remove(f);
    if (c.name != "missing.csv") std::ofstream(f) << c.text;
    const auto [key, msg] = message(recorded_scene("none", f.string()));
    EXPECT_EQ(key, "wave.radius_file") << msg;
    EXPECT_NE(msg.find(f.string()), std::string::npos) << "names the value: " << msg;
    EXPECT_NE(msg.find(c.allowed), std::string::npos) << msg;
  }
  // the good record read by itself: its rings are the cells, its times the samples
  const auto rec = read_radius_file("wave.radius_file", good.string(), ".", 0.4e-6);
  EXPECT_EQ(rec->z.size(), std::size_t(kCells));
  EXPECT_EQ(rec->t.size(), tb.t.size());
  // a record of a tube twice as long is refused for this one
  const auto [klen, mlen] = message([&] {
    json sc = recorded_scene("none", good.string());
    sc["swimmer"]["length"] = "0.8 um";
    return sc;
  }());
  EXPECT_EQ(klen, "wave.radius_file") << mlen;
  // the keys of the other waves, and a file without the recorded kind
  json with_ratio = recorded_scene("none", good.string());
  with_ratio["wave"]["contracted_ratio"] = 0.5;
  EXPECT_EQ(message(with_ratio).first, "wave.contracted_ratio");
  json without = recorded_scene("none", good.string());
  without["wave"].erase("radius_file");
  EXPECT_EQ(message(without).first, "wave.radius_file");
  json stray = sine_scene("none");
  stray["wave"]["radius_file"] = good.string();
  EXPECT_EQ(message(stray).first, "wave.radius_file");
  // the force-driven model's keys are refused with a recorded wave, as with step and sine
  json traction = recorded_scene("none", good.string());
  traction["model1d"]["short_wave_traction"] = true;
  EXPECT_EQ(message(traction).first, "model1d.short_wave_traction");
}
