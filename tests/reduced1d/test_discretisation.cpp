// Kernels of the 1D discretisation: exact means over linear R, resistance, telescoping,
// actuation laws and their rest radii, protocol segment geometry, input validation.
#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.hpp"
#include "reduced1d/discretisation.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/protocol.hpp"

using namespace swim::reduced1d;

namespace {
// Mean of g(R) over R linear from a to b by composite Simpson (reference).
template <class G>
double simpson_mean(G g, double a, double b, int n = 2000) {
  double s = g(a) + g(b);
  for (int k = 1; k < n; ++k) s += (k % 2 ? 4.0 : 2.0) * g(a + (b - a) * k / n);
  return s / (3.0 * n);
}
}  // namespace

TEST(Reduced1dKernels, MeansOverLinearRadiusAreExact) {
  for (auto [a, b] : {std::pair{1.0, 1.0}, {0.3, 1.2}, {1.7, 0.55}}) {
    EXPECT_NEAR(disc::mean_R1(a, b), simpson_mean([](double R) { return R; }, a, b), 1e-12);
    EXPECT_NEAR(disc::mean_R2(a, b), simpson_mean([](double R) { return R * R; }, a, b), 1e-12);
    EXPECT_NEAR(disc::mean_R4(a, b), simpson_mean([](double R) { return std::pow(R, 4); }, a, b), 1e-10);
    const double m4 = simpson_mean([](double R) { return std::pow(R, -4); }, a, b, 20000);
    EXPECT_NEAR(disc::mean_Rm4(a, b) / m4, 1.0, 1e-9);
  }
}

TEST(Reduced1dKernels, TubeLawIntegralsTelescope) {
  // With p_k = C1 (R_k - R0) the point sums equal the closed forms C1 (R_L^n+1 - R_0^n+1)/(n+1).
  const double C1 = 3.0, R0 = 1.0;
  std::vector<double> R = {1.0, 0.9, 0.62, 0.55, 0.8, 0.57}, dp;
  for (std::size_t k = 0; k + 1 < R.size(); ++k) dp.push_back(C1 * (R[k + 1] - R[k]));
  const auto I = disc::pressure_integrals(R.data(), dp.data(), int(R.size()));
  const double a = R.front(), b = R.back();
  EXPECT_NEAR(I.I1, C1 * (b * b - a * a) / 2, 1e-14);
  EXPECT_NEAR(I.I2, C1 * (b * b * b - a * a * a) / 3, 1e-14);
  EXPECT_NEAR(I.I4, C1 * (std::pow(b, 5) - std::pow(a, 5)) / 5, 1e-14);
  (void)R0;
}

TEST(Reduced1dKernels, ActuationLawRestRadius) {
  detail::ActuationLaw c = detail::ActuationLaw::constant(0.3);
  EXPECT_DOUBLE_EQ(c.rest_radius(1.0, 2.0), 1.0 - 0.15);
  // Regularised relay: level -1 below 0.5, 0 in [0.5, 0.9], +1 above (ramps of width 0.1).
  detail::ActuationLaw r;
  r.n = 4;
  double x[] = {0.45, 0.55, 0.85, 0.95}, y[] = {-1, 0, 0, 1};
  for (int k = 0; k < 4; ++k) r.x[k] = x[k], r.y[k] = y[k];
  EXPECT_DOUBLE_EQ(r(0.7), 0.0);
  EXPECT_DOUBLE_EQ(r(2.0), 1.0);
  EXPECT_NEAR(r(0.90), 0.5, 1e-12);  // centre of the smooth step
  for (double C1 : {0.5, 3.0, 50.0}) {
    const double Rb = r.rest_radius(1.0, C1);
    EXPECT_NEAR(C1 * (Rb - 1.0) + r(Rb), 0.0, 1e-12) << C1;
  }
}

TEST(Reduced1dProtocol, SegmentGeometryAndOverlaps) {
  Params p;
  p.wave = WaveKind::ForceDriven;
  p.numerics.cells = 40;
  const auto b = detail::segment_bounds(p);
  ASSERT_EQ(b.size(), 7u);
  const double ell = b[1] - b[0];
  EXPECT_NEAR((b[6] - b[5]) / ell, p.protocol.first_ratio, 1e-12);  // rightmost is the short one
  EXPECT_DOUBLE_EQ(b[6], p.geometry.L);
  const auto ov = detail::segment_overlaps(p);
  std::vector<double> len(6, 0.0);
  const double h = p.geometry.L / 40;
  for (const auto& c : ov) {
    len[c.seg_a] += c.w * h;
    if (c.seg_b != c.seg_a) len[c.seg_b] += (1 - c.w) * h;
  }
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(len[k], b[k + 1] - b[k], 1e-18);
}

TEST(Reduced1dValidation, RejectsUnusableParameters) {
  Params p;
  p.wave = WaveKind::ForceDriven;
  p.numerics.cells = 10;  // shortest segment L/16 needs >= 16 cells
  EXPECT_THROW(solve(p), swim::InputError);
  p.numerics.cells = 50;
  p.protocol.R_f = 1.2 * p.geometry.R0;
  EXPECT_THROW(solve(p), swim::InputError);
  Params s;
  s.step.width = 0;
  EXPECT_THROW(solve(s), swim::InputError);
}

TEST(Reduced1dEndTime, TransitTimesAndDuration) {
  Params p;
  EXPECT_DOUBLE_EQ(end_time(p), p.geometry.L / p.step.speed);
  p.wave = WaveKind::Sine;
  EXPECT_DOUBLE_EQ(end_time(p), p.sine.wavelength / p.sine.speed);
  p.duration = 0.5;
  EXPECT_DOUBLE_EQ(end_time(p), 0.5);
  p.duration = 0;
  p.wave = WaveKind::ForceDriven;
  EXPECT_GT(end_time(p), 1.0);  // generous bound on one cycle (a cycle takes ~0.28 s)
}
