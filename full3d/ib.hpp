// Immersed-boundary transfer between Lagrangian nodes and the MAC grid.
//
// Spreading (paper eq. 19, node forces F_k already integrated over the node's
// Lagrangian patch, so the quadrature weights dq dr ds are inside F_k):
//   f_c(x) = sum_k F_{k,c} D_h(x - X_k),  x on the c-faces,           N/m^3
// Interpolation (paper eq. 20):
//   U_{k,c} = sum_x h^3 u_c(x) D_h(x - X_k),                            m/s
// with D_h(x) = prod_d phi(x_d/h)/h (eq. 17) and phi = peskin_4pt (eq. 18).
// Each component is evaluated on its own staggered nodes (offsets 0 along its
// face direction, 1/2 elsewhere). Both operations use identical weights, so
// they are adjoint: sum_x h^3 f.u == sum_k F_k.U_k.
//
// Periodic directions wrap. At duct walls the stencil is truncated: kernel
// points outside the fluid, and the wall faces of the wall-normal component
// (held at zero by no-slip), are dropped in both operations (adjointness is
// kept; the force that would land on them is absorbed by the wall). The
// truncation only acts on nodes within 2h of a wall; for the swimmer (R0 = R_duct/2)
// it never does.
//
// Threads (parallel.hpp; `threads` = full3d.threads). Interpolation is split over
// the nodes. Spreading splits the z index range of the grid (the slowest index: each
// thread's planes are one contiguous block of memory) into one block of planes per
// thread (block edges at quantiles of the node distribution along z); every thread
// visits the nodes in index order and adds only the stencil points inside its own
// planes. Every grid value thus receives its contributions in node order whatever the
// thread count and the block edges, so both operations give the same results for any
// `threads` (bitwise with the default compiler flags; tests allow 1e-14 relative).
//
// Cost: the 4 weights of a stencil come from one square root (peskin_4pt_weights),
// computed once per node for the two staggering offsets of each direction and
// shared by the components; the x direction (contiguous in memory) is innermost. A
// spread overwrites its field: with the support of the field's last spread
// (SpreadSupport) it zeroes only that box of cells around the old nodes, not the whole
// field (on 128 cells across a tube fills about 3 % of the grid, and zeroing the whole
// 240 MB field took most of a spread).
#pragma once

#include <Eigen/Core>

#include "full3d/grid.hpp"

namespace swim::full3d {

/// The part of a field that spread() wrote: per direction the cell indices [lo, hi] around
/// the nodes (unwrapped along a periodic direction), or the whole direction. A field is zero
/// outside the support of the spread that last wrote it.
struct SpreadSupport {
  bool valid = false;  ///< false: unknown (the whole field may hold values; `whole` is then set)
  int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  bool whole[3] = {true, true, true};
};

/// f = spread(F) over the whole field (f is overwritten). X, F: 3 x N (m, N).
/// `support`: when given and valid, the support of the spread that last wrote f, which the
/// caller guarantees has not been changed since: only that part is zeroed (a tube fills a few
/// per cent of a fine grid, whose full zeroing took most of a spread). It is then set to this
/// spread's support. The result is the same either way.
void spread(const MacGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, VectorField& f,
            int threads = 1, SpreadSupport* support = nullptr);
/// f += spread(F).
void spread_add(const MacGrid& g, const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, VectorField& f,
                int threads = 1);
/// U = interpolate(u) at the nodes X (U resized to 3 x N).
void interpolate(const MacGrid& g, const VectorField& u, const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd& U,
                 int threads = 1);

}  // namespace swim::full3d
