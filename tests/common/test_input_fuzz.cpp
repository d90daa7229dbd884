// Sweep files (swim screen) and suite files (swim validate) are read as strictly as scenes:
// every key known and of its type, every value in range, every scene they produce read by the
// tier's reader before anything runs. The examples of each class, then two seeded fuzzers that
// mutate the shipped sweeps and suites (the scene fuzzer's mutations, and mutations of their own
// keys) and run the reading of `swim screen` and `swim validate` in process: every case must be
// accepted or rejected with an InputError that names a key; any other exception fails.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <typeinfo>
#include <vector>

#include "app/scene_checks.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/strict_json.hpp"
#include "common/sweep.hpp"
#include "fuzz_mutator.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"
#include "validation/suite.hpp"

namespace fs = std::filesystem;
using swim::InputError;
using swim::scene::json;

namespace {

const std::string kData = SWIM_SOURCE_DIR "/data";
const std::string kSweeps = kData + "/sweeps";
const std::string kSuites = kData + "/validation";

std::vector<std::pair<std::string, std::string>> texts_in(const std::string& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    out.emplace_back(f.string(), std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
  }
  return out;
}

/// The in-process reading of `swim screen` up to the first design run: the sweep, the other
/// tier's sections of its scenes, and the 1D reader on the first, the last and one other design.
void read_like_screen(const std::string& text, std::size_t probe) {
  const json j = swim::strict_json::parse(text, "sweep");
  const swim::sweep::Sweep sw = swim::sweep::parse_sweep(j, kSweeps, "fuzz", swim::reduced1d::metric_names());
  swim::app::check_sweep_scenes(sw);
  for (const std::size_t k : {std::size_t(0), probe % sw.count(), sw.count() - 1}) {
    json resolved;
    swim::reduced1d::read_scene(sw.design(k), resolved, sw.base_dir);
  }
}

/// The key an InputError names, or the message when it names none.
std::string key_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.key().empty() ? "(no key) " + std::string(e.what()) : e.key();
  }
  return "(accepted)";
}

std::string sweep_with(const json& vary, const json& extra = json::object()) {
  json s = {{"base", "../scenes/demo.json"}, {"vary", vary}};
  for (const auto& [k, v] : extra.items()) s[k] = v;
  return s.dump();
}

json quick_suite() { return swim::scene::load_file(kSuites + "/quick.json"); }

std::string suite_key(const json& suite, bool scenes = true) {
  return key_of([&] { swim::validation::check_suite(suite, kSuites + "/quick.json", kData, scenes); });
}

}  // namespace

TEST(StrictSweep, OverflowWrongTypesAndBadRangesAreRejectedNamingTheKey) {
  auto key = [](const std::string& text) { return key_of([&] { read_like_screen(text, 0); }); };
  // accepted as shipped
  EXPECT_EQ(key(sweep_with({{"wave.contracted_ratio", {{"from", 0.4}, {"to", 0.6}, {"count", 3}}}})), "(accepted)");
  // four axes of 65 536 values: 2^64 designs, refused naming the axes and the limit (never wrapped)
  json big = json::object();
  for (const char* k : {"swimmer.length", "wave.contracted_ratio", "swimmer.radius", "time.output_interval"})
    big[k] = {{"from", 1}, {"to", 2}, {"count", 65536}};
  try {
    swim::sweep::parse_sweep(json::parse(sweep_with(big)), kSweeps, "x", swim::reduced1d::metric_names());
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "vary");
    EXPECT_NE(std::string(e.what()).find("at most 1000000 designs"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("swimmer.length (65536) x wave.contracted_ratio"), std::string::npos) << e.what();
  }
  const json axis = {{"swimmer.length", {{"values", {"0.3 um"}}}}};
  EXPECT_EQ(key(sweep_with(axis, {{"metric", 3}})), "metric");
  EXPECT_EQ(key(sweep_with(axis, {{"goal", 1}})), "goal");
  EXPECT_EQ(key(sweep_with(axis, {{"name", 5}})), "name");
  EXPECT_EQ(key(sweep_with(axis, {{"description", {{"a", 1}}}})), "description");
  EXPECT_EQ(key(sweep_with({{"wave.contracted_ratio", {{"from", 0.3}, {"to", 0.5}, {"count", 2}, {"spacing", 2}}}})),
            "vary.wave.contracted_ratio.spacing");
  // subnormal, overflowing and NaN-producing ranges
  EXPECT_EQ(key(sweep_with({{"wave.contracted_ratio", {{"from", 4e-320}, {"to", 1e-319}, {"count", 3}}}})),
            "vary.wave.contracted_ratio");
  EXPECT_EQ(key(sweep_with({{"wave.contracted_ratio", {{"from", -1.7e308}, {"to", 1.7e308}, {"count", 3}}}})),
            "vary.wave.contracted_ratio");
  // an axis `swim run --set` would refuse
  EXPECT_EQ(key(sweep_with({{"full3d.nosuch", {{"values", {1, 2}}}}})), "vary.full3d.nosuch");
  EXPECT_EQ(key(sweep_with({{"swimmer..length", {{"values", {"0.3 um"}}}}})), "vary.swimmer..length");
}

