// Coupled immersed-boundary time step (paper eqs. 12-16, 19-21), Stokes flow.
//
// Per step (dt), with node positions X^n, node velocities V^n, fluid u^n:
//   force on the fluid (eq. 16):  -Fbar = F(X) + F^e(t, X) - m a,
//       F = -dE/dX (membrane.hpp), F^e the actuation, a = (V^n - V^{n-1})/dt
//       the node acceleration (omitted when all masses are zero);
//   spread (eq. 19), one backward-Euler Stokes step (stokes.hpp), interpolate (eq. 20).
// Schemes for the node update:
//   ForwardEuler (eq. 21, the paper's):  u^{n+1} = S_dt(u^n, f(X^n)),
//       X^{n+1} = X^n + dt U(u^{n+1}; X^n).
//   Midpoint (RK2 predictor-corrector):  u* = S_{dt/2}(u^n, f(X^n)),
//       X* = X^n + dt/2 U(u*; X^n);  u^{n+1} = S_dt(u^n, f(X*, t+dt/2)),
//       X^{n+1} = X^n + dt U(u^{n+1}; X*).
//   Second order in dt while the fluid is quasi-steady (rho h^2/mu << dt, the
//   regime of the swimmer: ~1e-9 s vs dt ~ 1e-5 s); the backward-Euler fluid
//   memory term is otherwise first order.
// Guards (swim::NumericalError with cause and remedy): non-finite positions,
// velocities or forces; advective CFL max|U| dt / h > max_cfl; a membrane edge
// longer than h/2 (leak rule of Section 2.3.1).
#pragma once

#include <Eigen/Core>
#include <complex>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "full3d/grid.hpp"
#include "full3d/ib.hpp"
#include "full3d/membrane.hpp"
#include "full3d/stokes.hpp"
#include "full3d/wall_stabilizer.hpp"

