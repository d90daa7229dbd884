// Error types behind the command-line exit codes of the product contract.
//
//   InputError      -> exit 2: bad scene, flag or sweep. Thrown before anything is written.
//                      The message names the key, the offending value and what is allowed.
//   NumericalError  -> exit 3: instability, solver non-convergence, radius collapse, a node
//                      spacing beyond h/2. The message names the likely cause and the
//                      parameter to change; the caller keeps the partial results.
#pragma once

#include <stdexcept>
#include <cstdio>
#include <string>

namespace swim {

class InputError : public std::runtime_error {
 public:
  InputError(std::string key, std::string value, std::string allowed)
      : std::runtime_error(format(key, value, allowed)), key_(std::move(key)) {}
  const std::string& key() const { return key_; }

 private:
  static std::string format(const std::string& key, const std::string& value,
                            const std::string& allowed) {
    std::string m = "invalid input: key '" + key + "'";
    if (!value.empty()) m += " = " + value;
    m += ": " + allowed;
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

}  // namespace swim
