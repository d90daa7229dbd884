// Test helper: the response of a long unbounded tube (L = 40 R0, 400 cells) to a fixed
// sinusoidal load q0 cos(k z) of grid mode m (k = m pi / L), q0 = 2e-3 C1 R0, from rest.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include <gtest/gtest.h>

#include "reduced1d/internal.hpp"
#include "reduced1d/solver.hpp"

namespace swim::reduced1d::test {

struct ModeResponse {
  double amplitude = 0;        ///< the mode's amplitude over the middle half, in units of q0 / C1
  double stiffness_ratio = 1;  ///< C(k) / C1 = 1 + D kd^4 / C1, kd = (2/h) sin(k h / 2)
  double relaxation_time = 0;  ///< eta / C(k), eta = 16 mu / (R0^3 kd^2) [+ 4 mu kd with the traction]
};

/// The response at t = t_over_relaxation relaxation times, with the short-wave traction on or
/// off and the wall's axial bending D (0: none).
inline ModeResponse mode_response(int m, double D, bool traction, double t_over_relaxation) {
  Params p;
  p.wave = WaveKind::ForceDriven;
  p.swimmer.outer = OuterFlow::Unbounded;
  p.swimmer.short_wave_traction = traction;
  p.wall.D_axial = D;
  const double R0 = p.geometry.R0, C1 = p.wall.C1, mu = p.fluid.mu;
  const int N = 400;
  p.geometry.L = 40 * R0;
  p.numerics.cells = N;
  p.numerics.rtol = 1e-8;
  const double L = p.geometry.L, h = L / N;
  const double k = m * 3.14159265358979323846 / L, kd = 2.0 / h * std::sin(0.5 * k * h);
  // the free-ended wall's fourth difference on the grid's modes: (2 - 2 cos k h)^2 / h^4 = kd^4
  const double stiffness = C1 + D * kd * kd * kd * kd;
  const double eta = 16.0 * mu / (R0 * R0 * R0 * kd * kd) + (traction ? 4.0 * mu * kd : 0.0);
  ModeResponse out;
  out.stiffness_ratio = stiffness / C1;
  out.relaxation_time = eta / stiffness;
  const double q0 = 2e-3 * C1 * R0;
  std::vector<double> q(N), c(N);
  for (int i = 0; i < N; ++i) {
    c[i] = std::cos(k * (i + 0.5) * h);
    q[i] = q0 * c[i];
  }
  const double t = t_over_relaxation * out.relaxation_time;
  p.numerics.output_interval = t;
  const Result r = detail::solve_fixed_actuation(p, q, t);
  if (r.failure) ADD_FAILURE() << r.failure->what();
  if (r.radius_times.size() != 2u) {
    ADD_FAILURE() << "expected two samples, got " << r.radius_times.size();
    return out;
  }
  EXPECT_NEAR(r.radius_times[1], t, 1e-9 * t);
  double num = 0, den = 0;
  for (int i = N / 4; i < 3 * N / 4; ++i) {
    num += (r.radius[std::size_t(N) + i] - R0) * c[i];
    den += c[i] * c[i];
  }
  out.amplitude = -(num / den) / (q0 / C1);
  return out;
}

}  // namespace swim::reduced1d::test
