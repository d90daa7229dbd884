#include "full3d/packed_cholesky.hpp"

extern "C" {
// LAPACK, Fortran interface (the hidden length of the one-character UPLO argument last)
void dpptrf_(const char* uplo, const int* n, double* ap, int* info, std::size_t uplo_len);
void dpptrs_(const char* uplo, const int* n, const int* nrhs, const double* ap, double* b, const int* ldb, int* info,
             std::size_t uplo_len);
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

void PackedCholesky::solve(double* b, int nrhs, int ldb) const {
  if (n_ == 0 || nrhs == 0) return;
  int info = 0;
  dpptrs_("L", &n_, &nrhs, l_.data(), b, &ldb, &info, 1);
  if (info != 0) throw LapackError("dpptrs", info);
}

}  // namespace swim::full3d
