// A single 3D run's own discretisation error, from a second run on a coarser grid
// (`swim run SCENE --tier 3d --error-estimate`, docs/full3d.md "A run's own error estimate").
//
// With the figure f on the run's grid (cell size h) and F on the coarser grid (H = r h, r > 1),
// the extrapolation to h -> 0 at an assumed order p is
//     E_p = f + (f - F) / (r^p - 1).
// The order the immersed boundary shows on affordable grids is not known for a single pair of
// grids (it is pre-asymptotic: observed orders between about 0.25 and 2), so the estimate takes
// the orders 0.5 and 2, the span of what those grids show, and 1 (wider than the range a
// three-grid Richardson accepts as asymptotic, validation::kImmersedBoundaryOrders: a single
// pair cannot tell whether it is asymptotic, so its interval covers the pre-asymptotic orders):
//     extrapolated value   E_1,
//     interval             [min, max] of {E_0.5, E_1, E_2},
//     error                max |E_p - E_1| over those p.
// E_p is monotone in p, so the interval holds E_p for every p of the range: a figure that
// follows f0 + C h^p exactly with p in [0.5, 2] has its f0 inside the interval.
// A figure that is positive by its nature (the cycle time) whose lower bound falls below 0
// has that bound clipped to 0 (with a note giving the unclipped value; E_1 too when it is
// negative); the error and extrapolated_order0_5, extrapolated_order2 keep the unclipped values.
//
// The cycle time is estimated by the smeared lumen's model instead (lumen_two_grid_estimate):
// the kernel narrows the lumen the flow sees by a multiple of h and the cycle goes as the
// lumen's R^-4, so the estimate's E_p are taken of y = T^(-1/4), the figure that is linear in h
// on the converged suite's series (validation::lumen_fit), and mapped back, T = y^-4. The mean
// velocity per cycle is the displacement per cycle over the cycle time in every run, so its
// estimate is the ratio of theirs (ratio_estimate).
#pragma once

#include <string>
#include <vector>

#include "common/scene.hpp"
#include "full3d/scene3d.hpp"
#include "validation/richardson.hpp"

