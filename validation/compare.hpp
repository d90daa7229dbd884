// Comparison of two velocity histories U(t) (1D and 3D) over a cycle.
//
// Both are linearly interpolated onto n equally spaced points of a common window and
// compared by the relative L2 difference |a - b|_2 / |b|_2 (b the reference) and the Pearson
// correlation. Two windows: absolute time over the shorter of the two cycles, and phase
// t / T_cycle over [0, 1] (each series on its own cycle time), since the two tiers' cycle
// times can differ by several times while the shape of U(t) agrees.
#pragma once

#include <vector>

namespace swim::validation {

struct SeriesComparison {
  double l2_relative = 0;
  double correlation = 0;
  int points = 0;
};

/// t_a, u_a: series to judge; t_b, u_b: the reference; both cover [0, T_a] and [0, T_b].
/// phase = true compares u_a(s T_a) with u_b(s T_b), s in [0, 1]; otherwise both on [0, min T].
/// Throws InputError for empty or non-increasing time arrays.
SeriesComparison compare_series(const std::vector<double>& t_a, const std::vector<double>& u_a, double T_a,
                                const std::vector<double>& t_b, const std::vector<double>& u_b, double T_b,
                                bool phase, int n = 400);

/// Linear interpolation of (t, u) at x (clamped to the ends).
double interpolate_linear(const std::vector<double>& t, const std::vector<double>& u, double x);

}  // namespace swim::validation