namespace swim::full3d {

/// The node update: the paper's forward Euler (eq. 21), the midpoint predictor-corrector, or
/// the first-order damped Runge-Kutta-Chebyshev method, which takes a step of s stages (s
/// velocity evaluations) and is stable for dt lambda <= beta_s ~ 1.93 s^2 instead of 2
/// (ChebyshevStages; docs/full3d.md, "Chebyshev stages").
enum class IbScheme { ForwardEuler, Midpoint, Chebyshev };

/// The coefficients of the first-order damped Runge-Kutta-Chebyshev method with s stages
/// (Verwer, Hundsdorfer and Sommeijer 1990; Verwer 1996) for y' = f(y):
///   Y_0 = y_n,  Y_1 = Y_0 + mut[1] dt f(Y_0),
///   Y_j = mu[j] Y_{j-1} + nu[j] Y_{j-2} + mut[j] dt f(Y_{j-1})  (j = 2..s),  y_{n+1} = Y_s,
/// with w0 = 1 + damping / s^2, w1 = T_s(w0) / T_s'(w0), b_j = 1 / T_j(w0). Its stability
/// polynomial is T_s(w0 + w1 z) / T_s(w0): |R| <= 1 on the real interval [-beta, 0] with
/// beta = (1 + w0) / w1 ~ (2 - 4 damping / 3) s^2, and |R| <= 1 / T_s(w0) < 1 inside it.
/// Stage j sits at time c[j] dt (c[s] = 1). s = 1 is forward Euler.
struct ChebyshevStages {
  int s = 1;
  double w0 = 1.0, w1 = 1.0;
  std::vector<double> mu, nu, mut, c;  ///< index j = 0..s (entries 0, and 1 of mu, nu, unused)
  double stability_interval() const { return (1.0 + w0) / w1; }
};
ChebyshevStages chebyshev_stages(int s, double damping = 0.05);
/// The fewest stages s <= max_stages with fraction * beta_s >= dt lambda (1 when lambda <= 0);
/// max_stages when none suffices.
int chebyshev_stages_for(double dt, double lambda, double fraction, int max_stages);

struct IbOptions {
  IbScheme scheme = IbScheme::ForwardEuler;
  double max_cfl = 0.5;       ///< max |U| dt / h allowed
  bool check_no_leak = true;  ///< enforce max edge < h/2 after every step
  /// true: a step whose CFL number exceeds max_cfl is rejected (IbStepStats::rejected, state
  /// unchanged) instead of throwing; the adaptive run driver then retries with a smaller dt.
  bool reject_on_cfl = false;
  std::string dt_key = "dt";  ///< name of the time step in remedies (the run driver passes "full3d.dt")
  int threads = 1;            ///< threads for spreading, interpolation and membrane forces (parallel.hpp)
  /// true: the wall moves in axisymmetric ring motions only. Each ring's interpolated node
  /// velocities are replaced by the ring's mean axial velocity plus its mean radial velocity
  /// along each node's own radial direction (no azimuthal or lobed motion), so the rings stay
  /// circles about the tube axis (full3d.membrane.axisymmetric, docs/full3d.md "Wall wrinkling").
  bool axisymmetric_wall = false;
  /// The step tau of the fluid's inertia term, rho (u^{n+1} - u^n) / tau (s); 0: each step's
  /// own dt. In creeping flow the term is a relaxation of the quasi-steady Stokes solution,
  /// rho / tau being 1e-4 to 1e-2 of mu |g|^2 on the grid's smallest wavenumber, so a fixed tau
  /// changes the flow by that fraction of one step's velocity change; the adaptive run driver
  /// sets tau = full3d.adaptive.dt_max, and the Stokes solver then factorises once per run
  /// instead of once per step size (docs/full3d.md, "Adaptive time step").
  double inertia_step = 0.0;
  /// The stabilised wall update (wall_stabilizer.hpp): which stiffness its model operator
  /// holds (None: the plain explicit update) and its mobility's multiple of the grid-scale
  /// sheet mobility. Forward Euler only.
  WallStabilization wall_stabilization = WallStabilization::None;
  double stabilization_factor = 1.0;
  StokesOptions stokes{};
};

/// The axisymmetric part of node velocities U of the mesh's rings (IbOptions::axisymmetric_wall),
/// in place: per ring, the mean axial velocity and the mean radial velocity along each
/// node's radial direction from the axis through mesh.axis_start.
void project_axisymmetric(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd& U);

struct IbState {
  double t = 0.0;          ///< s
  Eigen::Matrix3Xd X;      ///< node positions, m
  Eigen::Matrix3Xd V;      ///< node velocities of the last step, m/s
  Eigen::Matrix3Xd V_prev; ///< node velocities of the step before (inertia term)
  VectorField u;           ///< fluid velocity on the MAC faces, m/s
};

struct IbStepStats {
  double max_node_speed = 0.0;  ///< m/s
  double cfl = 0.0;
  int stokes_iterations = 0;
  double max_divergence = 0.0;  ///< 1/s
  double max_edge = 0.0;        ///< m
  /// Midpoint: max over nodes of |U(u^{n+1}; X*) - U(u*; X^n)|, m/s (the embedded
  /// forward-Euler error estimate: dt times this is twice its local error)
  double max_velocity_change = 0.0;
  bool rejected = false;        ///< IbOptions::reject_on_cfl: CFL above max_cfl, state unchanged
  int fluid_solves = 0;         ///< Stokes solves of the step (its velocity evaluations)
  // wall time of the parts of this step, s (for swim bench)
  double time_forces = 0.0;     ///< membrane + actuation forces
  double time_spread = 0.0;     ///< spreading (eq. 19)
  double time_fluid = 0.0;      ///< Stokes solves
  double time_interp = 0.0;     ///< interpolation (eq. 20)
};

/// External (actuation) force per node, N: f(t, X) -> 3 x N_n.
using ExternalForceFn = std::function<Eigen::Matrix3Xd(double t, const Eigen::Matrix3Xd& X)>;

class IbSolver {
 public:
  /// node_mass: per-node masses, kg (size N_n; zeros drop the inertia term).
  IbSolver(const MacGrid& grid, const FluidParams& fluid, CylinderMesh mesh, MembraneParams membrane,
           Eigen::VectorXd node_mass, IbOptions opt = {});

  /// X = reference mesh, V = 0, u = 0, t = 0.
  IbState initial_state() const;
  void set_external_force(ExternalForceFn f) { external_ = std::move(f); }

  /// Advances s by dt. Throws swim::NumericalError (state left at the last good step).
  /// `stages`: the number of Chebyshev stages (IbScheme::Chebyshev only; 1 is the forward
  /// Euler step). The state's V is then the step's mean node velocity (X^{n+1} - X^n) / dt
  /// and u the fluid velocity of the last stage.
  IbStepStats step(IbState& s, double dt, int stages = 1);

