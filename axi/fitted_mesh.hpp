// Structured, periodic quadrilateral mesh of the meridian plane fitted to the round wall, for
// the sharp-interface (boundary-fitted) Stokes solver of the axisymmetric tier
// (axi/fe_stokes_axi.hpp).
//
// Domain: 0 <= r <= Rc, x periodic with period P. The membrane is the meridian polygon through
// the vertices X_k = (x_k, r_k), k = 0..n-1, x strictly increasing, 0 < r_k < Rc, an open tube
// (two free ends) with x_{n-1} - x_0 < P.
//
// Vertex columns (vertical lines x = const, periodic, numbered c = 0..NC-1):
//   c = 0..n-1          the membrane vertices, x = x_c;
//   c = n..n+m-2        the m-1 interior lines of the gap (m = gap_columns) from x_{n-1} to
//                       x_0 + P. Gap column widths (i = 0..m-1, from x_{n-1} on):
//                         w_i(q) = min(w_L q^i, w_R q^(m-1-i)),
//                       w_L = x_{n-1} - x_{n-2} and w_R = x_1 - x_0 the adjacent membrane segments,
//                       with the common ratio q in [1, gap_growth] that fills the gap
//                       (sum_i w_i(q) = G = x_0 + P - x_{n-1}, by bisection; the ratio of
//                       neighbouring widths is then <= q). When no such q exists (the gap is
//                       shorter than m min(w_L, w_R), or longer than the widths at q =
//                       gap_growth can reach) the gap is divided uniformly, w_i = G/m.
// Element column c lies between vertex columns c and c+1 (column NC is column 0 shifted by P):
// NC = n - 1 + m element columns (closed test mode: NC = n, no gap, the last column from x_{n-1}
// to x_0 + P).
//
// Interface radius rho_c of each vertex column: r_c on the membrane columns; in the gap linear in
// x between r_{n-1} and r_0. Vertex rows j = 0..Ny, Ny = cells_inner + cells_outer, at radius
//   r_{c,j} = rho_c j / cells_inner                                  (j <= cells_inner)
//   r_{c,j} = rho_c + (Rc - rho_c)(j - cells_inner) / cells_outer   (j >= cells_inner)
// (uniform rows), or graded towards the membrane line where the columns are narrow
// (wall_row_aspect > 0, see FittedMeshParams): the singular flow at the tube's free rims then
// sees elements refined in both directions.
// The membrane is the mesh line j = cells_inner between the vertex columns 0 and n-1 (closed:
// all columns). Every element (c, j), j = 0..Ny-1, is the quadrilateral with the vertical sides
// x = x_c, x = x_{c+1} and straight top and bottom edges; the geometry map is bilinear (Q1):
//   x(xi) = x_c (1 - xi)/2 + x_{c+1} (1 + xi)/2,
//   r(xi, eta) = sum of the four corner radii times the Q1 shape functions, xi, eta in [-1, 1].
// Its Jacobian is x_xi r_eta, positive when the rows are increasing (always, for 0 < rho < Rc)
// and the columns are increasing; it is checked anyway at the four corners (bilinear: positive
// there implies positive everywhere).
//
// Q2 nodes: (2 NC) x (2 Ny + 1), index I = 0..2NC-1 along x (periodic; I = 2c is vertex column
// c, I odd a column of midside/centre nodes), J = 0..2Ny along r (J = 2j the vertex row j); node
// (I, J) has the global index I (2Ny + 1) + J. A midside or centre node sits at the bilinear
// image of the reference midpoint or centre. Membrane vertex k is node (2k, 2 cells_inner).
//
// The topology (node and element numbering, and so every sparsity pattern) depends only on
// (n, params), never on X.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace swim::axi {

struct FittedMeshParams {
  double Rc = 0, period = 0;   ///< container radius and period, m
  int cells_inner = 8;         ///< element rows between the axis and the membrane line
  int cells_outer = 8;         ///< element rows between the membrane line and the container wall
  int gap_columns = 16;        ///< element columns across the gap between the tube's ends (periodic)
  double gap_growth = 1.2;     ///< largest ratio of neighbouring gap column widths
  bool closed = false;         ///< test mode: the membrane spans the whole period (x_n == x_0 + P implied, no gap, n columns)
  /// Rows graded towards the membrane line in narrow columns (> 0): in vertex column c the row
  /// next to the membrane line is at most wall_row_aspect times the narrower adjacent column's
  /// width high, the rows above and below it growing geometrically (one ratio per side and
  /// column, at most 4) to fill the distance to the axis and to the container. 0: uniform rows.
  double wall_row_aspect = 0.0;
};

