// Dense 1D real transforms as small matrix products (line_transform.hpp).
#include "full3d/line_transform.hpp"

#include <immintrin.h>

#include <cmath>
#include <numbers>

namespace swim::full3d {

namespace {

// cos(pi a / b) and sin(pi a / b) with the argument reduced exactly in integers first, so
// that every entry of a large table is as accurate as the first ones.
double cos_pi_frac(long a, long b) {
  a %= 2 * b;
  return std::cos(std::numbers::pi * double(a) / double(b));
}
double sin_pi_frac(long a, long b) {
  a %= 2 * b;
  return std::sin(std::numbers::pi * double(a) / double(b));
}

// Portable kernel: the compiler vectorises the inner loop along a row of B and C.
void gemm_generic(int M, int N, int K, const double* A, int lda, const double* B, int ldb, double* C, int ldc) {
  for (int i = 0; i < M; ++i) {
    double* c = C + long(i) * ldc;
    const double* a = A + long(i) * lda;
    for (int j = 0; j < N; ++j) c[j] = 0.0;
    for (int k = 0; k < K; ++k) {
      const double aik = a[k];
      const double* b = B + long(k) * ldb;
      for (int j = 0; j < N; ++j) c[j] += aik * b[j];
    }
  }
}

// AVX2/FMA kernel: blocks of 4 rows x 8 columns of C in 8 registers, the k loop innermost
// (one pass over a 4 x K panel of A and a K x 8 panel of B per block); then 4-column blocks,
// single columns and single rows for the edges.
__attribute__((target("avx2,fma"))) void gemm_avx2(int M, int N, int K, const double* A, int lda,
                                                     const double* B, int ldb, double* C, int ldc) {
  int i = 0;
  for (; i + 4 <= M; i += 4) {
    const double* a0 = A + long(i) * lda;
    const double* a1 = a0 + lda;
    const double* a2 = a1 + lda;
    const double* a3 = a2 + lda;
    double* c0 = C + long(i) * ldc;
    double* c1 = c0 + ldc;
    double* c2 = c1 + ldc;
    double* c3 = c2 + ldc;
    int j = 0;
    for (; j + 8 <= N; j += 8) {
      __m256d s00 = _mm256_setzero_pd(), s01 = s00, s10 = s00, s11 = s00, s20 = s00, s21 = s00, s30 = s00,
              s31 = s00;
      const double* b = B + j;
      for (int k = 0; k < K; ++k, b += ldb) {
        const __m256d b0 = _mm256_loadu_pd(b), b1 = _mm256_loadu_pd(b + 4);
        __m256d x = _mm256_broadcast_sd(a0 + k);
        s00 = _mm256_fmadd_pd(x, b0, s00);
        s01 = _mm256_fmadd_pd(x, b1, s01);
        x = _mm256_broadcast_sd(a1 + k);
        s10 = _mm256_fmadd_pd(x, b0, s10);
        s11 = _mm256_fmadd_pd(x, b1, s11);
        x = _mm256_broadcast_sd(a2 + k);
        s20 = _mm256_fmadd_pd(x, b0, s20);
        s21 = _mm256_fmadd_pd(x, b1, s21);
        x = _mm256_broadcast_sd(a3 + k);
        s30 = _mm256_fmadd_pd(x, b0, s30);
        s31 = _mm256_fmadd_pd(x, b1, s31);
      }
      _mm256_storeu_pd(c0 + j, s00);
      _mm256_storeu_pd(c0 + j + 4, s01);
      _mm256_storeu_pd(c1 + j, s10);
      _mm256_storeu_pd(c1 + j + 4, s11);
      _mm256_storeu_pd(c2 + j, s20);
      _mm256_storeu_pd(c2 + j + 4, s21);
      _mm256_storeu_pd(c3 + j, s30);
      _mm256_storeu_pd(c3 + j + 4, s31);
    }
    for (; j + 4 <= N; j += 4) {
      __m256d s0 = _mm256_setzero_pd(), s1 = s0, s2 = s0, s3 = s0;
      const double* b = B + j;
      for (int k = 0; k < K; ++k, b += ldb) {
        const __m256d b0 = _mm256_loadu_pd(b);
        s0 = _mm256_fmadd_pd(_mm256_broadcast_sd(a0 + k), b0, s0);
        s1 = _mm256_fmadd_pd(_mm256_broadcast_sd(a1 + k), b0, s1);
        s2 = _mm256_fmadd_pd(_mm256_broadcast_sd(a2 + k), b0, s2);
        s3 = _mm256_fmadd_pd(_mm256_broadcast_sd(a3 + k), b0, s3);
      }
      _mm256_storeu_pd(c0 + j, s0);
      _mm256_storeu_pd(c1 + j, s1);
      _mm256_storeu_pd(c2 + j, s2);
      _mm256_storeu_pd(c3 + j, s3);
    }
    for (; j < N; ++j) {
      double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
      const double* b = B + j;
      for (int k = 0; k < K; ++k, b += ldb) {
        s0 = std::fma(a0[k], *b, s0);
        s1 = std::fma(a1[k], *b, s1);
        s2 = std::fma(a2[k], *b, s2);
        s3 = std::fma(a3[k], *b, s3);
      }
      c0[j] = s0;
      c1[j] = s1;
      c2[j] = s2;
      c3[j] = s3;
    }
  }
  for (; i < M; ++i) {
    const double* a = A + long(i) * lda;
    double* c = C + long(i) * ldc;
    int j = 0;
    for (; j + 4 <= N; j += 4) {
      __m256d s = _mm256_setzero_pd();
      const double* b = B + j;
      for (int k = 0; k < K; ++k, b += ldb) s = _mm256_fmadd_pd(_mm256_broadcast_sd(a + k), _mm256_loadu_pd(b), s);
      _mm256_storeu_pd(c + j, s);
    }
    for (; j < N; ++j) {
      double s = 0;
      const double* b = B + j;
      for (int k = 0; k < K; ++k, b += ldb) s = std::fma(a[k], *b, s);
      c[j] = s;
    }
  }
}

using GemmFn = void (*)(int, int, int, const double*, int, const double*, int, double*, int);

GemmFn select_gemm() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return gemm_avx2;
  return gemm_generic;
}

const GemmFn gemm_kernel = select_gemm();

}  // namespace

