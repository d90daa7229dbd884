#include "common/progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <string>
#include <utility>

namespace swim {

namespace {
thread_local std::string t_prefix;
thread_local bool t_lines = false;
}  // namespace

Progress::Context::Context(std::string prefix, bool lines) : saved_prefix_(t_prefix), saved_lines_(t_lines) {
  t_prefix = std::move(prefix);
  t_lines = lines;
}

Progress::Context::~Context() {
  t_prefix = std::move(saved_prefix_);
  t_lines = saved_lines_;
}

Progress::Progress(std::string label, double t_end, int enabled)
    : label_(t_prefix + std::move(label)), t_end_(t_end),
      on_(enabled < 0 ? isatty(STDERR_FILENO) != 0 : enabled > 0), tty_(!t_lines && isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() { done(); }

void Progress::update(double t) {
  if (!on_ || t_end_ <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(tty_ ? 250 : 10000)) return;
  last_ = now;
  const double wall = std::chrono::duration<double>(now - start_).count();
  const double frac = t / t_end_;
  const double rate = wall > 0 ? t / wall : 0.0;  // simulated seconds per wall second
  const double left = frac > 0 ? wall * (1.0 - frac) / frac : 0.0;
  std::fprintf(stderr, tty_ ? "\r%s: %5.1f%%  t = %.4g s  %.3g sim-s/s  ~%.0f s left   "
                            : "%s: %5.1f%%  t = %.4g s  %.3g sim-s/s  ~%.0f s left\n",
               label_.c_str(), 100.0 * frac, t, rate, left);
  std::fflush(stderr);
}

void Progress::step(std::size_t done, std::size_t total, const std::string& what) {
  if (!on_ || total == 0) return;
  const auto now = std::chrono::steady_clock::now();
  last_ = now;
  const double wall = std::chrono::duration<double>(now - start_).count();
  const double frac = double(done) / double(total);
  const double left = frac > 0 ? wall * (1.0 - frac) / frac : 0.0;
  std::fprintf(stderr, tty_ ? "\r%s: %5.1f%%  %s  ~%.0f s left   " : "%s: %5.1f%%  %s  ~%.0f s left\n",
               label_.c_str(), 100.0 * frac, what.c_str(), left);
  std::fflush(stderr);
}

void Progress::done() {
  if (on_ && !finished_) {
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (tty_)
      std::fprintf(stderr, "\r%s: done in %.2f s%40s\n", label_.c_str(), wall, "");
    else
      std::fprintf(stderr, "%s: done in %.2f s\n", label_.c_str(), wall);
  }
  finished_ = true;
}

}  // namespace swim
