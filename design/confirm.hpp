// Confirmation of 1D designs in 3D (or on the axisymmetric tier, confirm.tier = "axi"): the
// design's scene on the grid its sweep chooses, run
// once (a finished run in the runs folder is reused, an interrupted one continues from its
// checkpoint), and the figures of both tiers side by side.
//
//   figures compared per design: the sweep's metric, displacement per cycle [m], cycle time [s],
//   mean velocity [m/s]; relative difference (3D - 1D) / |3D|.
//   error bars (confirm.error_estimate, default true): each 3D run that finishes is followed by
//   the coarse-grid run of `swim run --error-estimate` (validation/error_estimate.hpp) in its
//   folder's error_estimate/coarse/, and its summary.json gets the same `error_estimate`, with
//   the sweep's metric estimated too; an axisymmetric run likewise, on about 3/4 of its cells
//   across, estimated at the sharp interface's orders (sharp_interface_error_estimate_json),
//   and again on its own grid with its rings at half the spacing (error_estimate/wall), whose
//   change widens each figure's interval (the wall's resolution, which the grids do not see).
//   The error bar of a figure f is the largest distance from f to the estimate's interval of
//   extrapolations, max(|f - interval_low|, |f - interval_high|): how far the run's own figure
//   may lie from its value on ever finer grids.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "design/rank_agreement.hpp"
#include "reduced1d/report.hpp"

