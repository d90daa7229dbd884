// The packed Cholesky solve of the capacitance solvers (full3d/packed_cholesky.hpp): LAPACK
// factors, the substitutions two right-hand sides per pass over the factor.
//  * on random symmetric positive definite matrices of orders 1 to 37 (every remainder of
//    the four-way unrolled dot products) and 1 to 5 right-hand sides (pairs and a single
//    one), A x = b holds to a backward-stable residual, and each column equals its own
//    single-column solve to the last bit (the pairing is only a loop fusion);
//  * a matrix that is not positive definite is refused with the order of the failing minor.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "full3d/packed_cholesky.hpp"

using swim::full3d::LapackError;
using swim::full3d::PackedCholesky;

namespace {

// A = M M^T + n I (well conditioned, full), returned dense (column-major) and packed lower.
void random_spd(int n, std::mt19937& rng, std::vector<double>& dense, std::vector<double>& packed) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> m(std::size_t(n) * n);
  for (auto& x : m) x = u(rng);
  dense.assign(std::size_t(n) * n, 0.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double s = i == j ? n : 0.0;
      for (int k = 0; k < n; ++k) s += m[std::size_t(k) * n + i] * m[std::size_t(k) * n + j];
      dense[std::size_t(j) * n + i] = s;
    }
  packed.clear();
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i) packed.push_back(dense[std::size_t(j) * n + i]);
}

}  // namespace

TEST(PackedCholesky, SolvesEveryOrderAndPairing) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 1; n <= 37; ++n) {
    std::vector<double> a, ap;
    random_spd(n, rng, a, ap);
    const PackedCholesky chol(ap, n);
    for (int nrhs = 1; nrhs <= 5; ++nrhs) {
      const int ldb = n + 3;  // a leading dimension above the order
      std::vector<double> b(std::size_t(ldb) * nrhs);
      for (auto& x : b) x = u(rng);
      std::vector<double> x = b;
      chol.solve(x.data(), nrhs, ldb);
      for (int q = 0; q < nrhs; ++q) {
        const double* xq = x.data() + std::size_t(q) * ldb;
        const double* bq = b.data() + std::size_t(q) * ldb;
        double res = 0.0, scale = 0.0;
        for (int i = 0; i < n; ++i) {
          double s = -bq[i];
          for (int j = 0; j < n; ++j) s += a[std::size_t(j) * n + i] * xq[j];
          res = std::max(res, std::abs(s));
          scale = std::max(scale, std::abs(bq[i]));
        }
        EXPECT_LT(res, 1e-13 * n * scale) << "n = " << n << ", nrhs = " << nrhs << ", column " << q;
        // the same column alone: bit-identical
        std::vector<double> one(bq, bq + n);
        chol.solve(one.data(), 1, n);
        for (int i = 0; i < n; ++i) ASSERT_EQ(one[std::size_t(i)], xq[i]) << "n = " << n << ", column " << q;
        // untouched beyond the order
        for (int i = n; i < ldb; ++i) ASSERT_EQ(xq[i], bq[i]);
      }
    }
  }
}

TEST(PackedCholesky, RefusesAMatrixThatIsNotPositiveDefinite) {
  // [[1, 2], [2, 1]]: the leading minor of order 2 is -3
  try {
    PackedCholesky c({1.0, 2.0, 1.0}, 2);
    FAIL() << "factorised an indefinite matrix";
  } catch (const LapackError& e) {
    EXPECT_EQ(e.info(), 2);
  }
}
