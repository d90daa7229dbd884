// The project's own SUNDIALS kernels against references: the optimised serial N_Vector
// operations (installed on every vector of sun::make_vector) against the distribution's
// serial implementations, and the band + low-rank (Woodbury) linear solver against a dense
// LU solve of the same matrix, also when the band is factored by cell blocks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_linearsolver.h>
#include <sunmatrix/sunmatrix_band.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "reduced1d/linear_solvers.hpp"
#include "reduced1d/sundials.hpp"

using namespace swim::reduced1d;

namespace {

struct Rng {  // splitmix64 -> [-1, 1)
  std::uint64_t s;
  double operator()() {
    s += 0x9E3779B97F4A7C15ull;
    std::uint64_t z = s;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return 2.0 * double((z ^ (z >> 31)) >> 11) * 0x1.0p-53 - 1.0;
  }
};

/// A pair of vectors with the same content: `fast` with the project's ops, `ref` with the
/// distribution's serial ops.
struct Pair {
  sun::Vector fast, ref;
  Pair(long n, SUNContext ctx, Rng& rng, double offset = 0.0)
      : fast(sun::make_vector(n, ctx)), ref(N_VNew_Serial(n, ctx)) {
    for (long i = 0; i < n; ++i) sun::data(fast.get())[i] = sun::data(ref.get())[i] = rng() + offset;
  }
};

void expect_same(N_Vector a, N_Vector b, double tol, const char* what) {
  const long n = N_VGetLength(a);
  for (long i = 0; i < n; ++i)
    EXPECT_NEAR(sun::data(a)[i], sun::data(b)[i], tol * (1.0 + std::abs(sun::data(b)[i]))) << what << " i=" << i;
}


// Fills the tridiagonal band matrix A (n x n, bandwidths 1) with random entries, diagonal
// diag + rng() and off-diagonal off * rng(); returns the same matrix dense.
Eigen::MatrixXd fill_tridiagonal(SUNMatrix A, long n, Rng& rng, double diag, double off) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  for (long i = 0; i < n; ++i)
    for (long j = std::max(0L, i - 1); j <= std::min(n - 1, i + 1); ++j) {
      const double v = i == j ? diag + rng() : off * rng();
      SM_ELEMENT_B(A, i, j) = v;
      D(i, j) = v;
    }
  return D;
}

}  // namespace

