// swim optimize SPEC.json: the best design of a parameter box on the 1D tier (design/optimize.hpp),
// confirmed in 3D (design/confirm.hpp). Writes trajectory.csv, optimum.scene.json, optimize.png,
// confirm.json, confirm.md, confirm.png, and optimum.json last.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/app.hpp"
#include "app/ranks.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/progress.hpp"
#include "common/run_folder.hpp"
#include "common/si_format.hpp"
#include "design/confirm.hpp"
#include "design/optimize.hpp"
#include "full3d/scene3d.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/screen.hpp"

namespace swim::app {
namespace fs = std::filesystem;

namespace {

std::string value_text(const design::Parameter& p, double v) {
  if (!p.integer && (p.si_unit == "m" || p.si_unit == "s")) return si(v * p.to_si, p.si_unit, 4);
  const scene::json j = p.scene_value(v);
  return j.is_string() ? j.get<std::string>() : j.dump();
}

}  // namespace

int optimize(const std::string& spec_path, const std::string& out_opt, int progress, bool overwrite, bool confirm,
             int threads) {
  const design::Spec spec = design::read_spec(spec_path);
  const std::size_t n = spec.parameters.size();
  std::vector<double> start(n);
  for (std::size_t i = 0; i < n; ++i) start[i] = spec.parameters[i].start;
  if (confirm) {  // the designs must run on the confirming tier too: the start's scene is checked before anything runs
    try {
      const scene::json sc = design::confirm_scene(spec.design(start), spec.confirm, threads);
      design::check_confirm_scene(sc, spec.confirm);
      design::check_error_estimate(sc, spec.confirm, "confirm");
    } catch (const InputError& e) {
      const std::string L = design::tier_label(design::confirm_tier(spec.confirm));
      throw InputError(e.key(), "", "the start design on the " + L + " tier (add --no-confirm to skip the " + L +
                                        " run): " + e.what());
    }
  }
  const std::string out = out_opt.empty() ? "out/optimize-" + spec.name : out_opt;
  scene::json identity = scene::load_file(spec_path);
  identity.erase("description");
  identity["base"] = spec.base;
  if (identity.contains("confirm")) {
    const scene::json c = design::confirm_identity(identity["confirm"]);
    if (c.is_null()) identity.erase("confirm");
    else identity["confirm"] = c;
  }
  output::RunFolder folder(out, {"optimize", identity, overwrite, false, "--out", "optimum.json", "confirm-runs"});

  design::SearchOptions so;
  for (const auto& p : spec.parameters) {
    so.lo.push_back(p.lo);
    so.hi.push_back(p.hi);
  }
  so.start = start;
  so.constraints = spec.constraint_count();
  so.maximize = spec.maximize;
  so.max_evaluations = spec.max_evaluations;
  so.xtol_rel = spec.tolerance;
  if (ranks::distributed())
    // COBYLA chooses each point from the evaluations before it: the search is sequential, and
    // so is the single 3D run of its optimum; the other ranks wait for the command to end
    std::printf("optimize: COBYLA evaluates one design at a time (each point follows from the ones before), so the "
                "search and its 3D confirmation run on rank 0; the other %d rank(s) have nothing to run\n",
                ranks::size() - 1);
  Progress bar("optimize " + spec.name, spec.max_evaluations, progress);
  std::vector<double> wall_of;
  const auto t0 = std::chrono::steady_clock::now();
  const design::SearchResult r = design::search(so, [&](const std::vector<double>& x) {
    const auto t = std::chrono::steady_clock::now();
    design::Evaluation e = design::evaluate_1d(spec, x);
    wall_of.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
    bar.update(static_cast<double>(wall_of.size()));
    return e;
  });
  bar.done();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // trajectory.csv: every evaluation in order, SI values with their units in the column names
  {
    output::AtomicFile f(out + "/trajectory.csv");
    std::ostream& csv = f.stream();
    csv << "evaluation";
    for (const auto& p : spec.parameters) csv << "," << p.key << "_si" << (p.si_unit.empty() ? "" : "[" + p.si_unit + "]");
    csv << "," << spec.objective << ",best_so_far_" << spec.objective;
    if (spec.min_ratio > 0) csv << ",directed_to_diffusive_constraint";
    if (std::isfinite(spec.max_load_Pa)) csv << ",load_constraint";
    csv << ",feasible,status,wall_time_s\n";
    long best = -1;
    char b[40];
    for (std::size_t k = 0; k < r.trajectory.size(); ++k) {
      const auto& e = r.trajectory[k];
      if (e.feasible() && (best < 0 || (spec.maximize ? e.objective > r.trajectory[best].objective
                                                      : e.objective < r.trajectory[best].objective)))
        best = static_cast<long>(k);
      csv << k;
      for (std::size_t i = 0; i < n; ++i) {
        const auto& p = spec.parameters[i];
        const double v = p.integer ? std::round(e.x[i]) : e.x[i];
        csv << "," << output::csv_number(v * p.to_si, b);
      }
      csv << "," << (e.ok ? std::string(output::csv_number(e.objective, b)) : "");
      csv << "," << (best >= 0 ? std::string(output::csv_number(r.trajectory[best].objective, b)) : "");
      for (double g : e.constraints) csv << "," << (e.ok ? std::string(output::csv_number(g, b)) : "");
      std::string msg = e.ok ? "ok" : "failed: " + e.message;
      for (char& c : msg)
        if (c == ',' || c == '\n') c = ';';
      csv << "," << (e.feasible() ? 1 : 0) << "," << msg << "," << wall_of[k] << "\n";
    }
    f.commit();
  }

  const std::string unit = reduced1d::metric_unit(spec.objective);
  auto shown = [&](double v) {
    if (unit == "m" || unit == "m/s") return si(v, unit);
    char b[48];
    std::snprintf(b, sizeof b, "%.4g %s", v, unit.c_str());
    return std::string(b);
  };
  std::size_t feasible = 0;
  for (const auto& e : r.trajectory) feasible += e.feasible();
  scene::json summary = {{"status", "ok"},
                         {"spec", spec_path},
                         {"name", spec.name},
                         {"algorithm", "NLopt LN_COBYLA (derivative-free, bounds and inequality constraints), "
                                       "coordinates scaled to [0, 1]"},
                         {"stop_reason", r.stop_reason},
                         {"objective", spec.objective},
                         {"goal", spec.maximize ? "max" : "min"},
                         {"evaluations", r.trajectory.size()},
                         {"feasible_evaluations", feasible},
                         {"wall_time_s", wall}};
  std::vector<std::string> plot_args = {out + "/trajectory.csv", out + "/optimize.png", spec.objective, spec.name};
  for (const auto& p : spec.parameters) {
    char b[80];
    std::snprintf(b, sizeof b, "%.10g:%.10g", p.lo * p.to_si, p.hi * p.to_si);
    plot_args.push_back(b);
  }
  plot("plot_optimize.py", plot_args);
  std::printf("optimize %s: %zu evaluations in %s (%zu feasible), %s\n", spec.name.c_str(), r.trajectory.size(),
              si(wall, "s").c_str(), feasible, r.stop_reason.c_str());
  if (r.best < 0) {
    std::string why = "the 1D runs (see trajectory.csv)";
    if (spec.min_ratio > 0) {  // the ratio reached: g = (min - ratio) / min
      double g = 1;
      for (const auto& e : r.trajectory)
        if (e.ok) g = std::min(g, e.constraints[0]);
      char b[160];
      std::snprintf(b, sizeof b, "constraints.min_directed_to_diffusive_ratio = %g (the largest ratio reached: %.3g)",
                    spec.min_ratio, spec.min_ratio * (1 - g));
      why = b;
    }
    summary["status"] = "failed: no feasible design among " + std::to_string(r.trajectory.size()) +
                        " evaluations; the binding constraint: " + why;
    output::write_json(out + "/optimum.json", summary);
    std::fflush(stdout);
    std::fprintf(stderr, "swim: %s\n  the trajectory is kept in %s/trajectory.csv\n",
                 summary["status"].get<std::string>().c_str(), out.c_str());
    return 3;
  }
  const design::Evaluation& best = r.trajectory[r.best];
  scene::json params = scene::json::object();
  std::string best_text;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = spec.parameters[i];
    params[p.key] = {{"value", p.scene_value(best.x[i])}, {"si", (p.integer ? std::round(best.x[i]) : best.x[i]) * p.to_si}};
    best_text += (i ? ", " : "") + p.key + " = " + value_text(p, best.x[i]);
  }
  const scene::json best_scene = spec.design(best.x);
  output::write_json(out + "/optimum.scene.json", best_scene);
  summary["best_evaluation"] = r.best;
  summary["best_parameters"] = params;
  summary["best_objective"] = best.objective;
  summary["best_scene"] = best_scene;
  std::printf("best (evaluation %ld): %s -> %s %s\n", r.best, best_text.c_str(), spec.objective.c_str(),
              shown(best.objective).c_str());
  int code = 0;
  if (confirm) {
    scene::json resolved;
    const reduced1d::Params p = reduced1d::read_scene(best_scene, resolved, spec.base_dir);
    const auto one = reduced1d::run_designs({p}, 1);
    design::ConfirmOptions o{spec.objective, spec.maximize, spec.confirm, threads, progress, out + "/confirm-runs", {}};
    std::vector<design::Candidate> optimum = {{0, best_text, "optimum", 1, best_scene, one[0].metrics, {}, {}}};
    design::match_recovery_end(optimum[0], spec.base_dir);  // the 1D cycle ends as the confirming run's
    const std::string tier = design::confirm_tier(spec.confirm), T = "_" + tier;
    scene::json report = design::confirm_candidates(optimum, o);
    report["agreement_absent_because"] = "one design (the optimum) is confirmed: the agreement is its relative differences";
    output::write_json(out + "/confirm.json", report);
    {
      output::AtomicFile md(out + "/confirm.md");
      md.stream() << design::confirm_markdown(report, design::tier_title(tier) + " confirmation of the optimum of " + spec.name);
      md.commit();
    }
    plot("plot_confirm.py", {out + "/confirm.json", out + "/confirm.png", spec.name + " (optimum)"});
    const scene::json& d = report["designs"][0];
    summary["confirm"] = {{"status", report["status"]},
                          {"file", "confirm.json"},
                          {"figures_1d", d["figures_1d"]},
                          {"figures" + T, d["figures" + T]},
                          {"relative_difference" + T + "_vs_1d", d["relative_difference" + T + "_vs_1d"]}};
    const scene::json& rel = d["relative_difference" + T + "_vs_1d"][spec.objective];
    const std::string t = design::tier_short(tier);
    std::printf("%s confirmation: %s; %s %s, (%s - 1D)/|%s| = %s\n  -> %s/confirm.md\n",
                design::tier_title(tier).c_str(),
                report["status"].get<std::string>().c_str(), t.c_str(),
                d["figures" + T][spec.objective].is_number() ? shown(d["figures" + T][spec.objective].get<double>()).c_str() : "n/a",
                t.c_str(), t.c_str(),
                rel.is_number() ? (std::to_string(static_cast<int>(std::lround(100 * rel.get<double>()))) + " %").c_str() : "n/a",
                out.c_str());
    if (report["status"] != "ok") code = 3;
  }
  output::write_json(out + "/optimum.json", summary);  // last: its status says the search finished
  std::printf("  -> %s/optimum.json, %s/trajectory.csv, %s/optimize.png\n", out.c_str(), out.c_str(), out.c_str());
  std::fflush(stdout);
  if (code != 0)
    std::fprintf(stderr, "swim: the %s confirmation run failed: %s\n",
                 design::tier_label(design::confirm_tier(spec.confirm)).c_str(),
                 summary["confirm"]["status"].get<std::string>().c_str());
  return code;
}

}  // namespace swim::app
