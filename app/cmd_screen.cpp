#include <cctype>
#include <cstdlib>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "app/app.hpp"
#include "app/ranks.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/si_format.hpp"
#include "common/progress.hpp"
#include "common/run_folder.hpp"
#include "common/sweep.hpp"
#include "app/scene_checks.hpp"
#include "design/confirm.hpp"
#include "design/rank_agreement.hpp"
#include "full3d/scene3d.hpp"
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

// An SI base unit as UDUNITS spells it ("m", "m.s-1", "m-1.kg.s-1") in the column style of
// series.csv: "m", "m_per_s", "kg_per_m_s".
std::string unit_suffix(const std::string& unit) {
  std::vector<std::string> up, down;
  std::string token;
  const auto flush = [&] {
    if (token.empty()) return;
    std::size_t k = 0;
    while (k < token.size() && std::isalpha(static_cast<unsigned char>(token[k]))) ++k;
    const std::string name = token.substr(0, k);
    const int e = k < token.size() ? std::atoi(token.c_str() + k) : 1;
    const std::string power = std::abs(e) > 1 ? std::to_string(std::abs(e)) : "";
    (e < 0 ? down : up).push_back(name + power);
    token.clear();
  };
  for (char c : unit) {
    if (c == '.' || c == ' ' || c == '*') flush();
    else token += c;
  }
  flush();
  std::string out;
  for (const auto& u : up) out += (out.empty() ? "" : "_") + u;
  if (!down.empty()) out += out.empty() ? "per" : "_per";
  for (const auto& d : down) out += "_" + d;
  return out;
}

// Human-facing value of a metric: SI prefixes for lengths, velocities, times, volumes.
std::string shown(double v, const std::string& metric) {
  const std::string unit = reduced1d::metric_unit(metric);
  if (unit == "m" || unit == "m/s" || unit == "m^3" || unit == "s") return si(v, unit);
  char b[64];
  std::snprintf(b, sizeof b, "%.4g%s%s", v, unit.empty() ? "" : " ", unit.c_str());
  return b;
}

// The confirmation runs of `cands` over the MPI ranks, in candidate order. A run whose rank
// reported an error (not a numerical failure, which the run's own summary records) is a failed
// run of that design.
std::vector<design::Confirmed> confirm_over_ranks(const std::vector<design::Candidate>& cands,
                                                  const design::ConfirmOptions& o) {
  fs::create_directories(o.runs_dir);
  std::vector<ranks::Task> tasks;
  for (const auto& c : cands) {
    const scene::json sc = design::confirm_scene(c.scene, o.section, o.threads);
    tasks.push_back({design::tier_label(design::confirm_tier(o.section)) + " run of design " + std::to_string(c.design),
                     {{"kind", "confirm3d"},
                      {"tier", design::confirm_tier(o.section)},
                      {"scene", sc},
                      {"runs_dir", fs::absolute(o.runs_dir).string()},
                      {"label", design::confirm_label(c)},
                      {"error_estimate", design::wants_error_estimate(o.section)},
                      {"metric", o.metric}},
                     cost_3d(sc),
                     {}});
  }
  const ranks::Outcome r = ranks::distribute(tasks, run_task, 1);
  std::vector<design::Confirmed> runs;
  for (size_t i = 0; i < cands.size(); ++i) {
    if (r.results[i].contains("error")) {
      design::Confirmed c;
      c.folder = (fs::path(o.runs_dir) / design::confirm_label(cands[i])).string();
      c.summary = {{"status", "failed: " + r.results[i]["error"].get<std::string>()}};
      runs.push_back(c);
    } else {
      runs.push_back(design::confirmed_from_json(r.results[i]));
    }
  }
  return runs;
}

