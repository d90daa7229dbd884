// Structured, periodic quadrilateral mesh of the meridian plane fitted to the round wall, for
// the sharp-interface (boundary-fitted) Stokes solver of the axisymmetric tier
// (axi/fe_stokes_axi.hpp).
//
// Domain: 0 <= r <= Rc, x periodic with period P. The membrane is the meridian polygon through
// the vertices X_k = (x_k, r_k), k = 0..n-1, 0 < r_k < Rc, an open tube (two free ends) with
// x_0 < x_{n-1} < x_0 + P. x need not increase along the wall: a segment may stand radially or
// turn back, as long as the mesh below can be built with positive Jacobians.
//
// Vertex columns (periodic, numbered c = 0..NC-1), each a line from the axis (row 0) through
// its wall-line point W_c (row cells_inner) to the container (row Ny):
//   c = 0..n-1          the membrane vertices, W_c = X_c;
//   c = n..n+m-2        the m-1 interior lines of the gap (m = gap_columns) from x_{n-1} to
//                       x_0 + P. Gap column widths (i = 0..m-1, from x_{n-1} on):
//                         w_i(q) = min(w_L q^i, w_R q^(m-1-i)),
//                       w_L, w_R the axial widths of the adjacent membrane segments (for a
//                       steep end segment, where its axial width is below half its length,
//                       half its length), with the common ratio q in [1, gap_growth] that fills
//                       the gap (sum_i w_i(q) = G = x_0 + P - x_{n-1}, by bisection; the ratio
//                       of neighbouring widths is then <= q). When no such q exists (the gap is
//                       shorter than m min(w_L, w_R), or longer than the widths at q =
//                       gap_growth can reach) the gap is divided uniformly, w_i = G/m. The
//                       gap's wall-line radius is linear in x between r_{n-1} and r_0.
// Element column c lies between vertex columns c and c+1 (column NC is column 0 shifted by P):
// NC = n - 1 + m element columns (closed test mode: NC = n, no gap, the last column from x_{n-1}
// to x_0 + P).
//
// Radii. Vertex rows j = 0..Ny, Ny = cells_inner + cells_outer; vertex (c, j) is at radius
//   r_{c,j} = rho_c j / cells_inner                                  (j <= cells_inner)
//   r_{c,j} = rho_c + (Rc - rho_c)(j - cells_inner) / cells_outer   (j >= cells_inner)
// (rho_c the radius of W_c; uniform rows), or graded towards the membrane line where the columns
// are narrow (wall_row_aspect > 0, see FittedMeshParams): the singular flow at the tube's free
// rims then sees elements refined in both directions.
//
// Axial positions: vertical lines where the wall is a gentle graph, lines that leave a steep
// wall across it. Along the wall line (membrane and gap, periodic) let a_k in [0, pi] be the
// angle of segment k = (W_k, W_{k+1}) with the +x axis (0 along the axis, pi/2 radial, beyond
// pi/2 turned back), l_k its length, dx_k its axial width, and s_k = s(a_k) its steepness,
// s(a) = smoothstep((a - a0)/(a1 - a0)) (C^1; 0 for a <= a0 = atan 0.7, 1 for a >= a1 = atan 3).
//   Far positions xi_c: the columns' lines end (at the axis and at the container) at axial
//   positions with increments dxi_k = dx_k + e_k - g_k, where e_k = gamma s_k l_k (gamma = 1/2:
//   a steep segment is given half its length of axial room) and the extra is taken back from the
//   gentle segments nearby: each e_m is shared among the segments k = m - M..m + M (M = 24) in
//   proportion to (1 - s_k) max(dx_k, 0) (M + 1 - |k - m|), which shrinks them (the gap's wide
//   columns, next to the rims, give most of it). The offsets o_c = xi_c - x_c, summed from the
//   column farthest from any steep segment (o = 0 there), are then zero outside the windows.
//   Tilt psi_c = psi_max s(|phi_c|) sign(phi_c), phi_c in (-pi, pi] the angle of the chord
//   W_{c+1} - W_{c-1} with the +x axis, psi_max = 60 deg: the line leaves W_c along the chord's
//   normal turned at most 60 deg from the radial direction, (-sin psi, cos psi) outwards and
//   (sin psi, -cos psi) inwards, so that it enters the fluid on the correct side even where the
//   wall stands radially or turns back.
//   Band b_c = min(max(3 l_c, 1.5 |o_c|), 0.9 d) on each side (l_c the longer adjacent wall-line
//   segment, d the distance from W_c to the axis or to the container).
// With u = |r_{c,j} - rho_c| / b_c the vertex's x is the cubic Hermite
//   x_{c,j} = x_c + o_c h01(u) -/+ b_c tan(psi_c) h10(u)   (u < 1; - outside, + inside)
//   x_{c,j} = xi_c                                          (u >= 1)
// (h01 = 3u^2 - 2u^3, h10 = u - 2u^2 + u^3): it leaves W_c with the tilt psi_c and meets the
// vertical x = xi_c with a vertical tangent. The radii are those above in every case. Where no
// wall-line segment within M + 1 columns is steeper than a0, psi_c = 0 and o_c = 0: the line is
// exactly vertical (x = x_c), and a gentle graph wall gets the vertical-line mesh.
//
// Every element (c, j), j = 0..Ny-1, is the quadrilateral with straight edges through its four
// vertices; the geometry map is bilinear (Q1). Its Jacobian is checked at the four corners of
// every element (bilinear: positive there implies positive everywhere); a non-positive one is
// the mesh's only geometric rejection (the wall shape it cannot follow).
//
// Q2 nodes: (2 NC) x (2 Ny + 1), index I = 0..2NC-1 along the columns (periodic; I = 2c is
// vertex column c, I odd a column of midside/centre nodes), J = 0..2Ny along r (J = 2j the vertex
// row j); node (I, J) has the global index I (2Ny + 1) + J. A midside or centre node sits at the
// bilinear image of the reference midpoint or centre. Membrane vertex k is node (2k, 2 cells_inner).
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
  /// remedy) for a non-finite vertex, r outside (0, Rc), a tube that does not fit the period
  /// (not x_0 < x_{n-1} < x_0 + P) or a non-positive element Jacobian (the wall shape the mesh
  /// cannot follow, naming the element and the nearest wall vertex).
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
  /// x of the wall-line point W_c of vertex column c = 0..NC (column NC = column 0 + P); the
  /// column's x everywhere when its line is vertical.
  double column_x(int c) const { return xcol_[c]; }
  const std::vector<double>& column_xs() const { return xcol_; }
  /// Interface radius of vertex column c = 0..NC (periodic): the radius of W_c.
  double interface_radius(int c) const { return rho_[c % nc_]; }
  /// Radius of vertex (c, j), c = 0..NC (periodic), j = 0..Ny.
  double vertex_r(int c, int j) const { return vr_[size_t(c % nc_) * (ny_ + 1) + j]; }
  /// Axial position of vertex (c, j), c = 0..NC (column NC = column 0 + P), j = 0..Ny.
  double vertex_x(int c, int j) const {
    return c >= nc_ ? vx_[size_t(c - nc_) * (ny_ + 1) + j] + p_.period : vx_[size_t(c) * (ny_ + 1) + j];
  }
  /// Whether vertex column c's line is vertical (x = column_x(c) on every row).
  bool column_vertical(int c) const { return vertical_[c % nc_] != 0; }
  /// The four corners of element e: (x, r) of (xi, eta) = (-1,-1), (1,-1), (1,1), (-1,1).
  void corners(int e, double x[4], double r[4]) const;
  /// Physical position of Q2 node (I, J) (I = 0..2NC-1; the periodic image is P further).
  Eigen::Vector2d node_position(int I, int J) const;
  /// The element containing (x, r) (x wrapped by P into [x(r), x(r) + P), x(r) the axial
  /// position of vertex column 0's line at radius r; 0 <= r <= Rc, else std::invalid_argument)
  /// and the reference coordinates there (the bilinear map inverted by Newton's method);
  /// returns the element index. x is returned wrapped. On a shared edge either neighbour may be
  /// returned.
  int locate(double& x, double r, double& xi, double& eta) const;
  /// Smallest element Jacobian x_xi r_eta - x_eta r_xi over the corners (for diagnostics).
  double min_jacobian() const { return min_jac_; }

 private:
  FittedMeshParams p_;
  int n_, nc_, ny_;
  bool fitted_ = false;
  std::vector<double> xcol_;  ///< NC + 1: x of the wall-line points
  std::vector<double> rho_;   ///< NC: radius of the wall-line points
  std::vector<double> frac_;  ///< NC x (Ny + 1): r_{c,j} = frac (0..1 of rho_c inside; of Rc - rho_c outside)
  std::vector<double> vx_, vr_;  ///< NC x (Ny + 1): vertex positions
  std::vector<char> vertical_;   ///< NC: the column's line is vertical
  double min_jac_ = 0;
};

}  // namespace swim::axi
