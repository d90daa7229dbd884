// Verdicts of the validation suite, judged with the error bars of the 3D reference.
//
// Every reference value carries an error (richardson.hpp: the extrapolation's error, or the
// spread of the grids when they are not in the asymptotic range). Error estimates of this
// kind are bounds on a discretisation error, not independent random deviations, so they are
// combined linearly: two values a ± ea and b ± eb differ beyond their uncertainty when
// |a - b| > ea + eb, i.e. when their error bars do not overlap.
//
//   trend claim (grows with L, largest for the shortest swimmer, ...): reproduced when every
//     difference it rests on exceeds the combined uncertainty in the claimed direction;
//     refuted when one difference exceeds it in the opposite direction; inconclusive
//     otherwise (with the error bars that would settle it);
//   claim against a number (1.5 body lengths/s within 20 %): reproduced when the whole
//     interval value ± error lies inside the tolerance band, refuted when it lies wholly
//     outside, inconclusive otherwise;
//   1D against 3D (each figure): pass when |difference| + reference error <= tolerance (the
//     whole interval inside the band), fail when |difference| - reference error > tolerance,
//     inconclusive otherwise; a difference within the reference's error bar cannot fail.
//   A claim over several cases is refuted when one case refutes it, not assessed when a case
//   lacks its data, reproduced when every case reproduces it, inconclusive otherwise.
//   3D against a converged reference (each figure): disagree when |3D - ref| > e_3d + e_ref
//     (the same linear combination of error bars); otherwise agree, or inconclusive when
//     e_3d + e_ref exceeds kAgreementResolution of the reference (bars that wide overlap anyway).
//
// A case's reference is its axisymmetric reference ("reference", the extrapolation of an axi
// grid series) when the suite gives it one, else its 3D extrapolation ("reference3d"): every
// 1D verdict and every finding is judged against that one (judged_reference).
#pragma once

#include <string>

#include "common/scene.hpp"
#include "validation/richardson.hpp"

namespace swim::validation {

/// The order range of a suite file's `order_range` key (at the top, or per case): a name,
/// "immersed_boundary" ([0.5, 1.5]) or "sharp_interface" ([1, 3.5]), or [lo, hi] with
/// 0 < lo < hi <= 20. Throws InputError naming `key`, the value and what is allowed.
OrderRange parse_order_range(const scene::json& value, const std::string& key);

/// 1D against the 3D reference: rel = (1D - ref) / |ref|, rel_error = reference error / |ref|,
/// tolerance relative. "pass", "fail" or "inconclusive"; "not assessed" when rel or
/// rel_error is not finite.
std::string tolerance_verdict(double rel, double rel_error, double tolerance);

/// Widest combined error bar, relative to the reference value, under which overlapping bars
/// say "agree": wider bars overlap whatever the two values are, and say nothing.
constexpr double kAgreementResolution = 0.25;

/// Two values with their error bars (b the reference): "disagree" when |a - b| > ea + eb;
/// otherwise "agree" when ea + eb <= kAgreementResolution |b|, "inconclusive" when the bars
/// are wider than that; "not assessed" when a number is not finite.
std::string agreement_verdict(double a, double ea, double b, double eb);

/// The reference a case of a report is judged against: its "reference" (the axisymmetric
/// reference) when it has one, else its "reference3d"; an empty object when it has neither.
/// Each figure key (displacement_per_cycle_m, ...) holds {"value", "error", ...}.
const scene::json& judged_reference(const scene::json& case_report);

/// "axisymmetric reference" or "3D reference": which one judged_reference() returns.
std::string judged_reference_name(const scene::json& case_report);

/// A 1D model's figures (entry: displacement_per_cycle_m, cycle_time_s,
/// mean_velocity_per_cycle_m_per_s) against the case's judged reference: sets the entry's
/// `relative_error_vs_reference` ((1D - ref) / |ref| per figure), `reference_error_relative`
/// (error / |ref|; null when not finite) and `judged_against`. A figure the reference lacks
/// is left out (no verdict).
void compare_with_reference(scene::json& entry, const scene::json& case_report);

/// U(t) correlation with the reference run, its uncertainty (the spread of the correlation
/// over the reference's grids) and the smallest passing correlation: "pass" when corr - error
/// >= threshold, "fail" when corr + error < threshold, else "inconclusive".
std::string correlation_verdict(double corr, double error, double threshold);

/// The U(t) comparison a 1D model's entry is judged by, as judged_reference() for the
/// figures: its `velocity_vs_reference` (against the finest axisymmetric run) when the entry
/// has it, else its `velocity_vs_finest3d`; an empty object when it has neither. An entry
/// whose axisymmetric comparison has no correlation (no axi run completed a cycle) gets no
/// U(t) verdict: it is never judged against 3D instead.
const scene::json& judged_velocity(const scene::json& entry);

/// "finest axisymmetric run" or "finest 3D run": which run judged_velocity() compares with.
std::string judged_velocity_name(const scene::json& entry);

/// The verdicts of one 1D model of a report from its `relative_error_vs_reference`,
/// `reference_error_relative` (thresholds: displacement_per_cycle_relative, ...) and its
/// judged_velocity() (`phase_correlation`, `phase_correlation_grid_spread`;
/// velocity_phase_correlation): {"displacement_per_cycle": "pass", ...}. A figure whose
/// numbers the entry lacks is left out; one whose numbers are null is "not assessed".
scene::json model_verdicts(const scene::json& entry, const scene::json& thresholds);

/// The paper's conclusions judged on the cases of a report (each with `group`,
/// `sweep_value`, `name`, `reference3d`, `runs3d`, `models1d` with `verdicts`, `length_m`);
/// `thresholds` as in the suite file. Each finding: claim, status ("reproduced", "refuted",
/// "inconclusive", "not assessed"), rule, evidence (values with their errors), comparisons
/// (for trends), and to_settle (inconclusive) or reason (not assessed). Never NaN.
scene::json findings(const scene::json& cases, const scene::json& thresholds);

}  // namespace swim::validation
