// Round elastic wall of the axisymmetric tier: the continuum limit of the 3D tier's spring
// network (full3d/membrane.hpp) restricted to axisymmetric shapes, discretised along the
// meridian.
//
// Reference shape: the cylinder of radius R0 and length L, meridian coordinate s0 in [0, L].
// Current shape: the meridian curve (x(s0), r(s0)). Stretches
//   lambda_s = |d(x, r)/ds0|   (meridional),      lambda_t = r / R0   (hoop).
//
// Stretching, per unit REFERENCE area (the Cauchy-Born limit of the equilateral network with
// one lattice direction along the hoop: 3 springs per node, node area (sqrt(3)/2) a^2, the hoop
// springs stretched by lambda_t, the two slanted (+-60 deg) by
// q = sqrt(lambda_t^2 cos^2 60 + lambda_s^2 sin^2 60)):
//   W_s = (ks / sqrt(3)) [ (lambda_t - 1)^2 + 2 (q - 1)^2 ],   q = sqrt(lambda_t^2/4 + 3 lambda_s^2/4).
// Linearised it is isotropic: 2D Young's modulus Y = 2 ks / sqrt(3), Poisson ratio 1/3.
//
// Bending, per unit reference area (Koiter-type, strains per reference length, as the network
// measures angles between triangle normals), rigidity D (J), nu_b = 1/3 (the network's):
//   W_b = (D/2) [ k_s^2 + k_t^2 + 2 nu_b k_s k_t ],
//   k_s = d psi / d s0,   k_t = (cos psi - 1) / R0,   psi = atan2(dr, dx),
// (k_t = hoop curvature cos psi / r times hoop stretch r / R0, minus its reference 1/R0). A
// uniform contraction costs no bending energy and the reference cylinder is stress free.
//
// Energy E = int over the reference surface (2 pi R0 ds0) of W_s + W_b.
//
// Discretisation: n nodes X_k = (x_k, r_k) at reference positions s0_k (uniform, s0_k = k h with
// h = L/(n-1), unless given: graded_ring_positions refines them towards the two ends), linear
// segments e = (k, k+1) of reference length h_e = s0_{k+1} - s0_k between them, dual lengths
// hb_k = (h_{k-1} + h_k) / 2 at the interior nodes. (Uniform spacing: h_e = hb_k = h.)
//   Stretching, per segment: lambda_s,e = |X_{k+1} - X_k| / h_e (constant on the segment;
//     h_e is taken from reference() so that the reference shape is exactly stress free),
//     lambda_t linear along it, integrated by 2-point Gauss:
//       E_s = 2 pi R0 sum_e h_e (1/2) sum_{g=1,2} W_s(lambda_s,e, lambda_t(xi_g)),
//       xi_g = 1/2 -+ 1/(2 sqrt 3).
//   Bending: psi_e = atan2(dr_e, dx_e) per segment; at interior node k (1..n-2)
//       k_s,k = wrap(psi_k - psi_{k-1}) / hb_k = atan2(t_{k-1} x t_k, t_{k-1} . t_k) / hb_k
//     (the turning angle over the distance between the segments' midpoints, in (-pi, pi]);
//     k_t,e = (cos psi_e - 1) / R0 = (dx_e / l_e - 1) / R0;
//       E_b = 2 pi R0 (D/2) [ sum_e h_e k_t,e^2
//                             + sum_{k=1}^{n-2} w_k ( k_s,k^2 + 2 nu_b k_s,k kbar_t,k ) ],
//       kbar_t,k = (k_t,k-1 + k_t,k) / 2,
//     hoop term by the midpoint rule per segment, meridional and mixed terms at the interior
//     nodes. An end node has one segment and no turning angle: no bending term is centred on
//     it (the free edge carries no moment). The two end half-cells [0, h/2] and [L - h/2, L]
//     are carried by the first and last interior nodes (w_1 = hb_1 + h_0/2,
//     w_{n-2} = hb_{n-2} + h_{n-2}/2, w_k = hb_k otherwise; w_1 = L when n = 3), i.e. k_s is
//     extrapolated as a constant into the end half-cells. Sum w_k = L, every term is then an
//     O(h^2) quadrature of the continuum integral even when the curvature does not vanish at
//     the edges (dropping the half-cells is O(h) there), and a node still couples to at most 2
//     neighbours each side.
// Node areas (loads): A_k = 2 pi R0 hb_k, and pi R0 h_0, pi R0 h_{n-2} at the two end nodes.
// Forces are the exact analytic gradient -dE/dX: the generalised force on the WHOLE ring (N),
// rows 0 (axial) and 1 (radial); row 2 is 0.
//
// Uniform pressure: with the load -P A_k e_r (reference areas, potential P sum_k A_k r_k) and
// free ends, the uniform state x_k = lambda_s s0_k, r_k = lambda_t R0 with
//   dW_s/dlambda_s = 0 (no axial tension), dW_s/dlambda_t = -P R0
// is an exact equilibrium of both the continuum and the discrete wall (bending does not see
// it); for this W_s it is q = 1, lambda_t = 1 - P R0 / Y, lambda_s = sqrt((4 - lambda_t^2)/3),
// so C1 = P / (R0 - R) = Y / R0^2 at every load.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

