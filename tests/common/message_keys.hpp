// Shared by the message-key tests of both tiers: the key paths a reader resolves, and the
// scene keys named in the string literals of a source folder.
#pragma once

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/scene.hpp"

namespace swim::testing {

/// Every key path of a resolved scene ("a", "a.b", ...).
inline void collect_keys(const scene::json& j, const std::string& path, std::set<std::string>& out) {
  if (!path.empty()) out.insert(path);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it)
      collect_keys(it.value(), path.empty() ? it.key() : path + "." + it.key(), out);
}

/// Every key path `read(scene, resolved)` resolves for `base` with each list of `--set`
/// assignments in `variants` (variants switch on the conditional keys).
template <class Read>
std::set<std::string> resolved_keys(const scene::json& base, const std::vector<std::vector<std::string>>& variants,
                                    Read read) {
  std::set<std::string> keys;
  for (const auto& sets : variants) {
    scene::json sc = base;
    for (const auto& s : sets) scene::apply_override(sc, s);
    scene::json resolved;
    read(sc, resolved);
    collect_keys(resolved, "", keys);
  }
  return keys;
}

/// (file name, key) for every match of `key` inside a string literal of the .cpp/.hpp files
/// of `dir`, file names (an extension in `file_ext`) excepted.
inline std::vector<std::pair<std::string, std::string>> named_keys(const std::string& dir, const std::regex& key,
                                                                   const std::set<std::string>& file_ext) {
  const std::regex literal(R"("(?:[^"\\]|\\.)*")");
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string ext = e.path().extension().string();
    if (ext != ".cpp" && ext != ".hpp") continue;
    std::ifstream in(e.path());
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    for (std::sregex_iterator l(text.begin(), text.end(), literal), end; l != end; ++l) {
      const std::string lit = l->str();
      for (std::sregex_iterator k(lit.begin(), lit.end(), key); k != end; ++k) {
        const std::string name = k->str();
        if (file_ext.count(name.substr(name.rfind('.') + 1))) continue;
        out.emplace_back(e.path().filename().string(), name);
      }
    }
  }
  return out;
}

}  // namespace swim::testing