// Every overridden operation gives the reference result to round-off (1e-14 relative).
TEST(SundialsKernels, FastVectorOperationsMatchTheSerialReference) {
  auto ctx = sun::make_context();
  Rng rng{7};
  for (long n : {1L, 5L, 205L}) {
    Pair x(n, ctx.get(), rng), y(n, ctx.get(), rng), z(n, ctx.get(), rng), w(n, ctx.get(), rng, 2.0),
        id(n, ctx.get(), rng);
    const double tol = 1e-14;
    auto both = [&](auto op, const char* what) {
      op(x.fast.get(), y.fast.get(), z.fast.get(), w.fast.get(), id.fast.get());
      op(x.ref.get(), y.ref.get(), z.ref.get(), w.ref.get(), id.ref.get());
      expect_same(z.fast.get(), z.ref.get(), tol, what);
    };
    both([](N_Vector a, N_Vector b, N_Vector c, N_Vector, N_Vector) { N_VLinearSum(0.3, a, -1.7, b, c); }, "linearsum");
    both([](N_Vector a, N_Vector, N_Vector c, N_Vector, N_Vector) { N_VLinearSum(0.3, a, 1.0, c, c); }, "linearsum in place");
    both([](N_Vector, N_Vector, N_Vector c, N_Vector, N_Vector) { N_VConst(2.5, c); }, "const");
    both([](N_Vector a, N_Vector b, N_Vector c, N_Vector, N_Vector) { N_VProd(a, b, c); }, "prod");
    both([](N_Vector a, N_Vector, N_Vector c, N_Vector d, N_Vector) { N_VDiv(a, d, c); }, "div");
    both([](N_Vector a, N_Vector, N_Vector c, N_Vector, N_Vector) { N_VScale(-3.0, a, c); }, "scale");
    both([](N_Vector a, N_Vector, N_Vector c, N_Vector, N_Vector) { N_VAbs(a, c); }, "abs");
    both([](N_Vector, N_Vector, N_Vector c, N_Vector d, N_Vector) { N_VInv(d, c); }, "inv");
    both([](N_Vector a, N_Vector, N_Vector c, N_Vector, N_Vector) { N_VAddConst(a, 0.25, c); }, "addconst");
    both([](N_Vector a, N_Vector b, N_Vector c, N_Vector d, N_Vector) {
      double cc[3] = {0.5, -2.0, 1.5};
      N_Vector X[3] = {a, b, d};
      N_VLinearCombination(3, cc, X, c);
    }, "linearcombination");
    both([](N_Vector a, N_Vector b, N_Vector c, N_Vector d, N_Vector) {
      double cc[3] = {0.5, -2.0, 1.5};
      N_Vector X[3] = {c, b, d};  // first vector aliases the output
      N_VLinearCombination(3, cc, X, c);
      (void)a;
    }, "linearcombination aliased");
    // reductions
    auto reduce = [&](auto op, const char* what) {
      const double a = op(x.fast.get(), y.fast.get(), w.fast.get(), id.fast.get());
      const double b = op(x.ref.get(), y.ref.get(), w.ref.get(), id.ref.get());
      EXPECT_NEAR(a, b, 1e-13 * (1.0 + std::abs(b))) << what << " n=" << n;
    };
    reduce([](N_Vector a, N_Vector b, N_Vector, N_Vector) { return N_VDotProd(a, b); }, "dotprod");
    reduce([](N_Vector a, N_Vector, N_Vector, N_Vector) { return N_VMaxNorm(a); }, "maxnorm");
    reduce([](N_Vector a, N_Vector, N_Vector d, N_Vector) { return N_VWrmsNorm(a, d); }, "wrmsnorm");
    reduce([](N_Vector a, N_Vector, N_Vector d, N_Vector m) { return N_VWrmsNormMask(a, d, m); }, "wrmsnormmask");
    reduce([](N_Vector a, N_Vector, N_Vector d, N_Vector) { return N_VWSqrSumLocal(a, d); }, "wsqrsumlocal");
    reduce([](N_Vector a, N_Vector, N_Vector, N_Vector) { return N_VMin(a); }, "min");
    // multi-vector operations
    Pair z2(n, ctx.get(), rng);
    double a2[2] = {0.7, -1.1};
    N_Vector Yf[2] = {y.fast.get(), w.fast.get()}, Zf[2] = {z.fast.get(), z2.fast.get()};
    N_Vector Yr[2] = {y.ref.get(), w.ref.get()}, Zr[2] = {z.ref.get(), z2.ref.get()};
    N_VScaleAddMulti(2, a2, x.fast.get(), Yf, Zf);
    N_VScaleAddMulti(2, a2, x.ref.get(), Yr, Zr);
    expect_same(z.fast.get(), z.ref.get(), 1e-14, "scaleaddmulti 0");
    expect_same(z2.fast.get(), z2.ref.get(), 1e-14, "scaleaddmulti 1");
    double df[2], dr[2];
    N_VDotProdMulti(2, x.fast.get(), Yf, df);
    N_VDotProdMulti(2, x.ref.get(), Yr, dr);
    for (int k = 0; k < 2; ++k) EXPECT_NEAR(df[k], dr[k], 1e-13 * (1.0 + std::abs(dr[k])));
    // clones keep the fast table
    N_Vector c = N_VClone(x.fast.get());
    EXPECT_EQ(c->ops->nvlinearsum, x.fast->ops->nvlinearsum);
    N_VDestroy(c);
  }
}

