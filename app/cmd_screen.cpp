#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/app.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/si_format.hpp"
#include "common/progress.hpp"
#include "common/run_folder.hpp"
#include "common/sweep.hpp"
#include "app/scene_checks.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"

namespace swim::app {

namespace fs = std::filesystem;

namespace {

std::string describe(const sweep::Sweep& sw, size_t k) {
  std::string s;
  const auto idx = sw.indices(k);
  for (size_t a = 0; a < sw.axes.size(); ++a)
    s += (a ? ", " : "") + sw.axes[a].key + "=" + sw.axes[a].values[idx[a]].dump();
  return s;
}

std::string csv_field(std::string s) {
  for (char& c : s)
    if (c == ',' || c == '\n') c = ';';
  return s;
}

}  // namespace

int screen(const std::string& sweep_path, const std::string& out_opt, int jobs, int progress, bool overwrite) {
  const sweep::Sweep sw = sweep::read_sweep(sweep_path, reduced1d::metric_names());
  check_sweep_scenes(sw);
  // Validate every design before running any of them (exit 2, nothing written).
  std::vector<reduced1d::Params> designs;
  designs.reserve(sw.count());
  for (size_t k = 0; k < sw.count(); ++k) {
    scene::json resolved;
    try {
      designs.push_back(reduced1d::read_scene(sw.design(k), resolved, sw.base_dir));
    } catch (const InputError& e) {
      throw InputError(e.key(), "", std::string("in design ") + std::to_string(k) + " (" + describe(sw, k) + "): " + e.what());
    }
  }
  const std::string name = fs::path(sweep_path).stem().string();
  const std::string out = out_opt.empty() ? "out/screen-" + name : out_opt;
  // The folder belongs to this sweep (lock, another run's results refused unless --overwrite,
  // the same sweep's finished results replaced); the sweep is identified by what it runs.
  scene::json identity = {{"base", sw.base}, {"metric", sw.metric}, {"goal", sw.maximize ? "max" : "min"}};
  for (const auto& a : sw.axes) identity["vary"].push_back({a.key, a.values});
  output::RunFolder folder(out, {"screen", identity, overwrite, false, "--out", "screen.json"});

  Progress bar("screen " + name, static_cast<double>(designs.size()), progress);
  size_t finished = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const auto results = reduced1d::run_designs(designs, jobs, [&](size_t) { bar.update(static_cast<double>(++finished)); });
  bar.done();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // designs.csv: axis values as given and in SI, then every metric; failed designs keep
  // their status and leave the metric cells empty (never NaN).
  const auto& names = reduced1d::metric_names();
  output::AtomicFile csv_file(out + "/designs.csv");  // published complete, or not at all
  std::ostream& csv = csv_file.stream();
  csv << "design";
  for (const auto& a : sw.axes) csv << "," << a.key << "," << a.key << "_si" << (a.si_unit.empty() ? "" : "[" + a.si_unit + "]");
  csv << ",status";
  for (const auto& m : names) csv << "," << m;
  csv << ",cycles_completed,wall_time_s\n";
  long best = -1, failed = 0;
  for (size_t k = 0; k < results.size(); ++k) {
    const auto idx = sw.indices(k);
    csv << k;
    for (size_t a = 0; a < sw.axes.size(); ++a) {
      const auto& v = sw.axes[a].values[idx[a]];
      csv << "," << csv_field(v.is_string() ? v.get<std::string>() : v.dump()) << "," << sw.axes[a].si[idx[a]];
    }
    const auto& r = results[k];
    csv << "," << (r.ok ? "ok" : "failed: " + csv_field(r.message));
    char b[32];
    for (const auto& m : names) {
      std::snprintf(b, sizeof b, "%.8g", reduced1d::metric_value(r.metrics, m));
      csv << "," << (r.ok ? b : "");
    }
    csv << "," << r.metrics.cycles_completed << "," << r.wall_time_s << "\n";
    if (!r.ok) {
      ++failed;
      continue;
    }
    const double v = reduced1d::metric_value(r.metrics, sw.metric);
    if (best < 0 || (sw.maximize ? v > reduced1d::metric_value(results[best].metrics, sw.metric)
                                 : v < reduced1d::metric_value(results[best].metrics, sw.metric)))
      best = static_cast<long>(k);
  }
  csv_file.commit();

  scene::json summary = {{"status", best >= 0 ? "ok" : "failed: every design failed numerically"},
                         {"sweep", sweep_path},
                         {"designs", results.size()},
                         {"failed", failed},
                         {"metric", sw.metric},
                         {"goal", sw.maximize ? "max" : "min"},
                         {"wall_time_s", wall},
                         {"designs_per_s", wall > 0 ? results.size() / wall : 0.0}};
  if (best >= 0) {
    summary["best_design"] = best;
    summary["best_values"] = describe(sw, best);
    summary["best_metric_value"] = reduced1d::metric_value(results[best].metrics, sw.metric);
    summary["best_scene"] = sw.design(best);
  }
  std::vector<std::string> plot_args = {out + "/designs.csv", out + "/screen.png", sw.metric, sw.name};
  for (const auto& a : sw.axes) plot_args.push_back(a.key);
  try {
    plot("plot_screen.py", plot_args);
  } catch (const Interrupted& e) {
    // the designs are complete; the figure is not: the status says so, and nothing announces it
    summary["status"] = std::string(e.what()) + "; designs.csv is complete, screen.png was not written";
    output::write_json(out + "/screen.json", summary);
    throw;
  }
  output::write_json(out + "/screen.json", summary);  // last: its status says the sweep finished

  std::printf("screened %zu designs in %.3g s (%.4g designs/s), %ld failed\n", results.size(), wall,
              summary["designs_per_s"].get<double>(), failed);
  if (best < 0) {
    std::fprintf(stderr, "swim: every design failed numerically; see %s/designs.csv for the causes\n", out.c_str());
    return 3;
  }
  const std::string unit = reduced1d::metric_unit(sw.metric);
  const double bv = reduced1d::metric_value(results[best].metrics, sw.metric);
  char value[64];
  if (unit == "m" || unit == "m/s" || unit == "m^3" || unit == "s")
    std::snprintf(value, sizeof value, "%s", si(bv, unit).c_str());
  else
    std::snprintf(value, sizeof value, "%.4g%s%s", bv, unit.empty() ? "" : " ", unit.c_str());
  std::printf("best by %s (%s): design %ld: %s -> %s\n  -> %s/designs.csv, %s/screen.png\n", sw.metric.c_str(),
              sw.maximize ? "max" : "min", best, describe(sw, best).c_str(), value, out.c_str(), out.c_str());
  return 0;
}

}  // namespace swim::app
