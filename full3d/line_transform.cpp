// Dense 1D real transforms as small matrix products (line_transform.hpp).
#include "full3d/line_transform.hpp"

#if defined(__x86_64__) || defined(__i386__)
#define SWIM_LINE_TRANSFORM_AVX2 1
#include <immintrin.h>
#endif

#include <algorithm>
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
void gemm_generic(int M, int N, int K, const double* A, int lda, int inca, const double* B, int ldb, double* C,
                  int ldc) {
  for (int i = 0; i < M; ++i) {
    double* c = C + long(i) * ldc;
    const double* a = A + long(i) * lda;
    for (int j = 0; j < N; ++j) c[j] = 0.0;
    for (int k = 0; k < K; ++k) {
      const double aik = a[long(k) * inca];
      const double* b = B + long(k) * ldb;
      for (int j = 0; j < N; ++j) c[j] += aik * b[j];
    }
  }
}

#ifdef SWIM_LINE_TRANSFORM_AVX2
// AVX2/FMA kernel. A block of R rows (R <= 4) and 8 columns of C stays in 2R registers while
// k runs over a R x K panel of A (broadcast) and a K x 8 panel of B; the column edge is one
// 4-wide block and a masked block of 1-3 columns, the row edge a block of 1-3 rows, so that
// every product runs in vector registers (at 36 points the even/odd halves are 18 wide).
__attribute__((target("avx2,fma"))) inline __m256i tail_mask(int r) {
  return _mm256_setr_epi64x(r > 0 ? -1 : 0, r > 1 ? -1 : 0, r > 2 ? -1 : 0, 0);
}

template <int R>
__attribute__((target("avx2,fma"))) void rows_avx2(int N, int K, const double* A, int lda, int inca,
                                                     const double* B, int ldb, double* C, int ldc) {
  const double* a[R];
  double* c[R];
  for (int r = 0; r < R; ++r) {
    a[r] = A + long(r) * lda;
    c[r] = C + long(r) * ldc;
  }
  int j = 0;
  for (; j + 8 <= N; j += 8) {
    __m256d s0[R], s1[R];
    for (int r = 0; r < R; ++r) s0[r] = s1[r] = _mm256_setzero_pd();
    const double* b = B + j;
    for (int k = 0; k < K; ++k, b += ldb) {
      const __m256d b0 = _mm256_loadu_pd(b), b1 = _mm256_loadu_pd(b + 4);
      for (int r = 0; r < R; ++r) {
        const __m256d x = _mm256_broadcast_sd(a[r] + long(k) * inca);
        s0[r] = _mm256_fmadd_pd(x, b0, s0[r]);
        s1[r] = _mm256_fmadd_pd(x, b1, s1[r]);
      }
    }
    for (int r = 0; r < R; ++r) {
      _mm256_storeu_pd(c[r] + j, s0[r]);
      _mm256_storeu_pd(c[r] + j + 4, s1[r]);
    }
  }
  if (j + 4 <= N) {
    __m256d s0[R];
    for (int r = 0; r < R; ++r) s0[r] = _mm256_setzero_pd();
    const double* b = B + j;
    for (int k = 0; k < K; ++k, b += ldb) {
      const __m256d b0 = _mm256_loadu_pd(b);
      for (int r = 0; r < R; ++r) s0[r] = _mm256_fmadd_pd(_mm256_broadcast_sd(a[r] + long(k) * inca), b0, s0[r]);
    }
    for (int r = 0; r < R; ++r) _mm256_storeu_pd(c[r] + j, s0[r]);
    j += 4;
  }
  if (j < N) {  // 1-3 columns: masked loads and stores (nothing outside the row is touched)
    const __m256i mask = tail_mask(N - j);
    __m256d s0[R];
    for (int r = 0; r < R; ++r) s0[r] = _mm256_setzero_pd();
    const double* b = B + j;
    for (int k = 0; k < K; ++k, b += ldb) {
      const __m256d b0 = _mm256_maskload_pd(b, mask);
      for (int r = 0; r < R; ++r) s0[r] = _mm256_fmadd_pd(_mm256_broadcast_sd(a[r] + long(k) * inca), b0, s0[r]);
    }
    for (int r = 0; r < R; ++r) _mm256_maskstore_pd(c[r] + j, mask, s0[r]);
  }
}