// (M + s U V^T) x = b with M tridiagonal (band LU with pivoting) and rank 0 .. 7 terms whose
// columns differ in scale by decades and are nearly parallel (as the confined model's global
// terms are): the solution matches a dense LU solve of the assembled matrix to round-off.
TEST(SundialsKernels, LowRankBandSolverMatchesADenseSolve) {
  auto ctx = sun::make_context();
  Rng rng{11};
  for (long n : {4L, 37L, 205L})
    for (int rank : {0, 1, 2, 7}) {
      if (rank >= n) continue;
      auto y = sun::make_vector(n, ctx.get());
      sun::Matrix A(SUNBandMatrix(n, 1, 1, ctx.get()));
      sun::LowRankTerm term;
      static double s_value = 0;
      s_value = -0.37;
      term.scale = [](void*) { return s_value; };
      auto solver = sun::make_low_rank_band_solver(y.get(), A.get(), &term, ctx.get());
      // a Newton-like matrix whose sub-diagonal often exceeds the diagonal, so that partial
      // pivoting swaps rows
      Eigen::MatrixXd D = fill_tridiagonal(A.get(), n, rng, 2.0, 3.0);
      term.rank = rank;
      term.U.assign(std::size_t(n) * rank, 0.0);
      term.V.assign(std::size_t(n) * rank, 0.0);
      for (int k = 0; k < rank; ++k)
        for (long i = 0; i < n; ++i) {
          const double base = k >= 1 ? term.U[i] : 0.0;  // column 1 nearly parallel to column 0
          term.U[std::size_t(k) * n + i] = (k == 1 ? 1e3 * (base + 1e-6 * rng()) : std::pow(10.0, -k) * rng());
          term.V[std::size_t(k) * n + i] = rng();
        }
      for (int k = 0; k < rank; ++k)
        for (long i = 0; i < n; ++i)
          for (long j = 0; j < n; ++j)
            D(i, j) += s_value * term.U[std::size_t(k) * n + i] * term.V[std::size_t(k) * n + j];
      ASSERT_EQ(SUNLinSolSetup(solver.get(), A.get()), 0);
      auto b = sun::make_vector(n, ctx.get()), x = sun::make_vector(n, ctx.get());
      Eigen::VectorXd bb(n);
      for (long i = 0; i < n; ++i) bb(i) = sun::data(b.get())[i] = rng();
      ASSERT_EQ(SUNLinSolSolve(solver.get(), A.get(), x.get(), b.get(), 0.0), 0);
      const Eigen::VectorXd ref = D.partialPivLu().solve(bb);
      const double scale = ref.cwiseAbs().maxCoeff();
      const double cond = 1.0 / D.partialPivLu().rcond();
      for (long i = 0; i < n; ++i)
        EXPECT_NEAR(sun::data(x.get())[i], ref(i), 1e-15 * cond * scale + 1e-13 * scale)
            << "n=" << n << " rank=" << rank << " i=" << i;
      // in place (x aliases b), as CVODE calls it
      ASSERT_EQ(SUNLinSolSolve(solver.get(), A.get(), b.get(), b.get(), 0.0), 0);
      for (long i = 0; i < n; ++i) EXPECT_EQ(sun::data(b.get())[i], sun::data(x.get())[i]);
    }
}

// The Woodbury capacitance matrix I + s W^T M^{-1} Q is factored by a small dense LU with
// partial pivoting. With O(1) low-rank terms (the held segments' loads and the outer-flow
// pair of the confined Newton matrix) it is far from the identity and the LU interchanges
// rows after the first column; the solve must then apply every interchange before the
// forward substitution (whole-row swaps, as LAPACK's dgetf2). Checked against a dense LU
// of the assembled matrix to 1e-12 relative, with the capacitance matrix built so that its
// pivots come from below the diagonal in every column.
TEST(SundialsKernels, LowRankBandSolverPivotsTheCapacitanceMatrix) {
  auto ctx = sun::make_context();
  Rng rng{23};
  for (long n : {12L, 205L})
    for (int rank : {3, 4, 5, 7}) {
      auto y = sun::make_vector(n, ctx.get());
      sun::Matrix A(SUNBandMatrix(n, 1, 1, ctx.get()));
      sun::LowRankTerm term;  // scale 1
      auto solver = sun::make_low_rank_band_solver(y.get(), A.get(), &term, ctx.get());
      Eigen::MatrixXd D = fill_tridiagonal(A.get(), n, rng, 4.0, 0.5);
      // U: disjoint blocks of cells (like the held segments), V: the same blocks shifted by
      // one term, so that V^T M^{-1} U is large below its diagonal.
      term.rank = rank;
      term.U.assign(std::size_t(n) * rank, 0.0);
      term.V.assign(std::size_t(n) * rank, 0.0);
      const long block = n / rank;
      for (int k = 0; k < rank; ++k)
        for (long i = k * block; i < (k + 1) * block; ++i) {
          term.U[std::size_t(k) * n + i] = 1.0 + 0.1 * rng();
          const int kv = (k + rank - 1) % rank;  // V_kv lives on block k
          term.V[std::size_t(kv) * n + i] = (50.0 + 10.0 * rng()) / double(block);
        }
      for (int k = 0; k < rank; ++k)
        for (long i = 0; i < n; ++i)
          for (long j = 0; j < n; ++j) D(i, j) += term.U[std::size_t(k) * n + i] * term.V[std::size_t(k) * n + j];
      ASSERT_EQ(SUNLinSolSetup(solver.get(), A.get()), 0);
      auto b = sun::make_vector(n, ctx.get()), x = sun::make_vector(n, ctx.get());
      Eigen::VectorXd bb(n);
      for (long i = 0; i < n; ++i) bb(i) = sun::data(b.get())[i] = rng();
      ASSERT_EQ(SUNLinSolSolve(solver.get(), A.get(), x.get(), b.get(), 0.0), 0);
      const Eigen::VectorXd ref = D.partialPivLu().solve(bb);
      const double scale = ref.cwiseAbs().maxCoeff();
      for (long i = 0; i < n; ++i)
        EXPECT_NEAR(sun::data(x.get())[i], ref(i), 1e-12 * scale) << "n=" << n << " rank=" << rank << " i=" << i;
    }
}

