// MPI ranks: the independent runs of a command spread over the processes of `mpirun -n N swim …`
// (docs/mpi.md). Rank 0 is the master: it hands out tasks (largest cost first, dynamically, as
// ranks become free), runs tasks itself in one thread of its own, gathers the results and
// writes every output; the other ranks only serve tasks. Without mpirun (or with one rank)
// nothing here is used and the commands run as a single process.
//
// Built with MPI when CMake finds it (option SWIM_MPI, ON by default); without it the functions
// below report one rank, and a launch by mpirun with more than one rank is refused.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "common/scene.hpp"

namespace swim::app::ranks {

using scene::json;

/// Initialises MPI (thread level FUNNELED: only the main thread calls MPI) when the process was
/// started by mpirun (its environment says so), finalises it at the end. Nothing otherwise.
class Session {
 public:
  Session(int* argc, char*** argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

int size();  ///< ranks of the job (1 without mpirun)
int rank();  ///< this process's rank (0 without mpirun)
inline bool distributed() { return size() > 1; }
/// true when this swim was built with MPI (SWIM_MPI and MPI found)
bool built_with_mpi();
/// A launch by mpirun with more than one rank of a swim built without MPI: the refusal ("" when fine).
std::string unsupported_launch();

/// A task's work: its payload in, its result out (both JSON). An exception becomes the result
/// {"error": message}, so a failed run is reported and the other tasks go on.
using Work = std::function<json(const json& payload)>;

/// Ranks > 0: serve the master's tasks until it stops them. Returns the process's exit code.
int serve(const Work& work);

struct Task {
  std::string label;  ///< names the run in messages ("design 4", "3d tiny_3d_cycle"); "" : "run <index>"
  json payload;
  double cost = 0;                 ///< the scheduling estimate: larger runs are handed out first
  std::vector<std::size_t> after;  ///< tasks that must have finished before this one starts
};

/// A rank that stopped answering (no message for lost_after_s()): the tasks it held were handed
/// to other ranks and redone.
struct LostRank {
  int rank = 0;
  std::vector<std::size_t> tasks;  ///< the tasks it held when it was declared lost (redone)
  double silent_s = 0;             ///< seconds without a message when it was declared lost
};

struct Outcome {
  std::vector<json> results;      ///< per task
  std::vector<int> ran_on;        ///< per task: the rank whose result was kept
  std::vector<LostRank> lost;     ///< ranks lost during this call
  double wall_s = 0;
  double master_cpu_s = 0;        ///< CPU time of rank 0's main thread (handing out, gathering)
};

/// Rank 0: run every task over the ranks and return the results in task order. depth: tasks a
/// remote rank may hold at once (2 hides the hand-over latency of short runs; 1 balances long
/// runs best). on_result(i, result) is called on rank 0's main thread as each result arrives;
/// on_start(i, rank) as task i is handed to a rank (0: rank 0's own thread; a lost rank's task
/// is handed out again).
/// Lost ranks (a crash, a kill) are reported on stderr and in the outcome; their tasks are redone
/// by the others. A SIGINT/SIGTERM/SIGHUP (mpirun stopping the job after a rank died without
/// --enable-recovery) prints the runs in flight and ends the process with 128 + the signal;
/// outside this call rank 0 says it was stopped and ends the same way (Session installs it).
Outcome distribute(const std::vector<Task>& tasks, const Work& work, int depth = 1,
                   const std::function<void(std::size_t, const json&)>& on_result = {},
                   const std::function<void(std::size_t, int)>& on_start = {});

/// Rank 0: tells every worker rank to stop (once; later calls do nothing). Session's end calls
/// it, whatever the command's outcome.
void stop_workers();

/// Every rank lost so far in this process (rank 0).
const std::vector<LostRank>& lost_ranks();
/// Seconds of silence after which a rank is declared lost: $SWIM_MPI_LOST_AFTER_S, default 60.
double lost_after_s();

/// {"ranks", "lost_ranks": [{"rank", "tasks", "silent_s"}], "tasks_per_rank", "master_cpu_s"} for a
/// command's summary; tasks_per_rank counts the results kept per rank over the process,
/// master_cpu_s the CPU time rank 0's main thread spent handing out and gathering runs.
json summary();

}  // namespace swim::app::ranks
