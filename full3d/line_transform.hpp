// Dense 1D real transforms (FFTW's unnormalised REDFT10, REDFT01, RODFT00) applied to every
// line of a 2D array, as small matrix products.
//
// The capacitance solver transforms its cross-sections (30 to about 70 points across) line
// by line, a few thousand short transforms per solve. FFTW's r2r codelets do not vectorise
// across lines, and its DST-I (RODFT00) runs at twice the cost per point of a REDFT10 of the
// same length; the transform matrix applied to a block of lines is a matrix product whose
// inner loop runs along a line (or across adjacent lines) in SIMD registers, and it costs the
// same for every kind. At 36 points it takes 0.4-0.7 of FFTW's time for the cosine kinds and
// 0.25-0.35 for DST-I (docs/performance-3d.md, "Cross-section transforms as matrix products").
// Its cost per point grows as n instead of log n; with FFTW's slow DST-I in every face
// component the two break even at about 128 points across, beyond any grid the 3D tier runs.
#pragma once

#include <vector>

namespace swim::full3d {

/// The three unnormalised 1D transforms the staggered grid's cross-sections need, in FFTW's
/// conventions (Y = T X):
///   Redft10  Y_k = 2 sum_j X_j cos(pi (j + 1/2) k / n)                   (DCT-II)
///   Redft01  Y_k = X_0 + 2 sum_{j>0} X_j cos(pi j (k + 1/2) / n)          (DCT-III)
///   Rodft00  Y_k = 2 sum_j X_j sin(pi (j + 1) (k + 1) / (n + 1))          (DST-I)
enum class R2rKind { Redft10, Redft01, Rodft00 };

class LineTransform {
 public:
  LineTransform() = default;
  /// The n x n matrix of `kind` (n >= 0; n = 0 transforms nothing).
  LineTransform(R2rKind kind, int n);
  int size() const { return n_; }

  /// out(l, :) = T in(l, :) for l < lines: each line contiguous, lines ld apart.
  /// in and out must not overlap.
  void along(const double* in, int ld_in, double* out, int ld_out, int lines) const;
  /// out(:, w) = T in(:, w) for w < width: line elements ld apart, adjacent lines adjacent.
  /// in and out must not overlap.
  void across(const double* in, int ld_in, double* out, int ld_out, int width) const;

 private:
  int n_ = 0;
  int ne_ = 0, no_ = 0;        // (n + 1) / 2 and n / 2
  bool output_split_ = false;  // DCT-III: symmetric in the output index, else in the input index
  std::vector<double> te_, to_;    // the even and odd halves of T (line_transform.cpp), row-major
  std::vector<double> tet_, tot_;  // their transposes
};

/// C = A B with row-major A (M x K, leading dimension lda), B (K x N, ldb), C (M x N, ldc);
/// C does not overlap A or B. AVX2/FMA kernel when the CPU has it, portable loops otherwise.
void small_gemm(int M, int N, int K, const double* A, int lda, const double* B, int ldb, double* C, int ldc);
/// The portable kernel alone (what small_gemm runs on a CPU without AVX2/FMA; for the tests).
void small_gemm_portable(int M, int N, int K, const double* A, int lda, const double* B, int ldb, double* C,
                         int ldc);

}  // namespace swim::full3d
