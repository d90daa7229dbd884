// The references a case's 1D models are judged against, from the case's runs on a grid series:
//   - the 3D reference: displacement per cycle, cycle time and (where the paper gives it) the
//     largest centre displacement, each extrapolated to h -> 0 over the 3D grids that completed
//     a cycle (richardson.hpp); the mean velocity per cycle as displacement over cycle time;
//   - the axisymmetric reference: the same figures over the axi tier's grids, with the
//     reference's order range, each stated converged or not against a target relative error;
//   - the 3D extrapolation against the axisymmetric reference, figure by figure.
// Each is the report entry itself (report.json: "reference3d", "reference",
// "comparison_3d_vs_reference"); numbers that are not finite are null.
#pragma once

#include <vector>

#include "axi/scene_axi.hpp"
#include "validation/richardson.hpp"
#include "validation/run_cache.hpp"

namespace swim::validation {

/// The 3D reference of a case's resolution study over the runs that completed a cycle, with
/// the observed orders the 3D scheme can show (`orders`); the largest displacement with
/// `with_max`. Fewer than two such runs: a note and no values.
json reference_3d(const std::vector<Run3d>& runs, const OrderRange& orders, bool with_max);

/// The axisymmetric reference from its runs: each headline figure (and the largest centre
/// displacement with `with_max`) extrapolated to h -> 0 with the reference's order range over
/// the grids that completed a cycle; each figure converged when it is asymptotic, has an
/// observed order (three grids) and its relative error is at most `target`; the reference
/// converged when every figure is. When the whole cycle's time is not converged, it is taken
/// as the sum of its phases, each extrapolated on its own, and the mean velocity per cycle as
/// the displacement over that time (relative errors added); the whole cycle's extrapolation is
/// kept beside it. `statement` says so with the figures reached. With a `time_check`
/// (axi_time_check's entry) each figure's error includes the time integration's.
/// With a `wall_check` (axi_wall_check's entry) a figure the grids do not extrapolate (not
/// asymptotic; each such phase of the cycle time) adds the wall's resolution error on the finest
/// grid's rings, the check's error times (h_finest / h_coarsest)^kAxiSpacingExponent: the grids
/// refine the rings with h, so an asymptotic series carries the wall's error with the rest.
json axi_reference(const std::vector<RunAxi>& runs, const OrderRange& orders, bool with_max, double target,
                   const json& time_check = nullptr, const json& wall_check = nullptr);

/// The lowest power of the step tolerance at which the axi tier's time integration error falls:
/// its step control keeps the local error below tolerance x h with steps that scale as
/// sqrt(tolerance), so the error over a cycle falls at least as tolerance^(1/2).
constexpr double kAxiToleranceExponent = 0.5;

/// The time integration's share of a reference's error, measured by running one reference grid
/// again at a tighter step tolerance (axi.tolerance x `factor`, 0 < factor < 1): each figure's
/// change between the two runs, |f(tol) - f(factor tol)|, is (1 - factor^q) times the error at
/// the reference's tolerance when that error falls as tol^q, so the error at the reference's
/// tolerance is taken as the change / (1 - factor^q) with q = kAxiToleranceExponent (the
/// slowest fall; a faster one makes the error smaller). The entry (report.json
/// "reference"."time_check"): the factor, the grid, each figure's time error ("errors": keys as
/// the reference's figures, plus "phase_times_s", one per protocol phase) and a note; when
/// either run has no cycle, "errors" is empty and the note says why. axi_reference adds each
/// figure's time error to its error and, where the grids' differences lie within it, bounds the
/// figure at the scheme's lowest order (bound_within_time_error).
json axi_time_check(const RunAxi& at_tolerance, const RunAxi& tighter, double factor);

/// The lowest order at which the wall's discretisation error falls with the rings' spacing:
/// second order on a smooth wall, first where it folds (a kink between two rings).
constexpr double kAxiSpacingExponent = 1.0;

/// The wall's resolution share of a reference's error, measured by running the coarsest grid
/// again with its rings closer (axi.spacing_factor x `factor`, 0 < factor < 1), the fluid's grid
/// unchanged: each figure's change / (1 - factor^kAxiSpacingExponent), as axi_time_check. The
/// grid series refines the rings with h too, but a wall whose shape the rings resolve poorly (a
/// folded rim whose two layers close on a film of fluid) can move with the rings far more than
/// the grids' spread shows (docs/axi.md). Entry: report.json "reference"."wall_check".
json axi_wall_check(const RunAxi& at_spacing, const RunAxi& finer, double factor);

/// The 3D extrapolation (reference_3d's entry) against the axisymmetric reference, figure by
/// figure: both values with their errors, the difference, e_3d + e_ref, agree / disagree
/// (verdicts.hpp), the 3D series' observed order, and the finest 3D grid's relative error
/// against the reference. `runs`: the 3D runs that completed a cycle.
json compare_3d_with_reference(const json& ref3d, const json& ref, const std::vector<const Run3d*>& runs);

/// The reference's order range: its `order_range`, else the axi method's own (the fitted
/// method is a sharp-interface one, the immersed boundary first order at best).
OrderRange reference_orders(const json& ref, const axi::ParamsAxi& p);

}  // namespace swim::validation
