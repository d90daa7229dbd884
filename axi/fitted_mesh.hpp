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
// rims then sees elements refined in both directions. The first row's height is eta_c =
// wall_row_aspect min(w_{c-1}, w_c) (w the sizing widths of the adjacent wall-line segments),
// limited where the lines tilt (below): between columns c and c + 1 it may grow by at most
// 1.1 x 2^((1 - tau) / tau), tau = smoothstep(T / 0.2) of the larger of the two lines' slopes
// T = |lambda| + 2 max(|o| / b) (eta_c = min over k of eta_k times the allowed ratios between
// k and c). T = 0 on vertical lines (no limit), so a gentle wall's rows are unchanged; the
// limit is continuous in the shape (it binds only for tau above about 0.7, slopes above 0.14).
// Graded on each column's own width, the rows at the refined rims differ by the rings' ratio
// 1.5 per column, and lines leaning or fanning out across them crossed them.
//
// Axial positions: vertical lines where the wall is a gentle graph, lines that lean and fan out
// where it is steep. Along the wall line (membrane and gap, periodic) segment k = (W_k, W_{k+1})
// has the axial width dx_k, rise dr_k, length l_k, angle a_k = atan2(|dr_k|, dx_k) in [0, pi]
// with the axis, and the steepness s_k = smoothstep((a_k - a0)/(a1 - a0)) (C^1; 0 for a <= a0 =
// atan 0.7, 1 for a >= a1 = atan 3). Two terms, both zero on a gentle wall:
//   Far offsets o_c (one outside, one inside the wall). Far from the wall (at the axis and the
//   container) the lines end at x_c + o_c, spaced across segment k by dx_k + e_k - g_k:
//   e_k = s_k (gamma l_k + (|dx_k| - dx_k)/2) (gamma = 1/2; |dx| rounded at 0.1 l) is the room
//   a steep or turned-back segment gets, g_k what the gentle segments give back. Each e_m is
//   shared among the segments met walking away from m (up to 48 gentle ones, counting a segment
//   as 1 - s of one, or fewer once their axial widths reach 4 times the whole wall line's
//   extra; the last one counted by the fraction that reaches either limit exactly, so that the
//   offsets are continuous in the shape) in proportion to (1 - s_k) max(dx_k, 0): outside,
//   from the side the wall's outward normal faces (before m where the wall rises, dr_m > 0;
//   after it where it falls), inside from the other side. o_c is the running sum of e - g from the column farthest from any
//   steep segment (o = 0 there; zero again past the donors).
//   Lean lambda_c. The straight line through W_c with direction angle beta enters the fluid on
//   the correct side of both adjacent segments (angles a_in, a_out, signed) iff
//   max(a_in, a_out) < beta < min(a_in, a_out) + pi. beta = pi/2 unless the vertical is within
//   15 deg of either bound; the lean (beta - pi/2) is then the shortfall, through a C^1 ramp
//   over 10 deg, at most 75 deg; the leans are spread to the neighbours (largest within 2
//   columns, then two [1 2 1]/4 passes; each sign separately, never below a column's own
//   need). lambda = -tan(lean) = dx/dr of the line at the wall. Lines whose lambdas differ by
//   D diverge by up to 0.29 b D within the band b (below), so lambda's positive and negative
//   parts are then each raised to their upper envelope with slope l_k / B_k per segment
//   (part_c = max over k of part_k minus the sum of l / B between k and c; B_k the largest band
//   of the segment's two columns): across narrow columns (the rims' graded gap columns) the
//   lean falls no faster than the columns widen. The envelope never takes a column's line
//   within 15 deg of its own segments' directions (unless its own lean did).
// With u = |r_{c,j} - rho_c| / b (band b = min(max(3 |o|, 3 d / rows), 0.9 d), d the distance
// from W_c to the axis or the container, rows that side's row count):
//   x_{c,j} = x_c + lambda (r_{c,j} - rho_c) (1 - u^2)^2 + o u (2 - u)   (u < 1)
//   x_{c,j} = x_c + o                                                     (u >= 1).
// The radii are those above in every case. Where no segment is steeper than a0 (and none within
// 15 deg of radial), o = lambda = 0: the lines are exactly vertical (x = x_c to the bit).
//
// Every element (c, j), j = 0..Ny-1, is the quadrilateral with straight edges through its four
// vertices; the geometry map is bilinear (Q1). Its Jacobian is checked at the four corners of
// every element (bilinear: positive there implies positive everywhere); a non-positive one is
// the mesh's only geometric rejection (the wall shape it cannot follow). When the tilted lines
// fail that check and the wall line's x is strictly increasing, all lines are made vertical
// (x = x_c; valid for any such wall) and checked again. Otherwise (or if that fails too) the
// tilted mesh is smoothed around its first folded element (FittedMeshParams::elliptic_smoothing):
// on the fold's side of the wall line, in a window of vertex columns lo..hi (6 columns either
// side of the element, doubled while a fold remains inside the window, up to 48), the interior
// vertices solve Winslow's equations
//   alpha x_xixi - 2 beta x_xieta + gamma (x_etaeta + Q x_eta) = 0   (and the same for r),
//   alpha = x_eta^2 + r_eta^2, beta = x_xi x_eta + r_xi r_eta, gamma = x_xi^2 + r_xi^2,
// (central differences on the logical grid, Gauss-Seidel sweeps until no vertex moves by more
// than 1e-9 of the window's smallest edge, at most 4000), with the window's edge columns, the axis (or
// container) row and the wall line held. The logical coordinates then solve Laplace's equation
// on the physical window, a one-to-one map onto the logical rectangle for any simply connected
// window (Rado's theorem), so the lines unfold wherever the discrete solution follows it. The
// control term Q = -s_etaeta / s_eta, s the radii of the column's algebraic rows, keeps the rows
// graded towards the wall. Any other fold starts a window of its own. The smoothing changes
// nothing on a shape the algebraic lines mesh (vertices identical to the bit), so it is a
// discontinuous fallback: the mesh jumps where it engages, which the stepper's error control
// sees as any other change of the shape. Point location (locate) then searches the elements.
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