namespace swim::design {

using scene::json;

/// The sweep metrics a 3D summary reports (every 1D metric but the Brownian ratio).
const std::vector<std::string>& metrics_in_3d();
/// Throws InputError naming `key` when the 3D tier does not report `metric`.
void check_metric_in_3d(const std::string& metric, const std::string& key);

/// A "confirm" section ({"tier": "3d" | "axi", "grid": {"cells_across": n} | {"cell_size":
/// "<length>"}, "error_estimate": true | false}, all optional) read and checked; `where` names
/// it in messages. No grid: the design scene's own grid of the confirming tier (full3d.grid, or
/// axi.grid), that tier's default when the scene sets none.
json read_confirm_section(const json& section, const std::string& where);

/// The tier a read section confirms on: "3d" (the default) or "axi".
std::string confirm_tier(const json& section);
/// The tier for people: "3D" or "axisymmetric"; at the start of a title, "3D" or
/// "Axisymmetric"; beside a figure, "3D" or "axi".
std::string tier_label(const std::string& tier);
std::string tier_title(const std::string& tier);
std::string tier_short(const std::string& tier);

/// confirm.error_estimate of a read section: absent is true (kErrorEstimateDefault) on either tier.
constexpr bool kErrorEstimateDefault = true;
bool wants_error_estimate(const json& section);

/// A confirm section as part of a folder's identity: without error_estimate, which adds coarse
/// runs beside the confirming runs and changes none of them (so a sweep or spec confirmed with and
/// without it is the same, its finished runs reused); null when nothing else is left.
json confirm_identity(const json& section);

/// With the error estimate on: throws InputError naming `where`.error_estimate when the
/// prepared scene (confirm_scene) has no coarse grid on its tier (3D: validation::coarse_grid;
/// axisymmetric: validation::coarse_cells_across_axi, at least 8 cells across).
void check_error_estimate(const json& scene, const json& section, const std::string& where);

/// The summary key of the estimate that carries a sweep metric: cycle_time_s for
/// mean_cycle_time_s (the same mean of the cycles), the metric itself otherwise.
std::string estimated_figure(const std::string& metric);

/// A design scene prepared for its confirmation run: the section's grid and `threads` on its
/// tier (3D: full3d.grid, full3d.threads, no VTK frames; axi: axi.grid, axi.threads at most 2).
json confirm_scene(json scene, const json& section, int threads);

/// Reads a prepared scene (confirm_scene) with the reader of the section's tier: throws the
/// reader's InputError (naming the key) when the scene cannot run there.
void check_confirm_scene(const json& scene, const json& section);

struct Confirmed {
  json summary;        ///< the 3D run's summary.json
  std::string folder;  ///< its run folder
  bool reused = false; ///< a finished run found in the runs folder
  bool ok = false;     ///< status "ok"
  double cell_size_m = 0;  ///< the grid's h
  /// the error estimate's coarse run: run (or reused), its wall time (0 when none)
  bool coarse_run = false, coarse_reused = false;
  double coarse_wall_time_s = 0;
};

/// A Confirmed as JSON and back (how an MPI rank sends it to rank 0; the summary round-trips exactly).
json confirmed_to_json(const Confirmed& c);
Confirmed confirmed_from_json(const json& j);

/// The 3D run of `scene` (validated by the 3D reader) in runs_dir/<label>-<hash of the
/// resolved scene>: reused when finished, continued from a matching checkpoint, else run.
/// error_estimate: when the run finished with its per-cycle figures, then also its coarse run
/// (reused, continued or run the same way) and `error_estimate` in its summary, with `metric`'s
/// figure (estimated_figure) estimated too; a run whose summary has that estimate already is
/// left as it is.
/// tier "axi": the scene's axisymmetric run (axi/run_axi.hpp) in the same way, without an
/// error estimate.
Confirmed run_confirmed(const json& scene, const std::string& runs_dir, const std::string& label, int progress,
                        bool error_estimate = false, const std::string& metric = "", const std::string& tier = "3d");

/// One tier's figures of a design: {"<metric>", "displacement_per_cycle_m", "cycle_time_s",
/// "mean_velocity_m_per_s"}; a figure the run did not produce (no completed cycle) is null, and
/// so is every figure of a confirming run (3D or axisymmetric) that did not finish (status
/// other than "ok"). figures_confirming reads the confirming run's summary.json.
json figures_1d(const reduced1d::Metrics& m, const std::string& metric);
json figures_confirming(const json& summary, const std::string& metric);
/// The error bar of a confirming run's figure from its summary's `error_estimate` (estimated_figure of it):
/// max(|f - interval_low|, |f - interval_high|) with f the run's own value; null when the
/// summary has no estimate of it.
json error_bar_of(const json& summary, const std::string& figure);

/// {"<figure>": (3D - 1D) / |3D|} for every figure both tiers have (null otherwise).
json relative_differences(const json& fig1d, const json& fig3d);

/// The agreement as JSON: n, kendall_tau (+ _ci_95), spearman_rho (+ _ci_95), the method,
/// pair counts and the misranked pairs by design label; the keys and texts of the confirming
/// tier name it ("pairs_tied_in_3d", or "_axi").
json agreement_json(const RankAgreement& a, const std::vector<std::string>& labels, const std::string& tier = "3d");

/// A design of a sweep (or the optimum of a search) to confirm in 3D.
struct Candidate {
  std::size_t design = 0;   ///< its index in the sweep
  std::string values;       ///< its swept values, for people ("swimmer.length=\"0.3 um\", ...")
  std::string selected_as;  ///< "best", "spread" or "optimum"
  long rank_in_sweep = 0;   ///< 1 = best of the whole sweep by its metric
  json scene;               ///< the design's scene (1D; the section's grid is applied here)
  reduced1d::Metrics metrics;  ///< its 1D figures (after match_recovery_end: with the 3D run's rule)
  /// match_recovery_end: the rule that ends the 1D cycle ("" when not matched: a prescribed
  /// wave, or the sweep's figures kept), and the sweep's own figures when the rule changed them
  std::string recovery_end_1d;
  std::optional<reduced1d::Metrics> metrics_sweep;
};

/// A force-driven design's 1D cycle ends as its 3D run's does: when the design's scene states
/// no model1d.recovery_end, its 1D figures are computed again with the 3D run's rule (the
/// scene's full3d.recovery_end, else the 3D tier's default dead_band) and become c.metrics, the
/// sweep's own (the 1D default, the paper's energy rule) are kept in c.metrics_sweep; a design
/// that states a rule, or whose rule is the 3D run's already, keeps its figures. The cycle time
/// and the mean velocity per cycle of the two tiers then measure the same cycle (the energy
/// rule waits until the wall has relaxed far below the geometric band). A prescribed wave is
/// left as it is. `scene_dir` resolves the scene's relative files (wall.calibration). Throws
/// NumericalError when the 1D run with the 3D rule fails.
void match_recovery_end(Candidate& c, const std::string& scene_dir);

struct ConfirmOptions {
  std::string metric;  ///< must be in metrics_in_3d()
  bool maximize = true;
  json section;        ///< read_confirm_section()
  int threads = 1;     ///< threads of each 3D run
  int progress = -1;   ///< progress of each 3D run
  std::string runs_dir;
  /// runs candidate i's prepared scene (confirm_scene) as run_confirmed(scene, runs_dir, label,
  /// progress) would; empty: run_confirmed itself. An MPI command passes the runs its ranks made.
  std::function<Confirmed(std::size_t i, const json& scene, const std::string& label)> run;
};

/// The label of candidate c's run folder ("design-<k>").
std::string confirm_label(const Candidate& c);

/// Runs every candidate in 3D (design/confirm.hpp: reused when finished) and returns the report
/// written as confirm.json: per design both tiers' figures, their relative differences and
/// ranks; the rank agreement over the designs whose 3D run finished ("agreement", null with
/// "agreement_absent_because" below two); "status" "ok" or "failed: <the 3D failures>".
/// on_done(i, confirmed) after each run (printouts).
json confirm_candidates(const std::vector<Candidate>& candidates, const ConfirmOptions& o,
                        const std::function<void(std::size_t, const Confirmed&)>& on_done = {});

/// The confirmation report for people (confirm.md): SI-prefixed figures, ranks, agreement.
std::string confirm_markdown(const json& report, const std::string& title);

}  // namespace swim::design
