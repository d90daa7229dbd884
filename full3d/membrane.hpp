// Triangulated elastic cylinder: the swimmer's spring network (paper eqs. 6-11).
//
// Mesh: rings of n_theta nodes at x = x0 + r dx (r = 0..n_rings-1), axis along x;
// node (r, i) sits at angle 2 pi (i + (r mod 2)/2) / n_theta, so alternate
// rings are offset by half an angle step and every quad between rings splits
// into two near-equilateral triangles. With the ring chord
// c = 2 R0 sin(pi/n_theta) and the half-step chord s = 2 R0 sin(pi/(2 n_theta)),
// the equilateral ring spacing is dx = sqrt(c^2 - s^2); n_rings = round(L/dx) + 1
// and dx is then stretched to L/(n_rings - 1). Ends are open.
//
// Energies (X: 3 x N_n node positions, m):
//   E_e = ks/2 sum_edges (L_l - L0_l)^2                                     (eq. 7)
//   E_b = kb/2 sum_hinges L_l tan^2((theta_l - theta0_l)/2)                 (eq. 8)
// theta_l is the signed angle between the outward normals of the two
// triangles sharing interior edge l (positive for a convex fold), L_l the
// current edge length. BendingForm::ReferenceAngle uses theta0_l of the
// reference mesh (source-equations.md §6: the undeformed tube is an equilibrium);
// BendingForm::Printed uses theta0_l = 0 as eq. (8) is printed. Boundary
// edges (open ends) carry no bending term. Forces F_i = -dE/dX_i (eq. 9) are the
// exact analytic gradients.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>
#include <utility>

namespace swim::full3d {

struct CylinderMesh {
  double radius = 0.0;   ///< R0, m
  double length = 0.0;   ///< L, m
  int n_theta = 0;       ///< nodes per ring
  int n_rings = 0;
  double ring_spacing = 0.0;  ///< dx, m
  Eigen::Vector3d axis_start = Eigen::Vector3d::Zero();  ///< centre of ring 0; axis along +x

  Eigen::Matrix3Xd X0;                     ///< reference node positions
  std::vector<std::array<int, 3>> triangles;  ///< outward oriented
  std::vector<std::array<int, 2>> edges;
  Eigen::VectorXd rest_length;             ///< L0 per edge
  /// (a, b, c, d): shared edge a->b; c opposite in triangle (a,b,c), d in (b,a,d).
  std::vector<std::array<int, 4>> hinges;
  std::vector<int> hinge_edge;             ///< edge index of each hinge
  Eigen::VectorXd rest_angle;              ///< theta0 per hinge
  /// cos(theta0), sin(theta0) per hinge (set with rest_angle by make_cylinder; the bending
  /// forces fall back to computing them when their size does not match rest_angle)
  Eigen::VectorXd rest_cos, rest_sin;
  Eigen::VectorXd node_area;               ///< reference area carried by each node (1/3 of its triangles), m^2

