#include "app/ranks.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include <unistd.h>
#include <ctime>

#ifdef SWIM_HAVE_MPI
#include <mpi.h>
#endif

namespace swim::app::ranks {

namespace {

using Clock = std::chrono::steady_clock;

int g_size = 1, g_rank = 0;
[[maybe_unused]] bool g_mpi = false;      // MPI initialised by Session
[[maybe_unused]] bool g_stopped = false;  // stop_workers() done
std::vector<LostRank> g_lost;
std::map<int, long> g_kept;  // results kept per rank
double g_master_cpu = 0;     // s, rank 0's main thread in distribute()

[[maybe_unused]] double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// The job's size as the launcher's environment gives it (0 when not launched by one).
int launcher_size() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"})
    if (const char* s = std::getenv(v); s && *s) return std::atoi(s);
  if (std::getenv("PMIX_RANK")) return 1;  // started by a PMIx launcher, size unknown here
  return 0;
}

json error_result(const std::string& what) { return {{"error", what}}; }

json run_guarded(const Work& work, const json& payload);

/// Every task in this process, in order (no ranks to spread them over).
[[maybe_unused]] Outcome run_here(const std::vector<Task>& tasks, const Work& work,
                                  const std::function<void(std::size_t, const json&)>& on_result,
                                  const std::function<void(std::size_t, int)>& on_start) {
  Outcome o;
  const auto t0 = Clock::now();
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    if (on_start) on_start(i, 0);
    o.results.push_back(run_guarded(work, tasks[i].payload));
    o.ran_on.push_back(0);
    if (on_result) on_result(i, o.results.back());
  }
  o.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return o;
}

json run_guarded(const Work& work, const json& payload) {
  try {
    return work(payload);
  } catch (const std::exception& e) {
    return error_result(e.what());
  } catch (...) {
    return error_result("unknown exception");
  }
}

}  // namespace

int size() { return g_size; }
int rank() { return g_rank; }
double lost_after_s() {
  if (const char* s = std::getenv("SWIM_MPI_LOST_AFTER_S"); s && *s) {
    const double v = std::atof(s);
    if (v > 0) return v;
  }
  return 60.0;
}
const std::vector<LostRank>& lost_ranks() { return g_lost; }

json summary() {
  json lost = json::array();
  for (const auto& l : g_lost) lost.push_back({{"rank", l.rank}, {"tasks", l.tasks}, {"silent_s", l.silent_s}});
  json per = json::object();
  for (const auto& [r, n] : g_kept) per[std::to_string(r)] = n;
  return {{"ranks", g_size}, {"lost_ranks", lost}, {"tasks_per_rank", per}, {"master_cpu_s", g_master_cpu}};
}

#ifndef SWIM_HAVE_MPI

Session::Session(int*, char***) {}
Session::~Session() {}
bool built_with_mpi() { return false; }
std::string unsupported_launch() {
  if (launcher_size() > 1)
    return "this swim was built without MPI (libopenmpi-dev absent or SWIM_MPI=OFF at configure time), so mpirun "
           "would start " +
           std::to_string(launcher_size()) +
           " independent copies of the command; run it without mpirun, or rebuild with MPI (docs/mpi.md)";
  return {};
}
int serve(const Work&) { return 0; }
Outcome distribute(const std::vector<Task>& tasks, const Work& work, int,
                   const std::function<void(std::size_t, const json&)>& on_result,
                   const std::function<void(std::size_t, int)>& on_start) {
  return run_here(tasks, work, on_result, on_start);
}
void stop_workers() {}

#else  // SWIM_HAVE_MPI

