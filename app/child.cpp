// Child processes of swim (the plotting scripts): started with posix_spawn into their own
// process group; while one runs, SIGINT, SIGTERM and SIGHUP sent to swim are forwarded to that
// group and swim waits for the child before it goes on, so no child outlives the command. An
// interrupted child is reported as app::Interrupted (exit 128 + the signal, status
// "interrupted: ..."), never as a plotting failure.
#include <signal.h>
#include <spawn.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "app/app.hpp"

extern char** environ;

namespace swim::app {

namespace {

volatile std::sig_atomic_t g_signal = 0;     // the first signal received while a child runs
volatile std::sig_atomic_t g_child_group = 0;  // the child's process group (its PID), 0 when none

extern "C" void forward_signal(int sig) {
  if (g_signal == 0) g_signal = sig;
  const pid_t group = static_cast<pid_t>(g_child_group);
  if (group > 0) ::kill(-group, sig);
}

constexpr int kForwarded[] = {SIGINT, SIGTERM, SIGHUP};

/// The forwarding handlers, installed for the life of the object; the previous ones restored.
class SignalForwarding {
 public:
  SignalForwarding() {
    struct sigaction sa {};
    sa.sa_handler = forward_signal;
    sigemptyset(&sa.sa_mask);
    for (std::size_t k = 0; k < std::size(kForwarded); ++k) ::sigaction(kForwarded[k], &sa, &old_[k]);
  }
  ~SignalForwarding() {
    for (std::size_t k = 0; k < std::size(kForwarded); ++k) ::sigaction(kForwarded[k], &old_[k], nullptr);
  }
  SignalForwarding(const SignalForwarding&) = delete;
  SignalForwarding& operator=(const SignalForwarding&) = delete;

 private:
  struct sigaction old_[std::size(kForwarded)] {};
};

/// posix_spawnattr_t and posix_spawn_file_actions_t, destroyed by scope.
struct SpawnAttr {
  posix_spawnattr_t a;
  SpawnAttr() { posix_spawnattr_init(&a); }
  ~SpawnAttr() { posix_spawnattr_destroy(&a); }
  SpawnAttr(const SpawnAttr&) = delete;
  SpawnAttr& operator=(const SpawnAttr&) = delete;
};
struct SpawnActions {
  posix_spawn_file_actions_t a;
  SpawnActions() { posix_spawn_file_actions_init(&a); }
  ~SpawnActions() { posix_spawn_file_actions_destroy(&a); }
  SpawnActions(const SpawnActions&) = delete;
  SpawnActions& operator=(const SpawnActions&) = delete;
};

const char* signal_name(int sig) {
  switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
  }
}

}  // namespace

Interrupted::Interrupted(int sig, const std::string& during)
    : std::runtime_error(std::string("interrupted by ") + signal_name(sig) + " during " + during), signal_(sig) {}

ChildResult run_child(const std::vector<std::string>& argv, const std::string& what) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  SpawnAttr attr;
  SpawnActions actions;
  // the child's messages go to swim's stdout, with its own
  posix_spawn_file_actions_adddup2(&actions.a, STDOUT_FILENO, STDERR_FILENO);
  sigset_t defaults, none;
  sigemptyset(&defaults);
  for (int s : kForwarded) sigaddset(&defaults, s);
  sigemptyset(&none);
  posix_spawnattr_setsigdefault(&attr.a, &defaults);
  posix_spawnattr_setsigmask(&attr.a, &none);
  posix_spawnattr_setpgroup(&attr.a, 0);  // its own process group: the terminal's Ctrl-C reaches swim, which forwards it
  posix_spawnattr_setflags(&attr.a, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);

  ChildResult r;
  g_signal = 0;
  {
    const SignalForwarding forwarding;
    pid_t pid = 0;
    const int err = posix_spawn(&pid, args[0], &actions.a, &attr.a, args.data(), environ);
    if (err != 0) {
      r.spawn_error = std::strerror(err);
      return r;
    }
    g_child_group = pid;
    if (g_signal != 0) ::kill(-pid, g_signal);  // a signal that came before the group was known
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    g_child_group = 0;
    if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
    else if (WIFSIGNALED(status)) r.killed_by = WTERMSIG(status);
  }
  if (g_signal != 0) throw Interrupted(static_cast<int>(g_signal), what);
  return r;
}

bool plot(const std::string& script, const std::vector<std::string>& args) {
  // exit status 10 when matplotlib cannot be imported, the script's own status otherwise
  static const char* kRunner =
      "import sys, runpy\n"
      "try:\n"
      "    import matplotlib\n"
      "except ImportError:\n"
      "    sys.exit(10)\n"
      "sys.argv = sys.argv[1:]\n"
      "runpy.run_path(sys.argv[0], run_name='__main__')\n";
  std::vector<std::string> argv = {SWIM_PLOT_PYTHON, "-c", kRunner, std::string(SWIM_SOURCE_DIR) + "/tools/" + script};
  argv.insert(argv.end(), args.begin(), args.end());
  const ChildResult r = run_child(argv, "plotting with " + script);
  std::string why;
  if (!r.spawn_error.empty()) why = SWIM_PLOT_PYTHON + std::string(" could not be started: ") + r.spawn_error;
  else if (r.killed_by != 0) why = "the plotting process was killed by signal " + std::to_string(r.killed_by);
  else if (r.exit_code == 10) why = "python3-matplotlib is not installed";
  else if (r.exit_code != 0) why = "the script exited with status " + std::to_string(r.exit_code);
  if (why.empty()) return true;
  std::fprintf(stderr, "swim: warning: plotting with %s failed (%s); data files are complete\n", script.c_str(),
               why.c_str());
  return false;
}

}  // namespace swim::app
