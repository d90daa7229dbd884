// Signals and child processes: `swim screen` interrupted (SIGINT, as Ctrl-C sends it, or
// SIGTERM) while its plotting child runs stops the child, waits for it, exits 128 + the signal
// with screen.json saying "interrupted", and never announces screen.png; no child outlives swim.
// Also the small command-line refusals: one line, nothing left behind.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "common/scene.hpp"
#include "tests/support/files.hpp"

extern char** environ;

namespace fs = std::filesystem;
using swim::scene::json;

namespace {

fs::path tmpdir(const std::string& tag) { return swim::test::scratch_dir("swim_signals_" + tag); }
using swim::test::slurp;

/// The PIDs whose parent is `parent` (from /proc).
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> out;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = slurp(e.path() / "stat");
    const auto close = stat.rfind(')');
    if (close == std::string::npos) continue;
    char state = 0;
    int ppid = 0;
    if (std::sscanf(stat.c_str() + close + 1, " %c %d", &state, &ppid) == 2 && ppid == parent)
      out.push_back(static_cast<pid_t>(std::stoi(name)));
  }
  return out;
}

struct Interrupted {
  int status = 0;
  pid_t child = 0;
  std::string out, err;
};

/// Starts swim with `args` (after the executable), sends `sig` to swim alone once its plotting
/// child runs, and waits for swim.
Interrupted interrupt_plot(const fs::path& dir, std::vector<std::string> args, int sig) {
  const std::string swim = SWIM_BINARY_DIR "/bin/swim";
  args.insert(args.begin(), swim);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, (dir / "stdout.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, (dir / "stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  Interrupted r;
  const int err = posix_spawn(&pid, swim.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (err != 0) return r;
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
    if (const auto c = children_of(pid); !c.empty()) {
      r.child = c.front();
      break;
    }
    int st = 0;
    if (::waitpid(pid, &st, WNOHANG) == pid) {  // ended before plotting
      r.status = st;
      return r;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(pid, sig);
  ::waitpid(pid, &r.status, 0);
  r.out = slurp(dir / "stdout.txt");
  r.err = slurp(dir / "stderr.txt");
  return r;
}

/// `swim screen` on a two-design sweep, interrupted while it plots.
Interrupted interrupt_screen(const fs::path& dir, int sig) {
  const json sweep = {{"base", SWIM_SOURCE_DIR "/data/scenes/demo.json"},
                      {"vary", {{"wave.contracted_ratio", {{"values", {0.5, 0.6}}}}}}};
  std::ofstream(dir / "sweep.json") << sweep.dump();
  return interrupt_plot(dir, {"screen", (dir / "sweep.json").string(), "--out", (dir / "out").string(), "--jobs", "1",
                              "--quiet"},
                        sig);
}

}  // namespace

// `swim run --plot` likewise: the results are complete, the command is not; summary.json says
// interrupted and does not list run.png.
TEST(Signals, AnInterruptDuringARunsPlotSaysInterruptedInItsSummary) {
  const fs::path dir = tmpdir("run_plot");
  const Interrupted r = interrupt_plot(
      dir, {"run", SWIM_SOURCE_DIR "/data/scenes/demo.json", "--plot", "--out", (dir / "out").string(), "--quiet"}, SIGINT);
  ASSERT_NE(r.child, 0) << "swim run never started its plotting child; stderr: " << slurp(dir / "stderr.txt");
  ASSERT_TRUE(WIFEXITED(r.status)) << "swim was killed by signal " << WTERMSIG(r.status);
  EXPECT_EQ(WEXITSTATUS(r.status), 128 + SIGINT) << r.err;
  EXPECT_EQ(::kill(r.child, 0), -1);
  const json summary = json::parse(slurp(dir / "out" / "summary.json"));
  EXPECT_EQ(summary["status"].get<std::string>().rfind("interrupted by SIGINT", 0), 0u) << summary["status"];
  EXPECT_NE(summary["status"].get<std::string>().find("the results are complete"), std::string::npos);
  for (const auto& f : summary["files"]) EXPECT_NE(f["name"], "run.png");
  EXPECT_TRUE(summary["displacement_per_cycle_m"].is_number());
  EXPECT_NE(r.err.find("interrupted by SIGINT"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

TEST(Signals, AnInterruptDuringPlottingStopsTheChildAndTheCommandSaysInterrupted) {
  for (const int sig : {SIGINT, SIGTERM}) {
    const fs::path dir = tmpdir("screen_" + std::to_string(sig));
    const Interrupted r = interrupt_screen(dir, sig);
    ASSERT_NE(r.child, 0) << "swim screen never started its plotting child; stderr: " << slurp(dir / "stderr.txt");
    ASSERT_TRUE(WIFEXITED(r.status)) << "swim was killed by signal " << WTERMSIG(r.status);
    EXPECT_EQ(WEXITSTATUS(r.status), 128 + sig) << r.err;
    // the child was waited for: it no longer exists, and writes no figure after swim exited
    EXPECT_EQ(::kill(r.child, 0), -1);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_FALSE(fs::exists(dir / "out" / "screen.png"));
    const json screen = json::parse(slurp(dir / "out" / "screen.json"));
    EXPECT_EQ(screen["status"].get<std::string>().rfind("interrupted by SIG", 0), 0u) << screen["status"];
    EXPECT_EQ(r.out.find("screen.png"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("interrupted by"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    fs::remove_all(dir);
  }
}

TEST(Signals, UsageErrorsAreOneLineAndAnEmptyOutIsRefused) {
  const fs::path dir = tmpdir("usage");
  const std::string swim = "\"" SWIM_BINARY_DIR "/bin/swim\" ";
  const std::string demo = SWIM_SOURCE_DIR "/data/scenes/demo.json";
  auto run = [&](const std::string& args) {
    const int st = std::system((swim + args + " > /dev/null 2> \"" + (dir / "err.txt").string() + "\"").c_str());
    return std::make_pair(WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(dir / "err.txt"));
  };
  for (const std::string& args : std::vector<std::string>{"run " + demo + " --tier 2d", "run " + demo + " " + demo,
                                                          "screen x.json --jobs -3", "run " + demo + " --out \"\"",
                                                          "validate --out \"\""}) {
    const auto [code, err] = run(args);
    EXPECT_EQ(code, 2) << args << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << args << ": " << err;
  }
  // an --out "" never writes the default folder
  const auto [code, err] = run("run " + demo + " --out \"\"");
  EXPECT_NE(err.find("--out"), std::string::npos) << err;
  // a refusal leaves nothing behind in a folder of the user's own files
  fs::create_directories(dir / "mine");
  std::ofstream(dir / "mine" / "notes.txt") << "mine";
  const auto [c2, e2] = run("run " + demo + " --quiet --out \"" + (dir / "mine").string() + "\"");
  EXPECT_EQ(c2, 2) << e2;
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir / "mine")) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"notes.txt"});
  fs::remove_all(dir);
}

// A plotting failure says why: a python3 without matplotlib (here an importable module that
// refuses to load) is named as such, and the command still succeeds with its data files.
TEST(Signals, APlottingFailureSaysMatplotlibIsMissing) {
  const fs::path dir = tmpdir("nompl");
  fs::create_directories(dir / "py" / "matplotlib");
  std::ofstream(dir / "py" / "matplotlib" / "__init__.py") << "raise ImportError('matplotlib stand-in')\n";
  const json sweep = {{"base", SWIM_SOURCE_DIR "/data/scenes/demo.json"},
                      {"vary", {{"wave.contracted_ratio", {{"values", {0.5, 0.6}}}}}}};
  std::ofstream(dir / "sweep.json") << sweep.dump();
  const std::string cmd = "PYTHONPATH=\"" + (dir / "py").string() + "\" \"" SWIM_BINARY_DIR "/bin/swim\" screen \"" +
                          (dir / "sweep.json").string() + "\" --out \"" + (dir / "out").string() +
                          "\" --quiet > /dev/null 2> \"" + (dir / "err.txt").string() + "\"";
  const int st = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(st));
  EXPECT_EQ(WEXITSTATUS(st), 0);
  const std::string err = slurp(dir / "err.txt");
  EXPECT_NE(err.find("python3-matplotlib is not installed"), std::string::npos) << err;
  EXPECT_TRUE(fs::exists(dir / "out" / "designs.csv"));
  EXPECT_FALSE(fs::exists(dir / "out" / "screen.png"));
  EXPECT_EQ(json::parse(slurp(dir / "out" / "screen.json"))["status"], "ok");
  fs::remove_all(dir);
}