// --confirm K: the K/2 best and K/2 spread over the rest of the ranking, run in 3D (or on the
// axisymmetric tier, confirm.tier = "axi"), compared with the 1D tier; writes confirm.json,
// confirm.md, confirm.png and returns the summary for screen.json.
scene::json confirm_sweep(const sweep::Sweep& sw, const std::vector<reduced1d::DesignOutcome>& results, size_t k,
                          const scene::json& section, int threads, int progress, const std::string& out) {
  std::vector<size_t> ranked;
  for (size_t i = 0; i < results.size(); ++i)
    if (results[i].ok) ranked.push_back(i);
  auto value = [&](size_t i) { return reduced1d::metric_value(results[i].metrics, sw.metric); };
  std::stable_sort(ranked.begin(), ranked.end(),
                   [&](size_t a, size_t b) { return sw.maximize ? value(a) > value(b) : value(a) < value(b); });
  const std::vector<size_t> chosen = design::select_for_confirmation(ranked, k);
  std::vector<design::Candidate> cands;
  for (size_t c = 0; c < chosen.size(); ++c) {
    const size_t i = chosen[c];
    const long rank = static_cast<long>(std::find(ranked.begin(), ranked.end(), i) - ranked.begin()) + 1;
    cands.push_back({i, describe(sw, i), c < chosen.size() - chosen.size() / 2 ? "best" : "spread", rank, sw.design(i),
                     results[i].metrics, "", std::nullopt});  // the recovery end matched below
    design::match_recovery_end(cands.back(), sw.base_dir);  // the 1D cycle ends as the confirming run's
  }
  const std::string tier = design::confirm_tier(section);
  std::printf("confirming %zu of %zu designs %s (%zu best, %zu spread over the rest)%s\n", cands.size(),
              ranked.size(), tier == "axi" ? "on the axisymmetric tier" : "in 3D", cands.size() - cands.size() / 2, cands.size() / 2,
              cands.size() < k ? "; fewer designs completed in 1D than --confirm asks" : "");
  std::fflush(stdout);
  design::ConfirmOptions o{sw.metric, sw.maximize, section, threads, progress, out + "/confirm-runs", {}};
  std::vector<design::Confirmed> ranked_runs;
  if (ranks::distributed()) {
    // the confirmation runs over the ranks (largest first, one at a time per rank), gathered here; the
    // report below is then written from them exactly as from runs made in this process
    ranked_runs = confirm_over_ranks(cands, o);
    o.run = [&](size_t i, const scene::json&, const std::string&) { return ranked_runs[i]; };
  }
  scene::json report = design::confirm_candidates(cands, o, [&](size_t c, const design::Confirmed& r) {
    const auto& d = cands[c];
    const auto f3 = design::figures_confirming(r.summary, sw.metric);
    const std::string t = design::tier_short(tier);
    std::printf("  design %zu (%s, 1D rank %ld): 1D %s, %s %s; %s%s\n", d.design, d.values.c_str(), d.rank_in_sweep,
                shown(value(d.design), sw.metric).c_str(), t.c_str(),
                f3[sw.metric].is_number() ? shown(f3[sw.metric].get<double>(), sw.metric).c_str() : "n/a",
                r.reused ? "finished run reused" : (t + " run " + si(r.summary.value("wall_time_s", 0.0), "s")).c_str(),
                r.ok ? "" : (" -- " + r.summary.value("status", std::string())).c_str());
    std::fflush(stdout);
  });
  report["sweep"] = sw.name;
  report["selection"] = {{"requested", k},
                         {"rule", "the ceil(K/2) best by the sweep's metric, then floor(K/2) spread evenly over the rest "
                                  "of the 1D ranking (the worst included)"},
                         {"designs_completed_1d", ranked.size()}};
  output::write_json(out + "/confirm.json", report);
  {
    output::AtomicFile md(out + "/confirm.md");
    md.stream() << design::confirm_markdown(report, design::tier_title(tier) + " confirmation of the sweep " + sw.name);
    md.commit();
  }
  plot("plot_confirm.py", {out + "/confirm.json", out + "/confirm.png", sw.name});
  if (report["agreement"].is_object()) {
    const auto& a = report["agreement"];
    char tau[96] = "undefined (every pair tied)";
    if (a["kendall_tau"].is_number())
      std::snprintf(tau, sizeof tau, "%.3g [%.3g, %.3g]", a["kendall_tau"].get<double>(),
                    a["kendall_tau_ci_95"][0].get<double>(), a["kendall_tau_ci_95"][1].get<double>());
    const std::string tied = tier == "axi" ? std::string()
                                           : std::to_string(a["pairs_tied_by_3d_error_bars"].get<std::size_t>()) +
                                                 " pair(s) tied by the 3D error bars, ";
    std::printf("rank agreement over %d designs: Kendall tau %s, Spearman rho %.3g [%.3g, %.3g] (95 %%); "
                "%s%zu misranked design(s)\n  -> %s/confirm.md, %s/confirm.png\n",
                a["designs"].get<int>(), tau, a["spearman_rho"].get<double>(),
                a["spearman_rho_ci_95"][0].get<double>(), a["spearman_rho_ci_95"][1].get<double>(), tied.c_str(),
                report["misranked_designs"].size(), out.c_str(), out.c_str());
  }
  scene::json s = {{"status", report["status"]}, {"designs", report["designs_confirmed"]}, {"file", "confirm.json"}};
  if (report["agreement"].is_object()) {
    s["kendall_tau"] = report["agreement"]["kendall_tau"];
    s["spearman_rho"] = report["agreement"]["spearman_rho"];
  }
  return s;
}