TEST(StrictSuite, UnknownKeysWrongTypesAndBadValuesAreRejectedNamingTheKey) {
  EXPECT_EQ(suite_key(quick_suite()), "(accepted)");
  auto with = [](const std::function<void(json&)>& edit) {
    json s = quick_suite();
    edit(s);
    return s;
  };
  EXPECT_EQ(suite_key(with([](json& s) { s["nosuch"] = 1; }), false), "suite.nosuch");
  EXPECT_EQ(suite_key(with([](json& s) { s["cases"][0]["grid"] = s["cases"][0]["grids"]; }), false), "suite.cases[0].grid");
  EXPECT_EQ(suite_key(with([](json& s) { s["thresholds"]["cycle_time_relative"] = -0.5; }), false),
            "suite.thresholds.cycle_time_relative");
  EXPECT_EQ(suite_key(with([](json& s) { s["thresholds"]["velocity_phase_correlation"] = "high"; }), false),
            "suite.thresholds.velocity_phase_correlation");
  EXPECT_EQ(suite_key(with([](json& s) { s["thresholds"]["typo_relative"] = 0.1; }), false), "suite.thresholds.typo_relative");
  // the 1D tier's design targets: the thresholds' four keys, each required, at the suite and at a case
  const json targets = {{"displacement_per_cycle_relative", 0.1}, {"cycle_time_relative", 0.15},
                        {"mean_velocity_per_cycle_relative", 0.15}, {"velocity_phase_correlation", 0.8}};
  EXPECT_EQ(suite_key(with([&](json& s) { s["targets1d"] = targets; }), false), "(accepted)");
  EXPECT_EQ(suite_key(with([&](json& s) { s["cases"][0]["targets1d"] = targets; }), false), "(accepted)");
  EXPECT_EQ(suite_key(with([&](json& s) {
              s["targets1d"] = targets;
              s["targets1d"]["cycle_time_relative"] = 0;
            }), false),
            "suite.targets1d.cycle_time_relative");
  EXPECT_EQ(suite_key(with([&](json& s) {
              s["cases"][0]["targets1d"] = targets;
              s["cases"][0]["targets1d"].erase("velocity_phase_correlation");
            }), false),
            "suite.cases[0].targets1d.velocity_phase_correlation");
  EXPECT_EQ(suite_key(with([&](json& s) {
              s["targets1d"] = targets;
              s["targets1d"]["velocity_phase_correlation"] = 1.5;
            }), false),
            "suite.targets1d.velocity_phase_correlation");
  EXPECT_EQ(suite_key(with([](json& s) { s["targets1d"] = 0.1; }), false), "suite.targets1d");
  EXPECT_EQ(suite_key(with([](json& s) { s["cells1d"] = {50, -100}; }), false), "suite.cells1d");
  EXPECT_EQ(suite_key(with([](json& s) { s["name"] = 5; }), false), "suite.name");
  EXPECT_EQ(suite_key(with([](json& s) { s["models1d"][0]["calibrated"] = "yes"; }), false), "suite.models1d[0].calibrated");
  EXPECT_EQ(suite_key(with([](json& s) { s["models1d"][1]["label"] = 7; }), false), "suite.models1d[1].label");
  EXPECT_EQ(suite_key(with([](json& s) { s["cases"][0]["scene"] = 3; }), false), "suite.cases[0].scene");
  EXPECT_EQ(suite_key(with([](json& s) { s["cases"][0]["set"] = {{"a..b", 1}}; }), false), "suite.cases[0].set.a..b");
  // the scenes the suite would run, read by the tiers' readers before anything runs
  EXPECT_EQ(suite_key(with([](json& s) { s["models1d"][0]["set"]["model1d.nosuch"] = 1; })), "suite.models1d[0]");
  EXPECT_EQ(suite_key(with([](json& s) { s["models1d"][2]["set"]["numerics1d.cells"] = 0; })), "suite.models1d[2]");
  EXPECT_EQ(suite_key(with([](json& s) { s["cases"][0]["set"]["full3d.dt"] = "-1 ms"; })), "suite.cases[0].grids[0]");
  EXPECT_EQ(suite_key(with([](json& s) { s["cases"][0]["set"]["numerics1d.cells"] = -5; })), "suite.models1d[0]");
  EXPECT_EQ(suite_key(with([](json& s) { s["cases"][0]["time_variants3d"][0]["set"]["full3d.dt"] = "fast"; })),
            "suite.cases[0].time_variants3d[0].set");
  EXPECT_EQ(suite_key(with([](json& s) { s["rtol1d"] = {1e-4, 2.0}; }), false), "suite.rtol1d");
}