  int nodes() const { return int(X0.cols()); }
  int node(int ring, int i) const { return ring * n_theta + i; }
  int ring_of(int node_id) const { return node_id / n_theta; }
};

/// Builds the cylinder mesh. Throws swim::InputError for R0 <= 0, L <= 0, n_theta < 3.
CylinderMesh make_cylinder(double R0, double L, int n_theta, const Eigen::Vector3d& axis_start);
/// The reference quantities (rest lengths, rest angles with their cosines and sines, node
/// areas) from mesh.X0: the stress-free state is the reference shape X0.
void set_reference_geometry(CylinderMesh& mesh);
/// Seed imperfection of the stress-free shape (full3d.membrane.seed_mode, seed_amplitude):
/// every node of X0 moves radially to r = R0 (1 + eps cos(m phi)), phi its angle about the
/// axis, the same on every ring, and the reference quantities are recomputed, so the seeded
/// tube is an unstressed tube with lobes of amplitude eps R0. m = 0 or eps = 0: no change.
/// Throws swim::InputError for m = 1 or m < 0, eps outside [0, 0.5) and 2 m >= n_theta.
void seed_ring_mode(CylinderMesh& mesh, int m, double eps);
/// The same with several lobe numbers at once: r = R0 (1 + sum_k eps_k cos(m_k phi)) (pairs
/// (m_k, eps_k); a pair with m = 0 or eps = 0 adds nothing), each pair checked as above, the
/// sum's amplitude below 0.5. One pair gives seed_ring_mode's mesh bit for bit.
void seed_ring_modes(CylinderMesh& mesh, const std::vector<std::pair<int, double>>& modes);

/// How a uniform radial load acts on the wall: Hydrostatic, a pressure normal to the deformed
/// wall (a fluid); CentrallyDirected, a force of fixed magnitude per reference area directed at
/// the axis (the tier's actuation load, potential P sum A_i r_i).
enum class RingLoad { Hydrostatic, CentrallyDirected };
/// Linear buckling load (Pa) of a ring of radius R (m) and bending rigidity D (J) in mode m
/// (lobes w = a cos(m theta), inextensional: hoop stretching is much stiffer than bending):
///   hydrostatic          p_m = (m^2 - 1) D / R^3,
///   centrally directed   p_m = (m^2 - 1)^2 D / ((m^2 - 2) R^3)   (4.5 D / R^3 for m = 2).
/// A tube with free ends under a load uniform along its axis buckles in these modes, uniform
/// along the axis (no axial strain; docs/full3d.md, "Ring buckling"). m < 2: infinity.
double ring_buckling_pressure(int m, double D, double R, RingLoad load);
/// Linear growth rate (1/s, negative: decay) of ring mode m under the uniform load P (Pa)
/// with an overdamped wall c dX/dt = F per area (drag c, kg/(m^2 s)):
///   sigma_m = -K_m / (c R (1 + 1/m^2)),  K_m = (m^2-1)^2 D / R^3 - P ((m^2-1)^2 - 1) / m^2
/// (centrally directed; hydrostatic: K_m = (m^2 - 1) ((m^2 - 1) D / R^3 - P)); K_m = 0 at p_m.
double ring_mode_growth_rate(int m, double P, double D, double R, double drag, RingLoad load);
/// The mode m in [2, m_max] that grows fastest under P (largest positive ring_mode_growth_rate);
/// 0 when every mode is stable (P below every p_m).
int fastest_ring_mode(double P, double D, double R, RingLoad load, int m_max = 64);
/// n_theta whose ring chord is closest to (not above) the target node spacing.
int n_theta_for_spacing(double R0, double spacing);
/// Cylinder with target node spacing (m).
CylinderMesh make_cylinder_with_spacing(double R0, double L, double spacing, const Eigen::Vector3d& axis_start);
/// Coarsest mesh whose longest reference edge is below safety * h/2 (paper's no-leak rule),
/// with a node count per ring that is a multiple of `ring_multiple` (full3d.membrane.
/// ring_nodes_multiple; 1: any count).
CylinderMesh make_cylinder_for_grid(double R0, double L, double h, const Eigen::Vector3d& axis_start,
                                    double safety = 0.9, int ring_multiple = 1);

double max_edge_length(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X);
/// Throws swim::NumericalError if an edge is >= h/2 (fluid would leak through the membrane).
void check_no_leak(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double h, double t_s = -1.0);

enum class BendingForm { ReferenceAngle, Printed };

struct MembraneParams {
  double ks = 5.5e-8;  ///< spring constant, N/m
  double kb = 1.0e-15; ///< bending constant, N (energy = kb * length)
  BendingForm bending = BendingForm::ReferenceAngle;
};

/// Signed dihedral angle of hinge (a, b, c, d) and its gradient (3 x 4, columns a, b, c, d).
double dihedral_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& d, Eigen::Matrix<double, 3, 4>* grad = nullptr);

/// Spring (eq. 7) and hinge (eq. 8) energies, J. With threads > 1 the edges (hinges) are
/// summed in the static blocks of parallel_blocks and the block sums added in order:
/// reproducible for a given thread count, equal to threads = 1 up to round-off. The hinge
/// term is evaluated as add_bending_forces does, without trigonometric calls.
double stretching_energy(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double ks, int threads = 1);
double bending_energy(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double kb, BendingForm form,
                      int threads = 1);
/// X with inextensional ring lobes of mode m added: radial w = amp cos(m phi) and
/// tangential v = -(amp / m) sin(m phi) about the reference axis (v' = -w: the hoop does not
/// stretch to first order), the same on every ring.
Eigen::Matrix3Xd inextensional_lobes(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, int m, double amp);
/// The bending rigidity D (J) that eq. (8) gives this mesh's wall per unit k_b (N): the
/// energy of small inextensional lobes of mode m (inextensional_lobes; second difference in
/// the amplitude w) against the continuum (D / 2) int dkappa^2 dA, dkappa = (m^2 - 1) w
/// cos(m theta) / R0^2. The lobes must not stretch the hoop: a hinge measures the turning
/// between neighbouring edges, which purely radial lobes change by m^2 w / R0 per radian
/// instead of (m^2 - 1) w / R0 (D too high by m^4 / (m^2 - 1)^2, 1.78 for m = 2). Every hinge
/// angle scales with the edge length a times the curvature, so D / k_b = (sqrt(3) / 8) a for
/// an equilateral lattice (docs/full3d.md, "The wall model"): eq. (8) with a fixed k_b softens
/// as the mesh is refined.
double bending_rigidity_per_kb(const CylinderMesh& mesh, BendingForm form, int m = 2);
void add_stretching_forces(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double ks, Eigen::Matrix3Xd& F);
void add_bending_forces(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double kb, BendingForm form,
                        Eigen::Matrix3Xd& F);
