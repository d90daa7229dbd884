#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>

#include "app/app.hpp"
#include "app/scene_checks.hpp"
#include "axi/run_axi.hpp"
#include "axi/scene_axi.hpp"
#include "common/atomic_file.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/run_folder.hpp"
#include "common/run_record.hpp"
#include "common/progress.hpp"
#include "common/scene.hpp"
#include "common/si_format.hpp"
#include "full3d/run3d.hpp"
#include "full3d/run3d_output.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/report.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/solver.hpp"
#include "validation/error_estimate.hpp"

namespace swim::app {

namespace fs = std::filesystem;

std::string data_dir() {
  if (const char* d = std::getenv("SWIM_DATA_DIR")) return d;
  return SWIM_SOURCE_DIR "/data";
}

namespace {

// A prescribed wave has no protocol cycles: its per-cycle figures are those of its one transit.
bool is_transit(const scene::json& s) {
  return s["cycles_completed"].get<int>() == 0 && s["mean_velocity_per_cycle_m_per_s"].is_number();
}
std::string cycles_text(const scene::json& s) {
  if (is_transit(s)) return "one wave transit (prescribed wave, no protocol cycles)";
  const int n = s["cycles_completed"].get<int>();
  return std::to_string(n) + (n == 1 ? " cycle" : " cycles");
}

// run.png belongs to the run: listed in summary.json when drawn (the summary is committed again,
// still last); a rerun without --plot says that the earlier run's plot went with its results.
void plot_and_list(const std::string& out, bool plot_asked, bool had_plot) {
  const fs::path png = fs::path(out) / "run.png";
  if (!plot_asked) {
    if (had_plot && !fs::exists(png))
      std::fprintf(stderr, "swim: note: the earlier run.png in %s went with the earlier results; add --plot to draw this run\n",
                   out.c_str());
    return;
  }
  // the summary committed again (still last), after `change`
  auto rewrite_summary = [&](const std::function<void(scene::json&)>& change) { output::amend_summary(out, change); };
  try {
    if (!plot("plot_run.py", {out}) || !output::adopt(png.string())) return;
  } catch (const Interrupted& e) {
    // the results are complete; the command is not: the status says so, and run.png is not listed
    rewrite_summary([&](scene::json& j) {
      j["status"] = std::string(e.what()) + "; the results are complete, run.png was not written";
    });
    throw;
  }
  rewrite_summary([](scene::json&) {});
}

// One human-readable line per 1D run, SI prefixes; per-cycle figures only when a cycle completed.
void print_summary_1d(const std::string& name, const scene::json& s, double wall, const std::string& out) {
  std::string per_cycle;
  const bool transit = is_transit(s);
  if (s["mean_velocity_per_cycle_m_per_s"].is_number()) {
    char b[160];
    std::snprintf(b, sizeof b, "%s per %s, %s (%.3g body lengths/s)",
                  si(s["displacement_per_cycle_m"].get<double>(), "m").c_str(), transit ? "wave transit" : "cycle",
                  si(s["mean_velocity_per_cycle_m_per_s"].get<double>(), "m/s").c_str(),
                  s["body_lengths_per_cycle_per_s"].get<double>());
    per_cycle = b;
  } else {
    per_cycle = "no per-cycle figures (" + s["per_cycle_absent_because"].get<std::string>() + ")";
  }
  std::printf("%s (1d, %s): displacement %s; %s; %s; pumped %s; thermal rms %s per %s "
              "(directed/diffusive %.3g); wall time %s\n  -> %s/summary.json\n",
              name.c_str(), s["model"].get<std::string>().c_str(), si(s["displacement_m"].get<double>(), "m").c_str(),
              per_cycle.c_str(), cycles_text(s).c_str(), si(s["pumped_volume_m3"].get<double>(), "m^3").c_str(),
              si(s["brownian"]["thermal_rms_displacement_per_cycle_m"].get<double>(), "m").c_str(),
              transit ? "transit" : "cycle", s["brownian"]["directed_to_diffusive_ratio"].get<double>(), si(wall, "s").c_str(), out.c_str());
  for (const auto& w : s["implausible_because"])
    std::fprintf(stderr, "swim: warning: implausible result: %s\n", w.get<std::string>().c_str());
}

// A failure after the folder was taken: the summary says so (exit 3 for a write failure).
[[noreturn]] void fail_run(output::RunFolder& folder, const std::exception& e) {
  if (dynamic_cast<const OutputError*>(&e)) {
    const bool marked = folder.mark_failed(e.what());
    std::fprintf(stderr, "swim: partial results in %s are %s\n", folder.dir().c_str(),
                 marked ? "marked failed in summary.json" : "incomplete (summary.json removed)");
    throw;
  }
  if (!dynamic_cast<const InputError*>(&e)) folder.mark_failed(e.what());
  throw;
}

// --error-estimate: the same scene on a coarser grid (validation::coarse_grid), a run folder of
// its own in RUN/error_estimate/coarse (docs/full3d.md, "A run's own error estimate"). Read and
// checked as the run's own scene (InputError, exit 2, before anything is written).
validation::CoarseGrid coarse_run(const scene::json& sc, const full3d::Params3d& p) {
  validation::CoarseGrid c = validation::coarse_grid(sc, p, "--error-estimate");
  try {
    check_output_size(estimate_output(c.p), c.scene);
  } catch (const InputError& e) {
    throw InputError("--error-estimate", "the coarse grid full3d.grid.cells_across = " + std::to_string(c.cells),
                     std::string("the coarse run's scene is refused (") + e.what() +
                         "); refine the grid or leave --error-estimate out");
  }
  return c;
}

// Runs the coarse grid into its folder inside the run's. Its summary, or {"status": "failed: ..."}
// when it cannot give the per-cycle figures; a failure of the coarse run never fails the run.
scene::json run_coarse(const RunOptions& o, const validation::CoarseGrid& c, const std::string& out) {
  const std::string dir = validation::coarse_folder(out);
  auto failed = [&](const std::string& why) {
    output::reset_ledger(dir);  // the coarse run's files and failure are not the run's
    std::fflush(stdout);
    std::fprintf(stderr, "swim: error estimate: the coarse run failed (%s); the run goes on without an estimate\n",
                 why.c_str());
    return scene::json{{"status", "failed: the coarse run (" + std::to_string(c.cells) + " cells across): " + why}};
  };
  try {
    output::RunFolder folder(dir, {"3d", c.resolved, false, false, "--error-estimate"});
    full3d::RunControl ctl;
    ctl.progress = o.progress;
    ctl.max_output_bytes = static_cast<std::uintmax_t>(scene::output_limits(c.scene).max_bytes);
    full3d::RunOutcome r;
    try {
      r = full3d::run3d(c.p, c.resolved, dir, ctl);
    } catch (const std::exception& e) {
      folder.mark_failed(e.what());
      return failed(e.what());
    }
    if (r.failed) return failed(r.message);
    const auto& s = r.summary;
    if (!s["displacement_per_cycle_m"].is_number())
      return failed("no cycle completed (" + s.value("per_cycle_absent_because", std::string("no per-cycle figures")) + ")");
    std::printf("%s (3d, error estimate, coarse grid %d cells across, h = %s): %s per cycle, cycle %s; %ld steps; "
                "wall time %s\n  -> %s/summary.json\n",
                c.p.name.c_str(), c.cells, si(c.p.h, "m").c_str(), si(s["displacement_per_cycle_m"].get<double>(), "m").c_str(),
                si(s["cycle_time_s"].get<double>(), "s").c_str(), r.steps, si(s["wall_time_s"].get<double>(), "s").c_str(),
                dir.c_str());
    std::fflush(stdout);
    return s;
  } catch (const std::exception& e) {
    return failed(e.what());
  }
}

// The 3D tier: read and validate, run (full3d/run3d.hpp), report.
int run3d(const RunOptions& o, const scene::json& sc) {
  scene::json resolved;
  const full3d::Params3d p = full3d::read_scene3d(sc, resolved);
  check_other_tier(sc, "3d");
  full3d::check_fluid_memory(p);
  check_output_size(estimate_output(p), sc);
  if (!o.resume.empty() && !o.out.empty() && fs::path(o.out) != fs::path(o.resume))
    throw InputError("--out", o.out, "with --resume the run continues in the resumed folder; omit --out");
  if (!o.resume.empty() && o.overwrite)
    throw InputError("--overwrite", "", "cannot be combined with --resume (it would remove the run to continue)");
  if (!o.resume.empty() && o.error_estimate)
    throw InputError("--error-estimate", "--resume " + o.resume,
                     "cannot be combined with --resume (the estimate's coarse run is not continued); resume without "
                     "--error-estimate, or run the scene again with --error-estimate and --overwrite");
  std::optional<validation::CoarseGrid> coarse;
  if (o.error_estimate) coarse = coarse_run(sc, p);
  const std::string out = !o.resume.empty() ? o.resume : o.out.empty() ? "out/" + p.name + "-3d" : o.out;
  if (!o.resume.empty() && !fs::exists(full3d::checkpoint_path(out)))
    throw InputError("--resume", o.resume, "no checkpoint.bin in this folder");
  // a damaged or foreign checkpoint is refused before the folder is touched (a folder of
  // another tier is refused by the RunFolder below, naming its tier)
  if (!o.resume.empty()) {
    const std::string tier = output::RunFolder::tier_of(out);
    if (tier.empty() || tier == "3d") full3d::check_resumable(p, resolved, out);
  }
  const bool had_plot = fs::exists(fs::path(out) / "run.png");
  output::RunFolder folder(out, {"3d", resolved, o.overwrite, !o.resume.empty(), o.resume.empty() ? "--out" : "--resume"});
  full3d::RunControl ctl;
  ctl.progress = o.progress;
  ctl.max_output_bytes = static_cast<std::uintmax_t>(scene::output_limits(sc).max_bytes);
  ctl.resume = !o.resume.empty();
  scene::json coarse_summary;
  if (coarse) {
    if (o.progress != 0)
      std::fprintf(stderr, "swim: error estimate: 1 of 2, the coarse run (%d cells across, h = %s) into %s/error_estimate/coarse\n",
                   coarse->cells, si(coarse->p.h, "m").c_str(), out.c_str());
    coarse_summary = run_coarse(o, *coarse, out);
    if (o.progress != 0)
      std::fprintf(stderr, "swim: error estimate: 2 of 2, the run itself (%d cells across, h = %s)\n",
                   int(std::lround(2.0 * p.container_radius / p.h)), si(p.h, "m").c_str());
  }
  full3d::RunOutcome r;
  try {
    r = full3d::run3d(p, resolved, out, ctl);
    // the estimate joins the summary (committed again, still last) when the run itself finished
    if (coarse && !r.failed) {
      scene::json e = coarse_summary.contains("status") && coarse_summary["status"] != "ok"
                          ? coarse_summary
                          : validation::error_estimate_json(r.summary, coarse_summary, coarse->cells, p.h, coarse->p.h);
      output::amend_summary(out, [&](scene::json& j) { j["error_estimate"] = e; });
      r.summary["error_estimate"] = e;
    }
  } catch (const std::exception& e) {
    fail_run(folder, e);
  }
  const auto& s = r.summary;
  const int cycles = s["cycles_completed"].get<int>();
  std::string per_cycle = "no cycle completed";
  if (cycles > 0 && s.contains("cycle_times_s") && !s["cycle_times_s"].empty()) {
    double T = 0;
    for (const auto& v : s["cycle_times_s"]) T += v.get<double>();
    T /= double(s["cycle_times_s"].size());
    per_cycle = std::to_string(cycles) + (cycles == 1 ? " cycle of " : " cycles of ") + si(T, "s");
  }
  std::printf("%s (3d): displacement %s, mean velocity %s (%.3g body lengths/s); %s; pumped %s; %ld steps; "
              "wall time %s\n  -> %s/summary.json\n",
              p.name.c_str(), si(s["displacement_m"].get<double>(), "m").c_str(),
              si(s["mean_velocity_m_per_s"].get<double>(), "m/s").c_str(), s["body_lengths_per_s"].get<double>(),
              per_cycle.c_str(), si(s["pumped_volume_m3"].get<double>(), "m^3").c_str(), r.steps,
              si(s["wall_time_s"].get<double>(), "s").c_str(), out.c_str());
  std::fflush(stdout);
  for (const auto& w : s["implausible_because"])
    std::fprintf(stderr, "swim: warning: implausible result: %s\n", w.get<std::string>().c_str());
  if (s.contains("error_estimate")) {
    const auto& e = s["error_estimate"];
    if (e["status"] != "ok") {
      std::printf("  error estimate: %s\n", e["status"].get<std::string>().c_str());
    } else {
      for (const char* k : {"displacement_per_cycle_m", "cycle_time_s"}) {
        const auto& f = e[k];
        const char* unit = std::string(k) == "cycle_time_s" ? "s" : "m";
        std::printf("  error estimate, %s: %s on this grid, %s on %d cells across; extrapolated %s, interval [%s, %s]\n",
                    std::string(k) == "cycle_time_s" ? "cycle time" : "displacement per cycle",
                    si(f["fine"].get<double>(), unit).c_str(), si(f["coarse"].get<double>(), unit).c_str(),
                    e["coarse_cells_across"].get<int>(), si(f["extrapolated_order1"].get<double>(), unit).c_str(),
                    si(f["interval_low"].get<double>(), unit).c_str(), si(f["interval_high"].get<double>(), unit).c_str());
      }
    }
  }
  // a wall that buckled into lobes beyond half a cell: what chose the lobes (the seed or the
  // grid), and whether they changed during the run (full3d::wrinkle_note)
  std::fflush(stdout);  // the note follows the result line, also when both go to one file
  if (const std::string note = full3d::wrinkle_note(s); !note.empty()) std::fprintf(stderr, "%s\n", note.c_str());
  plot_and_list(out, o.plot, had_plot);
  if (r.failed) {
    std::fprintf(stderr, "swim: %s\n  partial results and the last checkpoint kept in %s\n", r.message.c_str(),
                 out.c_str());
    return 3;
  }
  return 0;
}

// The axisymmetric reference tier: read and validate, run (axi/run_axi.hpp), report.
int run_axi(const RunOptions& o, const scene::json& sc) {
  scene::json resolved;
  const axi::ParamsAxi p = axi::read_scene_axi(sc, resolved);
  check_other_tier(sc, "axi");
  if (!o.resume.empty() && !o.out.empty() && fs::path(o.out) != fs::path(o.resume))
    throw InputError("--out", o.out, "with --resume the run continues in the resumed folder; omit --out");
  if (!o.resume.empty() && o.overwrite)
    throw InputError("--overwrite", "", "cannot be combined with --resume (it would remove the run to continue)");
  const std::string out = !o.resume.empty() ? o.resume : o.out.empty() ? "out/" + p.name() + "-axi" : o.out;
  if (!o.resume.empty() && !fs::exists(full3d::checkpoint_path(out)))
    throw InputError("--resume", o.resume, "no checkpoint.bin in this folder");
  // a damaged or foreign checkpoint is refused before the folder is touched
  if (!o.resume.empty()) {
    const std::string tier = output::RunFolder::tier_of(out);
    if (tier.empty() || tier == "axi") axi::check_resumable_axi(p, resolved, out);
  }
  const bool had_plot = fs::exists(fs::path(out) / "run.png");
  output::RunFolder folder(out, {"axi", resolved, o.overwrite, !o.resume.empty(), o.resume.empty() ? "--out" : "--resume"});
  axi::RunControlAxi ctl;
  ctl.progress = o.progress;
  ctl.max_output_bytes = static_cast<std::uintmax_t>(scene::output_limits(sc).max_bytes);
  ctl.resume = !o.resume.empty();
  axi::RunOutcomeAxi r;
  try {
    r = axi::run_axi(p, resolved, out, ctl);
  } catch (const std::exception& e) {
    fail_run(folder, e);
  }
  const auto& s = r.summary;
  std::string per_cycle = "no cycle completed";
  if (s["mean_velocity_per_cycle_m_per_s"].is_number())
    per_cycle = si(s["displacement_per_cycle_m"].get<double>(), "m") + (is_transit(s) ? " per wave transit in " : " per cycle in ") +
                si(s["cycle_time_s"].get<double>(), "s") + ", " +
                si(s["mean_velocity_per_cycle_m_per_s"].get<double>(), "m/s");
  const std::string grid = p.method == axi::AxiMethod::ImmersedBoundary
                               ? std::to_string(p.nr) + " x " + std::to_string(p.nx) + " cells"
                               : std::string(p.triangles ? "the fitted triangles" : "the fitted quadrilaterals");
  std::printf("%s (axi): displacement %s; %s; %s; pumped %s; %ld steps on %s (h = %s); wall time %s\n"
              "  -> %s/summary.json\n",
              p.name().c_str(), si(s["displacement_m"].get<double>(), "m").c_str(), per_cycle.c_str(),
              cycles_text(s).c_str(), si(s["pumped_volume_m3"].get<double>(), "m^3").c_str(), r.steps, grid.c_str(),
              si(p.h, "m").c_str(), si(s["wall_time_s"].get<double>(), "s").c_str(), out.c_str());
  std::fflush(stdout);
  for (const auto& w : s["implausible_because"])
    std::fprintf(stderr, "swim: warning: implausible result: %s\n", w.get<std::string>().c_str());
  plot_and_list(out, o.plot, had_plot);
  if (r.failed) {
    std::fprintf(stderr, "swim: %s\n  partial results and the last checkpoint kept in %s\n", r.message.c_str(), out.c_str());
    return 3;
  }
  return 0;
}

}  // namespace

int run(const RunOptions& o) {
  // 1. Everything is read and validated before anything is written.
  if (o.error_estimate && o.tier != "3d")
    throw InputError("--error-estimate", "--tier " + o.tier,
                     "only a 3D run (--tier 3d) estimates its own discretisation error, by a second run on a coarser "
                     "grid; add --tier 3d or leave --error-estimate out");
  scene::json sc = scene::load_file(o.scene);
  for (const auto& s : o.sets) scene::apply_override(sc, s);
  if (o.threads > 0) {
    if (o.tier == "axi") {
      if (o.threads > 2)
        throw InputError("--threads", std::to_string(o.threads),
                         "1 or 2 with --tier axi (axi.threads: the second thread factors the systems the first solves)");
      scene::apply_override(sc, "axi.threads=" + std::to_string(o.threads));
    } else if (o.tier != "3d") {
      if (o.threads > 2)
        throw InputError("--threads", std::to_string(o.threads),
                         "1 or 2 with the 1D tier (numerics1d.threads: the second thread evaluates the force-driven "
                         "run's output samples while the first integrates); more with --tier 3d");
      scene::apply_override(sc, "numerics1d.threads=" + std::to_string(o.threads));
    } else {
      scene::apply_override(sc, "full3d.threads=" + std::to_string(o.threads));
    }
  }
  if (o.tier == "3d") return run3d(o, sc);
  if (o.tier == "axi") return run_axi(o, sc);
  if (!o.resume.empty())
    throw InputError("--resume", o.resume, "only the 3D and axisymmetric tiers write checkpoints; add --tier 3d or --tier axi");
  scene::json resolved;
  const std::string scene_dir = fs::path(o.scene).parent_path().string();
  const reduced1d::Params p = reduced1d::read_scene(sc, resolved, scene_dir.empty() ? "." : scene_dir);
  check_other_tier(sc, "1d");
  check_output_size(estimate_output(p), sc);
  check_auto_run_output(p, sc);
  const std::string out = o.out.empty() ? "out/" + p.name + "-1d" : o.out;

  // 2. Take the folder, run: the series and radius samples stream to disk as they are
  // produced (nothing is buffered in memory).
  const bool had_plot = fs::exists(fs::path(out) / "run.png");
  output::RunFolder folder(out, {"1d", resolved, o.overwrite, false, "--out"});
  const auto t0 = std::chrono::steady_clock::now();
  Progress progress("1d " + p.name, reduced1d::end_time(p), o.progress);
  std::unique_ptr<record::RunStream> stream;
  reduced1d::Result r;
  scene::json summary;
  try {
    stream = std::make_unique<record::RunStream>(out, reduced1d::series_columns());
    stream->limit(static_cast<std::uintmax_t>(scene::output_limits(sc).max_bytes));
    reduced1d::SolveOptions so;
    so.progress = [&](double t, double) { progress.update(t); };
    so.keep_samples = false;
    so.stream = stream.get();
    r = reduced1d::solve(p, so);
    progress.done();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // 3. Write (partial results too; summary.json last), report.
    summary = reduced1d::write_run(out, p, resolved, r, wall);
  } catch (const std::exception& e) {
    fail_run(folder, e);
  }
  const double wall = summary["wall_time_s"].get<double>();
  plot_and_list(out, o.plot, had_plot);
  print_summary_1d(p.name, summary, wall, out);
  if (r.failure) {
    std::fprintf(stderr, "swim: %s\n  partial results kept in %s\n", r.failure->what(), out.c_str());
    return 3;
  }
  return 0;
}

int demo(const std::string& out, int progress) {
  RunOptions o;
  o.scene = data_dir() + "/scenes/demo.json";
  o.out = out.empty() ? "out/demo" : out;
  o.progress = progress;
  o.plot = true;
  return run(o);
}

int scenes() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(data_dir() + "/scenes"))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    const scene::json j = scene::load_file(f.string());
    std::printf("%-34s %s\n", f.filename().string().c_str(), j.value("description", std::string("")).c_str());
  }
  return 0;
}

}  // namespace swim::app