#include "axi/meridian_mesh.hpp"

namespace swim::axi {

/// The bilinear map of a quadrilateral's corners (cx, cr) (in the order (xi, eta) = (-1,-1),
/// (1,-1), (1,1), (-1,1)) at (xi, eta): the point and the four derivatives of the map.
struct BilinearPoint {
  double x = 0, r = 0;    ///< the mapped point
  double xx = 0, xe = 0;  ///< dx/dxi, dx/deta
  double rx = 0, re = 0;  ///< dr/dxi, dr/deta
  double det() const { return xx * re - xe * rx; }
};
inline BilinearPoint bilinear_map(const double cx[4], const double cr[4], double xi, double eta) {
  constexpr double cs[4] = {-1, 1, 1, -1}, ct[4] = {-1, -1, 1, 1};
  BilinearPoint b;
  for (int i = 0; i < 4; ++i) {
    const double m = 0.25 * (1 + cs[i] * xi) * (1 + ct[i] * eta);
    const double mx = 0.25 * cs[i] * (1 + ct[i] * eta), me = 0.25 * ct[i] * (1 + cs[i] * xi);
    b.x += m * cx[i];
    b.r += m * cr[i];
    b.xx += mx * cx[i];
    b.xe += me * cx[i];
    b.rx += mx * cr[i];
    b.re += me * cr[i];
  }
  return b;
}

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
  /// Where the algebraic lines fold (a non-positive Jacobian), smooth the interior vertices
  /// around the fold by Winslow's elliptic equations before giving up (see the header).
  bool elliptic_smoothing = true;
};

