// Internal entry points of the reduced 1D tier, shared by solver.cpp and the tests.
// Not part of the product interface (reduced1d/solver.hpp is).
#pragma once

#include <functional>
#include <vector>

#include "reduced1d/solver.hpp"

namespace swim::reduced1d::detail {

/// Where a run's samples go as they are produced (solve() fills it from its SolveOptions).
struct Output {
  Output() = default;
  Output(ProgressFn p) : progress(std::move(p)) {}  // NOLINT: a progress function alone
  ProgressFn progress;
  /// Keep the typed samples (Result::series, radius snapshots) in memory.
  bool keep_samples = true;
  /// Also into this record (running figures, events; its stream writes them to disk).
  record::RunRecord* record = nullptr;
  /// Fault injection for the tests: a force-driven sample at a time for which this returns
  /// true counts as not finite (it may be called from the sample thread).
  std::function<bool(double t)> reject_sample;
};

/// Throws swim::InputError for parameters the solver cannot run with (the scene layer is
/// expected to have rejected them already; this is the solver's own guard).
void validate(const Params& p);

/// Characteristic relaxation time of the tube, tau = 16 mu L^2 / (C1 R0^3): the linearised
/// inertia-free wall-flow equation is R_t = (C1 R0^3 / 16 mu) R_zz.
double relaxation_time(const Params& p);

/// How a prescribed wave's time integrals are computed: Auto = by quadrature on the output
/// grid for the force-free model (U, Q_rear, Q_front are instantaneous functions of t) and
/// with CVODE for the paper's model (its velocity is an ODE state); Integrated = CVODE
/// always (the reference the quadrature is tested against).
enum class PrescribedPath { Auto, Integrated };

/// Prescribed Step/Sine wave: swimmer balance and end volumes as time integrals.
Result solve_prescribed(const Params& p, const Output& out, PrescribedPath path = PrescribedPath::Auto);

/// Force-driven wave under the Section-3 protocol (CVODE or IDA, root-located switches).
/// Unbounded outer flow without wall inertia: U is evaluated once per accepted step and X
/// integrated along the steps; `velocity_in_rhs` puts U back into every right-hand side
/// with X as an ODE state (the reference the step quadrature is tested against).
Result solve_force_driven(const Params& p, const Output& out, bool velocity_in_rhs = false);

/// Force-driven machinery with a FIXED actuation pressure q_cells[i] (inward positive, Pa)
/// on every cell and no protocol: integrates from R = R0 at rest to t_end. Used for the
/// uniform-load (static calibration) check; the result has phase 0 throughout.
Result solve_fixed_actuation(const Params& p, const std::vector<double>& q_cells, double t_end,
                             const Output& out = {});

/// A sample produced: into the record of `out` (and its stream), into the Result's typed
/// samples when kept, then the progress report. R: the N cell radii.
void emit(Result& res, const Output& out, const Sample& s, const double* R, int N, double t_end);

/// The short-wave wall traction's operator |k| on the cells (docs/outer-flow-1d.md, 3b):
/// |k| ~= sum_j c_j k^2 / (k^2 + s_j^2) within 1 % for every wavenumber of the grid, from the
/// tube's lowest mode pi/L to the discrete 2/h, with log-spaced nodes s_j (step <= 1.5 in
/// ln s) and positive least-squares weights c_j (5 to 10 nodes). Each term is one tridiagonal
/// relation per cell, (s_j^2 - D2) psi_j = -D2 V, with D2 the cell second difference with
/// mirror ends.
struct AbsKQuadrature {
  std::vector<double> s, c;  ///< nodes s_j [1/m] and weights c_j [1/m]
};
AbsKQuadrature abs_k_quadrature(double L, double h);

/// Overlap of a cell with the protocol segments: the cell [i h, (i+1) h] lies in segment
/// seg_a with length fraction w and in seg_b (= seg_a + 1) with fraction 1 - w. A cell never
/// spans more than two segments because validate() requires h <= the shortest segment.
struct CellOverlap {
  int seg_a = 0, seg_b = 0;
  double w = 1.0;
};
std::vector<CellOverlap> segment_overlaps(const Params& p);

/// Segment boundaries z_0 = 0 < z_1 < ... < z_n = L.
std::vector<double> segment_bounds(const Params& p);

}  // namespace swim::reduced1d::detail