__attribute__((target("avx2,fma"))) void gemm_avx2(int M, int N, int K, const double* A, int lda, int inca,
                                                     const double* B, int ldb, double* C, int ldc) {
  int i = 0;
  for (; i + 4 <= M; i += 4) rows_avx2<4>(N, K, A + long(i) * lda, lda, inca, B, ldb, C + long(i) * ldc, ldc);
  const double* Ai = A + long(i) * lda;
  double* Ci = C + long(i) * ldc;
  switch (M - i) {
    case 3:
      rows_avx2<3>(N, K, Ai, lda, inca, B, ldb, Ci, ldc);
      break;
    case 2:
      rows_avx2<2>(N, K, Ai, lda, inca, B, ldb, Ci, ldc);
      break;
    case 1:
      rows_avx2<1>(N, K, Ai, lda, inca, B, ldb, Ci, ldc);
      break;
    default:
      break;
  }
}

#endif  // SWIM_LINE_TRANSFORM_AVX2

using GemmFn = void (*)(int, int, int, const double*, int, int, const double*, int, double*, int);

GemmFn select_gemm() {
#ifdef SWIM_LINE_TRANSFORM_AVX2
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return gemm_avx2;
#endif
  return gemm_generic;
}

const GemmFn gemm_kernel = select_gemm();

}  // namespace

void small_gemm(int M, int N, int K, const double* A, int lda, const double* B, int ldb, double* C, int ldc) {
  if (M <= 0 || N <= 0) return;
  gemm_kernel(M, N, K, A, lda, 1, B, ldb, C, ldc);
}

// C = A B with A's columns inca apart.
void gemm_strided_a(int M, int N, int K, const double* A, int lda, int inca, const double* B, int ldb, double* C,
                    int ldc) {
  if (M <= 0 || N <= 0) return;
  gemm_kernel(M, N, K, A, lda, inca, B, ldb, C, ldc);
}

void small_gemm_portable(int M, int N, int K, const double* A, int lda, const double* B, int ldb, double* C,
                         int ldc) {
  if (M <= 0 || N <= 0) return;
  gemm_generic(M, N, K, A, lda, 1, B, ldb, C, ldc);
}

// The symmetry of the three kinds halves the work. DCT-II and DST-I are even or odd in the
// input index for even or odd k, T(k, n-1-j) = (-1)^k T(k, j): the even outputs are Te s and
// the odd ones To d, with s_j = x_j + x_{n-1-j} and d_j = x_j - x_{n-1-j}, j < n/2 (an odd
// n's middle input enters s alone and has no weight in the odd outputs). DCT-III has the same
// symmetry in the output index, T(n-1-k, j) = (-1)^j T(k, j): with e = Te x_even and
// o = To x_odd (k < n/2), y_k = e_k + o_k and y_{n-1-k} = e_k - o_k.
LineTransform::LineTransform(R2rKind kind, int n)
    : n_(n), ne_((n + 1) / 2), no_(n / 2), output_split_(kind == R2rKind::Redft01) {
  auto entry = [&](int k, int j) {
    switch (kind) {
      case R2rKind::Redft10:
        return 2.0 * cos_pi_frac(long(2 * j + 1) * k, 2L * n);
      case R2rKind::Redft01:
        return j == 0 ? 1.0 : 2.0 * cos_pi_frac(long(j) * (2 * k + 1), 2L * n);
      case R2rKind::Rodft00:
        return 2.0 * sin_pi_frac(long(j + 1) * (k + 1), long(n) + 1);
    }
    return 0.0;
  };
  // input split: te (ne x ne): rows k = 0, 2, ..., columns j < ne; to (no x no): rows k = 1, 3, ...
  // output split: te (ne x ne): rows k < ne, columns j = 0, 2, ...; to (ne x no): columns j = 1, 3, ...
  const int te_rows = ne_, to_rows = output_split_ ? ne_ : no_;
  te_.resize(std::size_t(te_rows) * ne_);
  to_.resize(std::size_t(to_rows) * no_);
  tet_.resize(te_.size());
  tot_.resize(to_.size());
  for (int r = 0; r < te_rows; ++r)
    for (int c = 0; c < ne_; ++c) {
      const double v = output_split_ ? entry(r, 2 * c) : entry(2 * r, c);
      te_[std::size_t(r) * ne_ + c] = v;
      tet_[std::size_t(c) * te_rows + r] = v;
    }
  for (int r = 0; r < to_rows; ++r)
    for (int c = 0; c < no_; ++c) {
      const double v = output_split_ ? entry(r, 2 * c + 1) : entry(2 * r + 1, c);
      to_[std::size_t(r) * no_ + c] = v;
      tot_[std::size_t(c) * to_rows + r] = v;
    }
}