/// Throws swim::InputError (keys `axi.fitted.*`, `container.radius`, `container.period`) for
/// parameters that cannot make a mesh: Rc, period not positive and finite, cells_inner,
/// cells_outer < 1, gap_columns < 1, gap_growth < 1 or not finite; std::invalid_argument for
/// membrane_nodes < 3.
void check_fitted_mesh_params(const FittedMeshParams& p, int membrane_nodes);

class FittedMesh final : public MeridianMesh {
 public:
  /// Topology only (positions unset until fit()). Checks the parameters (see above).
  FittedMesh(const FittedMeshParams& p, int membrane_nodes);

  /// Places the mesh on the membrane X (3 x n; row 0 axial x_k, row 1 radius r_k, row 2 ignored).
  /// Throws std::invalid_argument when X does not have n columns; swim::NumericalError (cause and
  /// remedy) for a non-finite vertex, r outside (0, Rc), a tube that does not fit the period
  /// (not x_0 < x_{n-1} < x_0 + P) or a non-positive element Jacobian (the wall shape the mesh
  /// cannot follow, naming the element and the nearest wall vertex).
  void fit(const Eigen::Matrix3Xd& X) override;

  const FittedMeshParams& params() const { return p_; }
  int membrane_nodes() const override { return n_; }
  int columns() const { return nc_; }            ///< element columns = vertex columns (periodic)
  int rows() const { return ny_; }               ///< element rows, cells_inner + cells_outer
  int elements() const override { return nc_ * ny_; }
  int node_columns() const { return 2 * nc_; }
  int node_rows() const { return 2 * ny_ + 1; }
  int nodes() const override { return node_columns() * node_rows(); }
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
  void corners(int e, double x[4], double r[4]) const override;
  /// Physical position of Q2 node (I, J) (I = 0..2NC-1; the periodic image is P further).
  Eigen::Vector2d node_position(int I, int J) const;
  /// The element containing (x, r) (x wrapped by P into [x(r), x(r) + P), x(r) the axial
  /// position of vertex column 0's line at radius r; 0 <= r <= Rc, else std::invalid_argument)
  /// and the reference coordinates there (the bilinear map inverted by Newton's method);
  /// returns the element index. x is returned wrapped. On a shared edge either neighbour may be
  /// returned.
  int locate(double& x, double r, double& xi, double& eta) const override;
  // ---- the solver's view (axi/meridian_mesh.hpp)
  ElementShape element_shape() const override { return ElementShape::quadrilateral; }
  int element_slot(int e, int a) const override { return element_node(e, a % 3, a / 3); }
  NodeKind node_kind(int node) const override {
    const int J = node % (2 * ny_ + 1);
    return J == 0 ? NodeKind::axis : (J == 2 * ny_ ? NodeKind::container : NodeKind::interior);
  }
  int wall_node(int k) const override { return node(2 * k, 2 * p_.cells_inner); }
  int wall_midside_node(int k) const override { return node(2 * k + 1, 2 * p_.cells_inner); }
  Eigen::Vector2d wall_point(int k) const override {
    return {vertex_x(k, p_.cells_inner), vertex_r(k, p_.cells_inner)};
  }
  bool closed() const override { return p_.closed; }
  /// The vertex column's line of ring 0 or n - 1, from the axis to the wall.
  void rim_path(int end, std::vector<RimPathEdge>& path) const override;
  double length_scale() const override { return p_.Rc / (p_.cells_inner + p_.cells_outer); }

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

  bool walkable_ = true;  ///< the lines are graphs over r, ordered along the axis (locate walks them)

  bool find_fold(int& bad_c, int& bad_j);
  bool invert(int e, double x, double r, double& xi, double& eta) const;
  static bool newton(const double cx[4], const double cr[4], double x, double r, double& xi, double& eta);
  static bool newton_step(const double cx[4], const double cr[4], double x, double r, double xi, double eta,
                          double& dxi, double& deta);
  int search(double& x, double r, double& xi, double& eta) const;
  double corner_jacobian(int c, int j) const;
  bool smooth_where_folded(int& bad_c, int& bad_j);
};

}  // namespace swim::axi
