#pragma once
// The triangular solves of a supernodal Cholesky factor L L^T = P S P^T from CHOLMOD, for one
// right-hand side, in the product's own loops.
//
// CHOLMOD's own solve calls the BLAS once or twice per supernode (dtrsv on the diagonal block,
// dgemv on the rows below it). The factors of the fitted Stokes system have tens of thousands
// of supernodes of a few columns each, where the calls' own overhead and OpenBLAS's blocked
// dtrsv (an axpy per column) cost more than the arithmetic: the preconditioner's application
// was half of the stepping thread's time (docs/performance.md). Here each supernode's panel is
// swept once per direction, column by column, with the updates of the diagonal block and of
// the rows below in the same pass: the forward solve is an axpy per column, the backward one a
// dot product per column, both vectorised by Eigen. The arithmetic is CHOLMOD's; only the order
// of the sums differs, so the results agree with cholmod_solve to round-off.
#include <cholmod.h>

#include <Eigen/Core>

namespace swim::axi {

/// Solves S x = b in place (x holds b on entry) with CHOLMOD's supernodal LL^T factor L of
/// P S P^T (int indices, real double values): y = P b, L w = y, L^T v = w, x = P^T v, where
/// row k of P S P^T is row perm[k] of S. `perm` defaults to the factor's own ordering (L.Perm);
/// a caller that permuted S itself and factored it in the natural ordering passes its own.
/// `work` is resized as needed and may be kept between calls. Throws std::invalid_argument when
/// L is not a numerical supernodal LL^T factor of that kind or x has the wrong size.
void supernodal_llt_solve(const cholmod_factor& L, Eigen::VectorXd& x, Eigen::VectorXd& work,
                          const int* perm = nullptr);

}  // namespace swim::axi
