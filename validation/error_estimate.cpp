#include "validation/error_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/errors.hpp"
#include "common/scene_shared.hpp"

namespace swim::validation {

namespace {
/// E_1, the interval [min, max] of the E_p and the error max |E_p - E_1| from e.extrapolated.
void spread_of_extrapolations(TwoGridEstimate& e) {
  e.extrapolated_order1 = e.extrapolated[1];
  e.interval_low = *std::min_element(e.extrapolated, e.extrapolated + 3);
  e.interval_high = *std::max_element(e.extrapolated, e.extrapolated + 3);
  e.error = 0.0;
  for (double v : e.extrapolated) e.error = std::max(e.error, std::abs(v - e.extrapolated_order1));
}

void append_note(std::string& note, const std::string& n) { note += (note.empty() ? "" : "; ") + n; }
}  // namespace

double extrapolate_two_grids(double fine, double coarse, double h_fine, double h_coarse, double order) {
  const double r = h_coarse / h_fine;
  return fine + (fine - coarse) / (std::pow(r, order) - 1.0);
}

TwoGridEstimate two_grid_estimate(double fine, double coarse, double h_fine, double h_coarse, bool positive,
                                  const double (&orders)[3]) {
  if (!std::isfinite(fine) || !std::isfinite(coarse))
    throw InputError("error_estimate", std::to_string(fine) + ", " + std::to_string(coarse),
                     "the figures of both grids must be finite");
  if (!(std::isfinite(h_fine) && std::isfinite(h_coarse) && h_fine > 0 && h_coarse > h_fine))
    throw InputError("error_estimate", std::to_string(h_fine) + ", " + std::to_string(h_coarse),
                     "the coarse grid's cell size must exceed the fine grid's (both positive)");
  TwoGridEstimate e;
  e.fine = fine;
  e.coarse = coarse;
  std::copy(std::begin(orders), std::end(orders), e.orders);
  for (int i = 0; i < 3; ++i) e.extrapolated[i] = extrapolate_two_grids(fine, coarse, h_fine, h_coarse, orders[i]);
  spread_of_extrapolations(e);
  auto add_note = [&](const std::string& n) { append_note(e.note, n); };
  char b[240];
  if ((fine > 0 && coarse < 0) || (fine < 0 && coarse > 0))
    add_note("the two grids give opposite signs: the coarse grid is far from the asymptotic range, so the "
             "interval means little");
  if (positive && e.interval_low < 0) {
    const double raw1 = e.extrapolated_order1;
    std::snprintf(b, sizeof b, "the lower bound %.4g (the extrapolation at order %g) is below 0; the figure is positive, "
                  "so interval_low is 0", e.interval_low,
                  orders[std::min_element(e.extrapolated, e.extrapolated + 3) - e.extrapolated]);
    add_note(b);
    e.interval_low = 0;
    e.clipped = true;
    if (raw1 < 0) {
      std::snprintf(b, sizeof b, "the order-%g extrapolation %.4g is below 0 too, so it is given as 0: the two "
                    "grids are too coarse for this figure's estimate", orders[1], raw1);
      add_note(b);
      e.extrapolated_order1 = 0;
    }
    e.interval_high = std::max(e.interval_high, 0.0);
  }
  return e;
}

TwoGridEstimate lumen_two_grid_estimate(double fine, double coarse, double h_fine, double h_coarse) {
  TwoGridEstimate power = two_grid_estimate(fine, coarse, h_fine, h_coarse, true);
  char b[320];
  if (!(fine > 0 && coarse > 0)) {
    std::snprintf(b, sizeof b, "the smeared lumen's model needs positive cycle times (%.4g s, %.4g s): the power series "
                  "instead", fine, coarse);
    append_note(power.note, b);
    return power;
  }
  const double y_fine = std::pow(fine, -0.25), y_coarse = std::pow(coarse, -0.25);
  TwoGridEstimate e;
  e.fine = fine;
  e.coarse = coarse;
  e.model = TwoGridEstimate::kSmearedLumen;
  for (int i = 0; i < 3; ++i) {
    const double y = extrapolate_two_grids(y_fine, y_coarse, h_fine, h_coarse, kEstimateOrders[i]);
    if (!(y > 0)) {
      std::snprintf(b, sizeof b, "the cycle time grows with refinement (%.4g s on the coarse grid, %.4g s on this one) "
                    "faster than the smeared lumen's model allows at order %g: the power series instead",
                    coarse, fine, kEstimateOrders[i]);
      append_note(power.note, b);
      return power;
    }
    e.extrapolated[i] = fine * std::pow(y / y_fine, -4.0);  // exactly fine where y = y_fine
  }
  spread_of_extrapolations(e);
  return e;
}

TwoGridEstimate ratio_estimate(const TwoGridEstimate& a, const TwoGridEstimate& b, double fine, double coarse,
                               double h_fine, double h_coarse) {
  if (!(b.interval_low > 0)) {
    TwoGridEstimate e = two_grid_estimate(fine, coarse, h_fine, h_coarse, false, a.orders);
    append_note(e.note,
                "the denominator's interval reaches 0, so the ratio of the two estimates is unbounded: the power series "
                "of this figure's own two values instead");
    return e;
  }
  TwoGridEstimate e;
  e.fine = fine;
  e.coarse = coarse;
  std::copy(std::begin(a.orders), std::end(a.orders), e.orders);
  e.model = TwoGridEstimate::kRatio;
  for (int i = 0; i < 3; ++i) e.extrapolated[i] = a.extrapolated[i] / b.extrapolated[i];
  e.extrapolated_order1 = a.extrapolated_order1 / b.extrapolated_order1;
  const double corners[4] = {a.interval_low / b.interval_low, a.interval_low / b.interval_high,
                             a.interval_high / b.interval_low, a.interval_high / b.interval_high};
  e.interval_low = *std::min_element(corners, corners + 4);
  e.interval_high = *std::max_element(corners, corners + 4);
  e.error = std::max(std::abs(e.interval_high - e.extrapolated_order1), std::abs(e.extrapolated_order1 - e.interval_low));
  if (!a.note.empty()) e.note = "the displacement's estimate: " + a.note;
  return e;
}

namespace {
/// extrapolated_order<p>, "." written "_".
std::string order_key(double p) {
  char b[32];
  std::snprintf(b, sizeof b, "extrapolated_order%g", p);
  std::string k = b;
  std::replace(k.begin(), k.end(), '.', '_');
  return k;
}
}  // namespace

scene::json to_json(const TwoGridEstimate& e) {
  scene::json j = {{"fine", e.fine},
                   {"coarse", e.coarse},
                   {"interval_low", e.interval_low},
                   {"interval_high", e.interval_high},
                   {"error", e.error},
                   {"model", e.model}};
  j[order_key(e.orders[0])] = e.extrapolated[0];
  j[order_key(e.orders[1])] = e.extrapolated_order1;
  j[order_key(e.orders[2])] = e.extrapolated[2];
  if (e.orders[1] != 1.0) j["central_order"] = e.orders[1];
  if (!e.note.empty()) j["note"] = e.note;
  return j;
}

namespace {
/// The figures an estimate covers (kEstimatedFigures and more_figures), or the failure that
/// one of the summaries lacks one: {"status": "failed: ..."}.
scene::json missing_figure(const scene::json& fine, const scene::json& coarse, std::vector<std::string>& figures,
                           const std::vector<std::string>& more_figures) {
  figures.assign(std::begin(kEstimatedFigures), std::end(kEstimatedFigures));
  for (const auto& k : more_figures)
    if (std::find(figures.begin(), figures.end(), k) == figures.end()) figures.push_back(k);
  for (const auto* s : {&fine, &coarse}) {
    const char* which = s == &fine ? "the run" : "the coarse run";
    for (const auto& k : figures)
      if (!s->contains(k) || !(*s)[k].is_number()) {
        const bool per_cycle = std::find(std::begin(kEstimatedFigures), std::end(kEstimatedFigures), k) != std::end(kEstimatedFigures);
        if (!per_cycle) return {{"status", std::string("failed: ") + which + " reports no " + k}};
        std::string why = s->contains("per_cycle_absent_because") && (*s)["per_cycle_absent_because"].is_string()
                              ? (*s)["per_cycle_absent_because"].get<std::string>()
                              : std::string("no ") + k;
        return {{"status", std::string("failed: ") + which + " has no per-cycle figures (" + why + ")"}};
      }
  }
  return nullptr;
}
}  // namespace

scene::json error_estimate_json(const scene::json& fine, const scene::json& coarse, int coarse_cells_across,
                                double h_fine, double h_coarse, const std::vector<std::string>& more_figures) {
  std::vector<std::string> figures;
  if (scene::json failed = missing_figure(fine, coarse, figures, more_figures); !failed.is_null()) return failed;
  scene::json j = {{"status", "ok"},
                   {"method", "two grids: this run and a second run on a coarser grid (error_estimate/coarse); "
                              "E_p = f + (f - F) / (r^p - 1), r = coarse_cell_size_m / fine_cell_size_m, at the "
                              "orders p of order_range and 1; extrapolated_order1 = E_1, interval = [min, max] of E_p, "
                              "error = max |E_p - E_1|; the cycle time's E_p taken of T^(-1/4) (the smeared lumen's "
                              "model) and mapped back; the mean velocity per cycle's the ratio of the displacement's "
                              "and the cycle time's, its interval the extreme ratios of their intervals (each figure's "
                              "model)"},
                   {"coarse_cells_across", coarse_cells_across},
                   {"coarse_cell_size_m", h_coarse},
                   {"fine_cell_size_m", h_fine},
                   {"order_range", {kEstimateOrders[0], kEstimateOrders[2]}}};
  const auto value = [](const scene::json& s, const char* k) { return s[k].get<double>(); };
  const TwoGridEstimate d = two_grid_estimate(value(fine, kEstimatedFigures[0]), value(coarse, kEstimatedFigures[0]),
                                              h_fine, h_coarse, false);
  const TwoGridEstimate t = lumen_two_grid_estimate(value(fine, kEstimatedFigures[1]),
                                                    value(coarse, kEstimatedFigures[1]), h_fine, h_coarse);
  j[kEstimatedFigures[0]] = to_json(d);
  j[kEstimatedFigures[1]] = to_json(t);
  j[kEstimatedFigures[2]] = to_json(ratio_estimate(d, t, value(fine, kEstimatedFigures[2]),
                                                   value(coarse, kEstimatedFigures[2]), h_fine, h_coarse));
  for (std::size_t i = 3; i < figures.size(); ++i) {
    const std::string& k = figures[i];
    j[k] = to_json(two_grid_estimate(fine[k].get<double>(), coarse[k].get<double>(), h_fine, h_coarse, false));
  }
  return j;
}

scene::json sharp_interface_error_estimate_json(const scene::json& fine, const scene::json& coarse,
                                                int coarse_cells_across, double h_fine, double h_coarse,
                                                const std::vector<std::string>& more_figures) {
  std::vector<std::string> figures;
  if (scene::json failed = missing_figure(fine, coarse, figures, more_figures); !failed.is_null()) return failed;
  const auto& P = kSharpInterfaceEstimateOrders;
  scene::json j = {{"status", "ok"},
                   {"method", "two grids: this run and a second run on a coarser grid (error_estimate/coarse); "
                              "E_p = f + (f - F) / (r^p - 1), r = coarse_cell_size_m / fine_cell_size_m, at the "
                              "orders p of order_range and the central order 2 (the fitted method's: a sharp "
                              "interface of second order); extrapolated_order2 = E_2, interval = [min, max] of E_p, "
                              "error = max |E_p - E_2|; every figure a power series in h; the mean velocity per "
                              "cycle's the ratio of the displacement's and the cycle time's, its interval the "
                              "extreme ratios of their intervals"},
                   {"coarse_cells_across", coarse_cells_across},
                   {"coarse_cell_size_m", h_coarse},
                   {"fine_cell_size_m", h_fine},
                   {"order_range", {P[0], P[2]}},
                   {"central_order", P[1]}};
  const auto value = [](const scene::json& s, const std::string& k) { return s[k].get<double>(); };
  const TwoGridEstimate d = two_grid_estimate(value(fine, kEstimatedFigures[0]), value(coarse, kEstimatedFigures[0]),
                                              h_fine, h_coarse, false, P);
  const TwoGridEstimate t = two_grid_estimate(value(fine, kEstimatedFigures[1]), value(coarse, kEstimatedFigures[1]),
                                              h_fine, h_coarse, true, P);
  j[kEstimatedFigures[0]] = to_json(d);
  j[kEstimatedFigures[1]] = to_json(t);
  j[kEstimatedFigures[2]] = to_json(ratio_estimate(d, t, value(fine, kEstimatedFigures[2]),
                                                   value(coarse, kEstimatedFigures[2]), h_fine, h_coarse));
  for (std::size_t i = 3; i < figures.size(); ++i)
    j[figures[i]] = to_json(two_grid_estimate(value(fine, figures[i]), value(coarse, figures[i]), h_fine, h_coarse,
                                              false, P));
  return j;
}

int coarse_cells_across_axi(int n) {
  int best = 0;
  const double target = 0.75 * n;
  for (int c = 8; c < n; c += 2)
    if (best == 0 || std::abs(c - target) < std::abs(best - target) - 1e-9) best = c;
  return best;
}

CoarseGrid coarse_grid(const scene::json& sc, const full3d::Params3d& p, const std::string& key) {
  const double width = 2.0 * p.container_radius;
  const int n = int(std::lround(width / p.h));
  const double target = 0.75 * n;
  int best = 0;
  for (int c = 4; c < n; ++c) {
    if (!scene::multiple_of(p.period, width / c)) continue;
    const double dc = std::abs(c - target), db = std::abs(best - target);
    if (best == 0 || dc < db - 1e-9 || (std::abs(dc - db) <= 1e-9 && c % 2 == 0 && best % 2 != 0)) best = c;
  }
  if (best == 0)
    throw InputError(key, "full3d.grid.cells_across = " + std::to_string(n),
                     "the error estimate needs a coarser grid of at least 4 cells across whose cell size divides "
                     "container.period; refine the grid or leave the error estimate out");
  CoarseGrid c;
  c.cells = best;
  c.scene = sc;
  scene::apply_override(c.scene, "full3d.grid.cell_size=null");
  scene::apply_override(c.scene, "full3d.grid.cells_across=" + std::to_string(best));
  try {
    c.p = full3d::read_scene3d(c.scene, c.resolved);
  } catch (const InputError& e) {
    throw InputError(key, "the coarse grid full3d.grid.cells_across = " + std::to_string(best),
                     std::string("the coarse run's scene is refused (") + e.what() +
                         "); refine the grid or leave the error estimate out");
  }
  return c;
}

std::string coarse_folder(const std::string& run_dir) {
  return (std::filesystem::path(run_dir) / "error_estimate" / "coarse").string();
}

}  // namespace swim::validation
