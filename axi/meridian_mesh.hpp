// What the fitted finite-element Stokes solver (axi/fe_stokes_axi.hpp) needs of a mesh of the
// meridian plane 0 <= r <= Rc, x periodic with period P, whose lines pass through the wall's
// rings: its velocity nodes and elements, where the wall's rings and the midpoints of its
// segments are, and a path of element edges from the axis to each rim.
//
// Two meshes implement it:
//   - FittedMesh (axi/fitted_mesh.hpp): structured quadrilaterals, Q2 nodes, rebuilt
//     algebraically on every shape; its topology depends only on the ring count.
//   - TriMesh (axi/tri_mesh.hpp): an unstructured triangulation made once on a reference shape
//     and moved with the wall (P2 nodes plus a centroid node: the P2+ element).
//
// Element slots (element_slot(e, a), a = 0..8):
//   quadrilateral: a = 3 b + i, the Q2 node at reference position (i, b) in {0, 1, 2}^2 (xi
//                  along i, eta along b; reference -1, 0, 1);
//   triangle:      0, 1, 2 the vertices (counter-clockwise), 3, 4, 5 the midpoints of the
//                  edges (0,1), (1,2), (2,0), 6 the centroid; slots 7 and 8 are -1.
// The velocity unknowns of a node follow its kind: both components inside the fluid, the axial
// one only on the axis (u_r = 0 there), none on the container wall (no slip).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace swim::axi {

enum class ElementShape { quadrilateral, triangle };
enum class NodeKind : signed char { interior, axis, container };

/// A straight edge of a path from the axis to a rim: its velocity nodes (end, midpoint, end)
/// and its two ends, in the order of the path (from the axis towards the rim).
struct RimPathEdge {
  int node[3] = {-1, -1, -1};
  double x0 = 0, r0 = 0, x1 = 0, r1 = 0;
};

class MeridianMesh {
 public:
  virtual ~MeridianMesh() = default;
  virtual ElementShape element_shape() const = 0;
  virtual int membrane_nodes() const = 0;
  virtual int nodes() const = 0;
  virtual int elements() const = 0;
  /// The velocity node in slot a of element e (see the header), -1 for an unused slot.
  virtual int element_slot(int e, int a) const = 0;
  virtual NodeKind node_kind(int node) const = 0;
  /// Places the mesh on the wall X (3 x n: axial position, radius, unused). Throws
  /// swim::NumericalError naming the cause for a shape it cannot follow (an element of
  /// non-positive Jacobian), std::invalid_argument for X of the wrong size.
  virtual void fit(const Eigen::Matrix3Xd& X) = 0;
  /// The corners of element e in the mesh's frame (quadrilateral: 4, counter-clockwise from
  /// (xi, eta) = (-1, -1); triangle: 3, the 4th left unset); periodic images are shifted by P
  /// so that the element is connected.
  virtual void corners(int e, double x[4], double r[4]) const = 0;
  /// The element containing (x, r) and the reference coordinates there (quadrilateral: xi, eta
  /// in [-1, 1]; triangle: the barycentric coordinates of vertices 1 and 2); x is wrapped into the
  /// mesh's period. Throws std::invalid_argument for r outside [0, Rc].
  virtual int locate(double& x, double r, double& xi, double& eta) const = 0;
  /// The velocity node at wall ring k, and at the midpoint of the wall segment (k, k + 1)
  /// (k = 0..n - 2; a closed wall also k = n - 1, the segment back to ring 0).
  virtual int wall_node(int k) const = 0;
  virtual int wall_midside_node(int k) const = 0;
  /// Position of ring k in the fitted mesh (k = 0..n - 1; a closed wall also k = n: ring 0
  /// shifted by P).
  virtual Eigen::Vector2d wall_point(int k) const = 0;
  /// Test mode: the wall spans the whole period (no rims).
  virtual bool closed() const = 0;
  /// A path of element edges from the axis to the rim of ring 0 (end 0) or ring n - 1 (end 1),
  /// in the fitted mesh.
  virtual void rim_path(int end, std::vector<RimPathEdge>& path) const = 0;
  /// The mesh's length scale (about its element size away from the wall), m: the scale of the
  /// solver's pressure unknowns.
  virtual double length_scale() const = 0;
};

}  // namespace swim::axi
