// Scene fuzzer: mutates the shipped scenes (value types, units, numbers, structure, text
// encodings) and runs the scene reading of `swim run` in process -- strict JSON, --set,
// the 1D reader, the 3D reader, the other tier's section check and the output-size check.
// Every case must be accepted or rejected with an InputError that names a key; anything
// else (another exception, a crash, a sanitizer report) fails. Deterministic seed; the
// failing case is printed so that it can be replayed.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <typeinfo>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "app/scene_checks.hpp"
#include "fuzz_mutator.hpp"
#include "common/errors.hpp"
#include "common/scene.hpp"
#include "common/strict_json.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/scene1d.hpp"

namespace fs = std::filesystem;
using swim::InputError;
using swim::scene::json;

namespace {

constexpr std::uint64_t kSeed = 0x5317'2026'1125ull;
constexpr int kCases = 12000;

std::vector<std::string> shipped_texts() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(SWIM_SOURCE_DIR) / "data" / "scenes"))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::vector<std::string> out;
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    out.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return out;
}

enum class Outcome { Accepted, Rejected };

// The in-process equivalent of `swim run` up to the point where a run would start.
Outcome read_like_run(const std::string& text, const std::vector<std::string>& sets, bool tier3d) {
  json sc = swim::strict_json::parse(text, "scene");
  if (!sc.is_object()) throw InputError("scene", "", "the top level must be a JSON object");
  for (const auto& s : sets) swim::scene::apply_override(sc, s);
  json resolved;
  if (tier3d) {
    const auto p = swim::full3d::read_scene3d(sc, resolved);
    swim::app::check_other_tier(sc, "3d");
    swim::app::check_output_size(swim::app::estimate_output(p), sc);
  } else {
    const auto p = swim::reduced1d::read_scene(sc, resolved);
    swim::app::check_other_tier(sc, "1d");
    swim::app::check_output_size(swim::app::estimate_output(p), sc);
    // the resolved scene is itself a valid scene (it is echoed into every run folder): a
    // rejection here is a failure of the reader, not of the case
    json again;
    try {
      swim::reduced1d::read_scene(resolved, again);
    } catch (const InputError& e) {
      throw std::logic_error(std::string("the resolved scene of an accepted scene is rejected: ") + e.what());
    }
  }
  return Outcome::Accepted;
}

}  // namespace

TEST(SceneFuzz, EveryMutatedSceneIsAcceptedOrRejectedNamingAKey) {
  const auto texts = shipped_texts();
  ASSERT_GE(texts.size(), 5u);
  swim::fuzz::Mutator m(kSeed);
  int accepted = 0, rejected = 0, failures = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int c = 0; c < kCases; ++c) {
    const std::size_t base = m.pick(texts.size());
    std::string text = texts[base];
    std::vector<std::string> sets;
    const int kind = static_cast<int>(m.pick(10));
    if (kind < 6) {  // document mutations
      json doc = json::parse(text);
      const int n = 1 + static_cast<int>(m.pick(3));
      for (int k = 0; k < n; ++k) m.mutate_document(doc);
      text = doc.dump(m.chance(0.5) ? 2 : -1);
    } else if (kind < 9) {  // text mutations
      m.mutate_text(text);
    } else {  // --set
      static const std::vector<std::string> keys = {"swimmer.radius", "swimmer.radius.", ".swimmer", "a..b", "wave.kind",
                                                    "full3d.dt", "model1d", "numerics1d.cells", "time.duration",
                                                    "output.max_bytes", "name", "protocol.segments", ""};
      static const std::vector<std::string> values = {"0.2 um", "0.1 0.2 um", "1e400", "null", "{\"a\":1,\"a\":2}",
                                                      "[[[[[[[[]]]]]]]]", "\xff", "64", "-3", "true", "auto",
                                                      "0x1p3 s", "{}", "\"quoted\"", "1000"};
      sets.push_back(m.any(keys) + "=" + m.any(values));
      if (m.chance(0.3)) sets.push_back(m.any(keys) + m.any(values));
    }
    // the 3D reader builds the membrane mesh (tens of ms for the paper scenes): mostly the small scenes
    const bool small = texts[base].find("\"tiny_3d") != std::string::npos;
    const bool tier3d = m.chance(small ? 0.2 : 0.005);
    try {
      read_like_run(text, sets, tier3d);
      ++accepted;
    } catch (const InputError& e) {
      ++rejected;
      if (e.key().empty()) {
        ++failures;
        ADD_FAILURE() << "case " << c << ": InputError without a key: " << e.what();
      }
    } catch (const std::exception& e) {
      ++failures;
      ADD_FAILURE() << "case " << c << " (scene " << base << ", " << (tier3d ? "3d" : "1d") << "): "
                    << typeid(e).name() << ": " << e.what() << "\n  text: " << swim::message_text(text, 400);
    }
    if (failures > 20) break;
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  RecordProperty("cases", accepted + rejected);
  RecordProperty("seconds", std::to_string(secs));
  std::printf("scene fuzzer: %d cases (%d accepted, %d rejected) in %.2f s, seed %llx\n", accepted + rejected,
              accepted, rejected, secs, static_cast<unsigned long long>(kSeed));
  EXPECT_GE(accepted + rejected, kCases);
  // the mutations must exercise both outcomes, or the fuzzer tests nothing
  EXPECT_GT(accepted, kCases / 50);
  EXPECT_GT(rejected, kCases / 2);
}