namespace {

enum Tag : int { kReady = 1, kTask = 2, kResult = 3, kBeat = 4, kStop = 5, kBye = 6 };

void send_text(const std::string& s, int dest, int tag) {
  MPI_Send(s.data(), static_cast<int>(s.size()), MPI_CHAR, dest, tag, MPI_COMM_WORLD);
}

/// A waiting message's source, tag and text, or false.
bool receive_any(int& source, int& tag, std::string& text) {
  int flag = 0;
  MPI_Status st;
  MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
  if (!flag) return false;
  int n = 0;
  MPI_Get_count(&st, MPI_CHAR, &n);
  text.assign(static_cast<std::size_t>(n), '\0');
  MPI_Recv(text.data(), n, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  source = st.MPI_SOURCE;
  tag = st.MPI_TAG;
  return true;
}

/// Polling interval: short after activity, growing to `cap` µs when idle (a blocking MPI receive
/// would spin a core, which oversubscribed ranks cannot spare).
struct Backoff {
  int us = 20;
  void reset() { us = 20; }
  std::chrono::microseconds next(int cap) {
    const int v = std::min(us, cap);
    us = std::min(us * 2, cap);
    return std::chrono::microseconds(v);
  }
};

/// One thread running tasks from a queue (the worker ranks' compute thread, rank 0's own worker).
class Runner {
 public:
  explicit Runner(const Work& w) : work_(w), thread_([this] { loop(); }) {}
  ~Runner() {
    {
      std::lock_guard l(m_);
      quit_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  void push(std::size_t id, json payload) {
    {
      std::lock_guard l(m_);
      todo_.emplace_back(id, std::move(payload));
      ++held_;
    }
    cv_.notify_all();
  }
  /// Finished results; waits up to `wait` for one when none is ready.
  std::vector<std::pair<std::size_t, json>> take(std::chrono::microseconds wait) {
    std::unique_lock l(m_);
    if (done_.empty() && wait.count() > 0) done_cv_.wait_for(l, wait, [&] { return !done_.empty(); });
    std::vector<std::pair<std::size_t, json>> out(std::make_move_iterator(done_.begin()), std::make_move_iterator(done_.end()));
    done_.clear();
    held_ -= static_cast<int>(out.size());
    return out;
  }
  int held() {
    std::lock_guard l(m_);
    return held_;
  }

 private:
  void loop() {
    for (;;) {
      std::pair<std::size_t, json> t;
      {
        std::unique_lock l(m_);
        cv_.wait(l, [&] { return quit_ || !todo_.empty(); });
        if (quit_) return;
        t = std::move(todo_.front());
        todo_.pop_front();
      }
      json r = run_guarded(work_, t.second);
      {
        std::lock_guard l(m_);
        done_.emplace_back(t.first, std::move(r));
      }
      done_cv_.notify_all();
    }
  }
  const Work& work_;
  std::mutex m_;
  std::condition_variable cv_, done_cv_;
  std::deque<std::pair<std::size_t, json>> todo_, done_;
  int held_ = 0;  // pushed, result not yet taken
  bool quit_ = false;
  std::thread thread_;
};

volatile std::sig_atomic_t g_signal = 0;
volatile std::sig_atomic_t g_in_distribute = 0;
// Rank 0 of a distributed command: mpirun stops the job with SIGTERM (then SIGKILL) when a rank
// dies without --enable-recovery. While runs are handed out, the master's loop names the runs in
// flight; elsewhere this says why the command stops (only async-signal-safe calls here).
extern "C" void on_stop_signal(int s) {
  g_signal = s;
  if (g_in_distribute) return;
  static const char msg[] =
      "swim: stopped by a signal from mpirun (it ends the job when a rank dies; --enable-recovery lets the others "
      "go on); finished runs are kept in their folders: run the same command again to go on from them\n";
  const ssize_t ignored = ::write(2, msg, sizeof msg - 1);
  (void)ignored;
  std::_Exit(128 + s);
}

}  // namespace

Session::Session(int* argc, char*** argv) {
  if (launcher_size() == 0) return;  // not started by mpirun: a single process, as always
  // No barrier in Open MPI's MPI_Finalize: rank 0 ends the run by a stop that every live worker
  // answers (stop_workers), and that barrier would wait for a rank that died (--enable-recovery).
  // A value the user set is kept.
  ::setenv("OMPI_MCA_async_mpi_finalize", "1", 0);
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  g_mpi = true;
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  if (g_rank == 0 && g_size > 1) {
    struct sigaction act = {};
    act.sa_handler = on_stop_signal;
    sigemptyset(&act.sa_mask);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &act, nullptr);
  }
}

Session::~Session() {
  if (!g_mpi) return;
  if (g_rank == 0) stop_workers();
  MPI_Finalize();
}

bool built_with_mpi() { return true; }
std::string unsupported_launch() { return {}; }

int serve(const Work& work) {
  Runner runner(work);
  send_text("", 0, kReady);
  Backoff backoff;
  auto last_beat = Clock::now();
  for (;;) {
    bool busy = false;
    for (auto& [id, result] : runner.take(std::chrono::microseconds(0))) {
      send_text(json{{"task", id}, {"result", std::move(result)}}.dump(), 0, kResult);
      last_beat = Clock::now();
      busy = true;
    }
    int source = 0, tag = 0;
    std::string text;
    while (receive_any(source, tag, text)) {
      busy = true;
      if (tag == kStop) {  // the answer tells rank 0 that nothing more is in flight from here
        send_text("", 0, kBye);
        return 0;
      }
      if (tag == kTask) {
        json m = json::parse(text);
        runner.push(m["task"].get<std::size_t>(), std::move(m["payload"]));
      }
    }
    if (Clock::now() - last_beat > std::chrono::seconds(1)) {
      send_text("", 0, kBeat);
      last_beat = Clock::now();
    }
    if (busy) backoff.reset();
    // a finished task wakes the wait at once; a task from rank 0 is awaited only when this rank
    // holds fewer than two (one running, one waiting): then it is seen within 1 ms, else the
    // rank sleeps up to 20 ms (rank 0 sends nothing else but the stop at the end)
    for (auto& [id, result] : runner.take(backoff.next(runner.held() >= 2 ? 20000 : 1000))) {
      send_text(json{{"task", id}, {"result", std::move(result)}}.dump(), 0, kResult);
      last_beat = Clock::now();
      backoff.reset();
    }
  }
}

void stop_workers() {
  if (!g_mpi || g_rank != 0 || g_stopped) return;
  g_stopped = true;
  // Every live worker is told to stop and answers; MPI_Finalize then needs no barrier (Session).
  // A lost rank is sent nothing unless it speaks again (declared lost while alive, for example
  // starved of CPU): a send to a dead peer leaves a connection attempt pending.
  auto lost = [](int r) {
    return std::any_of(g_lost.begin(), g_lost.end(), [&](const LostRank& l) { return l.rank == r; });
  };
  std::vector<int> stage(static_cast<std::size_t>(g_size), 0);  // 0 not told, 1 told, 2 answered
  auto tell = [&](int r) {
    MPI_Send(nullptr, 0, MPI_CHAR, r, kStop, MPI_COMM_WORLD);
    stage[static_cast<std::size_t>(r)] = 1;
  };
  for (int r = 1; r < g_size; ++r)
    if (!lost(r)) tell(r);
  // lost ranks get more than a heartbeat interval (1 s) to show they are alive; a told rank
  // that never answers is given up after lost_after_s()
  const auto t0 = Clock::now();
  const double listen_s = g_lost.empty() ? 0.0 : 2.5, give_up_s = lost_after_s() + listen_s;
  Backoff backoff;
  for (;;) {
    int source = 0, tag = 0;
    std::string text;
    while (receive_any(source, tag, text)) {  // late beats and results are dropped
      int& st = stage[static_cast<std::size_t>(source)];
      if (tag == kBye) st = 2;
      else if (st == 0) tell(source);
      backoff.reset();
    }
    const double waited = std::chrono::duration<double>(Clock::now() - t0).count();
    const bool answered = std::none_of(stage.begin() + 1, stage.end(), [](int st) { return st == 1; });
    if ((answered && waited >= listen_s) || waited > give_up_s) break;
    std::this_thread::sleep_for(backoff.next(2000));
  }
}

namespace {
// the master's view of the worker ranks, kept over the calls of one command
struct RankState {
  bool serving = false;  // its kReady arrived
  int capacity = 0;      // tasks it may be given now
  std::vector<std::size_t> held;
  Clock::time_point heard;
  bool lost = false;
};
std::vector<RankState> g_ranks;
}  // namespace

Outcome distribute(const std::vector<Task>& tasks, const Work& work, int depth,
                   const std::function<void(std::size_t, const json&)>& on_result,
                   const std::function<void(std::size_t, int)>& on_start) {
  if (!g_mpi || g_size == 1) return run_here(tasks, work, on_result, on_start);
  Outcome o;
  const auto t0 = Clock::now();
  const double cpu0 = thread_cpu_s();
  const std::size_t n = tasks.size();
  o.results.assign(n, json());
  o.ran_on.assign(n, -1);
  if (g_ranks.empty()) g_ranks.resize(static_cast<std::size_t>(g_size));
  depth = std::max(1, depth);
  for (int r = 1; r < g_size; ++r) {
    RankState& rs = g_ranks[static_cast<std::size_t>(r)];
    rs.heard = t0;  // silence between calls is rank 0's own
    rs.capacity = rs.serving ? depth : 0;
  }
  const double lost_after = lost_after_s();

  // ready tasks: their `after` done, not handed out; handed out largest cost first
  std::vector<int> state(n, 0);  // 0 waiting, 1 handed out, 2 done
  auto ready = [&](std::size_t i) {
    if (state[i] != 0) return false;
    return std::all_of(tasks[i].after.begin(), tasks[i].after.end(), [&](std::size_t a) { return state[a] == 2; });
  };
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return tasks[a].cost > tasks[b].cost; });
  auto next_ready = [&]() -> long {
    for (std::size_t i : order)
      if (ready(i)) return static_cast<long>(i);
    return -1;
  };

