// Direct linear solvers of the 1D tier's Newton systems, behind SUNDIALS' SUNLinearSolver.
//
// The Newton matrix is a band matrix M plus a low-rank term s U V^T (the held segments'
// couplings, and the confined outer flow's closure):
//   (M + s U V^T) x = b  by  Sherman-Morrison-Woodbury:
//   x = M^{-1} b - Z (I + s W^T Z)^{-1} s W^T M^{-1} b,  U = Q R (Q orthonormal), W = V R^T,
//   Z = M^{-1} Q.
// M is factored by one of
//   - band LU with partial pivoting (LAPACK dgbtf2's algorithm and layout), or
//   - block LU of a block-tridiagonal matrix over the cells (each diagonal block inverted
//     with partial pivoting) with a border of unknowns no cell row references (dense LU),
//     falling back to the band LU when the matrix leaves that structure or a diagonal block
//     is singular or ill-conditioned.
#pragma once

#include <vector>

#include "reduced1d/sundials.hpp"

namespace swim::reduced1d::sun {

/// Low-rank correction of a banded Newton matrix: the matrix actually solved with is
/// M + scale() U V^T, M the band matrix handed to the solver's setup, U and V column-major
/// n x rank. The owner refreshes U, V, rank together with the band Jacobian.
struct LowRankTerm {
  int rank = 0;
  std::vector<double> U, V;
  double (*scale)(void* ctx) = nullptr;  ///< factor of U V^T at the time of setup (1 if null)
  void* scale_ctx = nullptr;
  /// Set by the Jacobian function: the next setup keeps the previous one's factorisation
  /// and low-rank columns (the matrix, U and V are not read).
  bool keep_factorisation = false;
};

/// Direct linear solver for (band M) + scale U V^T: band LU with partial pivoting (own
/// optimised kernel, same algorithm as SUNLinSol_Band/LAPACK dgbtf2) and the
/// Sherman-Morrison-Woodbury formula with a rank x rank dense solve. `term` must outlive the
/// solver. A must be a SUNBandMatrix with the bandwidths used later.
LinearSolver make_low_rank_band_solver(N_Vector y, SUNMatrix A, LowRankTerm* term, SUNContext ctx);

/// Block structure of a band matrix whose unknowns are grouped in cells: unknowns
/// [offset, offset + block * count) are `count` cells of `block` unknowns each; a cell's rows
/// reach only its own and its two neighbouring cells; the unknowns before and after the cells
/// (the border) appear in no cell's row.
struct CellBlocks {
  long offset = 0;
  int block = 0;
  long count = 0;
};

/// The same solver for a band matrix with the structure of `cells`: the cells are factored
/// by block LU (block tridiagonal, each diagonal block inverted with partial pivoting), the
/// border by a small dense LU after them. A setup whose matrix leaves that structure, or
/// whose diagonal blocks are singular or too ill-conditioned for block elimination, falls
/// back to the band LU.
LinearSolver make_low_rank_block_solver(N_Vector y, SUNMatrix A, LowRankTerm* term, const CellBlocks& cells,
                                        SUNContext ctx);
/// Whether the last set-up of a solver made by make_low_rank_block_solver factored by blocks.
bool factored_by_blocks(SUNLinearSolver S);

}  // namespace swim::reduced1d::sun