namespace swim::axi {

struct AxiWallParams {
  double R0 = 0.0;  ///< reference radius, m
  double L = 0.0;   ///< reference length, m
  double ks = 0.0;  ///< the network's spring constant, N/m
  double D = 0.0;   ///< bending rigidity, J
  int nodes = 0;    ///< meridian nodes (rings), >= 3
  /// Reference positions s0_k of the nodes along the meridian, m: empty for the uniform spacing
  /// L / (nodes - 1), else `nodes` values from 0 to L, strictly increasing.
  std::vector<double> s0;
  /// false: the stretching energy without the network's Poisson coupling (axi.wall_poisson_coupling,
  /// a diagnostic; stretching_density)
  bool poisson_coupling = true;
};

/// Reference ring positions from 0 to L refined towards both ends: interior spacing at most
/// `spacing`; at each end the spacings end_ratio * d, end_ratio * d * growth, ... (d the
/// interior spacing) until they reach d. end_ratio = 1 gives the uniform spacing
/// L / ceil(L / spacing). Throws swim::InputError (keys `axi.rim_refinement`,
/// `axi.spacing_factor`) for end_ratio outside (0, 1], growth <= 1, spacing not in (0, L].
std::vector<double> graded_ring_positions(double L, double spacing, double end_ratio, double growth);

/// As graded_ring_positions, with every cut (interior segment boundaries of the actuation
/// protocol, increasing, in (0, L)) the midpoint of two neighbouring rings, so that the rings'
/// cells never straddle a segment: between two cuts the rings sit at the centres of m equal
/// cells (m = ceil(length / spacing), the same cell size d on every such interval when their
/// lengths are equal); in the two end intervals the rings run from the cut's half-cell d/2
/// through k equal cells of at most d to the rim's graded spacings; when less than half a cell
/// d is left beside the graded spacings, they alone fill the interval, scaled by a common
/// factor (below 1 when the interval is shorter than them, at most 1 + 1/(2 sum of the ratios)
/// above), so that no sliver cell appears. Without cuts it is graded_ring_positions. Throws as that does, and
/// swim::InputError (key `protocol.segments`) when an end interval is shorter than half a cell.
std::vector<double> segment_aligned_ring_positions(double L, double spacing, double end_ratio, double growth,
                                                   const std::vector<double>& cuts);

/// Stretching energy density W_s(lambda_s, lambda_t) per unit reference area (J/m^2) of the
/// network with spring constant ks (N/m); optionally its partial derivatives.
/// coupled = false: the diagnostic law without the Poisson coupling (axi.wall_poisson_coupling),
/// W = (Y/2)[(lambda_t - 1)^2 + (lambda_s - 1)^2] with the network's Y: Poisson ratio 0, and
/// under a uniform load with free ends (dW/dlambda_s = 0) the same hoop law as the network's,
/// dW/dlambda_t = Y (lambda_t - 1), at every load.
double stretching_density(double ks, double lambda_s, double lambda_t, double* dW_dls = nullptr,
                          double* dW_dlt = nullptr, bool coupled = true);

/// The network's linearised moduli: 2D Young's modulus Y = 2 ks / sqrt(3) (N/m), Poisson 1/3.
inline double young_modulus_2d(double ks) { return 2.0 * ks / 1.7320508075688772935; }
inline constexpr double kWallPoisson = 1.0 / 3.0;

class AxiWall {
 public:
  /// Throws swim::InputError for R0 <= 0, L <= 0, nodes < 3, ks <= 0, D < 0 (or non-finite).
  explicit AxiWall(const AxiWallParams& p);

