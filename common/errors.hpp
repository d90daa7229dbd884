// Error types behind the command-line exit codes of the product contract.
//
//   InputError      -> exit 2: bad scene, flag or sweep. Thrown before anything is written.
//                      The message names the key, the offending value and what is allowed.
//   NumericalError  -> exit 3: instability, solver non-convergence, radius collapse, a node
//                      spacing beyond h/2. The message names the likely cause and the
//                      parameter to change; the caller keeps the partial results.
//   OutputError     -> exit 3: a result file could not be written completely (disk full,
//                      read-only folder). The message names the file; the run folder's
//                      summary.json is marked failed (or removed when even that fails).
//
// Echoed values are shortened and made printable (messages never carry megabytes or
// raw control bytes): see message_text().
#pragma once

#include <stdexcept>
#include <cstdio>
#include <string>

namespace swim {

/// `text` made printable (control bytes and bytes that are not valid UTF-8 as \xNN) and
/// cut to at most `limit` bytes (never inside a UTF-8 sequence), with "... (N bytes)" appended.
std::string message_text(const std::string& text, size_t limit = 160);

/// True when `s` is valid UTF-8 (no overlong forms, no surrogates); else the offset of the
/// first bad byte goes to *bad_offset.
bool valid_utf8(const std::string& s, size_t* bad_offset = nullptr);

class InputError : public std::runtime_error {
 public:
  InputError(std::string key, std::string value, std::string allowed)
      : std::runtime_error(format(key, value, allowed)), key_(std::move(key)) {}
  const std::string& key() const { return key_; }

 private:
  static std::string format(const std::string& key, const std::string& value,
                            const std::string& allowed) {
    std::string m = "invalid input: key '" + message_text(key, 200) + "'";
    if (!value.empty()) m += " = " + message_text(value, 160);
    m += ": " + message_text(allowed, 2000);
    return m;
  }
  std::string key_;
};

class NumericalError : public std::runtime_error {
 public:
  /// cause: what happened; remedy: which parameter to change and how.
  NumericalError(std::string cause, std::string remedy, double t_s = -1.0)
      : std::runtime_error("numerical failure: " + cause + (t_s >= 0 ? " (at t = " + fmt(t_s) + " s)" : "") +
                           "; " + remedy),
        cause_(std::move(cause)), remedy_(std::move(remedy)), t_(t_s) {}
  const std::string& cause() const { return cause_; }
  const std::string& remedy() const { return remedy_; }
  double time() const { return t_; }

 private:
  static std::string fmt(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.6g", v);
    return b;
  }
  std::string cause_, remedy_;
  double t_;
};

class OutputError : public std::runtime_error {
 public:
  /// file: the file's name inside the run folder; reason: e.g. "disk full" or strerror text.
  OutputError(std::string file, std::string reason)
      : std::runtime_error("output failure: " + reason + " while writing " + file), file_(std::move(file)) {}
  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

}  // namespace swim
