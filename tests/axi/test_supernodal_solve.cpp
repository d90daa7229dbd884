// The product's triangular solves with CHOLMOD's supernodal factor (axi/supernodal_solve.hpp),
// against CHOLMOD's own solve and against the matrix they invert.
#include <gtest/gtest.h>

#include <Eigen/CholmodSupport>
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

#include "axi/supernodal_solve.hpp"
#include "cholmod_test_support.hpp"

namespace {

using Sparse = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

using swim::axi::testing::OpenFactor;
using swim::axi::testing::spd_element_matrix;
using Factor = OpenFactor<Eigen::Lower>;

// Expected: on three sizes (including one whose factor is a handful of supernodes), the solve
// equals CHOLMOD's own (cholmod_solve) to 1e-12 of the solution and leaves a residual
// |S x - b| below 1e-12 |b| (S is well conditioned here); the workspace is reused across calls
// and a second right-hand side gives its own answer.
TEST(SupernodalSolve, AgreesWithCholmodsSolveAndInvertsTheMatrix) {
  std::mt19937 rng(3);
  for (const auto& [ex, ey] : {std::pair{1, 1}, std::pair{6, 4}, std::pair{24, 12}}) {
    const Sparse S = spd_element_matrix(ex, ey, rng);
    Factor f;
    f.compute(S);
    ASSERT_EQ(f.info(), Eigen::Success);
    ASSERT_TRUE(f.factor()->is_super);
    Eigen::VectorXd work;
    for (int k = 0; k < 2; ++k) {
      const Eigen::VectorXd b = Eigen::VectorXd::Random(S.rows());
      const Eigen::VectorXd ref = f.solve(b);
      Eigen::VectorXd x = b;
      swim::axi::supernodal_llt_solve(*f.factor(), x, work);
      const Eigen::VectorXd Ssym = S.selfadjointView<Eigen::Lower>() * x;
      EXPECT_LT((x - ref).norm(), 1e-12 * ref.norm()) << ex << " x " << ey << " elements, n = " << S.rows()
                                                      << ", " << f.factor()->nsuper << " supernodes";
      EXPECT_LT((Ssym - b).norm(), 1e-12 * b.norm()) << ex << " x " << ey;
    }
  }
}

// A caller may permute S itself (P S P^T by its lower triangle, P from CHOLMOD's own analysis)
// and factor it in the natural ordering, passing P to the solve, as the fitted Stokes solver
// does. Expected: the factor has the same number of entries as CHOLMOD's own ordering gives
// (the same ordering, applied outside), it is the factor of P S P^T given by its upper triangle
// to the bit (which CHOLMOD transposes first), and the solve with P inverts S to 1e-12.
TEST(SupernodalSolve, SolvesWithAnOrderingAppliedOutsideTheFactor) {
  std::mt19937 rng(7);
  const Sparse S = spd_element_matrix(20, 10, rng);
  Factor own;
  own.compute(S);
  ASSERT_EQ(own.info(), Eigen::Success);
  const int n = int(S.rows());
  const int* perm = static_cast<const int*>(own.factor()->Perm);
  std::vector<int> pinv(n);
  for (int k = 0; k < n; ++k) pinv[perm[k]] = k;
  std::vector<Eigen::Triplet<double>> t;
  for (int c = 0; c < n; ++c)
    for (Sparse::InnerIterator it(S, c); it; ++it)
      if (it.row() >= c) {
        const int a = pinv[it.row()], b = pinv[c];
        t.emplace_back(std::max(a, b), std::min(a, b), it.value());
      }
  Sparse PSPt(n, n);
  PSPt.setFromTriplets(t.begin(), t.end());
  auto natural_order = [](auto& f) {
    f.cholmod().nmethods = 1;
    f.cholmod().method[0].ordering = CHOLMOD_NATURAL;
    f.cholmod().postorder = 0;
  };
  OpenFactor<Eigen::Lower> natural;
  natural_order(natural);
  natural.compute(PSPt);
  ASSERT_EQ(natural.info(), Eigen::Success);
  const cholmod_factor* L = natural.factor();
  OpenFactor<Eigen::Upper> upper;
  natural_order(upper);
  const Sparse PSPt_upper = PSPt.transpose();
  upper.compute(PSPt_upper);
  ASSERT_EQ(upper.info(), Eigen::Success);
  ASSERT_EQ(upper.factor()->xsize, L->xsize);
  EXPECT_EQ(std::memcmp(upper.factor()->x, L->x, sizeof(double) * L->xsize), 0);
  const cholmod_factor* Lown = own.factor();
  auto entries = [](const cholmod_factor* f) {
    const int* px = static_cast<const int*>(f->px);
    return px[f->nsuper];
  };
  EXPECT_EQ(entries(L), entries(Lown));
  const Eigen::VectorXd b = Eigen::VectorXd::Random(n);
  Eigen::VectorXd x = b, work;
  swim::axi::supernodal_llt_solve(*L, x, work, perm);
  const Eigen::VectorXd Sx = S.selfadjointView<Eigen::Lower>() * x;
  EXPECT_LT((Sx - b).norm(), 1e-12 * b.norm());
}

// Expected: a right-hand side of the wrong length and a factor that is not numerical (symbolic
// analysis only) are refused with std::invalid_argument.
TEST(SupernodalSolve, RefusesAWrongSizeAndASymbolicFactor) {
  std::mt19937 rng(5);
  const Sparse S = spd_element_matrix(3, 3, rng);
  Factor f;
  f.analyzePattern(S);
  Eigen::VectorXd work, x = Eigen::VectorXd::Ones(S.rows());
  EXPECT_THROW(swim::axi::supernodal_llt_solve(*f.factor(), x, work), std::invalid_argument);
  f.factorize(S);
  ASSERT_EQ(f.info(), Eigen::Success);
  Eigen::VectorXd y = Eigen::VectorXd::Ones(S.rows() + 1);
  EXPECT_THROW(swim::axi::supernodal_llt_solve(*f.factor(), y, work), std::invalid_argument);
  EXPECT_NO_THROW(swim::axi::supernodal_llt_solve(*f.factor(), x, work));
}

}  // namespace
