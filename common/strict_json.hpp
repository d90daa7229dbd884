// Strict JSON reading for scenes, sweeps and --set values. On top of RFC 8259 syntax
// (nlohmann's lexer, which also rejects text that is not UTF-8):
//   - nesting deeper than Limits::max_depth is rejected before it is built (the parser
//     and the document never recurse deeper than that),
//   - a key given twice in one object is rejected (no "last one wins"),
//   - numbers that do not fit a double (1e400) or that underflow to zero (1e-400) are
//     rejected,
//   - the text is bounded in size.
// Every rejection is a swim::InputError naming the dotted key path where it happened
// (or `what` at the top level), the offending text (shortened) and what is allowed.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace swim::strict_json {

using json = nlohmann::ordered_json;

struct Limits {
  int max_depth = 64;                   ///< objects/arrays inside each other
  std::size_t max_bytes = 16u << 20;    ///< whole text
};

/// Parse `text`; `what` names the source in messages ("scene", "--set").
json parse(const std::string& text, const std::string& what, const Limits& limits = {});

/// Read a file and parse it. The path must name a regular file (not a directory, FIFO or
/// device) of at most limits.max_bytes.
json parse_file(const std::string& path, const std::string& what, const Limits& limits = {});

}  // namespace swim::strict_json