void small_gemm(int M, int N, int K, const double* A, int lda, const double* B, int ldb, double* C, int ldc) {
  if (M <= 0 || N <= 0) return;
  gemm_kernel(M, N, K, A, lda, B, ldb, C, ldc);
}

void small_gemm_portable(int M, int N, int K, const double* A, int lda, const double* B, int ldb, double* C,
                         int ldc) {
  if (M <= 0 || N <= 0) return;
  gemm_generic(M, N, K, A, lda, B, ldb, C, ldc);
}

LineTransform::LineTransform(R2rKind kind, int n) : n_(n), t_(std::size_t(n) * n), tt_(std::size_t(n) * n) {
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j) {
      double v = 0.0;
      switch (kind) {
        case R2rKind::Redft10:
          v = 2.0 * cos_pi_frac(long(2 * j + 1) * k, 2L * n);
          break;
        case R2rKind::Redft01:
          v = j == 0 ? 1.0 : 2.0 * cos_pi_frac(long(j) * (2 * k + 1), 2L * n);
          break;
        case R2rKind::Rodft00:
          v = 2.0 * sin_pi_frac(long(j + 1) * (k + 1), long(n) + 1);
          break;
      }
      t_[std::size_t(k) * n + j] = v;
      tt_[std::size_t(j) * n + k] = v;
    }
}

void LineTransform::along(const double* in, int ld_in, double* out, int ld_out, int lines) const {
  small_gemm(lines, n_, n_, in, ld_in, tt_.data(), n_, out, ld_out);
}

void LineTransform::across(const double* in, int ld_in, double* out, int ld_out, int width) const {
  small_gemm(n_, width, n_, t_.data(), n_, in, ld_in, out, ld_out);
}

}  // namespace swim::full3d