namespace {
// A Newton-like matrix with the 1D tier's layout: one border unknown, `cells` cells of `S`
// unknowns, five border unknowns after them; band mu = S, ml = S + 2. Cell rows reach their
// own and the neighbouring cells (entries outside the band are left zero), border rows reach
// anything in the band. Some diagonal entries are small, so that the diagonal blocks must
// pivot. Returns the same matrix dense.
Eigen::MatrixXd fill_cells(SUNMatrix A, long cells, int S, Rng& rng) {
  const long o = 1, n = o + cells * S + 5, mu = S, ml = S + 2;
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  auto cell = [&](long i) { return (i < o || i >= o + cells * S) ? -1L : (i - o) / S; };
  for (long i = 0; i < n; ++i)
    for (long j = std::max(0L, i - ml); j <= std::min(n - 1, i + mu); ++j) {
      const long ci = cell(i), cj = cell(j);
      if (ci >= 0 && (cj < 0 || std::abs(ci - cj) > 1)) continue;
      double v = rng();
      if (i == j) v = (i % 3 == 0 ? 1e-3 : 4.0) + 0.5 * rng();
      SM_ELEMENT_B(A, i, j) = v;
      D(i, j) = v;
    }
  return D;
}

// A random low-rank term U V^T of `rank` columns in `term`, added to the dense matrix D too.
void add_random_low_rank_term(sun::LowRankTerm& term, Eigen::MatrixXd& D, long n, int rank, Rng& rng) {
  term.rank = rank;
  term.U.assign(std::size_t(n) * rank, 0.0);
  term.V.assign(std::size_t(n) * rank, 0.0);
  for (int k = 0; k < rank; ++k)
    for (long i = 0; i < n; ++i) {
      term.U[std::size_t(k) * n + i] = rng();
      term.V[std::size_t(k) * n + i] = 0.1 * rng();
    }
  for (int k = 0; k < rank; ++k)
    for (long i = 0; i < n; ++i)
      for (long j = 0; j < n; ++j) D(i, j) += term.U[std::size_t(k) * n + i] * term.V[std::size_t(k) * n + j];
}

// The solver's solution of a random right-hand side against a dense LU of D, to round-off
// times D's condition number.
void expect_solve_matches_dense(SUNLinearSolver solver, SUNMatrix A, const Eigen::MatrixXd& D, Rng& rng,
                                SUNContext ctx, const std::string& what) {
  const long n = D.rows();
  auto b = sun::make_vector(n, ctx), x = sun::make_vector(n, ctx);
  Eigen::VectorXd bb(n);
  for (long i = 0; i < n; ++i) bb(i) = sun::data(b.get())[i] = rng();
  ASSERT_EQ(SUNLinSolSolve(solver, A, x.get(), b.get(), 0.0), 0);
  const auto lu = D.partialPivLu();
  const Eigen::VectorXd ref = lu.solve(bb);
  const double scale = ref.cwiseAbs().maxCoeff(), cond = 1.0 / lu.rcond();
  for (long i = 0; i < n; ++i)
    EXPECT_NEAR(sun::data(x.get())[i], ref(i), 1e-15 * cond * scale + 1e-13 * scale) << what << " i=" << i;
}
}  // namespace

// The block-tridiagonal factorisation of the 1D tier's Newton matrix (cells of 9 unknowns,
// the traction model at N = 200; 3, wall inertia alone; 14, the largest compiled block)
// against a dense LU of the assembled matrix, with and without the low-rank term; a matrix
// that leaves the cell structure (an entry in a border column of a cell row) is factored by
// the band LU instead, with the same answer.
TEST(SundialsKernels, LowRankBlockSolverMatchesADenseSolve) {
  auto ctx = sun::make_context();
  Rng rng{37};
  for (int S : {3, 9, 14})
    for (long cells : {1L, 2L, 40L})
      for (int rank : {0, 3})
        for (bool foreign : {false, true}) {
          const long n = 1 + cells * S + 5;
          auto y = sun::make_vector(n, ctx.get());
          sun::Matrix A(SUNBandMatrix(n, S, S + 2, ctx.get()));
          sun::LowRankTerm term;
          auto solver =
              sun::make_low_rank_block_solver(y.get(), A.get(), &term, sun::CellBlocks{1, S, cells}, ctx.get());
          Eigen::MatrixXd D = fill_cells(A.get(), cells, S, rng);
          if (foreign) {  // cell 0's first row reaches the leading border unknown
            SM_ELEMENT_B(A.get(), 1, 0) = 0.7;
            D(1, 0) = 0.7;
          }
          add_random_low_rank_term(term, D, n, rank, rng);
          ASSERT_EQ(SUNLinSolSetup(solver.get(), A.get()), 0);
          EXPECT_EQ(sun::factored_by_blocks(solver.get()), !foreign) << "S=" << S << " cells=" << cells;
          expect_solve_matches_dense(solver.get(), A.get(), D, rng, ctx.get(),
                                     "S=" + std::to_string(S) + " cells=" + std::to_string(cells) +
                                         " rank=" + std::to_string(rank) + " foreign=" + std::to_string(foreign));
        }
}