// (default.json, converged.json and buckling.json: SuiteReference.TheShippedConvergedSuiteLoads,
// SuiteReference.TheShippedBucklingSuiteLoads, SuiteFile.ShippedSuitesLoad)
TEST(StrictSuite, TheShippedSuitesAreAccepted) {
  for (const char* name : {"quick.json", "resolution.json"})
    EXPECT_NO_THROW(swim::validation::load_suite(kSuites + "/" + name, kData)) << name;
}

TEST(SweepFuzz, EveryMutatedSweepIsAcceptedOrRejectedNamingAKey) {
  constexpr std::uint64_t kSeed = 0x5753'2026'1202ull;
  constexpr int kCases = 10000;
  auto texts = texts_in(kSweeps);
  ASSERT_GE(texts.size(), 2u);
  // sweeps with ranges of quantities and numbers, and with a log spacing
  texts.emplace_back("", sweep_with({{"swimmer.length", {{"from", "0.2 um"}, {"to", "0.8 um"}, {"count", 3}, {"spacing", "log"}}},
                                     {"wave.contracted_ratio", {0.4, 0.6}}},
                                    {{"metric", "mean_velocity_m_per_s"}, {"goal", "min"}, {"name", "s"}}));
  swim::fuzz::Mutator m(kSeed);
  int accepted = 0, rejected = 0, failures = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int c = 0; c < kCases && failures <= 20; ++c) {
    std::string text = texts[m.pick(texts.size())].second;
    const int kind = static_cast<int>(m.pick(10));
    if (kind < 4) {  // the scene fuzzer's document mutations
      json doc = json::parse(text);
      for (int k = 0, n = 1 + static_cast<int>(m.pick(3)); k < n; ++k) m.mutate_document(doc);
      text = doc.dump();
    } else if (kind < 8) {  // mutations of a sweep's own keys
      json doc = json::parse(text);
      json& vary = doc["vary"];
      static const std::vector<std::string> keys = {"swimmer.length", "wave.contracted_ratio", "full3d.nosuch",
                                                    "full3d.dt", "numerics1d.cells", "a..b", ".x", "time.duration",
                                                    "swimmer", "model1d.model", "axi.grid.cells_across", ""};
      static const std::vector<json> specs = {
          {{"from", 1}, {"to", 2}, {"count", 1001}},
          {{"from", 0.3}, {"to", 0.5}, {"count", 3}, {"spacing", 2}},
          {{"from", 4e-320}, {"to", 1e-310}, {"count", 2}},
          {{"from", -1.7e308}, {"to", 1.7e308}, {"count", 3}},
          {{"from", "0.1 um"}, {"to", "0.3 um"}, {"count", 2}, {"spacing", "log"}},
          {{"from", "0.1 um"}, {"to", 0.3}, {"count", 2}},
          {{"from", "1e-300 um"}, {"to", "1e300 um"}, {"count", 4}, {"spacing", "log"}},
          {{"from", 1}, {"to", 2}},
          {{"from", 1}, {"to", 2}, {"count", 0}},
          {{"values", json::array()}},
          {{"values", {nullptr, 1, "x", json::object()}}},
          {{"values", {"magic", "paper"}}},
          {1, 2, 3},
          json::array({json::array({1})}),
          "0.3 um",
          {{"values", {1}}, {"extra", 1}}};
      for (int k = 0, n = 1 + static_cast<int>(m.pick(3)); k < n; ++k) {
        switch (m.pick(4)) {
          case 0: vary[m.any(keys)] = m.any(specs); break;
          case 1: doc[m.any(std::vector<std::string>{"metric", "goal", "name", "description", "spacing", "base"})] = m.random_value(); break;
          case 2: doc["metric"] = m.any(std::vector<json>{"mean_velocity_m_per_s", "nosuch", 3, nullptr, "pumped_volume_m3"}); break;
          default:
            if (vary.is_object() && !vary.empty()) {
              std::string path;
              json* n2 = m.random_node(vary, path);
              *n2 = m.random_value();
            }
        }
      }
      text = doc.dump();
    } else {  // text mutations
      m.mutate_text(text);
    }
    try {
      read_like_screen(text, m.pick(1000000));
      ++accepted;
    } catch (const InputError& e) {
      ++rejected;
      if (e.key().empty()) {
        ++failures;
        ADD_FAILURE() << "case " << c << ": InputError without a key: " << e.what();
      }
    } catch (const std::exception& e) {
      ++failures;
      ADD_FAILURE() << "case " << c << ": " << typeid(e).name() << ": " << e.what()
                    << "\n  text: " << swim::message_text(text, 600);
    }
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("sweep fuzzer: %d cases (%d accepted, %d rejected) in %.2f s, seed %llx\n", accepted + rejected, accepted,
              rejected, secs, static_cast<unsigned long long>(kSeed));
  EXPECT_GE(accepted + rejected, kCases);
  EXPECT_GT(accepted, kCases / 50);
  EXPECT_GT(rejected, kCases / 2);
}

