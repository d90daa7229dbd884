// The paper's rigid circular container (Section 2.3.2, eqs. 22-25) on the MAC grid of the
// square duct: a fictitious domain with a distributed Lagrange multiplier.
//
// The duct Omega = [0,Lx) x [0,Ly] x [0,Lz] is the fictitious domain. The fluid domain omega
// is the cylinder r = |(y,z) - (Ly/2, Lz/2)| < Rc, axis along x. The velocity is constrained
// by the staircase rows E u = 0: u = 0 on every face whose centre lies outside, r > Rc (first
// order: the wall sits anywhere within a cell).
//
// The constrained Stokes step (stokes.hpp) solves
//   A u + G p + E^T lambda = b,   D u = 0,   E u = 0,
// lambda being the multiplier force (N/m^3) on the constrained nodes.
//
// VelocityConstraints also carries rows given by a caller: the test references'
// ghost-cell and surface-collocation walls (tests/full3d/reference/reference_stokes.hpp).
#pragma once

#include <Eigen/SparseCore>
#include <array>
#include <cstddef>
#include <vector>

#include "full3d/grid.hpp"

namespace swim::full3d {

struct CylinderOptions {
  bool enabled = false;        ///< constrain the duct flow to the cylinder r < radius
  double radius = 0.25e-6;     ///< Rc, m; 2 Rc <= min(Ly, Lz)
};

/// The staircase mask, shared by the constraint rows below and the capacitance solver
/// (capacitance_stokes.hpp): true when the face centre of component c (0..2) at
/// cross-section position (j, k) lies outside r = radius + gap about the duct axis
/// (Ly/2, Lz/2). Independent of the axial index (the geometry is x-invariant).
bool cylinder_outside(const MacGrid& g, double radius, int c, int j, int k, double gap = 0.0);

/// Sparse linear velocity constraints E u = 0 on the MAC faces (faces numbered component by
/// component, each in MacGrid::index order).
class VelocityConstraints {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

  VelocityConstraints() = default;
  /// The staircase rows of the cylinder of radius opt.radius (one unit row per outside face
  /// off the duct walls). Throws swim::InputError as check_geometry.
  VelocityConstraints(const MacGrid& g, const CylinderOptions& opt);
  /// Given rows E (rows x faces), the first mask_rows of them unit rows on masked faces.
  /// Throws swim::InputError as check_geometry, or if E has the wrong number of columns.
  VelocityConstraints(const MacGrid& g, double radius, Matrix E, std::size_t mask_rows);
  /// Throws swim::InputError for a non-duct grid, a radius <= 0 or 2 Rc > min(Ly, Lz).
  static void check_geometry(const MacGrid& g, double radius);

  std::size_t rows() const { return std::size_t(E_.rows()); }
  std::size_t mask_rows() const { return n_mask_; }
  std::size_t surface_rows() const { return rows() - n_mask_; }
  const Matrix& matrix() const { return E_; }

  /// out = E u
  void gather(const VectorField& u, std::vector<double>& out) const;
  /// f += scale * E^T lam
  void scatter_add(const std::vector<double>& lam, double scale, VectorField& f) const;

  /// True when the face centre of node (i,j,k) of component c lies outside the cylinder (r > Rc).
  bool outside(int c, int i, int j, int k) const;
  double radius() const { return rc_; }
  const MacGrid& grid() const { return grid_; }

 private:
  MacGrid grid_{1, 2, 2, 1.0, GridBoundary::SquareDuct};
  double rc_ = 0.0;
  std::array<std::size_t, 4> offset_{};  // global face index of component c starts at offset_[c]
  std::size_t n_mask_ = 0;
  Matrix E_;  // rows x total faces
};

/// The multiplier of an exact constrained solve (u, p) of A u + G p + E^T lam = b, recovered
/// from the momentum residual: lam = E (b - (alpha - mu L) u - G p), N/m^3 per row.
void recover_multiplier(const VelocityConstraints& con, const VectorField& b, const VectorField& u,
                        const ScalarField& p, double alpha, double mu, std::vector<double>& lam);

}  // namespace swim::full3d
