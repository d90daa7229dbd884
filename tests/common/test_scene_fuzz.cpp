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

class Mutator {
 public:
  explicit Mutator(std::uint64_t seed) : rng_(seed) {}

  std::size_t pick(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }
  bool chance(double p) { return std::uniform_real_distribution<double>(0, 1)(rng_) < p; }
  template <class T>
  const T& any(const std::vector<T>& v) { return v[pick(v.size())]; }

  // A random node of the document (an object member or array element) to mutate.
  json* random_node(json& root, std::string& path) {
    json* n = &root;
    path.clear();
    for (int depth = 0; depth < 4 && n->is_structured() && !n->empty(); ++depth) {
      if (depth > 0 && chance(0.3)) break;
      const std::size_t k = pick(n->size());
      if (n->is_object()) {
        auto it = n->begin();
        std::advance(it, static_cast<long>(k));
        path += (path.empty() ? "" : ".") + it.key();
        n = &it.value();
      } else {
        n = &(*n)[k];
        path += '[';  // (appended piecewise: GCC 12 warns falsely on "[" + std::string + "]")
        path += std::to_string(k);
        path += ']';
      }
    }
    return n;
  }

  json random_value() {
    static const std::vector<json> values = {
        nullptr, true, false, 0, -1, 1, 2.5, -0.0, 1e308, -1e308, 4.9e-324, 9223372036854775807LL,
        18446744073709551615ULL, "", "abc", "auto", "1", "0.2 um", "1 s", "5.5e-8 N/m", json::array(),
        json::object(), json::array({1, 2}), json::object({{"x", 1}}), json::array({json::object()}),
        "force_driven", "cylinder", "step", "sine", "1e400 um", "0x10 um", "nan um", "inf s", "-1 um", "0 s"};
    return any(values);
  }

  std::string random_quantity_text(const std::string& original) {
    static const std::vector<std::string> numbers = {"0", "-0", "1", "-1", "0.5", ".5", "5.", "1e-30", "1e30", "1e308",
                                                     "1e309", "1e-400", "0x1p-3", "inf", "nan", "1,5", "1.5.2", "",
                                                     "+1", "--1", "1e", "1e+", "0.1 0.2", "1 2", "١", "1\xc2\xa0"};
    static const std::vector<std::string> units = {"um", "m", "nm", "s", "ms", "Pa", "Pa*s", "kg/m^3", "N/m", "N",
                                                   "kg/m", "ug/um", "kg/(m^2*s)", "furlong", "degC", "K", "1/s",
                                                   "um um", "", "\xc2\xb5m", "m^2", "m2", "s-1", "um*2", "um/1000",
                                                   "um @ 5", "s since 2000-01-01", "log(re 1 m)", "(", "m^",
                                                   "um\t", " um ", "UM", "Pa/m", "g/(cm*s)", "lb"};
    const auto sp = original.find(' ');
    const std::string num = sp == std::string::npos ? original : original.substr(0, sp);
    const std::string unit = sp == std::string::npos ? "" : original.substr(sp + 1);
    switch (pick(4)) {
      case 0: return any(numbers) + " " + unit;
      case 1: return num + " " + any(units);
      case 2: return any(numbers) + " " + any(units);
      default: return num + any(units);
    }
  }

  void mutate_document(json& doc) {
    std::string path;
    json* n = random_node(doc, path);
    switch (pick(9)) {
      case 0:  // type change
        *n = random_value();
        break;
      case 1:  // unit and number strings
        if (n->is_string()) *n = random_quantity_text(n->get<std::string>());
        else *n = random_quantity_text("1 um");
        break;
      case 2:  // numbers
        if (n->is_number()) {
          static const std::vector<double> f = {-1, 0, 1e300, 1e-300, 0.5, 3, 1e6, -1e-6};
          *n = n->get<double>() * any(f);
        } else {
          *n = any(std::vector<json>{0, 1, -5, 1.0e15, 123456789012345678LL, 0.333});
        }
        break;
      case 3:  // delete a key
        if (n->is_object() && !n->empty()) n->erase(n->begin());
        else if (doc.is_object() && !doc.empty()) doc.erase(doc.begin());
        break;
      case 4:  // unknown or misspelled key
        if (n->is_object()) (*n)[any(std::vector<std::string>{"x", "Radius", "radius ", "", "full3d", "model1d",
                                                               "\xe2\x80\x8bname", "output", "max_bytes"})] = random_value();
        break;
      case 5:  // move a section under another name (the other tier's section, a shared one)
        if (doc.is_object() && !doc.empty()) {
          auto it = doc.begin();
          std::advance(it, static_cast<long>(pick(doc.size())));
          doc[any(std::vector<std::string>{"full3d", "model1d", "numerics1d", "wave", "protocol", "time", "output",
                                           "swimmer"})] = it.value();
        }
        break;
      case 6:  // wrap in an array / object
        *n = chance(0.5) ? json::array({*n}) : json::object({{"value", *n}});
        break;
      case 7:  // choice values across keys
        *n = any(std::vector<json>{"step", "sine", "force_driven", "box", "duct", "cylinder", "tube_law", "flow",
                                   "midpoint", "energy", "shape", "dead_band", "printed", "per_length", "auto"});
        break;
      default:  // output limits, names
        if (doc.is_object()) {
          if (chance(0.5)) doc["output"] = {{"max_bytes", any(std::vector<json>{1, 1000, 100000, -1, 1e18, "1 GB"})}};
          else doc["name"] = any(std::vector<json>{"../x", "a/b", "ok_name", "", ".", "x y", "\xc3\xa9"});
        }
    }
  }

  void mutate_text(std::string& t) {
    if (t.empty()) return;
    switch (pick(10)) {
      case 0: t.insert(pick(t.size()), 1, static_cast<char>(0x80 + pick(0x80))); break;  // stray non-ASCII byte
      case 1: t.resize(pick(t.size())); break;                                            // truncated file
      case 2: t[pick(t.size())] = static_cast<char>(pick(256)); break;                    // random byte
      case 3: {  // a key given twice
        const auto b = t.find('{');
        if (b != std::string::npos) t.insert(b + 1, "\"name\": \"dup\", \"name\": \"dup\",");
        break;
      }
      case 4: {  // deep nesting
        const std::size_t depth = 30 + pick(200);
        const auto b = t.find('{');
        if (b != std::string::npos) t.insert(b + 1, "\"deep\": " + std::string(depth, '[') + std::string(depth, ']') + ",");
        break;
      }
      case 5: {  // a number that does not fit, or underflows, or is hex
        const auto b = t.find(": ");
        if (b != std::string::npos)
          t.insert(b + 2, any(std::vector<std::string>{"1e400", "-1e999", "1e-400", "0x10", "NaN", "Infinity", "01",
                                                        "1.", ".5", "-", "1e5000"}) + " ");
        break;
      }
      case 6: t = "\xef\xbb\xbf" + t; break;  // byte-order mark
      case 7: {                                // UTF-16
        std::string u;
        for (char c : t) u += std::string{c, '\0'};
        t = "\xff\xfe" + u;
        break;
      }
      case 8: t.insert(pick(t.size()), std::string("\0", 1)); break;  // NUL byte
      default: {                                                      // overlong / surrogate in a string
        const auto q = t.find("\": \"");
        if (q != std::string::npos) t.insert(q + 4, any(std::vector<std::string>{"\xc0\xaf", "\xed\xa0\x80", "\xf4\x90\x80\x80"}));
      }
    }
  }

 private:
  std::mt19937_64 rng_;
};

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
  Mutator m(kSeed);
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
