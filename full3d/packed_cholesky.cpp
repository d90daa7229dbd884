#include "full3d/packed_cholesky.hpp"

#include "common/dot.hpp"

extern "C" {
// LAPACK, Fortran interface (the hidden length of the one-character UPLO argument last)
void dpptrf_(const char* uplo, const int* n, double* ap, int* info, std::size_t uplo_len);
}

namespace swim::full3d {

LapackError::LapackError(const std::string& routine, int info)
    : std::runtime_error(routine + (info < 0 ? ": illegal value of argument " + std::to_string(-info)
                                             : ": the leading minor of order " + std::to_string(info) +
                                                   " is not positive definite")),
      info_(info) {}

PackedCholesky::PackedCholesky(std::vector<double> packed_lower, int n) : l_(std::move(packed_lower)), n_(n) {
  if (l_.size() != packed_size(n)) throw LapackError("dpptrf", -3);
  if (n == 0) return;
  int info = 0;
  dpptrf_("L", &n_, l_.data(), &info, 1);
  if (info != 0) throw LapackError("dpptrf", info);
}

// The substitutions run over the packed factor once for a pair of right-hand sides (the two
// planes of a paired axial mode share one factor): forward L y = b by columns (an axpy per
// column, as dtpsv), backward L^T x = y by dot products over the same columns (dot4, while
// the column is in cache). Reference dpptrs makes one pass over the factor per right-hand
// side and direction, and the factors of a capacitance solve (megabytes) do not stay in
// cache between passes.
namespace {
template <int R>
void substitute(const double* l, int n, double* const* b) {
  const double* col = l;
  for (int j = 0; j < n; ++j) {  // forward: L y = b
    const int len = n - j;
    double y[R];
    for (int r = 0; r < R; ++r) y[r] = (b[r][j] /= col[0]);
    for (int r = 0; r < R; ++r) {
      double* x = b[r] + j;
      const double yr = y[r];
      for (int i = 1; i < len; ++i) x[i] -= col[i] * yr;
    }
    col += len;
  }
  for (int j = n - 1; j >= 0; --j) {  // backward: L^T x = y
    const int len = n - j;
    col -= len;
    for (int r = 0; r < R; ++r) b[r][j] = (b[r][j] - dot4(col + 1, b[r] + j + 1, len - 1)) / col[0];
  }
}
}  // namespace

void PackedCholesky::solve(double* b, int nrhs, int ldb) const {
  if (n_ == 0 || nrhs <= 0) return;
  if (ldb < n_) throw std::invalid_argument("PackedCholesky::solve: leading dimension below the order");
  int q = 0;
  for (; q + 1 < nrhs; q += 2) {
    double* const pair[2] = {b + std::size_t(q) * ldb, b + std::size_t(q + 1) * ldb};
    substitute<2>(l_.data(), n_, pair);
  }
  if (q < nrhs) {
    double* const one[1] = {b + std::size_t(q) * ldb};
    substitute<1>(l_.data(), n_, one);
  }
}

}  // namespace swim::full3d
