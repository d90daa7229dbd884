// Unstructured triangular mesh of the meridian plane for the fitted method's Stokes solver
// (axi/fe_stokes_axi.hpp, the P2+ element), made once on a reference shape of the wall and then
// moved with it.
//
// Why: the structured mesh (axi/fitted_mesh.hpp) runs one column of elements from the axis
// through every ring to the container, so a rim that hooks back over a wedge of lumen forces
// every column of the hook through the wedge, and its lines fold. A triangulation has no
// columns: it fills the wedge with elements of its own.
//
// Generation (CGAL's constrained Delaunay triangulation, refined by Delaunay_mesher_no_edge_
// refinement_2): the strip [x_L, x_L + P] x [0, Rc], x_L in the middle of the gap between the
// tube's ends, with the wall's segments (ring to ring), the axis, the container wall and the two
// cuts x = x_L, x_L + P as constraints. The cuts carry the same points (radii Rc j / m, m =
// ceil(Rc / s), s the size bound at the cuts) and, since no constrained edge is split, keep
// them: the two cuts' vertices are identified (the mesh is periodic), and every ring is a vertex
// and every wall segment an edge.
// Triangles are refined until their longest edge is below `size` (beyond the tube's ends, in the
// gap the period closes, below the larger bound of TriMeshParams::gap_size; the axis and the
// container wall divided along the same field) and their smallest angle above
// asin(sqrt(angle_bound)) (20.7 deg for the default 0.125) wherever a new vertex does not
// encroach on a constraint; near the wall the rings' spacing sets the elements' size, which then
// grows away from it.
//
// Nodes (P2+): the vertices (0..V-1), the edges' midpoints (V..V+E-1), the triangles' centroids
// (V+E..V+E+T-1). A node's kind: on the axis or the container wall when it lies there (an edge's
// midpoint when both its ends do), else interior.
//
// Motion (fit): the vertices move by the harmonic extension of the rings' displacement from the
// reference shape, stiffened where the reference elements are small (the P1 Laplacian with
// weight A_min / A_T per triangle, so that small elements near the wall move nearly rigidly):
// the axial displacement is fixed at the rings only (the axis and the container slide), the
// radial one at the rings, the axis (0) and the container (0). The two factorisations are made
// once; a fit is two solves and an orientation check of every triangle (a non-positive one is a
// swim::NumericalError, the shape this mesh cannot follow: the caller meshes again on a nearer
// reference). The topology never changes, so the solver's pattern holds for the mesh's life.
// Copies share the topology and the factorisations.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

#include "axi/meridian_mesh.hpp"

namespace swim::axi {

struct TriMeshParams {
  double Rc = 0, period = 0;  ///< container radius and period, m
  double size = 0;            ///< longest edge of a triangle (where the rings do not set a finer one), m
  double angle_bound = 0.125; ///< CGAL's shape criterion b = sin^2 theta_min (circumradius over shortest edge <= 1 / (2 sqrt(b)))
  /// Beyond the tube's ends (the gap between them, which the period closes) the size bound grows
  /// with the axial distance d from the nearer end as size min(gap_size, 1 + 5 d / Rc), the
  /// rate of the structured mesh's gap columns; 1: the same size everywhere.
  double gap_size = 1.0;
};

class TriMesh final : public MeridianMesh {
 public:
  /// Meshes around the reference wall X_ref (3 x n, n >= 3: axial positions, radii in (0, Rc),
  /// the tube shorter than the period, its segments not crossing). Throws std::invalid_argument
  /// for bad parameters or such a shape; swim::NumericalError when the triangulation does not
  /// keep the rings or the cuts (a wall segment crossing another). The mesh is fitted to X_ref.
  TriMesh(const TriMeshParams& p, const Eigen::Matrix3Xd& X_ref);

  ElementShape element_shape() const override { return ElementShape::triangle; }
  int membrane_nodes() const override;
  int nodes() const override;
  int elements() const override;
  int element_slot(int e, int a) const override;
  NodeKind node_kind(int node) const override;
  void fit(const Eigen::Matrix3Xd& X) override;
  void corners(int e, double x[4], double r[4]) const override;
  int locate(double& x, double r, double& xi, double& eta) const override;
  int wall_node(int k) const override;
  int wall_midside_node(int k) const override;
  Eigen::Vector2d wall_point(int k) const override;
  bool closed() const override { return false; }
  void rim_path(int end, std::vector<RimPathEdge>& path) const override;
  double length_scale() const override;

  const TriMeshParams& params() const;
  /// The reference shape the mesh was made on.
  const Eigen::Matrix3Xd& reference() const;
  int vertices() const;
  /// Whether the mesh fitted to X would be valid (every triangle positively oriented), without
  /// changing this mesh; the cause when it is not.
  bool follows(const Eigen::Matrix3Xd& X, std::string* cause = nullptr) const;
  /// The smallest angle of a triangle of the current fit, radians (0 before a fit).
  double min_angle() const { return min_angle_; }
  /// The smallest angle the mesher aims for, asin(sqrt(angle_bound)), radians.
  double bound_angle() const;
  /// The smallest angle below which a fit of this mesh counts as degraded, for a nominal
  /// threshold `angle` (radians): `angle` times min(1, the made mesh's smallest angle over
  /// bound_angle()). Where the wall's own shape keeps the made mesh's smallest angle below the
  /// bound (constrained segments meeting at a sharp corner, rings closer than the gap between
  /// them), a new mesh cannot do better, and the threshold falls with it. Call on the mesh as
  /// made (fitted to its reference shape).
  double remesh_threshold(double angle) const;
  /// Position of node `node` in element e (its slot's point; the element's periodic image).
  Eigen::Vector2d slot_position(int e, int a) const;

 private:
  struct Topology;
  std::shared_ptr<const Topology> t_;
  std::vector<double> x_, r_;  ///< current vertex positions
  double min_angle_ = 0.0;
  /// the current positions for X into x, r; false (cause set) if some triangle is not positive
  bool place(const Eigen::Matrix3Xd& X, std::vector<double>& x, std::vector<double>& r, double* min_angle,
             std::string* cause) const;
  // point location: a bucket grid over the current fit, built on the first query after a fit
  mutable std::vector<int> bucket_start_, bucket_tris_;
  mutable double bx0_ = 0, br0_ = 0, bcell_ = 0;
  mutable int bnx_ = 0, bnr_ = 0;
  mutable bool buckets_ = false;
  void build_buckets() const;
};

}  // namespace swim::axi