// --grid-check: the scene of the sweep's design k on `factor` times its cells (numerics1d.cells),
// as a user's --set would give it.
scene::json refined_scene(const sweep::Sweep& sw, size_t k, const reduced1d::Params& at_n, int factor) {
  scene::json sc = sw.design(k);
  scene::apply_override(sc, "numerics1d.cells=" + std::to_string(at_n.numerics.cells * factor));
  return sc;
}

// The grid check's summary (screen.json "grid_check"): per design the metric's relative change
// from N to factor N cells, the designs beyond `tolerance`, the rank agreement of the two
// rankings over the designs that completed on both grids, and the best design on each.
scene::json grid_check_summary(const sweep::Sweep& sw, const std::vector<reduced1d::DesignOutcome>& at_n,
                               const std::vector<reduced1d::DesignOutcome>& refined, int factor, double tolerance,
                               std::vector<double>& change) {
  std::vector<double> x, y;
  std::vector<size_t> both;
  long over = 0, failed_refined = 0, largest_at = -1;
  double largest = 0;
  change.assign(at_n.size(), std::numeric_limits<double>::quiet_NaN());  // (never written: a cell stays empty)
  for (size_t k = 0; k < at_n.size(); ++k) {
    if (!refined[k].ok) {
      if (at_n[k].ok) ++failed_refined;
      continue;
    }
    if (!at_n[k].ok) continue;
    const double a = reduced1d::metric_value(at_n[k].metrics, sw.metric);
    const double b = reduced1d::metric_value(refined[k].metrics, sw.metric);
    if (!std::isfinite(a) || !std::isfinite(b) || b == 0) continue;
    change[k] = (a - b) / std::abs(b);
    if (std::abs(change[k]) > tolerance) ++over;
    if (std::abs(change[k]) > largest) largest = std::abs(change[k]), largest_at = static_cast<long>(k);
    x.push_back(a);
    y.push_back(b);
    both.push_back(k);
  }
  const auto best_of = [&](const std::vector<double>& v) {
    size_t i = 0;
    for (size_t j = 1; j < v.size(); ++j)
      if (sw.maximize ? v[j] > v[i] : v[j] < v[i]) i = j;
    return static_cast<long>(both[i]);
  };
  scene::json g = {{"cells_factor", factor},
                   {"tolerance_relative", tolerance},
                   {"change_definition", "(metric on N cells - metric on " + std::to_string(factor) +
                                             " N cells) / |metric on " + std::to_string(factor) + " N cells|"},
                   {"designs_compared", both.size()},
                   {"designs_over_tolerance", over},
                   {"failed_on_refined_grid", failed_refined}};
  if (both.empty()) {
    g["status"] = "no design completed on both grids";
    return g;
  }
  std::vector<double> abs_change;
  for (size_t k : both) abs_change.push_back(std::abs(change[k]));
  std::sort(abs_change.begin(), abs_change.end());
  g["status"] = "ok";
  g["largest_change_relative"] = change[largest_at < 0 ? both[0] : largest_at];
  g["largest_change_design"] = largest_at < 0 ? static_cast<long>(both[0]) : largest_at;
  const size_t mid = abs_change.size() / 2;
  g["median_abs_change_relative"] =
      abs_change.size() % 2 ? abs_change[mid] : 0.5 * (abs_change[mid - 1] + abs_change[mid]);
  const long best_n = best_of(x), best_refined = best_of(y);
  g["best_design"] = best_n;
  g["best_design_on_refined_grid"] = best_refined;
  g["best_design_unchanged"] = best_n == best_refined;
  if (both.size() >= 2) {
    const design::RankAgreement ra = design::rank_agreement(x, y);
    g["kendall_tau"] = ra.kendall_defined ? scene::json(ra.kendall_tau) : scene::json(nullptr);
    g["spearman_rho"] = ra.spearman_rho;
    g["misranked_pairs"] = ra.misranked.size();
  }
  return g;
}

}  // namespace