namespace swim::validation {

/// The assumed orders of the estimate: the span of the immersed boundary's observed orders on
/// affordable grids, and 1.
constexpr double kEstimateOrders[3] = {0.5, 1.0, 2.0};
/// The same for the axisymmetric tier's fitted method (a sharp interface of second order): the
/// range a three-grid Richardson accepts of it (kSharpInterfaceOrders, 1 to 3.5), and 2.
constexpr double kSharpInterfaceEstimateOrders[3] = {1.0, 2.0, 3.5};

struct TwoGridEstimate {
  double fine = 0, coarse = 0;
  /// the assumed orders, lowest, central, highest (kEstimateOrders or kSharpInterfaceEstimateOrders)
  double orders[3] = {kEstimateOrders[0], kEstimateOrders[1], kEstimateOrders[2]};
  double extrapolated[3] = {0, 0, 0};  ///< E_p for p = orders
  /// E at the central order (E_1 of the 3D estimate; a positive figure's: at least 0)
  double extrapolated_order1 = 0;
  double interval_low = 0, interval_high = 0;
  double error = 0;                    ///< max |E_p - E_1|
  bool clipped = false;                ///< interval_low raised to 0 (a positive figure)
  /// why a bound was clipped, or that the grids give opposite signs; empty otherwise
  std::string note;
  /// what the E_p are extrapolations of: kPowerSeries, kSmearedLumen or kRatio
  std::string model = kPowerSeries;
  static constexpr const char* kPowerSeries = "power series in h";
  static constexpr const char* kSmearedLumen = "smeared lumen: T^(-1/4) as a power series in h";
  static constexpr const char* kRatio = "ratio of the displacement's and the cycle time's estimates";
};

/// E_p = fine + (fine - coarse) / (r^p - 1), r = h_coarse / h_fine.
double extrapolate_two_grids(double fine, double coarse, double h_fine, double h_coarse, double order);

/// The estimate of one figure at the assumed `orders` (lowest, central, highest). positive: the
/// figure cannot be negative (a bound or the central E below 0 is reported as 0, with a note).
/// Throws InputError for non-finite values or h_coarse <= h_fine.
TwoGridEstimate two_grid_estimate(double fine, double coarse, double h_fine, double h_coarse, bool positive,
                                  const double (&orders)[3] = kEstimateOrders);

/// The estimate of a cycle time T by the smeared lumen's model: E_p of y = T^(-1/4) (fine and
/// coarse both positive), mapped back as T = E_p(y)^-4; the interval [min, max] of those, the
/// error max |E_p - E_1| in T. When an E_p(y) is not positive (the cycle grows with refinement
/// faster than the model allows) the power-series estimate of T (positive) instead, with a note.
/// Throws InputError as two_grid_estimate, and for a non-positive fine or coarse figure.
TwoGridEstimate lumen_two_grid_estimate(double fine, double coarse, double h_fine, double h_coarse);

/// The estimate of a ratio q = a / b from the estimates of a and of b > 0 (the mean velocity
/// per cycle from the displacement per cycle and the cycle time): E_p = a.E_p / b.E_p; the
/// interval the extreme ratios of the two intervals' bounds (q is monotone in a and in b > 0,
/// so every pair of values inside both intervals gives a q inside it); error max |bound - E_1|.
/// fine and coarse are the two runs' own q. When b's interval reaches 0, the power-series
/// estimate of q's own two values instead, with a note.
TwoGridEstimate ratio_estimate(const TwoGridEstimate& a, const TwoGridEstimate& b, double fine, double coarse,
                               double h_fine, double h_coarse);

/// summary.json's object of one figure: fine, coarse, interval_low, interval_high, error, model,
/// extrapolated_order<p> for each assumed order p ("." written "_": extrapolated_order0_5,
/// extrapolated_order1, extrapolated_order2 in the 3D estimate; extrapolated_order1,
/// extrapolated_order2, extrapolated_order3_5 in the sharp interface's), the central one the
/// possibly clipped value, central_order when it is not 1, and note when clipped.
scene::json to_json(const TwoGridEstimate& e);

/// The headline figures of a run (summary.json keys) the estimate covers.
constexpr const char* kEstimatedFigures[3] = {"displacement_per_cycle_m", "cycle_time_s",
                                              "mean_velocity_per_cycle_m_per_s"};

/// summary.json's `error_estimate` object from the two runs' summaries: method, the grids,
/// order_range and an object per figure of kEstimatedFigures and of `more_figures` (further
/// summary keys, e.g. a sweep's metric); {"status": "failed: ..."} (no numbers) when either
/// summary has no per-cycle figures or lacks one of `more_figures`.
scene::json error_estimate_json(const scene::json& fine_summary, const scene::json& coarse_summary, int coarse_cells_across,
                                double h_fine, double h_coarse, const std::vector<std::string>& more_figures = {});

/// summary.json's `error_estimate` of an axisymmetric run (the fitted method, a sharp
/// interface) from its summary and its coarse run's: as error_estimate_json with the orders
/// kSharpInterfaceEstimateOrders, every figure a power series in h (no smeared lumen: the wall
/// is a boundary of the mesh), the mean velocity per cycle the ratio of the displacement's and
/// the cycle time's estimates.
scene::json sharp_interface_error_estimate_json(const scene::json& fine_summary, const scene::json& coarse_summary,
                                                int coarse_cells_across, double h_fine, double h_coarse,
                                                const std::vector<std::string>& more_figures = {});

/// The coarse grid's cells across of an axisymmetric run on `cells_across` (even, at least 8):
/// the even count nearest to 3/4 of it, at least 8 and below it (the smaller on a tie); 0 when
/// there is none (cells_across below 10).
int coarse_cells_across_axi(int cells_across);

/// The coarse grid of a 3D run's estimate: the same scene on the grid the 3D reader accepts
/// (the container period a multiple of the cell size) nearest to 3/4 of the run's cells
/// across, coarser than it (an even count on a tie); the scene's cell_size replaced by
/// cells_across, everything else unchanged.
struct CoarseGrid {
  int cells = 0;
  scene::json scene;     ///< the scene as given, on the coarse grid
  scene::json resolved;  ///< as the 3D reader resolved it
  full3d::Params3d p;
};
/// Throws InputError naming `key` (the option or scene key that asked for the estimate) when
/// there is no such grid of at least 4 cells, or the 3D reader refuses the coarse scene.
CoarseGrid coarse_grid(const scene::json& scene, const full3d::Params3d& p, const std::string& key);

/// The coarse run's folder inside the run's: RUN/error_estimate/coarse.
std::string coarse_folder(const std::string& run_dir);

}  // namespace swim::validation