/// Throws swim::InputError (keys `axi.fitted.*`, `container.radius`, `container.period`) for
/// parameters that cannot make a mesh: Rc, period not positive and finite, cells_inner,
/// cells_outer < 1, gap_columns < 1, gap_growth < 1 or not finite; std::invalid_argument for
/// membrane_nodes < 3.
void check_fitted_mesh_params(const FittedMeshParams& p, int membrane_nodes);

class FittedMesh {
 public:
  /// Topology only (positions unset until fit()). Checks the parameters (see above).
  FittedMesh(const FittedMeshParams& p, int membrane_nodes);

  /// Places the mesh on the membrane X (3 x n; row 0 axial x_k, row 1 radius r_k, row 2 ignored).
  /// Throws std::invalid_argument when X does not have n columns; swim::NumericalError (cause and
  /// remedy) for a non-finite vertex, x not strictly increasing, r outside (0, Rc), a tube that
  /// does not fit the period (x_{n-1} - x_0 >= P) or a non-positive element Jacobian.
  void fit(const Eigen::Matrix3Xd& X);

  const FittedMeshParams& params() const { return p_; }
  int membrane_nodes() const { return n_; }
  int columns() const { return nc_; }            ///< element columns = vertex columns (periodic)
  int rows() const { return ny_; }               ///< element rows, cells_inner + cells_outer
  int elements() const { return nc_ * ny_; }
  int node_columns() const { return 2 * nc_; }
  int node_rows() const { return 2 * ny_ + 1; }
  int nodes() const { return node_columns() * node_rows(); }
  int element(int c, int j) const { return c * ny_ + j; }
  int element_column(int e) const { return e / ny_; }
  int element_row(int e) const { return e % ny_; }
  /// Global index of Q2 node (I, J); I is wrapped periodically.
  int node(int I, int J) const {
    const int m = 2 * nc_;
    I %= m;
    if (I < 0) I += m;
    return I * (2 * ny_ + 1) + J;
  }
  /// Global Q2 node of membrane vertex k.
  int membrane_node(int k) const { return node(2 * k, 2 * p_.cells_inner); }
  /// Q2 node of element e at local position (a, b), a, b in {0, 1, 2} (reference -1, 0, 1).
  int element_node(int e, int a, int b) const {
    return node(2 * element_column(e) + a, 2 * element_row(e) + b);
  }

  // ---- geometry (valid after fit())
  bool fitted() const { return fitted_; }
  /// x of vertex column c = 0..NC (column NC = column 0 + P).
  double column_x(int c) const { return xcol_[c]; }
  const std::vector<double>& column_xs() const { return xcol_; }
  /// Interface radius of vertex column c = 0..NC (periodic).
  double interface_radius(int c) const { return rho_[c % nc_]; }
  /// Radius of vertex (c, j), c = 0..NC (periodic), j = 0..Ny.
  double vertex_r(int c, int j) const;
  /// The four corners of element e: (x, r) of (xi, eta) = (-1,-1), (1,-1), (1,1), (-1,1).
  void corners(int e, double x[4], double r[4]) const;
  /// Physical position of Q2 node (I, J) (I = 0..2NC-1; for the periodic image use column_x).
  Eigen::Vector2d node_position(int I, int J) const;
  /// The element containing (x, r) (x wrapped by P into [x_0, x_0 + P); 0 <= r <= Rc, else
  /// std::invalid_argument) and the reference coordinates there; returns the element index.
  /// x is returned wrapped. On a shared edge either neighbour may be returned.
  int locate(double& x, double r, double& xi, double& eta) const;
  /// Smallest and largest element Jacobian x_xi r_eta over the corners (for diagnostics).
  double min_jacobian() const { return min_jac_; }

 private:
  FittedMeshParams p_;
  int n_, nc_, ny_;
  bool fitted_ = false;
  std::vector<double> xcol_;  ///< NC + 1
  std::vector<double> rho_;   ///< NC
  std::vector<double> frac_;  ///< NC x (Ny + 1): r_{c,j} = frac (0..1 of rho_c inside; of Rc - rho_c outside)
  double min_jac_ = 0;
};

}  // namespace swim::axi
