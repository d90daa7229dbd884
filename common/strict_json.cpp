#include "common/strict_json.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <unordered_set>
#include <vector>

#include "common/errors.hpp"

namespace swim::strict_json {
namespace {

// A SAX handler that builds the document itself, so that depth, duplicate keys and number
// range are checked while parsing. nlohmann's parser is iterative; with the depth bounded
// here no later recursion (dump, destruction, comparison) can run deep either.
class Builder {
 public:
  using number_integer_t = json::number_integer_t;
  using number_unsigned_t = json::number_unsigned_t;
  using number_float_t = json::number_float_t;
  using string_t = json::string_t;
  using binary_t = json::binary_t;

  Builder(std::string what, const Limits& limits) : what_(std::move(what)), limits_(limits) {}

  bool null() { return value(json(nullptr)); }
  bool boolean(bool v) { return value(json(v)); }
  bool number_integer(number_integer_t v) { return value(json(v)); }
  bool number_unsigned(number_unsigned_t v) { return value(json(v)); }
  bool number_float(number_float_t v, const string_t& raw) {
    if (!std::isfinite(v))
      return fail(raw, "number does not fit a double (magnitude above 1.8e308)");
    if (v == 0.0 && raw.find_first_of("123456789") < raw.find_first_of("eE"))
      return fail(raw, "number underflows to zero in a double (magnitude below 2.2e-308)");
    return value(json(v));
  }
  bool string(string_t& v) { return value(json(std::move(v))); }
  bool binary(binary_t&) { return fail("", "binary values are not JSON text"); }
  bool start_object(std::size_t) { return open(json::object()); }
  bool key(string_t& k) {
    Frame& f = stack_.back();
    if (!f.keys.insert(k).second) {
      f.key = k;
      return fail("\"" + k + "\"", "key given twice in one object; give each key once");
    }
    f.key = std::move(k);
    return true;
  }
  bool end_object() { return close(); }
  bool start_array(std::size_t) { return open(json::array()); }
  bool end_array() { return close(); }
  bool parse_error(std::size_t position, const std::string& last_token, const nlohmann::detail::exception& ex) {
    if (!error_) {
      std::string m = ex.what();
      // "[json.exception.parse_error.101] parse error at line 3, column 7: ..." -> keep the part
      // after the id; the last token is echoed through message_text by InputError.
      if (const auto p = m.find("] "); p != std::string::npos) m = m.substr(p + 2);
      if (ex.id == 406) {  // out_of_range: a number beyond the range of a double
        error_ = Problem{where(), last_token.empty() ? "" : "'" + last_token + "'",
                         "number does not fit a double (magnitude above 1.8e308)"};
        return false;
      }
      // A bad string (not UTF-8, a control character) belongs to its key; any other syntax
      // error to the text as a whole, with the key path it was found at.
      const std::string at = where();
      if (m.find("invalid string") != std::string::npos)
        error_ = Problem{at, last_token.empty() ? "" : "'" + last_token + "'",
                         "is not valid JSON text (" + m + ") near byte " + std::to_string(position)};
      else
        error_ = Problem{what_, last_token.empty() ? "" : "'" + last_token + "'",
                         "is not valid JSON (" + m + ") near byte " + std::to_string(position) +
                             (at == what_ ? "" : ", in " + at)};
    }
    return false;
  }

  struct Problem {
    std::string key, value, allowed;
  };
  json result() { return std::move(root_); }
  const std::optional<Problem>& error() const { return error_; }

 private:
  struct Frame {
    json* node;
    std::unordered_set<std::string> keys;
    std::string key;
  };

  // Dotted path of the value being read, for messages.
  std::string where() const {
    std::string p;
    for (const auto& f : stack_) {
      if (f.node->is_object() && !f.key.empty()) {
        if (!p.empty()) p += '.';
        p += f.key;
      }
      if (f.node->is_array()) {
        p += '[';
        p += std::to_string(f.node->size());
        p += ']';
      }
    }
    return p.empty() ? what_ : p;
  }

  bool fail(const std::string& value, const std::string& allowed) {
    if (!error_) error_ = Problem{where(), value, allowed};
    return false;
  }

  // Insert into the current container; returns the stored value.
  json* insert(json&& v) {
    if (stack_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    json& parent = *stack_.back().node;
    if (parent.is_array()) {
      parent.push_back(std::move(v));
      return &parent.back();
    }
    // ordered_map is a vector of pairs: append without its linear key search (the key set
    // of the frame has already rejected duplicates).
    auto& obj = parent.get_ref<json::object_t&>();
    auto& vec = static_cast<std::vector<std::pair<const std::string, json>>&>(obj);
    vec.emplace_back(stack_.back().key, std::move(v));
    return &vec.back().second;
  }

  bool value(json&& v) {
    insert(std::move(v));
    return true;
  }

  bool open(json&& container) {
    if (static_cast<int>(stack_.size()) >= limits_.max_depth)
      return fail("", "nested deeper than " + std::to_string(limits_.max_depth) + " levels of objects and arrays");
    json* node = insert(std::move(container));
    stack_.push_back(Frame{node, {}, {}});
    return true;
  }

  bool close() {
    stack_.pop_back();
    return true;
  }

  std::string what_;
  Limits limits_;
  json root_;
  std::vector<Frame> stack_;
  std::optional<Problem> error_;
};

}  // namespace

namespace {
// `shown`: replaces the echoed value of a problem found at the top level (the file name).
json parse_text(const std::string& text, const std::string& what, const Limits& limits, const std::string& shown) {
  if (text.size() > limits.max_bytes)
    throw InputError(what, std::to_string(text.size()) + " bytes",
                     "is too large; at most " + std::to_string(limits.max_bytes) + " bytes are read");
  Builder b(what, limits);
  bool ok = false;
  try {
    ok = json::sax_parse(text, &b, json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/false);
  } catch (const json::exception& e) {  // defensive: the handler reports errors, it does not throw
    throw InputError(what, "", std::string("is not valid JSON: ") + e.what());
  }
  if (const auto& e = b.error()) {
    if (e->key == what && !shown.empty()) throw InputError(what, shown, e->allowed + (e->value.empty() ? "" : " at " + e->value));
    throw InputError(e->key, e->value, e->allowed);
  }
  if (!ok) throw InputError(what, shown, "is not valid JSON");
  return b.result();
}
}  // namespace

json parse(const std::string& text, const std::string& what, const Limits& limits) {
  return parse_text(text, what, limits, "");
}

json parse_file(const std::string& path, const std::string& what, const Limits& limits) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  const std::string shown = "\"" + path + "\"";
  if (ec || !fs::exists(st)) throw InputError(what, shown, "file not found; give an existing JSON file");
  if (fs::is_directory(st)) throw InputError(what, shown, "is a directory; give a JSON file");
  if (!fs::is_regular_file(st))
    throw InputError(what, shown, "is not a regular file (a device, FIFO or socket); give a JSON file");
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError(what, shown, "file cannot be read: " + ec.message());
  if (size > limits.max_bytes)
    throw InputError(what, shown, "is too large (" + std::to_string(size) + " bytes); at most " +
                                      std::to_string(limits.max_bytes) + " bytes are read");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(what, shown, "file cannot be opened; check its permissions");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(what, shown, "file cannot be read");
  return parse_text(text, what, limits, shown);
}

}  // namespace swim::strict_json
