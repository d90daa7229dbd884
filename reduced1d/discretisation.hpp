// Spatial discretisation kernels of the reduced 1D tier (header-only, allocation-free).
//
// Grid: N cells of width h = L/N, centres z_i = (i + 1/2) h. Integrals along z use the
// N + 2 points {0, z_0, ..., z_{N-1}, L}; the N + 1 intervals between consecutive points
// have lengths h/2, h, ..., h, h/2, and interval j contains the cell face z = j h (the face
// is the midpoint of every interior interval). The radius is reconstructed linearly
// between consecutive points; every z-integral below is exact for that reconstruction.
// docs/reduced1d.md derives each formula.
#pragma once

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "reduced1d/params.hpp"
#include "reduced1d/recorded_wave.hpp"

namespace swim::reduced1d::disc {

inline constexpr double pi = std::numbers::pi;

/// Mean of R over [a, b] for R linear between a and b.
inline double mean_R1(double a, double b) { return 0.5 * (a + b); }
/// Mean of R^2.
inline double mean_R2(double a, double b) { return (a * a + a * b + b * b) / 3.0; }
/// Mean of R^4 (no division by b - a: exact and robust when a == b).
inline double mean_R4(double a, double b) {
  const double a2 = a * a, b2 = b * b;
  return (a2 * a2 + a2 * a * b + a2 * b2 + a * b * b2 + b2 * b2) / 5.0;
}
/// Mean of R^-4.
inline double mean_Rm4(double a, double b) {
  const double ab = a * b;
  return (a * a + ab + b * b) / (3.0 * ab * ab * ab);
}
/// Poiseuille resistance of a length d with R linear from a to b: dp = -r Q.
inline double resistance(double mu, double d, double a, double b) {
  return (8.0 * mu / pi) * d * mean_Rm4(a, b);
}

/// Resistance of an open end's half cell as a drainage layer: the quasi-steady flux through a
/// length d whose pressure follows the wall, dp = C1 dR (the actuation uniform over the half
/// cell), Q = -(pi / 8 mu) R^4 C1 R_z, integrates exactly to Q = -(pi / 8 mu d) mean(R^4) dp
/// whatever the profile R(z) between a and b (docs/reduced1d.md, "The open ends").
inline double drainage_resistance(double mu, double d, double a, double b) {
  return (8.0 * mu / pi) * d / mean_R4(a, b);
}
/// d/da and d/db of drainage_resistance.
inline void drainage_dresistance(double mu, double d, double a, double b, double& ra, double& rb) {
  const double m = mean_R4(a, b), r = (8.0 * mu / pi) * d / m;
  const double a2 = a * a, b2 = b * b;
  const double ma = (4.0 * a2 * a + 3.0 * a2 * b + 2.0 * a * b2 + b2 * b) / 5.0;
  const double mb = (4.0 * b2 * b + 3.0 * b2 * a + 2.0 * b * a2 + a2 * a) / 5.0;
  ra = -r * ma / m;
  rb = -r * mb / m;
}

/// Integrals I_n = int R^n p_z dz (n = 1, 2, 4) over the point set, exact for linear R and p
/// between consecutive points: sum_k (p_{k+1} - p_k) mean_Rn(R_k, R_{k+1}).
struct PressureIntegrals {
  double I1 = 0, I2 = 0, I4 = 0;
};

/// dp[k] = p_{k+1} - p_k for k = 0..n-2, R[k] for k = 0..n-1.
inline PressureIntegrals pressure_integrals(const double* R, const double* dp, int npoints) {
  PressureIntegrals s;
  for (int k = 0; k + 1 < npoints; ++k) {
    const double a = R[k], b = R[k + 1];
    s.I1 += dp[k] * mean_R1(a, b);
    s.I2 += dp[k] * mean_R2(a, b);
    s.I4 += dp[k] * mean_R4(a, b);
  }
  return s;
}

/// Coefficients of the swimmer balance  m_eff W = thrust - D(t) - c X(t),  D' = drag integrand.
struct BalanceCoefficients {
  double m_eff = 1;       ///< m (per area) or 2 pi R0 m (per length)
  double thrust = 0;      ///< multiplies I4 (0 when thrust is off)
  double drag = 0;        ///< multiplies I1 (per area) or I2 (per length)
  bool per_length = false;
  double c_ext = 0;       ///< external drag coefficient (0 unless ResistiveForce)