TEST(SuiteFuzz, EveryMutatedSuiteIsAcceptedOrRejectedNamingAKey) {
  constexpr std::uint64_t kSeed = 0x5375'2026'1202ull;
  constexpr int kCases = 10000;
  const auto texts = texts_in(kSuites);
  ASSERT_GE(texts.size(), 2u);
  swim::fuzz::Mutator m(kSeed);
  int accepted = 0, rejected = 0, failures = 0, with_scenes = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int c = 0; c < kCases && failures <= 20; ++c) {
    const auto& [path, original] = texts[m.pick(texts.size())];
    std::string text = original;
    const int kind = static_cast<int>(m.pick(10));
    if (kind < 4) {
      json doc = json::parse(text);
      for (int k = 0, n = 1 + static_cast<int>(m.pick(3)); k < n; ++k) m.mutate_document(doc);
      text = doc.dump();
    } else if (kind < 8) {  // mutations of a suite's own keys
      json doc = json::parse(text);
      static const std::vector<std::string> sets = {"numerics1d.cells", "full3d.dt", "model1d.model", "wall.C1",
                                                    "full3d.nosuch", "swimmer.radius", "a..b", "time.duration"};
      static const std::vector<json> values = {0, -5, 100, "-1 ms", "1 ms", "magic", "paper", nullptr, "0.2 um", 1e300};
      for (int k = 0, n = 1 + static_cast<int>(m.pick(3)); k < n; ++k) {
        // an earlier mutation may have replaced the lists: mutate what is there
        if (!doc.is_object() || !doc["cases"].is_array() || doc["cases"].empty() || !doc["cases"][0].is_object() ||
            !doc["models1d"].is_array() || doc["models1d"].empty() || !doc["models1d"][0].is_object())
          break;
        json& cs = doc["cases"][0];
        try {  // a mutation that does not apply to what an earlier one left is skipped
        switch (m.pick(6)) {
          case 0: cs["set"][m.any(sets)] = m.any(values); break;
          case 1: doc["models1d"][0]["set"][m.any(sets)] = m.any(values); break;
          case 2: doc["thresholds"][m.any(std::vector<std::string>{"cycle_time_relative", "velocity_phase_correlation", "nosuch"})] = m.random_value(); break;
          case 3: doc[m.any(std::vector<std::string>{"cells1d", "rtol1d", "name", "order_range", "extremes3d", "reference_target_relative"})] = m.random_value(); break;
          case 4: cs[m.any(std::vector<std::string>{"grids", "calibration_grid", "grid_key", "scene", "paper", "time_variants3d", "reference", "gird"})] = m.random_value(); break;
          default: {
            std::string p;
            *m.random_node(doc, p) = m.random_value();
          }
        }
        } catch (const json::exception&) {
        }
      }
      text = doc.dump();
    } else {
      m.mutate_text(text);
    }
    // the tiers' readers on every scene (tens of ms for the larger suites): a share of the cases
    // of the quick suite, whose scenes are small; the structure on every case
    const bool scenes = path.find("quick.json") != std::string::npos && m.chance(0.02);
    with_scenes += scenes;
    try {
      const json doc = swim::strict_json::parse(text, "suite");
      swim::validation::check_suite(doc, path, kData, scenes);
      ++accepted;
    } catch (const InputError& e) {
      ++rejected;
      if (e.key().empty()) {
        ++failures;
        ADD_FAILURE() << "case " << c << ": InputError without a key: " << e.what();
      }
    } catch (const std::exception& e) {
      ++failures;
      ADD_FAILURE() << "case " << c << ": " << typeid(e).name() << ": " << e.what()
                    << "\n  text: " << swim::message_text(text, 600);
    }
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("suite fuzzer: %d cases (%d accepted, %d rejected, %d with every scene read) in %.2f s, seed %llx\n",
              accepted + rejected, accepted, rejected, with_scenes, secs, static_cast<unsigned long long>(kSeed));
  EXPECT_GE(accepted + rejected, kCases);
  EXPECT_GT(accepted, kCases / 50);
  EXPECT_GT(rejected, kCases / 2);
}