int screen(const std::string& sweep_path, const std::string& out_opt, int jobs, int progress, bool overwrite,
           int confirm, int threads, double grid_check) {
  const int factor = 2;  // --grid-check: every design again on twice its cells
  if (grid_check != 0 && !(grid_check > 0 && grid_check < 1))
    throw InputError("--grid-check", std::to_string(grid_check),
                     "a relative tolerance of the metric's change on twice the cells, in (0, 1), e.g. 0.05");
  const sweep::Sweep sw = sweep::read_sweep(sweep_path, reduced1d::metric_names());
  check_sweep_scenes(sw);
  // --confirm K: checked in full (K, the metric, every design's scene on the confirming tier)
  // before any 1D run
  scene::json confirm_section;
  if (confirm > 0) {
    if (static_cast<size_t>(confirm) > sw.count())
      throw InputError("--confirm", std::to_string(confirm),
                       "must be at most the number of designs in the sweep (" + std::to_string(sw.count()) + ")");
    if (confirm < 2)
      throw InputError("--confirm", std::to_string(confirm), "must be at least 2 (a rank agreement needs two designs)");
    design::check_metric_in_3d(sw.metric, "metric");
    confirm_section = design::read_confirm_section(sw.confirm, "confirm");
    for (size_t k = 0; k < sw.count(); ++k) {
      try {
        const scene::json sc = design::confirm_scene(sw.design(k), confirm_section, threads);
        design::check_confirm_scene(sc, confirm_section);
        design::check_error_estimate(sc, confirm_section, "confirm");
      } catch (const InputError& e) {
        throw InputError(e.key(), "", std::string("in design ") + std::to_string(k) + " (" + describe(sw, k) +
                                          ") on the " + design::tier_label(design::confirm_tier(confirm_section)) +
                                          " tier: " + e.what());
      }
    }
  } else if (!sw.confirm.is_null()) {
    design::read_confirm_section(sw.confirm, "confirm");
  }
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
  const size_t n_designs = designs.size();
  std::vector<scene::json> refined_scenes;  // --grid-check: designs[n_designs + k]'s scene
  if (grid_check > 0) {
    for (size_t k = 0; k < n_designs; ++k) {
      try {
        refined_scenes.push_back(refined_scene(sw, k, designs[k], factor));
        scene::json resolved;
        designs.push_back(reduced1d::read_scene(refined_scenes.back(), resolved, sw.base_dir));
      } catch (const InputError& e) {
        throw InputError(e.key(), "", std::string("in design ") + std::to_string(k) + " (" + describe(sw, k) +
                                          ") on " + std::to_string(factor) + " times its cells (--grid-check): " + e.what());
      }
    }
  }
  const std::string name = fs::path(sweep_path).stem().string();
  const std::string out = out_opt.empty() ? "out/screen-" + name : out_opt;
  // The folder belongs to this sweep (lock, another run's results refused unless --overwrite,
  // the same sweep's finished results replaced); the sweep is identified by what it runs.
  scene::json identity = {{"base", sw.base}, {"metric", sw.metric}, {"goal", sw.maximize ? "max" : "min"}};
  for (const auto& a : sw.axes) identity["vary"].push_back({a.key, a.values});
  if (const scene::json c = design::confirm_identity(sw.confirm); !c.is_null()) identity["confirm"] = c;
  if (grid_check > 0) identity["grid_check"] = {{"cells_factor", factor}, {"tolerance_relative", grid_check}};
  // the runs of --confirm live in confirm-runs/: a rerun of the same sweep reuses the finished ones
  output::RunFolder folder(out, {"screen", identity, overwrite, false, "--out", "screen.json", "confirm-runs"});

  Progress bar("screen " + name, static_cast<double>(designs.size()), progress);
  size_t finished = 0;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<reduced1d::DesignOutcome> results;
  if (ranks::distributed()) {
    // mpirun: one design at a time per rank (rank 0's own thread included), two held per rank to
    // hide the hand-over; the outcomes come back exactly as computed
    std::vector<ranks::Task> tasks;
    const std::string base_dir = fs::absolute(sw.base_dir).string();
    for (size_t i = 0; i < designs.size(); ++i) {
      const size_t k = i % n_designs;
      const scene::json sc = i < n_designs ? sw.design(k) : refined_scenes[k];
      tasks.push_back({"1D run of design " + std::to_string(k) + (i >= n_designs ? " (grid check)" : ""),
                       {{"kind", "1d"}, {"scene", sc}, {"base_dir", base_dir}},
                       cost_1d(designs[i]),
                       {}});
    }
    const ranks::Outcome r =
        ranks::distribute(tasks, run_task, 2, [&](size_t, const scene::json&) { bar.update(static_cast<double>(++finished)); });
    for (const auto& x : r.results) {
      if (x.contains("error")) {
        reduced1d::DesignOutcome o;
        o.message = x["error"].get<std::string>();
        results.push_back(o);
      } else {
        results.push_back(reduced1d::outcome_from_json(x));
      }
    }
  } else {
    results = reduced1d::run_designs(designs, jobs, [&](size_t) { bar.update(static_cast<double>(++finished)); });
  }
  bar.done();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<reduced1d::DesignOutcome> refined;
  std::vector<double> change;
  scene::json grid_j;
  if (grid_check > 0) {
    refined.assign(std::make_move_iterator(results.begin() + static_cast<long>(n_designs)),
                   std::make_move_iterator(results.end()));
    results.resize(n_designs);
    grid_j = grid_check_summary(sw, results, refined, factor, grid_check, change);
  }

  // designs.csv: axis values as given and, for a quantity, in SI with the unit in the column
  // name as series.csv has it (swimmer.length, swimmer.length_m); a number or a choice
  // ("step") has its one column. Then every metric; failed designs keep their status and
  // leave the metric cells empty (never NaN).
  const auto& names = reduced1d::metric_names();
  const auto has_si_column = [](const sweep::Axis& a) { return !a.si_unit.empty() && a.si_unit != "index"; };
  output::AtomicFile csv_file(out + "/designs.csv");  // published complete, or not at all
  std::ostream& csv = csv_file.stream();
  csv << "design";
  for (const auto& a : sw.axes) {
    csv << "," << a.key;
    if (has_si_column(a)) csv << "," << a.key << "_" << unit_suffix(a.si_unit);
  }
  csv << ",status";
  for (const auto& m : names) csv << "," << m;
  // --grid-check: the design on twice its cells, the metric there and its relative change
  if (grid_check > 0) csv << ",grid_check_cells,grid_check_status,grid_check_" << sw.metric << ",grid_check_change_relative";
  csv << ",cycles_completed,wall_time_s\n";
  long best = -1, failed = 0;
  for (size_t k = 0; k < results.size(); ++k) {
    const auto idx = sw.indices(k);
    csv << k;
    for (size_t a = 0; a < sw.axes.size(); ++a) {
      const auto& v = sw.axes[a].values[idx[a]];
      csv << "," << csv_field(v.is_string() ? v.get<std::string>() : v.dump());
      if (has_si_column(sw.axes[a])) csv << "," << sw.axes[a].si[idx[a]];
    }
    const auto& r = results[k];
    csv << "," << (r.ok ? "ok" : "failed: " + csv_field(r.message));
    char b[32];
    for (const auto& m : names) {
      std::snprintf(b, sizeof b, "%.8g", reduced1d::metric_value(r.metrics, m));
      csv << "," << (r.ok ? b : "");
    }
    if (grid_check > 0) {
      const auto& q = refined[k];
      csv << "," << designs[n_designs + k].numerics.cells << "," << (q.ok ? "ok" : "failed: " + csv_field(q.message));
      std::snprintf(b, sizeof b, "%.8g", reduced1d::metric_value(q.metrics, sw.metric));
      csv << "," << (q.ok ? b : "");
      std::snprintf(b, sizeof b, "%.6g", change[k]);
      csv << "," << (std::isfinite(change[k]) ? b : "");
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
  if (grid_check > 0) summary["grid_check"] = grid_j;
  std::vector<std::string> plot_args = {out + "/designs.csv", out + "/screen.png", sw.metric, sw.name,
                                        std::string("--goal=") + (sw.maximize ? "max" : "min")};
  for (const auto& a : sw.axes) plot_args.push_back(a.key);
  try {
    plot("plot_screen.py", plot_args);
  } catch (const Interrupted& e) {
    // the designs are complete; the figure is not: the status says so, and nothing announces it
    summary["status"] = std::string(e.what()) + "; designs.csv is complete, screen.png was not written";
    output::write_json(out + "/screen.json", summary);
    throw;
  }
  std::printf("screened %zu designs in %.3g s (%.4g designs/s), %ld failed\n", results.size(), wall,
              summary["designs_per_s"].get<double>(), failed);
  if (best < 0) {
    output::write_json(out + "/screen.json", summary);
    std::fprintf(stderr, "swim: every design failed numerically; see %s/designs.csv for the causes\n", out.c_str());
    return 3;
  }
  std::printf("best by %s (%s): design %ld: %s -> %s\n  -> %s/designs.csv, %s/screen.png\n", sw.metric.c_str(),
              sw.maximize ? "max" : "min", best, describe(sw, best).c_str(),
              shown(reduced1d::metric_value(results[best].metrics, sw.metric), sw.metric).c_str(), out.c_str(),
              out.c_str());
  if (grid_check > 0 && grid_j["status"] == "ok") {
    const long worst = grid_j["largest_change_design"].get<long>();
    char tau[48] = "undefined";
    if (grid_j.contains("kendall_tau") && grid_j["kendall_tau"].is_number())
      std::snprintf(tau, sizeof tau, "%.3g", grid_j["kendall_tau"].get<double>());
    std::printf("grid check on %d times the cells: %ld of %zu designs change their %s by more than %.3g %%; largest "
                "%+.3g %% (design %ld: %s); median %.3g %%; Kendall tau of the two rankings %s; the best design %s\n",
                factor, grid_j["designs_over_tolerance"].get<long>(), grid_j["designs_compared"].get<size_t>(),
                sw.metric.c_str(), 100 * grid_check, 100 * grid_j["largest_change_relative"].get<double>(), worst,
                describe(sw, static_cast<size_t>(worst)).c_str(), 100 * grid_j["median_abs_change_relative"].get<double>(),
                tau,
                grid_j["best_design_unchanged"].get<bool>()
                    ? "is the same"
                    : ("differs: design " + std::to_string(grid_j["best_design_on_refined_grid"].get<long>())).c_str());
  } else if (grid_check > 0) {
    std::printf("grid check on %d times the cells: %s\n", factor, grid_j["status"].get<std::string>().c_str());
  }
  std::fflush(stdout);
  int code = 0;
  if (confirm > 0) {
    summary["confirm"] = confirm_sweep(sw, results, static_cast<size_t>(confirm), confirm_section, threads, progress, out);
    code = summary["confirm"]["status"] == "ok" ? 0 : 3;
  }
  if (ranks::distributed()) summary["mpi"] = ranks::summary();
  output::write_json(out + "/screen.json", summary);  // last: its status says the sweep finished
  std::fflush(stdout);
  if (code != 0)
    std::fprintf(stderr, "swim: %s confirmation run failed: %s\n  the finished runs and the report are kept in %s\n",
                 design::confirm_tier(confirm_section) == "axi" ? "an axisymmetric" : "a 3D",
                 summary["confirm"]["status"].get<std::string>().c_str(), out.c_str());
  return code;
}

}  // namespace swim::app