  static BalanceCoefficients from(const Params& p) {
    BalanceCoefficients b;
    const double L = p.geometry.L, R0 = p.geometry.R0, mu = p.fluid.mu;
    b.per_length = p.swimmer.balance == Balance::PerLength;
    b.m_eff = b.per_length ? 2.0 * pi * R0 * p.wall.m : p.wall.m;
    b.thrust = p.swimmer.thrust ? pi * p.fluid.rho / (8.0 * mu * L) : 0.0;
    b.drag = b.per_length ? pi / L : 1.0 / (2.0 * L);
    if (p.swimmer.drag == ExternalDrag::ResistiveForce) {
      const double c_par = 2.0 * pi * mu / (std::log(2.0 * L / R0) - 0.5);
      b.c_ext = b.per_length ? c_par : c_par / (2.0 * pi * R0);
    }
    return b;
  }
  double drag_integrand(const PressureIntegrals& s) const { return drag * (per_length ? s.I2 : s.I1); }
  double thrust_term(const PressureIntegrals& s) const { return thrust * s.I4; }
  double velocity(double thrust_value, double D, double X) const {
    return (thrust_value - D - c_ext * X) / m_eff;
  }
};

/// Elastic energy of the cell radii: sum (1/2) C1 (R_i - R0)^2 2 pi R0 h.
inline double elastic_energy(const double* R, int N, double R0, double C1, double h) {
  double e = 0;
  for (int i = 0; i < N; ++i) e += (R[i] - R0) * (R[i] - R0);
  return 0.5 * C1 * e * 2.0 * pi * R0 * h;
}

/// Prescribed radius R(z, t) and dR/dt for the Step and Sine waves (params.hpp formulas).
struct PrescribedShape {
  WaveKind kind = WaveKind::Step;
  double R0 = 0, L = 0;
  double Rmin = 0, s = 0, w = 0;    // step
  double a = 0, lambda = 0;         // sine (s shared)
  std::shared_ptr<const RecordedRadius> rec;  // recorded

  static PrescribedShape from(const Params& p) {
    PrescribedShape sh;
    sh.kind = p.wave;
    sh.R0 = p.geometry.R0;
    sh.L = p.geometry.L;
    if (p.wave == WaveKind::Recorded) {
      sh.rec = p.recorded;
    } else if (p.wave == WaveKind::Step) {
      sh.Rmin = p.step.R_min;
      sh.s = p.step.speed;
      sh.w = p.step.width;
    } else {
      sh.a = p.sine.amplitude;
      sh.lambda = p.sine.wavelength;
      sh.s = p.sine.speed;
    }
    return sh;
  }
  /// R and dR/dt at (z, t).
  void eval(double z, double t, double& R, double& Rt) const {
    if (kind == WaveKind::Recorded) {
      rec->eval(z, t, R, Rt);
    } else if (kind == WaveKind::Step) {
      const double x = (L - s * t - z) / w;
      // tanh(x) rounds to +-1 in double precision for |x| > 19.1; skip the libm call there.
      const double th = x > 19.5 ? 1.0 : (x < -19.5 ? -1.0 : std::tanh(x));
      const double amp = R0 - Rmin;
      R = Rmin + amp * 0.5 * (1.0 + th);
      Rt = amp * 0.5 * (1.0 - th * th) * (-s / w);
    } else {
      const double k = 2.0 * pi / lambda;
      const double ph = k * (z + s * t);
      R = R0 - 0.5 * a * (1.0 - std::cos(ph));
      Rt = -0.5 * a * std::sin(ph) * k * s;
    }
  }
  /// R and dR/dt at the n points z[k] = z0 + k dz (uniform spacing) at time t. The step
  /// wave uses tanh(x) = (1 - e) / (1 + e) and 1 - tanh^2 = 4 e / (1 + e)^2 with
  /// e = exp(-2x), and since x falls by dz / w from point to point, e grows by the constant
  /// factor exp(2 dz / w): one exponential per 16 points instead of a tanh per point (the
  /// values agree with eval() to a few ulps of R0). Saturated points (|x| > 19.5) take
  /// exactly eval()'s values.
  void eval_uniform(double z0, double dz, int n, double t, double* R, double* Rt) const {
    if (kind == WaveKind::Recorded) {
      rec->eval_uniform(z0, dz, n, t, R, Rt);
      return;
    }
    if (kind != WaveKind::Step) {
      for (int k = 0; k < n; ++k) eval(z0 + k * dz, t, R[k], Rt[k]);
      return;
    }
    const double amp = R0 - Rmin, half = 0.5 * amp, rate = -s / w, iw = 1.0 / w;
    const double grow = std::exp(2.0 * dz * iw);
    const double xs = L - s * t - z0;
    constexpr int kAnchor = 16;  // fresh exponential every kAnchor points (bounds the round-off)
    int fresh = 0;               // points left before the next fresh exponential
    double e = 0;
    for (int k = 0; k < n; ++k) {
      const double x = (xs - k * dz) * iw;
      if (x > 19.5 || x < -19.5) {
        const double th = x > 0 ? 1.0 : -1.0;
        R[k] = Rmin + half * (1.0 + th);
        Rt[k] = 0.0;  // amp 0.5 (1 - th^2) rate with th^2 = 1
        fresh = 0;
        continue;
      }
      if (fresh == 0) {
        e = std::exp(-2.0 * x);
        fresh = kAnchor;
      } else {
        e *= grow;
      }
      --fresh;
      const double ip = 1.0 / (1.0 + e);
      R[k] = Rmin + amp * ip;             // Rmin + amp (1 + th) / 2, (1 + th) / 2 = 1 / (1 + e)
      Rt[k] = half * (4.0 * e * ip * ip) * rate;
    }
  }
};

}  // namespace swim::reduced1d::disc
