// Dense symmetric positive definite solves: the Cholesky factor L of a matrix of order n in
// packed lower storage (column j holds L(j..n-1, j), columns concatenated: n (n + 1) / 2
// doubles), factorised by LAPACK dpptrf (Debian liblapack-dev); the substitutions make one
// pass over the factor per pair of right-hand sides (dpptrs makes one per right-hand side).
// The one place where LAPACK info codes become exceptions.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace swim::full3d {

/// LAPACK reported a failure: info < 0 an illegal argument (a bug), info > 0 the leading
/// minor of that order is not positive definite.
class LapackError : public std::runtime_error {
 public:
  LapackError(const std::string& routine, int info);
  int info() const { return info_; }

 private:
  int info_;
};

class PackedCholesky {
 public:
  /// Doubles of a packed triangle of order n.
  static std::size_t packed_size(int n) { return std::size_t(n) * std::size_t(n + 1) / 2; }
  /// Offset of column j in a packed lower triangle of order n.
  static std::size_t column(int j, int n) { return std::size_t(j) * n - std::size_t(j) * (j - 1) / 2; }

  PackedCholesky() = default;
  /// Factorises (dpptrf) the symmetric positive definite matrix of order n whose lower
  /// triangle is given packed. Throws LapackError (info > 0: not positive definite).
  PackedCholesky(std::vector<double> packed_lower, int n);
  /// In place: the nrhs columns of b (leading dimension ldb >= n) become A^{-1} b (forward
  /// and backward substitution, two columns per pass over the factor).
  void solve(double* b, int nrhs, int ldb) const;
  int order() const { return n_; }
  std::size_t bytes() const { return l_.size() * sizeof(double); }

 private:
  std::vector<double> l_;
  int n_ = 0;
};

}  // namespace swim::full3d