double elastic_energy(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const MembraneParams& p,
                      int threads = 1);
/// F_i = -dE/dX_i (eq. 9), N. With threads > 1 the edges and hinges are split into static
/// blocks, each accumulated into its own buffer and the buffers summed in a fixed order
/// (parallel.hpp): reproducible for a given thread count, equal to threads = 1 up to round-off.
/// `energy`: also the stretching and bending energies of X, J, from the same pass (equal to
/// stretching_energy and bending_energy with the same threads).
Eigen::Matrix3Xd elastic_forces(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const MembraneParams& p,
                                int threads = 1, std::array<double, 2>* energy = nullptr);

/// Node masses m_i = areal_density (kg/m^2) * node_area_i. The paper's equal
/// masses are recovered by passing total/N_n per node directly instead.
Eigen::VectorXd node_masses(const CylinderMesh& mesh, double areal_density);

/// Distance of every node from the reference axis, m.
Eigen::VectorXd node_radii(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X);
/// Mean radius of each ring, m.
Eigen::VectorXd ring_radii(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X);
/// The same from node radii already computed (node_radii).
Eigen::VectorXd ring_radii(const CylinderMesh& mesh, const Eigen::VectorXd& node_r);

/// Outward radial unit vector of every node (from the reference axis).
Eigen::Matrix3Xd radial_directions(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X);

/// Static response of the membrane alone to a uniform inward pressure P (Pa):
/// per-node load -P * node_area_i * e_r,i (conservative: potential P sum A_i r_i),
/// equilibrium of E(X) + P sum A_i r_i. Mesh and load share the rotation and mirror symmetries
/// of the tube, so the equilibrium is a stack of circular rings (radius r_k, axial position
/// x_k); it is found by Newton on those 2 n_rings - 1 unknowns (banded finite-difference
/// Jacobian, about 20 force evaluations per iteration) and then checked on every node of the
/// full mesh. The symmetric equilibrium's stability against non-axisymmetric (buckling) modes
/// is not part of the solve; tests check it for the loads the calibration uses.
struct PressureResponse {
  Eigen::Matrix3Xd X;
  Eigen::VectorXd ring_radius;  ///< per ring, m
  double mid_radius = 0.0;      ///< mean radius of the middle ring(s), m
  double c1 = 0.0;              ///< effective C1 = P / (R0 - mid_radius), Pa/m
  int iterations = 0;
  double max_residual_force = 0.0;  ///< N
};
/// Throws swim::NumericalError when Newton does not reach tol_force (N, the largest nodal
/// force imbalance on the full mesh; <= 0 selects 1e-7 of the largest nodal load).
/// `start`: a stack of circular rings to start Newton from (its ring radii and axial
/// positions; the undeformed tube when null), for a continuation in the load.
PressureResponse relax_under_pressure(const CylinderMesh& mesh, const MembraneParams& p, double pressure,
                                      double tol_force = 0.0, int max_iterations = 50,
                                      const Eigen::Matrix3Xd* start = nullptr);
/// The same static response under an inward pressure that varies along the axis: the nodes of
/// ring k carry -ring_pressure[k] * node_area_i * e_r,i (conservative: potential
/// sum_k P_k sum_{i in ring k} A_i r_i). The load keeps the tube's rotation and mirror
/// symmetries, so the equilibrium is again a stack of circular rings, found by the same Newton
/// solve. The default tolerance is 1e-7 of the largest nodal load (max_k |P_k| max_i A_i);
/// `c1` is the middle ring(s)' pressure over R0 - mid_radius. A constant profile gives
/// relax_under_pressure's result bit for bit. Throws swim::InputError unless ring_pressure
/// holds one finite value per ring.
PressureResponse relax_under_ring_pressures(const CylinderMesh& mesh, const MembraneParams& p,
                                            const Eigen::VectorXd& ring_pressure, double tol_force = 0.0,
                                            int max_iterations = 50, const Eigen::Matrix3Xd* start = nullptr);

}  // namespace swim::full3d
