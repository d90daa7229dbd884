#!/usr/bin/env bash
# The MPI figures of docs/performance.md ("Over MPI ranks"): 1D screening throughput with
# 2 ranks x 1 thread against 1 rank x 2 threads, and the MPI overhead per 1D design with 3 ranks
# on 2 cores. Benchmarks, not tests.
#
#   tools/bench_mpi.sh [SWIM] [OUT]     (default build/bin/swim, out/bench-mpi; REPEAT=2, SIDE=20)
#
# The sweep is data/sweeps/eps_lambda_force.json made denser (SIDE lengths x SIDE ratios of
# force-driven designs). Each configuration runs REPEAT times; the run with the least CPU time
# is kept. Two measures of each:
#   - wall: designs/s of screen.json (the 1D phase alone, plots excluded);
#   - CPU: user + system time of the whole command and its children (/usr/bin/time: MPI start-up,
#     rank 0's handing out and gathering, the ranks' polling, the plot, every design).
# On a machine shared with other work the wall figures measure the scheduler as much as the
# program (with kernel.sched_autogroup_enabled, mpirun's ranks form their own scheduling group
# and take a share of the cores apart from the shell's); the CPU figures do not.
set -euo pipefail
root="$(cd "$(dirname "$(readlink -f "${BASH_SOURCE[0]}")")/.." && pwd)"
swim="${1:-$root/build/bin/swim}"
out="${2:-out/bench-mpi}"
repeat="${REPEAT:-2}"
side="${SIDE:-20}"
mkdir -p "$out"
sweep="$out/sweep.json"
/usr/bin/python3 - "$root/data/sweeps/eps_lambda_force.json" "$sweep" "$side" <<'PY'
import json, os, sys
s = json.load(open(sys.argv[1]))
s["name"] = "bench_mpi"
s["base"] = os.path.join(os.path.dirname(os.path.abspath(sys.argv[1])), s["base"])
s["vary"]["swimmer.length"]["count"] = int(sys.argv[3])
s["vary"]["wave.contracted_ratio"]["count"] = int(sys.argv[3])
json.dump(s, open(sys.argv[2], "w"), indent=1)
PY
mpi=(mpirun --oversubscribe)
[[ $(id -u) -eq 0 ]] && mpi+=(--allow-run-as-root)

measure() {  # tag jobs-flag command...: "designs_per_s cpu_s wall_s master_cpu_s" of the least-CPU run
  local tag=$1 jobs=$2; shift 2
  for ((i = 0; i < repeat; ++i)); do
    /usr/bin/time -f "%U %S %e" -o "$out/$tag.time" "$@" screen "$sweep" --quiet --overwrite --out "$out/$tag" $jobs > /dev/null
    /usr/bin/python3 -c "
import json
s = json.load(open('$out/$tag/screen.json'))
u, k, e = map(float, open('$out/$tag.time').read().split()[-3:])
print(s['designs_per_s'], u + k, e, s.get('mpi', {}).get('master_cpu_s', 0))"
  done | sort -g -k2 | head -1
}

r1=$(measure jobs1 "--jobs 1" "$swim")
r2t=$(measure jobs2 "--jobs 2" "$swim")
r2r=$(measure ranks2 "" "${mpi[@]}" -n 2 "$swim")
r3r=$(measure ranks3 "" "${mpi[@]}" -n 3 "$swim")
/usr/bin/python3 - "$out/bench-mpi.json" "$((side * side))" "$(nproc)" "$r1" "$r2t" "$r2r" "$r3r" "$(cut -d' ' -f1-3 /proc/loadavg)" <<'PY'
import json, sys
f, n, cores = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
conf = ["1_rank_1_thread", "1_rank_2_threads", "2_ranks_1_thread", "3_ranks_on_2_cores"]
m = {c: dict(zip(["designs_per_s", "cpu_s", "wall_s", "master_cpu_s"], map(float, v.split())))
     for c, v in zip(conf, sys.argv[4:8])}
cpu1 = m["1_rank_1_thread"]["cpu_s"] / n  # one design's own CPU time, plot and start-up included
res = {
    "designs": n, "cores": cores, "load_average_at_end": sys.argv[8], "runs": m,
    # designs per CPU-second, 2 ranks against 2 threads (1 = MPI costs nothing more)
    "throughput_2_ranks_over_2_threads_cpu": m["1_rank_2_threads"]["cpu_s"] / m["2_ranks_1_thread"]["cpu_s"],
    "throughput_2_ranks_over_2_threads_wall": m["2_ranks_1_thread"]["designs_per_s"] / m["1_rank_2_threads"]["designs_per_s"],
    "cpu_per_design_s": cpu1,
    # CPU that 3 ranks on 2 cores spend per design beyond the single process, over a design's own CPU time
    "mpi_overhead_per_design_3_ranks_2_cores": (m["3_ranks_on_2_cores"]["cpu_s"] - m["1_rank_1_thread"]["cpu_s"]) / n / cpu1,
    "rank0_master_cpu_per_design_fraction_3_ranks": m["3_ranks_on_2_cores"]["master_cpu_s"] / n / cpu1,
}
json.dump(res, open(f, "w"), indent=1)
print(json.dumps(res, indent=1))
PY