  /// Largest decay rate lambda_max (1/s) of the linearised explicit coupling at s.X: the
  /// dominant eigenvalue of X' = U(F(X)) linearised, i.e. of v -> -I S J v with J = dF/dX
  /// (membrane forces, finite differences; the actuation relays saturate and are left out), S the Stokes solve with the step dt on
  /// u^n = 0 (the quasi-steady mobility) and I / spreading the IB transfer operators.
  /// Forward Euler is stable while dt lambda_max < 2. With the stabilised wall update the
  /// operator is v -> -G I S G J v, G = (I + dt B)^{-1/2}, the rate of the update a step of dt
  /// makes, which falls as dt grows (dt times it grows). Power iteration from a fixed
  /// pseudo-random start (reproducible), `iterations` coupled solves. Leaves s unchanged.
  /// `start`: when given and of the mesh's size, the iteration starts from it (a warm start from
  /// an earlier estimate) and leaves its last vector there.
  double explicit_rate(const IbState& s, double dt, int iterations = 10, Eigen::Matrix3Xd* start = nullptr);

  /// Ritz values of the same operator (with the stabilised wall update: of the update's own
  /// operator at dt), 1/s, by `iterations` Arnoldi steps from `start` (as explicit_rate), and
  /// each Ritz pair's residual over |mu|. A step of dt amplifies a mode of rate mu by
  /// |1 - dt mu|; the power iteration's magnitude bounds that only when the rates are real,
  /// which this checks (the stabilised update's linearisation G M G H is similar to a
  /// symmetric matrix).
  struct RateSpectrum {
    std::vector<std::complex<double>> ritz;  ///< Ritz values, 1/s
    std::vector<double> residual;            ///< each pair's residual over |mu|
  };
  RateSpectrum explicit_spectrum(const IbState& s, double dt, int iterations, const Eigen::Matrix3Xd* start = nullptr);

  /// Force the structure exerts on the fluid, -Fbar of eq. (16), N per node.
  Eigen::Matrix3Xd fluid_force(const Eigen::Matrix3Xd& X, double t, const Eigen::Matrix3Xd& accel) const;

  /// The wall's stretching and bending energies at X, J. They come from the same pass as
  /// the elastic forces at X, which is kept for the next step from X (a run asks for the
  /// energy of each new state, then steps from it: one pass per step serves both).
  std::array<double, 2> elastic_energy_parts(const Eigen::Matrix3Xd& X) const;

  const MacGrid& grid() const { return grid_; }
  const CylinderMesh& mesh() const { return mesh_; }
  /// The stabilised wall update's operator (null without full3d.wall_stabilization).
  const WallStabilizer* stabilizer() const { return stab_.get(); }
  StokesSolver& stokes() { return stokes_; }
  const StokesSolver& stokes() const { return stokes_; }
  const IbOptions& options() const { return opt_; }

 private:
  /// The start vector of a rate estimate: `start` when it has the mesh's size, otherwise a
  /// fixed pseudo-random field (reproducible on resume).
  static Eigen::Matrix3Xd rate_start(Eigen::Index n, const Eigen::Matrix3Xd* start);
  /// Calls body(apply) with apply(v) = A v, the linearised (stabilised) update's decay operator
  /// at s and dt (an empty matrix when v is zero or not finite), the pressure output restored.
  template <class Body>
  auto with_linearised_coupling(const IbState& s, double dt, Body&& body);
  void guard_finite(const Eigen::Matrix3Xd& A, const char* what, double t) const;
  /// The elastic forces at X, from the kept pass when it was made at the same X.
  const Eigen::Matrix3Xd& elastic(const Eigen::Matrix3Xd& X) const;
  struct ElasticPass {
    Eigen::Matrix3Xd X, F;
    std::array<double, 2> energy{};
  };
  mutable ElasticPass elastic_;
  std::string dt_remedy() const;
  MacGrid grid_;
  CylinderMesh mesh_;
  MembraneParams membrane_;
  Eigen::VectorXd mass_;
  IbOptions opt_;
  StokesSolver stokes_;
  std::unique_ptr<WallStabilizer> stab_;
  ExternalForceFn external_;
  VectorField work_f_, work_u_, work_uh_;  ///< step() work fields, reused between steps
  /// the support of work_f_'s last spread: every write to work_f_ is a spread given it
  SpreadSupport f_support_;
};

}  // namespace swim::full3d
