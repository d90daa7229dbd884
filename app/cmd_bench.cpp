// swim bench: performance figures, measured in one run so that ratios are meaningful on a
// shared machine. 1D part: wall time of one force-driven cycle at N = 50, 200, 800 (best
// of several repetitions) and screening throughput (designs per second) on all cores.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include "app/app.hpp"
#include "common/output.hpp"
#include "common/scene.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"
#include "reduced1d/solver.hpp"

namespace swim::app {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

reduced1d::Params demo_params(const std::vector<std::string>& sets) {
  scene::json sc = scene::load_file(data_dir() + "/scenes/demo.json");
  for (const auto& s : sets) scene::apply_override(sc, s);
  scene::json resolved;
  return reduced1d::read_scene(sc, resolved, data_dir() + "/scenes");
}

}  // namespace

int bench(const std::string& out_opt, bool quick) {
  const std::string out = out_opt.empty() ? "out/bench" : out_opt;
  output::make_dir(out);
  scene::json report = scene::json::object();
  const int reps = quick ? 1 : 5;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  report["hardware_threads"] = cores;

  std::printf("== 1D tier ==\n");
  std::printf("one force-driven cycle (demo scene, best of %d):\n", reps);
  std::printf("  %6s %12s %10s %10s %10s\n", "N", "wall [ms]", "steps", "switches", "cycle [s]");
  scene::json cycles = scene::json::array();
  for (int n : {50, 200, 800}) {
    const auto p = demo_params({"numerics1d.cells=" + std::to_string(n), "protocol.cycles=1", "time.duration=\"auto\""});
    double best = 1e300;
    reduced1d::Result r;
    for (int k = 0; k < reps; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      r = reduced1d::solve(p);
      best = std::min(best, seconds_since(t0));
    }
    const auto m = reduced1d::metrics(p, r);
    const long steps = r.stats.count("steps") ? r.stats.at("steps") : 0;
    std::printf("  %6d %12.3f %10ld %10ld %10.4g%s\n", n, 1e3 * best, steps, r.switches, m.mean_cycle_time_s,
                r.failure ? "  FAILED" : "");
    cycles.push_back({{"cells", n}, {"wall_time_s", best}, {"steps", steps}, {"switches", r.switches},
                      {"cycle_time_s", m.mean_cycle_time_s}, {"ok", !r.failure}});
  }
  report["force_driven_cycle"] = cycles;

  std::printf("screening throughput (%u threads):\n", cores);
  scene::json thr = scene::json::object();
  for (const std::string kind : {"step", "force_driven"}) {
    const int n = kind == "step" ? (quick ? 100 : 1000) : (quick ? 20 : 100);
    std::vector<reduced1d::Params> designs;
    for (int k = 0; k < n; ++k) {
      const double lambda = 0.3 + 0.6 * (k % 10) / 9.0;
      const double length_um = 0.2 + 0.6 * (k / 10 % 10) / 9.0;
      char l[64], s[64];
      std::snprintf(l, sizeof l, "wave.contracted_ratio=%.4f", lambda);
      std::snprintf(s, sizeof s, "swimmer.length=\"%.4f um\"", length_um);
      std::vector<std::string> sets = {l, s, "wave.kind=\"" + kind + "\""};
      if (kind == "step") sets.push_back("protocol=null");
      designs.push_back(demo_params(sets));
    }
    const auto t0 = std::chrono::steady_clock::now();
    const auto res = reduced1d::run_designs(designs, 0);
    const double wall = seconds_since(t0);
    long failed = std::count_if(res.begin(), res.end(), [](const auto& r) { return !r.ok; });
    std::printf("  %-13s %6d designs in %8.3f s: %9.1f designs/s (%ld failed)\n", kind.c_str(), n, wall, n / wall, failed);
    thr[kind] = {{"designs", n}, {"wall_time_s", wall}, {"designs_per_s", n / wall}, {"failed", failed}};
  }
  report["screening"] = thr;
  output::write_json(out + "/bench.json", report);
  std::printf("  -> %s/bench.json\n", out.c_str());
  return 0;
}

}  // namespace swim::app
