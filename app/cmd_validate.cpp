// swim validate [SUITE] [--quick]: the 1D-vs-3D validation report (validation/suite.hpp).
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "app/app.hpp"
#include "app/ranks.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/si_format.hpp"
#include "validation/suite.hpp"

namespace fs = std::filesystem;

namespace swim::app {

int validate(const std::string& suite_opt, bool quick, const std::string& out_opt, int threads, int progress,
             const std::vector<std::string>& only) {
  const std::string suite =
      !suite_opt.empty() ? suite_opt : data_dir() + "/validation/" + (quick ? "quick.json" : "default.json");
  if (!fs::is_regular_file(suite))
    throw InputError("suite", "\"" + suite + "\"", "a suite file (shipped: data/validation/default.json, quick.json)");
  if (threads < 1 || threads > 64) throw InputError("--threads", std::to_string(threads), "an integer from 1 to 64");
  const scene::json s = validation::load_suite(suite, data_dir());  // bad input stops here, before anything is written
  for (const auto& n : only) {
    bool found = false;
    for (const auto& cs : s["cases"]) found = found || validation::case_selected_by(cs, n);
    if (!found) throw InputError("--case", n, "the scene file name or the name of a case of " + suite);
  }
  const std::string name = s.value("name", fs::path(suite).stem().string());
  const std::string out = out_opt.empty() ? "out/validation-" + name : out_opt;
  fs::create_directories(out);
  validation::SuiteOptions o;
  o.suite = suite;
  o.out_dir = out;
  o.data_dir = data_dir();
  o.threads = threads;
  o.only = only;
  if (progress != 0) o.progress = [](const std::string& line) { std::fprintf(stderr, "validate: %s\n", line.c_str()); };
  o.run_progress = progress;
  o.scenes_checked = true;
  if (ranks::distributed()) {
    // mpirun: the suite's 3D runs, axi runs and calibrations over the ranks (largest first; the
    // finest grid after the grid whose cycle sets its frame interval), into the suite's cache;
    // the report's pass below then reads them as it reads any cached run
    const scene::json plan = validation::plan_runs(o);
    // each run's own progress as whole lines prefixed by the run and its rank (the ranks share
    // one terminal); on when the master's stderr is a terminal or --progress forces it
    const int run_progress = progress > 0 || (progress < 0 && isatty(STDERR_FILENO) != 0) ? 1 : 0;
    std::vector<ranks::Task> tasks;
    for (std::size_t i = 0; i < plan.size(); ++i) {
      scene::json job = plan[i]["job"];
      job["progress"] = run_progress;
      tasks.push_back({plan[i]["label"].get<std::string>(),
                       {{"kind", "validate"},
                        {"job", std::move(job)},
                        {"tag", "run " + std::to_string(i + 1) + "/" + std::to_string(plan.size())}},
                       plan[i]["cost"].get<double>(),
                       plan[i]["after"].get<std::vector<std::size_t>>()});
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto now = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    validation::PlanClock clock(plan, ranks::size());
    std::vector<int> on_rank(tasks.size(), 0);
    size_t finished = 0;
    const ranks::Outcome r = ranks::distribute(
        tasks, run_task, 1,
        [&](size_t i, const scene::json& res) {
          ++finished;
          // a run read from the cache, not needed, or failed (often at once) does not time its kind
          const std::string status = res.value("status", std::string());
          const bool cached = res.value("cached", false), not_needed = status.rfind("not needed", 0) == 0;
          const bool computed = !res.contains("error") && !cached && !not_needed && status.rfind("failed", 0) != 0;
          const double t = now();
          clock.finished(i, t, computed);
          if (progress != 0)
            std::fprintf(stderr, "validate: run %zu/%zu %s on rank %d %s: %s; %zu of %zu done; %s\n", i + 1,
                         tasks.size(), tasks[i].label.c_str(), on_rank[i],
                         cached         ? "(from the cache)"
                         : not_needed   ? "(not needed)"
                                        : ("in " + si(t - clock.started_at(i), "s")).c_str(),
                         res.contains("error") ? res["error"].get<std::string>().c_str() : status.c_str(), finished,
                         tasks.size(),
                         finished == tasks.size() ? "the report next"
                                                  : validation::PlanClock::describe(clock.left(t)).c_str());
        },
        [&](size_t i, int rank) {
          on_rank[i] = rank;
          clock.started(i, now());
          if (progress != 0)
            std::fprintf(stderr, "validate: run %zu/%zu started on rank %d: %s\n", i + 1, tasks.size(), rank,
                         tasks[i].label.c_str());
        });
    std::printf("validation suite %s: %zu run(s) over %d ranks in %s%s\n", name.c_str(), tasks.size(), ranks::size(),
                si(r.wall_s, "s").c_str(),
                r.lost.empty() ? "" : (", " + std::to_string(r.lost.size()) + " rank(s) lost (their runs redone)").c_str());
    std::fflush(stdout);
  }
  const scene::json report = validation::run_suite(o);
  output::write_json(out + "/report.json", report);
  const bool plotted = plot("plot_validation.py", {out});
  // the verdicts against the suite's thresholds, and each 1D model's against the 1D tier's design
  // targets over the cases that state them (label: met, judged; in the suite's model order)
  int pass = 0, fail = 0, inconclusive = 0;
  std::vector<std::pair<std::string, std::array<int, 2>>> met;
  for (const auto& c : report["cases"])
    for (const auto& m : c["models1d"]) {
      const scene::json verdicts = m.value("verdicts", scene::json::object());
      for (const auto& [k, v] : verdicts.items()) {
        pass += v == "pass";
        fail += v == "fail";
        inconclusive += v == "inconclusive";
      }
      if (!m.contains("target_verdicts")) continue;
      const std::string label = m["label"];
      auto it = std::find_if(met.begin(), met.end(), [&](const auto& e) { return e.first == label; });
      if (it == met.end()) it = met.insert(met.end(), {label, {0, 0}});
      for (const auto& [k, v] : m["target_verdicts"].items()) {
        it->second[0] += v == "pass";
        ++it->second[1];
      }
    }
  std::printf("validation suite %s: %zu case(s), %d verdicts pass, %d fail, %d inconclusive; wall time %s\n  -> "
              "%s/report.json%s\n",
              name.c_str(), report["cases"].size(), pass, fail, inconclusive,
              si(report["wall_time_s"].get<double>(), "s").c_str(),
              out.c_str(), plotted ? ", report.md, report.html and figures" : "");
  for (const auto& [label, n] : met)
    std::printf("  1D model \"%s\": %d of %d design targets met\n", label.c_str(), n[0], n[1]);
  for (const auto& c : report["cases"])
    if (c.contains("reference") && c["reference"].contains("statement"))
      std::printf("  %s: axisymmetric reference %s\n", c["name"].get<std::string>().c_str(),
                  c["reference"]["statement"].get<std::string>().c_str());
  for (const auto& f : report["findings"])
    std::printf("  %-13s %s\n", f["status"].get<std::string>().c_str(), f["claim"].get<std::string>().c_str());
  const scene::json& cache = report["cache"];
  std::printf("  cache: %ld result(s) reused after verification, %zu rejected and recomputed%s\n",
              cache["reused"].get<long>(), cache["rejections"].size(), cache["rejections"].empty() ? "" : ":");
  for (const auto& r : cache["rejections"])
    std::printf("    %s: %s\n", r["path"].get<std::string>().c_str(), r["reason"].get<std::string>().c_str());
  if (!cache["verified"].get<bool>()) {
    const scene::json& u = cache["unverified"][0];
    std::fprintf(stderr, "swim: output failure: %zu result file(s) the report read changed while the suite ran (%s: %s); "
                 "run swim validate again to recompute them\n",
                 cache["unverified"].size(), u["path"].get<std::string>().c_str(), u["reason"].get<std::string>().c_str());
    return 3;
  }
  return 0;
}

}  // namespace swim::app
