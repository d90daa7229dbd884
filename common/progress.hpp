// Progress of long runs on stderr: percent of simulated time, simulation rate and the
// estimated wall time left. Quiet when stderr is not a terminal unless forced on; then (a log
// file, a pipe) it writes one whole line every 10 s instead of rewriting one line 4 times a
// second.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace swim {

class Progress {
 public:
  /// While alive, every Progress this thread creates puts `prefix` before its label and, with
  /// `lines`, writes whole lines even on a terminal (several processes sharing one terminal, the
  /// ranks of an MPI command, would otherwise overwrite each other's line). Nested contexts
  /// restore the outer one.
  class Context {
   public:
    Context(std::string prefix, bool lines);
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

   private:
    std::string saved_prefix_;
    bool saved_lines_;
  };

  /// enabled: -1 = only when stderr is a terminal, 0 = never, 1 = always.
  Progress(std::string label, double t_end, int enabled = -1);
  ~Progress();
  void update(double t);
  /// Coarse steps (each seconds long): "label: 23.1%  what  ~N s left" at step done of total, every step
  /// written (rewritten in place on a terminal).
  void step(std::size_t done, std::size_t total, const std::string& what);
  void done();

 private:
  std::string label_;
  double t_end_;
  bool on_;
  bool tty_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace swim