// Blocks of at most 8 unknowns (the default traction model at N = 50: 8) are inverted with
// their rows held in vector registers (linear_solvers.cpp, invert_in_registers); every
// third diagonal entry of fill_cells is small, so the inversions pivot. Against a dense LU
// of the assembled matrix, with and without the low-rank term.
TEST(SundialsKernels, LowRankBlockSolverWithBlocksOfAtMostEightMatchesADenseSolve) {
  auto ctx = sun::make_context();
  Rng rng{41};
  for (int S : {4, 5, 8})
    for (long cells : {1L, 2L, 40L})
      for (int rank : {0, 3}) {
        const long n = 1 + cells * S + 5;
        auto y = sun::make_vector(n, ctx.get());
        sun::Matrix A(SUNBandMatrix(n, S, S + 2, ctx.get()));
        sun::LowRankTerm term;
        auto solver = sun::make_low_rank_block_solver(y.get(), A.get(), &term, sun::CellBlocks{1, S, cells}, ctx.get());
        Eigen::MatrixXd D = fill_cells(A.get(), cells, S, rng);
        add_random_low_rank_term(term, D, n, rank, rng);
        ASSERT_EQ(SUNLinSolSetup(solver.get(), A.get()), 0);
        EXPECT_TRUE(sun::factored_by_blocks(solver.get())) << "S=" << S << " cells=" << cells;
        expect_solve_matches_dense(solver.get(), A.get(), D, rng, ctx.get(),
                                   "S=" + std::to_string(S) + " cells=" + std::to_string(cells) +
                                       " rank=" + std::to_string(rank));
      }
}

// A set-up asked to keep the factorisation (LowRankTerm::keep_factorisation, the second of
// IDACalcIC's two solves after a switch) solves with the previous set-up's matrix and low-rank
// term, whatever the matrix and term now hold; without the flag the next set-up factors the
// new ones. A solver that has not factored yet factors even when asked to keep.
TEST(SundialsKernels, ASetUpThatKeepsTheFactorisationSolvesWithThePreviousMatrix) {
  auto ctx = sun::make_context();
  Rng rng{43};
  const int S = 8;
  const long cells = 12, n = 1 + cells * S + 5;
  auto y = sun::make_vector(n, ctx.get());
  sun::Matrix A(SUNBandMatrix(n, S, S + 2, ctx.get()));
  sun::LowRankTerm term;
  auto solver = sun::make_low_rank_block_solver(y.get(), A.get(), &term, sun::CellBlocks{1, S, cells}, ctx.get());
  term.keep_factorisation = true;  // nothing to keep yet: factors
  Eigen::MatrixXd D1 = fill_cells(A.get(), cells, S, rng);
  add_random_low_rank_term(term, D1, n, 3, rng);
  ASSERT_EQ(SUNLinSolSetup(solver.get(), A.get()), 0);
  expect_solve_matches_dense(solver.get(), A.get(), D1, rng, ctx.get(), "first set-up");
  // a different matrix and term, kept out
  SUNMatZero(A.get());
  Eigen::MatrixXd D2 = fill_cells(A.get(), cells, S, rng);
  add_random_low_rank_term(term, D2, n, 2, rng);
  ASSERT_GT((D2 - D1).cwiseAbs().maxCoeff(), 0.1);
  term.keep_factorisation = true;
  ASSERT_EQ(SUNLinSolSetup(solver.get(), A.get()), 0);
  expect_solve_matches_dense(solver.get(), A.get(), D1, rng, ctx.get(), "kept set-up");
  term.keep_factorisation = false;
  ASSERT_EQ(SUNLinSolSetup(solver.get(), A.get()), 0);
  expect_solve_matches_dense(solver.get(), A.get(), D2, rng, ctx.get(), "next set-up");
}