  int nodes() const { return n_; }
  /// Largest reference node spacing, m (L / (nodes - 1) when uniform).
  double ds0() const { return h_; }
  /// Smallest reference node spacing, m.
  double min_ds0() const { return h_min_; }
  const AxiWallParams& params() const { return p_; }
  /// Reference positions: row 0 = axial x_k = s0_k (axis start at 0), row 1 = r = R0, row 2 = 0.
  const Eigen::Matrix3Xd& reference() const { return X0_; }
  /// Reference positions s0_k of the nodes along the meridian (row 0 of reference()), m.
  std::vector<double> reference_positions() const {
    std::vector<double> s(n_);
    for (int k = 0; k < n_; ++k) s[k] = X0_(0, k);
    return s;
  }
  /// Reference area carried by each node (2 pi R0 h, half at the two ends), m^2.
  const Eigen::VectorXd& node_area() const { return A_; }

  /// Stretching and bending energies of positions X (3 x nodes, the layout of reference();
  /// row 2 ignored), J. Any axial origin: only differences of x enter.
  std::array<double, 2> energies(const Eigen::Matrix3Xd& X) const;
  /// Generalised forces -dE/dX (rows 0 and 1: axial and radial force on the whole ring, N;
  /// row 2 = 0), the exact analytic gradient; `energy`: the energies of the same pass. O(n),
  /// one scratch allocation besides the result. No geometry checks: non-finite X or two
  /// coincident consecutive nodes give non-finite forces (the caller reports them); r <= 0 is
  /// evaluated as written (lambda_t <= 0). Throws swim::InputError when X is not 3 x nodes.
  Eigen::Matrix3Xd forces(const Eigen::Matrix3Xd& X, std::array<double, 2>* energy = nullptr) const;
  /// Energy of the wall uniformly at radius R (all x at reference): 2 pi R0 L W_s(1, R/R0), J.
  double uniform_energy(double R) const;
  /// The stiffness K = -dF/dX at X (2n x 2n, unknowns [x_0, r_0, x_1, r_1, ...], N/m): central
  /// differences of forces() with step eps (m), five colours per component (a ring's force
  /// depends on the rings at most 2 away), symmetrised (the exact K is the energy's Hessian).
  Eigen::SparseMatrix<double> stiffness(const Eigen::Matrix3Xd& X, double eps) const;

 private:
  double evaluate(const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd* F, std::array<double, 2>* energy) const;

  AxiWallParams p_;
  int n_ = 0;
  double h_ = 0.0, h_min_ = 0.0;
  Eigen::Matrix3Xd X0_;
  Eigen::VectorXd A_;
  Eigen::VectorXd h0_;  ///< reference segment lengths h_e
  Eigen::VectorXd w_;   ///< meridional bending weights w_k (interior nodes; 0 at the ends)
};

/// Static equilibrium of the wall under a uniform inward pressure P (Pa).
struct AxiPressureResponse {
  Eigen::Matrix3Xd X;               ///< equilibrium positions (x_0 held at 0)
  double mid_radius = 0.0;          ///< radius of the middle node (mean of the two for even n), m
  double c1 = 0.0;                  ///< P / (R0 - mid_radius), Pa/m
  int iterations = 0;               ///< Newton steps taken
  double max_residual_force = 0.0;  ///< largest nodal force imbalance |F_k - P A_k e_r| (N)
};

/// Equilibrium of E(X) + P sum_k A_k r_k (per-node load -P A_k e_r, conservative) from the
/// reference shape: Newton on the 2n - 1 unknowns (x_0 held; sum_k F_x,k = 0 identically), the
/// banded Jacobian by central differences of forces() (5 colours: a node couples to at most 2
/// neighbours each side), a banded LU with partial pivoting, backtracking on the residual.
/// Stops when the largest nodal imbalance is below tol_force (N; <= 0 selects
/// 1e-9 |P| max A_k). Throws swim::InputError for P = 0 or non-finite, max_iterations < 1;
/// swim::NumericalError when Newton does not converge within max_iterations.
AxiPressureResponse relax_under_pressure(const AxiWall& wall, double P, double tol_force = 0.0,
                                         int max_iterations = 50);

/// The same for a pressure P_k on each ring (load -P_k A_k e_r; P has one value per ring, some
/// non-zero), from the shape `start` (the reference, or the equilibrium of a nearby load: Newton
/// from the reference does not reach a deep contraction of a short segment); tol_force <= 0
/// selects 1e-9 max |P_k| max A_k. mid_radius and c1 are left 0 (they are a uniform load's).
/// Throws swim::InputError for a profile of the wrong length, non-finite or all zero, a start
/// shape that is not 3 x nodes and finite, max_iterations < 1; swim::NumericalError as above.
AxiPressureResponse relax_under_ring_pressures(const AxiWall& wall, const std::vector<double>& P,
                                               const Eigen::Matrix3Xd& start, double tol_force = 0.0,
                                               int max_iterations = 50);

}  // namespace swim::axi
