// Dense line transforms (full3d/line_transform.hpp): each kind against FFTW's r2r transform
// of the same kind, both orientations with padded rows, the inverse pairs, and the small
// matrix product (the AVX2/FMA kernel and the portable one) on every edge shape of its
// register blocks.
#include <fftw3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "full3d/line_transform.hpp"

namespace swim::full3d {
namespace {

fftw_r2r_kind fftw_kind(R2rKind k) {
  switch (k) {
    case R2rKind::Redft10:
      return FFTW_REDFT10;
    case R2rKind::Redft01:
      return FFTW_REDFT01;
    case R2rKind::Rodft00:
      return FFTW_RODFT00;
  }
  return FFTW_REDFT10;
}

// FFTW's transform of one line (stride 1) of length n.
std::vector<double> fftw_line(R2rKind k, const std::vector<double>& x) {
  const int n = int(x.size());
  std::vector<double> in(x), out(x.size());
  fftw_plan p = fftw_plan_r2r_1d(n, in.data(), out.data(), fftw_kind(k), FFTW_ESTIMATE);
  fftw_execute(p);
  fftw_destroy_plan(p);
  return out;
}

std::vector<double> random_vector(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> v(n);
  for (auto& x : v) x = u(rng);
  return v;
}

TEST(LineTransform, MatchesFftwAlongAndAcrossLines) {
  for (R2rKind kind : {R2rKind::Redft10, R2rKind::Redft01, R2rKind::Rodft00})
    for (int n : {1, 2, 3, 4, 5, 7, 8, 9, 13, 31, 35, 36, 37, 50, 64}) {
      const LineTransform t(kind, n);
      const int lines = 11, pad = 3, ld = n + pad;  // padded rows; the pads must stay untouched
      // along: line l = row l
      const auto in = random_vector(std::size_t(lines) * ld, 7u + unsigned(n));
      std::vector<double> out(std::size_t(lines) * ld, 42.0);
      t.along(in.data(), ld, out.data(), ld, lines);
      double err = 0.0, scale = 0.0;
      for (int l = 0; l < lines; ++l) {
        const std::vector<double> x(in.begin() + long(l) * ld, in.begin() + long(l) * ld + n);
        const auto y = fftw_line(kind, x);
        for (int k = 0; k < n; ++k) {
          err = std::max(err, std::abs(out[std::size_t(l) * ld + k] - y[k]));
          scale = std::max(scale, std::abs(y[k]));
        }
        for (int k = n; k < ld; ++k) EXPECT_EQ(out[std::size_t(l) * ld + k], 42.0);
      }
      EXPECT_LT(err, 1e-14 * n * std::max(scale, 1.0)) << "along, n = " << n;
      // across: line w = column w of an n x width block with rows ld apart
      const int width = 13;
      const int ldw = width + pad;
      const auto in2 = random_vector(std::size_t(n) * ldw, 11u + unsigned(n));
      std::vector<double> out2(std::size_t(n) * ldw, 42.0);
      t.across(in2.data(), ldw, out2.data(), ldw, width);
      err = 0.0;
      scale = 0.0;
      for (int w = 0; w < width; ++w) {
        std::vector<double> x(static_cast<std::size_t>(n));
        for (int j = 0; j < n; ++j) x[j] = in2[std::size_t(j) * ldw + w];
        const auto y = fftw_line(kind, x);
        for (int k = 0; k < n; ++k) {
          err = std::max(err, std::abs(out2[std::size_t(k) * ldw + w] - y[k]));
          scale = std::max(scale, std::abs(y[k]));
        }
      }
      for (int j = 0; j < n; ++j)
        for (int w = width; w < ldw; ++w) EXPECT_EQ(out2[std::size_t(j) * ldw + w], 42.0);
      EXPECT_LT(err, 1e-14 * n * std::max(scale, 1.0)) << "across, n = " << n;
    }
}

TEST(LineTransform, InversePairsGiveTheIdentityTimesTheirNormalisation) {
  // REDFT01 (REDFT10 x) = 2 n x, RODFT00 (RODFT00 x) = 2 (n + 1) x
  for (int n : {1, 6, 35, 36, 48}) {
    const LineTransform f(R2rKind::Redft10, n), b(R2rKind::Redft01, n), s(R2rKind::Rodft00, n);
    const int lines = 5;
    const auto x = random_vector(std::size_t(lines) * n, 3u + unsigned(n));
    std::vector<double> y(x.size()), z(x.size());
    f.along(x.data(), n, y.data(), n, lines);
    b.along(y.data(), n, z.data(), n, lines);
    double err = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) err = std::max(err, std::abs(z[i] / (2.0 * n) - x[i]));
    EXPECT_LT(err, 1e-14 * n) << "DCT-II/III, n = " << n;
    s.across(x.data(), lines, y.data(), lines, lines);
    s.across(y.data(), lines, z.data(), lines, lines);
    err = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) err = std::max(err, std::abs(z[i] / (2.0 * (n + 1)) - x[i]));
    EXPECT_LT(err, 1e-14 * n) << "DST-I, n = " << n;
  }
}

TEST(LineTransform, SmallGemmMatchesTheTripleLoopOnEveryEdgeShape) {
  // every remainder of the 4-row and 8/4-column register blocks, and K = 0 (C = 0)
  for (int M = 1; M <= 9; ++M)
    for (int N = 1; N <= 19; ++N)
      for (int K : {0, 1, 3, 8}) {
        const int lda = K + 2, ldb = N + 1, ldc = N + 3;
        const auto A = random_vector(std::size_t(M) * lda, 1u + unsigned(M));
        const auto B = random_vector(std::size_t(std::max(K, 1)) * ldb, 2u + unsigned(N));
        std::vector<double> C(std::size_t(M) * ldc, 42.0), Cp(C);
        small_gemm(M, N, K, A.data(), lda, B.data(), ldb, C.data(), ldc);
        small_gemm_portable(M, N, K, A.data(), lda, B.data(), ldb, Cp.data(), ldc);
        for (int i = 0; i < M; ++i) {
          for (int j = 0; j < N; ++j) {
            double ref = 0.0;
            for (int k = 0; k < K; ++k) ref += A[std::size_t(i) * lda + k] * B[std::size_t(k) * ldb + j];
            EXPECT_NEAR(C[std::size_t(i) * ldc + j], ref, 1e-15 * (K + 1)) << M << "x" << N << "x" << K;
            EXPECT_NEAR(Cp[std::size_t(i) * ldc + j], ref, 1e-15 * (K + 1)) << M << "x" << N << "x" << K;
          }
          for (int j = N; j < ldc; ++j) EXPECT_EQ(C[std::size_t(i) * ldc + j], 42.0);
          for (int j = N; j < ldc; ++j) EXPECT_EQ(Cp[std::size_t(i) * ldc + j], 42.0);
        }
      }
}

}  // namespace
}  // namespace swim::full3d