// One scene, one validation: in a 3D or axi run (and a calibration) the 1D tier's sections are
// read by the 1D reader, so a value it refuses is refused there too.
TEST(StrictScene, TheOneDimensionalSectionsAreCheckedInEveryRun) {
  const json demo = swim::scene::load_file(kData + "/scenes/tiny_3d_cycle.json");
  EXPECT_NO_THROW(swim::app::check_other_tier(demo, "3d"));
  for (const auto& [set, key] : std::vector<std::pair<std::string, std::string>>{
           {"numerics1d.cells=0", "numerics1d.cells"}, {"model1d.model=\"magic\"", "model1d.model"}}) {
    json sc = demo;
    swim::scene::apply_override(sc, set);
    for (const char* tier : {"3d", "axi"}) {
      try {
        swim::app::check_other_tier(sc, tier);
        ADD_FAILURE() << set << " accepted in a " << tier << " run";
      } catch (const InputError& e) {
        EXPECT_EQ(e.key(), key) << e.what();
      }
    }
  }
}

// A calibration file read by the 1D tier (wall.calibration) is refused, naming the key, when
// it is a directory, was changed after swim wrote it, or records a failed calibration.
TEST(StrictCalibration, ADirectoryAChangedFileAndAFailedStatusAreRefused) {
  const fs::path dir = fs::temp_directory_path() / ("swim_strict_cal_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "folder");
  fs::create_directories(dir / "failed");
  const json cal = {{"C1_Pa_per_m", 5.5e6}, {"hydraulic_offset_inner_m", 1e-8}, {"hydraulic_offset_outer_m", 1e-8},
                    {"status", "ok"}};
  swim::output::write_json((dir / "calibration.json").string(), cal);
  auto read_with = [&](const fs::path& file) {
    json sc = swim::scene::load_file(kData + "/scenes/demo.json");
    swim::scene::apply_override(sc, "wall.spring_constant=null");
    swim::scene::apply_override(sc, "wall.C1=null");
    swim::scene::apply_override(sc, "wall.calibration=\"" + file.string() + "\"");
    return key_of([&] {
      json resolved;
      swim::reduced1d::read_scene(sc, resolved);
    });
  };
  EXPECT_EQ(read_with(dir / "calibration.json"), "(accepted)");
  EXPECT_EQ(read_with(dir / "folder"), "wall.calibration");
  {  // a changed digit of C1
    std::ifstream in(dir / "calibration.json");
    std::string t((std::istreambuf_iterator<char>(in)), {});
    t[t.find("5.5") + 2] = '6';
    std::ofstream(dir / "changed.json") << t;
  }
  EXPECT_EQ(read_with(dir / "changed.json"), "wall.calibration");
  json failed = cal;
  failed["status"] = "failed: hydraulic radii: no convergence";
  swim::output::write_json((dir / "failed" / "calibration.json").string(), failed);
  EXPECT_EQ(read_with(dir / "failed" / "calibration.json"), "wall.calibration");
  fs::remove_all(dir);
}
