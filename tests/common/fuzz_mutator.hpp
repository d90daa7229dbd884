// The mutator of the input fuzzers (tests/common/test_scene_fuzz.cpp, test_input_fuzz.cpp):
// JSON document mutations (types, unit and number strings, numbers, deleted, unknown and moved
// keys, wrapped values, choice values, limits and names) and text mutations (stray and invalid
// UTF-8 bytes, truncation, duplicate keys, deep nesting, out-of-range and hex numbers, a
// byte-order mark, UTF-16, NUL bytes). Deterministic for a seed.
#pragma once

#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "common/scene.hpp"

namespace swim::fuzz {

using json = swim::scene::json;

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

}  // namespace swim::fuzz