  auto name = [&](std::size_t id) { return tasks[id].label.empty() ? "run " + std::to_string(id) : tasks[id].label; };
  std::size_t done = 0;
  Runner local(work);
  std::vector<std::size_t> local_held;
  std::vector<MPI_Request> sends;
  std::vector<std::unique_ptr<std::string>> send_buffers;  // alive until their sends complete
  auto finish = [&](std::size_t id, json result, int by) {
    if (state[id] == 2) return;  // a lost rank's late answer for a task redone elsewhere
    state[id] = 2;
    ++done;
    o.results[id] = std::move(result);
    o.ran_on[id] = by;
    ++g_kept[by];
    if (on_result) on_result(id, o.results[id]);
  };

  g_signal = 0;
  g_in_distribute = 1;

  Backoff backoff;
  while (done < n) {
    bool busy = false;
    // messages from the worker ranks
    int source = 0, tag = 0;
    std::string text;
    while (receive_any(source, tag, text)) {
      busy = true;
      RankState& rs = g_ranks[static_cast<std::size_t>(source)];
      rs.heard = Clock::now();
      if (rs.lost) continue;
      if (tag == kReady) {
        rs.serving = true;
        rs.capacity = depth;
      }
      if (tag == kResult) {
        json m = json::parse(text);
        const std::size_t id = m["task"].get<std::size_t>();
        rs.held.erase(std::remove(rs.held.begin(), rs.held.end(), id), rs.held.end());
        rs.capacity = depth - static_cast<int>(rs.held.size());
        finish(id, std::move(m["result"]), source);
      }
    }
    // rank 0's own thread
    for (auto& [id, result] : local.take(std::chrono::microseconds(0))) {
      local_held.erase(std::remove(local_held.begin(), local_held.end(), id), local_held.end());
      finish(id, std::move(result), 0);
      busy = true;
    }
    // lost ranks: their tasks go back to the queue
    const auto now = Clock::now();
    for (int r = 1; r < g_size; ++r) {
      RankState& rs = g_ranks[static_cast<std::size_t>(r)];
      const double silent = std::chrono::duration<double>(now - rs.heard).count();
      if (rs.lost || silent <= lost_after) continue;
      rs.lost = true;
      LostRank l{r, rs.held, silent};
      std::string list;
      for (std::size_t id : rs.held) {
        if (state[id] == 1) state[id] = 0;
        list += (list.empty() ? "" : ", ") + name(id);
      }
      std::fprintf(stderr, "swim: rank %d lost: no message for %.0f s (%s); %s\n", r, silent,
                   "it crashed, was killed or hangs",
                   list.empty() ? "it held no run" : ("its runs are redone by the other ranks: " + list).c_str());
      std::fflush(stderr);
      rs.held.clear();
      rs.capacity = 0;
      o.lost.push_back(l);
      g_lost.push_back(l);
      busy = true;
    }
    // hand out ready tasks: rank 0's own thread first (no hand-over), then the free ranks
    for (long i; local_held.empty() && (i = next_ready()) >= 0;) {
      state[i] = 1;
      local_held.push_back(static_cast<std::size_t>(i));
      if (on_start) on_start(static_cast<std::size_t>(i), 0);
      local.push(static_cast<std::size_t>(i), tasks[i].payload);
      busy = true;
    }
    for (int r = 1; r < g_size; ++r) {
      RankState& rs = g_ranks[static_cast<std::size_t>(r)];
      for (long i; !rs.lost && rs.capacity > 0 && (i = next_ready()) >= 0;) {
        state[i] = 1;
        rs.held.push_back(static_cast<std::size_t>(i));
        --rs.capacity;
        if (on_start) on_start(static_cast<std::size_t>(i), r);
        send_buffers.push_back(std::make_unique<std::string>(json{{"task", i}, {"payload", tasks[i].payload}}.dump()));
        sends.emplace_back();
        MPI_Isend(send_buffers.back()->data(), static_cast<int>(send_buffers.back()->size()), MPI_CHAR, r, kTask,
                  MPI_COMM_WORLD, &sends.back());
        busy = true;
      }
    }
    // completed sends release their buffers (a send to a lost rank is abandoned)
    for (std::size_t k = 0; k < sends.size();) {
      int flag = 0;
      MPI_Test(&sends[k], &flag, MPI_STATUS_IGNORE);
      if (flag) {
        sends.erase(sends.begin() + static_cast<long>(k));
        send_buffers.erase(send_buffers.begin() + static_cast<long>(k));
      } else {
        ++k;
      }
    }
    if (g_signal) {
      std::string flight;
      for (std::size_t id : local_held) flight += (flight.empty() ? "" : ", ") + name(id) + " on rank 0";
      for (int r = 1; r < g_size; ++r)
        for (std::size_t id : g_ranks[static_cast<std::size_t>(r)].held)
          flight += (flight.empty() ? "" : ", ") + name(id) + " on rank " + std::to_string(r);
      std::fprintf(stderr,
                   "swim: stopped by signal %d (mpirun ends the job when a rank dies; --enable-recovery lets the "
                   "others go on) with %zu of %zu run(s) finished; in flight: %s. Finished runs are kept where the "
                   "command keeps them (run folders); run the same command again to redo the rest\n",
                   static_cast<int>(g_signal), done, n, flight.empty() ? "none" : flight.c_str());
      std::fflush(stderr);
      std::_Exit(128 + g_signal);
    }
    if (busy) {
      backoff.reset();
    } else {
      // a result of rank 0's own thread wakes the wait at once; the ranks' messages are seen
      // within 2 ms (a rank holding two tasks does not wait for the hand-over)
      for (auto& [id, result] : local.take(backoff.next(2000))) {
        local_held.erase(std::remove(local_held.begin(), local_held.end(), id), local_held.end());
        finish(id, std::move(result), 0);
        backoff.reset();
      }
    }
  }
  g_in_distribute = 0;
  // sends still pending go to lost ranks only: abandoned, their buffers kept for the process's life
  static std::vector<std::unique_ptr<std::string>> abandoned;
  for (std::size_t k = 0; k < sends.size(); ++k) {
    MPI_Request_free(&sends[k]);
    abandoned.push_back(std::move(send_buffers[k]));
  }
  o.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  o.master_cpu_s = thread_cpu_s() - cpu0;
  g_master_cpu += o.master_cpu_s;
  return o;
}

#endif  // SWIM_HAVE_MPI

}  // namespace swim::app::ranks