void LineTransform::along(const double* in, int ld_in, double* out, int ld_out, int lines) const {
  if (n_ == 0 || lines <= 0) return;
  thread_local std::vector<double> ws;
  const int to_rows = output_split_ ? ne_ : no_;
  ws.resize(std::size_t(lines) * (output_split_ ? 2 * ne_ : 2 * (ne_ + no_)));
  double* e = ws.data();                          // lines x ne
  double* o = e + std::size_t(lines) * ne_;        // lines x to_rows
  if (output_split_) {
    gemm_strided_a(lines, ne_, ne_, in, ld_in, 2, tet_.data(), ne_, e, ne_);
    gemm_strided_a(lines, ne_, no_, in + 1, ld_in, 2, tot_.data(), ne_, o, ne_);
    for (int l = 0; l < lines; ++l) {
      const double* el = e + std::size_t(l) * ne_;
      const double* ol = o + std::size_t(l) * ne_;
      double* y = out + std::size_t(l) * ld_out;
      for (int k = 0; k < no_; ++k) {
        y[k] = el[k] + ol[k];
        y[n_ - 1 - k] = el[k] - ol[k];
      }
      if (ne_ > no_) y[no_] = el[no_] + ol[no_];
    }
    return;
  }
  double* sp = o + std::size_t(lines) * to_rows;  // lines x ne: s
  double* dp = sp + std::size_t(lines) * ne_;       // lines x no: d
  for (int l = 0; l < lines; ++l) {
    const double* x = in + std::size_t(l) * ld_in;
    double* sl = sp + std::size_t(l) * ne_;
    double* dl = dp + std::size_t(l) * no_;
    for (int j = 0; j < no_; ++j) {
      sl[j] = x[j] + x[n_ - 1 - j];
      dl[j] = x[j] - x[n_ - 1 - j];
    }
    if (ne_ > no_) sl[no_] = x[no_];
  }
  small_gemm(lines, ne_, ne_, sp, ne_, tet_.data(), ne_, e, ne_);
  small_gemm(lines, no_, no_, dp, no_, tot_.data(), no_, o, no_);
  for (int l = 0; l < lines; ++l) {
    const double* el = e + std::size_t(l) * ne_;
    const double* ol = o + std::size_t(l) * no_;
    double* y = out + std::size_t(l) * ld_out;
    for (int k = 0; k < no_; ++k) {
      y[2 * k] = el[k];
      y[2 * k + 1] = ol[k];
    }
    if (ne_ > no_) y[n_ - 1] = el[no_];
  }
}

void LineTransform::across(const double* in, int ld_in, double* out, int ld_out, int width) const {
  if (n_ == 0 || width <= 0) return;
  thread_local std::vector<double> ws;
  ws.resize(std::size_t(2 * ne_) * width);
  double* a = ws.data();                      // ne x width
  double* b = a + std::size_t(ne_) * width;   // ne x width
  if (output_split_) {
    small_gemm(ne_, width, ne_, te_.data(), ne_, in, 2 * ld_in, a, width);
    small_gemm(ne_, width, no_, to_.data(), no_, in + ld_in, 2 * ld_in, b, width);
    for (int k = 0; k < no_; ++k) {
      const double* ek = a + std::size_t(k) * width;
      const double* ok = b + std::size_t(k) * width;
      double* y0 = out + std::size_t(k) * ld_out;
      double* y1 = out + std::size_t(n_ - 1 - k) * ld_out;
      for (int w = 0; w < width; ++w) {
        y0[w] = ek[w] + ok[w];
        y1[w] = ek[w] - ok[w];
      }
    }
    if (ne_ > no_) {
      const double* ek = a + std::size_t(no_) * width;
      const double* ok = b + std::size_t(no_) * width;
      double* y = out + std::size_t(no_) * ld_out;
      for (int w = 0; w < width; ++w) y[w] = ek[w] + ok[w];
    }
    return;
  }
  for (int j = 0; j < no_; ++j) {
    const double* x0 = in + std::size_t(j) * ld_in;
    const double* x1 = in + std::size_t(n_ - 1 - j) * ld_in;
    double* sj = a + std::size_t(j) * width;
    double* dj = b + std::size_t(j) * width;
    for (int w = 0; w < width; ++w) {
      sj[w] = x0[w] + x1[w];
      dj[w] = x0[w] - x1[w];
    }
  }
  if (ne_ > no_) std::copy_n(in + std::size_t(no_) * ld_in, width, a + std::size_t(no_) * width);
  small_gemm(ne_, width, ne_, te_.data(), ne_, a, width, out, 2 * ld_out);
  small_gemm(no_, width, no_, to_.data(), no_, b, width, out + ld_out, 2 * ld_out);
}

}  // namespace swim::full3d
