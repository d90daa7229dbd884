// The paper's rigid circular container (Section 2.3.2, eqs. 22-25 and
// Remark 1) on the MAC grid of the square duct: a fictitious domain with a
// distributed Lagrange multiplier.
//
// The duct Omega = [0,Lx) x [0,Ly] x [0,Lz] is the fictitious domain. The
// fluid domain omega is the cylinder r = |(y,z) - (Ly/2, Lz/2)| < Rc, axis
// along x. The velocity is constrained by linear rows E u = 0:
//   Staircase:    (default) u = 0 on every face whose centre lies outside,
//                 r > Rc (first order: the wall sits anywhere within a cell);
//   GhostLinear:  on an outside face g with a fluid neighbour i along
//                 y or z (the one most aligned with the radial direction at g),
//                 the linear interpolant along the grid line g-i vanishes where
//                 the line crosses r = Rc: (1 - t) u_i + t u_g = 0, t the
//                 crossing's fraction from i to g (a ghost-cell wall, Tseng and
//                 Ferziger 2003); the other outside faces are held at zero;
//   SurfacePoints: the paper's Remark 1. Mask rows u = 0 on faces farther
//     than mask_gap*h outside, r > Rc + mask_gap h, plus surface rows:
//     the bilinear interpolant, in the (y,z) plane of the face layer, of each
//     velocity component at points (Rc cos t, Rc sin t) spaced about
//     surface_spacing*h apart in arc length, one set per x-layer of every
//     component. A stencil node on a ghost position folds onto its mirror
//     with weight -w (the duct's ghost rule); wall faces (held at zero) drop.
//
// The constrained Stokes step (stokes.hpp) solves
//   A u + G p + E^T lambda = b,   D u = 0,   E u = 0,
// lambda being the multiplier force (N/m^3) on the constrained nodes.
#pragma once

#include <Eigen/SparseCore>
#include <array>
#include <cstddef>
#include <vector>

#include "full3d/grid.hpp"

namespace swim::full3d {

/// How the no-slip wall of the cylinder is imposed (see the header comment).
enum class CylinderWall { Staircase, GhostLinear, SurfacePoints };

struct CylinderOptions {
  bool enabled = false;        ///< constrain the duct flow to the cylinder r < radius
  double radius = 0.25e-6;     ///< Rc, m; 2 Rc <= min(Ly, Lz)
  CylinderWall wall = CylinderWall::Staircase;
  double surface_spacing = 1.0;  ///< SurfacePoints: arc spacing of the surface points, in cells h
  double mask_gap = 1.0;       ///< SurfacePoints: mask only r > Rc + mask_gap h (cells)
};

/// The staircase mask, shared by the constraint rows below and the direct per-mode
/// solver (direct_stokes.hpp): true when the face centre of component c (0..2) at
/// cross-section position (j, k) lies outside r = radius + gap about the duct axis
/// (Ly/2, Lz/2). Independent of the axial index (the geometry is x-invariant).
bool cylinder_outside(const MacGrid& g, double radius, int c, int j, int k, double gap = 0.0);

/// Sparse linear velocity constraints E u = 0 on the MAC faces.
class VelocityConstraints {
 public:
  VelocityConstraints() = default;
  /// Builds the cylinder's rows. Throws swim::InputError for a non-duct grid,
  /// a radius <= 0 or 2 Rc > min(Ly, Lz), or non-positive spacing / negative gap.
  VelocityConstraints(const MacGrid& g, const CylinderOptions& opt);

  std::size_t rows() const { return std::size_t(E_.rows()); }
  std::size_t mask_rows() const { return n_mask_; }
  std::size_t surface_rows() const { return rows() - n_mask_; }

  /// out = E u
  void gather(const VectorField& u, std::vector<double>& out) const;
  /// f += scale * E^T lam
  void scatter_add(const std::vector<double>& lam, double scale, VectorField& f) const;
  /// z = (alpha E E^T + mu E (-L) E^T) r = E A E^T r, the multiplier block of the
  /// preconditioner (L with the duct's wall rules).
  void apply_local_helmholtz(const std::vector<double>& r, std::vector<double>& z, double alpha, double mu) const;

  /// True when the face centre of node (i,j,k) of component c lies outside the cylinder (r > Rc).
  bool outside(int c, int i, int j, int k) const;
  double radius() const { return rc_; }

 private:
  MacGrid grid_{1, 2, 2, 1.0, ContainerKind::SquareDuct};
  double rc_ = 0.0;
  std::array<std::size_t, 4> offset_{};  // global face index of component c starts at offset_[c]
  std::size_t n_mask_ = 0;
  Eigen::SparseMatrix<double, Eigen::RowMajor> E_;  // rows x total faces
  Eigen::SparseMatrix<double, Eigen::RowMajor> EEt_, ELEt_;
};

}  // namespace swim::full3d
