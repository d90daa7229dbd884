// Reduced 1D tier: time integration of the lubrication fluid-structure model.
//
// solve() integrates the model described in params.hpp with SUNDIALS (CVODE BDF for
// the prescribed waves and the inertia-free force-driven wave, IDA for the force-driven
// wave with wall inertia, which is a DAE), locates protocol switches with SUNDIALS root
// finding, and samples the state every numerics.output_interval.
//
// A numerical failure (radius collapse, integrator failure, step budget exhausted) does
// not throw: the result carries the samples up to the failure and `failure` names the
// cause and the parameter to change. The caller writes the partial results and exits 3.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "common/run_record.hpp"
#include "reduced1d/params.hpp"

namespace swim::reduced1d {

/// One output row (all SI).
struct Sample {
  double t = 0;            ///< time [s]
  double X = 0;            ///< swimmer displacement [m]
  double W = 0;            ///< swimmer velocity [m/s]
  double energy = 0;       ///< wall elastic + kinetic energy [J]
  double R_min = 0;        ///< smallest radius along the tube [m]
  double R_max = 0;        ///< largest radius along the tube [m]
  double Q_rear = 0;       ///< volume flux through z = 0 in +z [m^3/s]
  double Q_front = 0;      ///< volume flux through z = L in +z [m^3/s]
  double V_rear = 0;       ///< int_0^t Q_rear [m^3]
  double V_front = 0;      ///< int_0^t Q_front [m^3]
  double tube_volume = 0;  ///< discrete tube volume sum(pi R_i^2 dz) [m^3]
  // Force-free model (0 in the paper's mode):
  double p_rear = 0;       ///< lumen pressure at z = 0 (confined; gauge p_rear + p_front = 0) [Pa]
  double p_front = 0;      ///< lumen pressure at z = L [Pa]
  double Q_total = 0;      ///< confined: total swimmer-frame flux through a container section [m^3/s]
  double F_lumen = 0;      ///< axial force of the lumen fluid on the tube, pi [R^2 p]_L^0 [N]
  double F_outer = 0;      ///< axial force of the outer fluid on the tube (= -F_lumen) [N]
  double V_rear_lab = 0;   ///< int (Q_rear + U pi R(0)^2) dt: lumen volume through z = 0, lab frame [m^3]
  double V_front_lab = 0;  ///< same through z = L [m^3]
  int phase = 0;           ///< force-driven: 0 contraction, 1 recovery, 2 done; prescribed: 0
};

/// True when every value of the sample is finite.
bool finite(const Sample& s);

struct Result {
  std::vector<Sample> series;
  std::vector<double> z;             ///< cell centres [m]
  std::vector<double> radius_times;  ///< times of the radius snapshots [s]
  std::vector<double> radius;        ///< row-major snapshots: radius[k * z.size() + i] [m]
  std::vector<double> cycle_start;   ///< start time of each cycle [s]
  std::vector<double> cycle_end;     ///< end time of each completed cycle (energy back within tol) [s]
  /// force-driven: every time a segment reached R_f within delta, in order, over all cycles
  /// (each cycle's front segment first); empty for a constant actuation.
  std::vector<double> segment_reached;
  long switches = 0;                 ///< number of protocol force switches (all cycles)
  /// Drag coefficient of the straight tube (R = R0) in the model's outer flow, F = -zeta U
  /// [N s/m]; 0 in the paper's mode (no outer flow).
  double drag_coefficient = 0;
  std::map<std::string, long> stats; ///< integrator statistics (steps, rhs evals, ...)
  std::optional<NumericalError> failure;  ///< set when the run stopped on a numerical failure
  /// The run record (common/run_record.hpp) of solve(): every sample went through it (its
  /// running figures, events and status are complete; its rows are kept on request).
  record::RunRecord record;
};

/// Called after every output sample with the current and final simulated times.
using ProgressFn = std::function<void(double t, double t_end)>;

/// How solve() keeps and writes what it produces.
struct SolveOptions {
  ProgressFn progress;
  /// Keep Result::series and the radius snapshots (typed samples) in memory.
  bool keep_samples = true;
  /// Keep the rows of Result::record in memory (named columns).
  bool keep_record_rows = false;
  /// Stream every row and snapshot to disk as produced (memory then stays bounded). The
  /// Result's record stays attached to it (write_run commits it).
  record::RunStream* stream = nullptr;
};

Result solve(const Params& params, const SolveOptions& options);
Result solve(const Params& params, const ProgressFn& progress = {});

/// The columns of a 1D run's series.csv: the common ones (record::common_series_columns()),
/// then the force-free model's lumen pressures, total flux, force split and lab-frame volumes.
const std::vector<std::string>& series_columns();
/// A sample as a series row (series_columns() order).
std::vector<double> series_row(const Sample& s);
/// An empty record of a run of these parameters (tier, model, length, columns, cell centres).
record::RunRecord new_record(const Params& params);
/// The record of a finished Result whose record is empty (built from its kept samples).
record::RunRecord record_of(const Params& params, const Result& r);

/// Drag coefficient zeta [N s/m] of the straight tube (R = R0) towed through the model's outer
/// flow (confined: lumen, annulus and free pipe; unbounded: resistive force); 0 in paper mode.
double straight_tube_drag(const Params& params);

/// End time of a run: params.duration when > 0, else the transit time of a prescribed wave
/// (L / s for the step, lambda / s for the sine); for the force-driven wave with no duration
/// an upper bound used for progress and the step budget.
double end_time(const Params& params);

}  // namespace swim::reduced1d
