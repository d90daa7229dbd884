// Sharp-interface (boundary-fitted) finite-element Stokes solver of the axisymmetric tier.
//
// Steady, swirl-free axisymmetric Stokes flow, viscosity mu, in the rigid cylinder r < Rc,
// periodic along x with period P; unknowns u = (u_x, u_r) and p. u_r = 0 on the axis (u_x free
// there: the natural condition of the r-weighted form), u = 0 at r = Rc. Weak form with the
// full volume measure dV = 2 pi r dr dx, so that a ring force F_k (N, on the whole ring) enters
// directly:
//   a(u,v) = int 2 mu [ dr u_r dr v_r + (u_r/r)(v_r/r) + dx u_x dx v_x
//                       + 1/2 (dx u_r + dr u_x)(dx v_r + dr v_x) ] dV
//   b(v,q) = - int q (dr v_r + v_r/r + dx v_x) dV
//   a(u,v) + b(v,p) = sum_k F_k . v(X_k) + int f . v dV   for all v,     b(u,q) = 0 for all q.
// The membrane (the wall's meridian polygon X_k) is a zero-thickness interface inside one
// fluid: the velocity is continuous across it, the traction jumps by the membrane force.
//
// Discretisation: the mesh of axi/fitted_mesh.hpp (rebuilt on X at every factor()), whose
// membrane vertices are mesh vertices. Crouzeix-Raviart quadrilateral Q2-P1disc: continuous Q2
// velocity on the bilinear (Q1) geometry map (subparametric: the midside and centre nodes at the
// bilinear images of the reference midpoints and centre), pressure discontinuous, linear in
// PHYSICAL coordinates per element with the basis {1, (x - x_c)/h_x, (r - r_c)/h_r} (x_c, r_c the
// mean of the element's corners, h_x and h_r the mean lengths of its xi- and eta-edges (on an
// element with vertical sides: its width and mean height); the scaling does not change the
// space). Being discontinuous, the pressure may jump across the membrane, and the constant
// in each element makes every element conserve mass: int_e div u dV = 0 (to round-off).
//
// Quadrature: 3x3 Gauss-Legendre (exact to degree 5 per direction). For any bilinear map
// (vertical or tilted sides) the divergence terms det J (r dr v_r + v_r + r dx v_x) =
// r (cofactors of J) . (reference derivatives) + v_r det J are polynomials of degree <= 3 per
// direction, and times the pressure basis (bilinear in the reference coordinates) <= 4, so
// b(., .) and the element mass balances are EXACT; on rectangles every term of a(., .) except the hoop term
// u_r v_r / r is of degree <= 5 (exact), and the hoop term is exact in the axis row (u_r = r g
// there). Elsewhere the integrands are rational (1/r, 1/r_eta) and smooth on the element; the
// rule's error is O(h^6) per unit volume, far below the O(h^3) of the Q2 velocity. A body force
// f and the Poiseuille load (constant f) are integrated exactly on rectangles.
//
// Algebra: unknowns [velocity DOFs (Dirichlet DOFs eliminated) | pressure coefficients]; the
// constant pressure coefficient of element 0 (the axis element of column 0) is pinned to 0 and
// its continuity row dropped (it holds automatically: the sum of all elements' mass balances is
// the flux through the container wall, zero). The pressure unknowns are scaled by mu/L
// (L = Rc / (cells_inner + cells_outer)) and the continuity rows by the same factor, so that
// the symmetric system [A  s B^T; s B  0] has blocks of one size. One CSC pattern (explicit
// zeros included) for the life of the object, including the couplings between membrane vertices
// up to 2 apart (closed mode: periodically); each element's 21 x 21 scatter positions are
// precomputed, so assembly is quadrature plus a scatter. Sparse LU: UMFPACK through Eigen's
// UmfPackLU, symbolic analysis once (on the first factor(), with real values), numeric
// factorisation per factor(). The returned pressure has zero volume mean.
//
// Membrane coupling (the constructor's `coupling`). The wall is a P1 (piecewise-linear) curve;
// its ring forces F_k are the generalised forces of the vertex positions, and the membrane
// velocity U_k drives dX_k/dt. Two symmetric choices, both with the exact power balance
// F . U = a(u, u) and a symmetric mobility F -> U (reciprocity), because the load is G F and the
// velocity is G^T u with one matrix G:
//   vertex:      G = point evaluation at the vertices: load sum_k F_k . v(X_k), U_k = u(X_k)
//                (the weak form as first specified). The point loads on the Q2 trace excite the
//                unloaded midside nodes: the membrane velocity converges only at FIRST order
//                (a uniformly sheared closed membrane: 38 / 19 / 9.6 % error at 2 / 4 / 8 rows;
//                a uniform radial load moves the fluid at O(h) instead of not at all).
//   consistent:  (default) G = L D^-1, the P1-Galerkin transfer with a lumped membrane mass: the
//                force per area at vertex k is t_k = F_k / A_k, A_k = int phi_k dA (phi_k the hat
//                function of vertex k along the meridian, dA = 2 pi r ds), the traction t_h =
//                sum t_k phi_k loads the fluid as int t_h . v dA (on the vertex AND midside nodes
//                of the membrane edges, 3-point Gauss per edge: exact), and the membrane velocity
//                is the hat average U_k = int phi_k u dA / A_k. A uniform traction is then loaded
//                exactly (closed-membrane tests: exact pressure jump, no flow; shear at the
//                Q2 rate); U_k differs from u(X_k) by O(h^2) (h^2 u''/12 on a uniform mesh).
// The stiffness term is added as dt G K G^T, so its pattern couples the membrane's trace nodes
// (vertex and midside) of vertices up to 2 apart, i.e. trace nodes up to 4 vertex spacings apart.
//
// Reuse of factorisations (set_reuse; ON by default). The time stepper calls factor() on meshes
// that move only slightly between calls, and the numeric factorisation dominates its cost. With
// reuse on, factor() always assembles the CURRENT system A(X) + scale G K G^T but factors it only
// when needed; solve() then solves the current system by right-preconditioned restarted GMRES
// (Givens rotations, modified Gram-Schmidt with one re-orthogonalisation), the preconditioner
// being the stored factorisation of an earlier system. Right preconditioning: the minimised
// residual is the TRUE residual b - A x, so the stopping test is on what is asked for; after each
// cycle the true residual is recomputed (one product) and the solve only returns when
//   ||b - A x||_2 <= reuse_tolerance ||b||_2   (2-norm of the scaled system, default 1e-12),
// or, with a factorisation of the current system, when GMRES stagnates (the best that
// factorisation gives; the best iterate by true residual is returned). A numeric factorisation
// (the pattern never changes: the symbolic analysis is kept) happens when there is none yet,
// when the caller forces it (factor's `force`), when the previous solve needed more than
// `refactor_after` iterations (checked at the next solve, so that a system solved twice, as the
// Rosenbrock stages are, is refactored before its second solve), or when GMRES with the old
// factorisation does not converge within the cycle (the current system is then factored and
// solved again: an unconverged answer is never returned). A solve may name a warm-start slot
// (solve's `guess`): GMRES then starts from the best multiple of that slot's last solution.
//
// The preconditioner (reuse on) is the factorisation of the system regularised on its pressure
// diagonal,
//   [A  B^T; B  -e I],   e = eps d,   d = the largest diagonal entry of the velocity block,
//   eps = 1e-12 (kPressureRegularisation).
// The saddle-point system (symmetric: the viscous form, the divergence and the wall's stiffness
// term are) has zero pressure diagonals, so an unpivoted
// symmetric factorisation of it breaks down; regularised, the pressure (whose block is now
// diagonal) is eliminated exactly: p = (B u - g) / e and
//   S u = f + B^T g / e,   S = A + B^T B / e,
// S symmetric positive definite when A is, with A's own sparsity (the discontinuous pressure
// couples only one element's velocities, which A couples already). S is factored by CHOLMOD's
// supernodal Cholesky (BLAS-3 kernels) as P S P^T by its lower triangle, P CHOLMOD's own
// fill-reducing ordering found once, in the natural ordering (no transpose per factorisation),
// its OpenMP regions inline (axi/serial_openmp.hpp); the factor's triangular solves are the
// product's own (axi/supernodal_solve.hpp).
// As a preconditioner it is
// nearly exact: one application leaves a relative residual of about 5e-6 (eps = 1e-10: 2e-5;
// 1e-8: 3e-3), a second 1e-10. Measured on paper_amplitude_0.82's system at 32 cells across
// (33 047 unknowns, one core): a numeric factorisation 0.09 s (+0.05 s to form S) and one
// application 6-7 ms, against 0.83 s and 35 ms for UMFPACK's threshold-pivoted LU of the
// unregularised system (10.1 million entries in L + U) and 0.42 s and 6-7 ms for a simplicial
// LDL^T of the regularised one (1.7 million entries in L). When the Cholesky fails (S not
// positive definite: a velocity block made indefinite by the wall's stiffness term) or GMRES on
// a fresh one does not converge, the solver falls back to UMFPACK's LU until
// forget_factorisation (factorisation_fallbacks() counts). Preconditioner solves run UMFPACK
// without iterative refinement (UMFPACK_IRSTEP = 0): its refinement would use the CURRENT values
// of the matrix it refers to with the factors of an older one. With reuse off every factor()
// factors by UMFPACK and solve() is the direct solve with one refinement step (the original
// behaviour); so is the prescribed wall's constrained (unsymmetric) system.
// GMRES's products with A_ read its lower triangle only and take each entry below the diagonal
// for its mirror as well: the system is symmetric (the viscous form and the divergence are
// assembled symmetrically, the wall's stiffness term is symmetrised), so no copy of A_ by rows is
// refreshed after each assembly. A product reads half the entries but scatters half its updates:
// about the time of a product by rows (docs/performance.md). The operator GMRES solves is then
// symmetric to the last bit, the one the preconditioner factors (S is formed from the same lower
// triangle).
//
// Factorisation in the background (set_background_factorisation; off by default, on in the
// time stepper). With the Cholesky in use, a factor() that keeps an earlier factorisation starts
// the Cholesky of the system it assembled on a worker thread (it forms S from A_, which nothing
// writes until the worker is joined, into a second Cholesky object with its own B and e); the
// solves go on with the earlier factorisation. The worker's factorisation is installed
//   - at this system's second solve (the Rosenbrock stages' correction: then solved on the
//     system's own Cholesky),
//   - when a solve needs the current system's factorisation (the refactor_after trigger, a GMRES
//     cycle that does not converge), instead of factoring again,
//   - at the next factor(), before it assembles: the preconditioner of the next system.
// Every point of installation is fixed by the sequence of calls, never by the worker's timing,
// so a run is repeated bit for bit. A failed background Cholesky falls back to UMFPACK's LU as a
// synchronous one does; forget_factorisation and a prescribed wall discard a pending one. On a
// 2-core machine the factorisations then run beside the solves: one cycle of the round
// paper_aspect_L0.2 at half ring spacing took 38 s of wall time at 16 cells and 195 s at 32 cells
// across, against 62 s and 352 s factoring in turn before the CHOLMOD threads were confined
// (docs/performance.md).
// Timing::factor counts the caller's time in factorisations and in waiting for a worker,
// Timing::factor_background the workers' own.
//
// Measured on a driver run (16 k unknowns): a factorisation costs ~15 GMRES iterations; a reused
// LU needs 6-9 iterations one step later (the stage system also changes with gamma dt; a scale
// ratio 1.5 adds ~5 iterations), growing to 12-15 after ~5 steps; refactor_after = 8 was faster
// than 14, and the answers agree with fresh factorisations to ~1e-14.
//
// Not copyable or movable (the LU object refers to the matrix held inside).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <Eigen/CholmodSupport>
#include <Eigen/UmfPackSupport>

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "axi/fitted_mesh.hpp"

namespace swim::axi {

/// The BLAS that UMFPACK's dense kernels run in, as the run's statistics report it: OpenBLAS's
/// own configuration string when it is the provider (looked up at run time), otherwise
/// "not OpenBLAS (the reference BLAS or another provider)". The fitted method's factorisations
/// take about 1.5 times the CPU time on Debian's reference BLAS (docs/performance.md).
std::string blas_provider();

class FittedStokes {
 public:
  /// Topology fixed by (params, membrane nodes n): builds the sparsity pattern once (including
  /// the couplings between membrane vertices up to 2 apart, used by the stiffness term below).
  /// Throws swim::InputError for bad parameters (check_fitted_mesh_params) and mu not positive
  /// and finite (key `fluid.viscosity`).
  /// How ring forces load the fluid and how the membrane velocity is read (see the header
  /// comment "Membrane coupling"); an addition to the original interface, defaulted.
  enum class Coupling { consistent, vertex };
  FittedStokes(const FittedMeshParams& p, double mu, int membrane_nodes, Coupling coupling = Coupling::consistent);
  /// The same on any mesh of the meridian plane (axi/meridian_mesh.hpp): the structured
  /// quadrilaterals above, or a triangulation moved with the wall (axi/tri_mesh.hpp, the P2+
  /// element; see the header comment "Triangles"). Its topology fixes the pattern for the
  /// solver's life.
  FittedStokes(std::unique_ptr<MeridianMesh> mesh, double mu, Coupling coupling = Coupling::consistent);
  ~FittedStokes();
  FittedStokes(const FittedStokes&) = delete;
  FittedStokes& operator=(const FittedStokes&) = delete;

  /// Assembles on the mesh fitted to X and factors (numeric factorisation; the symbolic analysis
  /// on the first call only). Optional: a symmetric stiffness K (2n x 2n, ordering
  /// [x_0, r_0, x_1, r_1, ...], entries only between membrane vertices at most 2 apart) times
  /// `scale` (K in N/m, scale in s) is ADDED to the velocity block at the membrane vertices'
  /// velocity DOFs: (A + dt K) u = F. Throws what FittedMesh::fit throws; std::invalid_argument
  /// for a K of the wrong size or with an entry between vertices more than 2 apart;
  /// swim::NumericalError when UMFPACK fails (singular matrix, out of memory).
  /// With reuse on (see "Reuse of factorisations") the numeric factorisation may be deferred or
  /// skipped; `force` factors now regardless.
  void factor(const Eigen::Matrix3Xd& X, const Eigen::SparseMatrix<double>* K = nullptr, double scale = 0.0,
              bool force = false);

  /// Reuse of factorisations as GMRES preconditioners (default on, refactor_after = 8,
  /// tolerance 1e-12; see the header comment). Off: a fresh factorisation at every factor().
  /// Throws std::invalid_argument for refactor_after < 0 or a tolerance not in (0, 1).
  void set_reuse(bool on, int refactor_after = kRefactorAfter, double tolerance = kReuseTolerance);
  bool reuse() const { return reuse_; }
  /// Drops the factorisation, the symbolic analysis and the warm-start solutions: the next
  /// factor() and solve() start as a new solver's first do. A run checkpoints after calling it, so that a run resumed from the
  /// checkpoint (new solvers) repeats the uninterrupted one bit for bit.
  void forget_factorisation();
  static constexpr int kRefactorAfter = 8;
  /// Regularisation of the pressure diagonal in the preconditioner (see the header comment).
  static constexpr double kPressureRegularisation = 1e-12;
  /// Times the regularised system's Cholesky failed and the solver fell back to UMFPACK's LU
  /// (since the solver's construction; not restored on resume).
  long factorisation_fallbacks() const { return fallbacks_; }
  /// "Cholesky (CHOLMOD)" or "LU (UMFPACK)": what the next reused solve preconditions with.
  std::string preconditioner() const;
  /// Background factorisation (default off; see the header comment "Factorisation in the
  /// background"): with reuse on and the Cholesky in use, every factor() that keeps an earlier
  /// factorisation starts the current system's Cholesky on a worker thread; it becomes the
  /// preconditioner at this system's second solve, at a solve that needs it (an unconverged
  /// GMRES cycle, the refactor_after trigger) and at the next factor(). Off: the worker (if any)
  /// is joined and its factorisation kept.
  void set_background_factorisation(bool on);
  bool background_factorisation() const { return background_; }
  static constexpr double kReuseTolerance = 1e-12;
  /// GMRES iterations (preconditioner applications) and relative true residual ||b - A x|| / ||b||
  /// of the last solve (0 and not computed, -1, with reuse off).
  int last_iterations() const { return last_iters_; }
  double last_residual() const { return last_res_; }

  /// With the current factorisation: ring forces F (3 x n, rows 0/1 the axial/radial force on the
  /// whole ring, N) at the membrane vertices, and optionally a body force density (f_x, f_r),
  /// N/m^3; returns the membrane vertices' velocities U (3 x n, rows 0/1 axial/radial, row 2 = 0).
  /// May be called several times per factorisation. Keeps the full solution for the queries.
  /// `guess` (0 to kGuessSlots - 1; -1 = none) names a warm-start slot: with reuse on, GMRES
  /// starts from the last solution solved in that slot, scaled to the best multiple for the
  /// current system (alpha = argmin ||b - alpha A x_prev||), or from zero when that leaves a
  /// larger residual than ||b||. A caller that solves the same kind of system on a slowly moving
  /// mesh (a time stepper's stages) gives each kind its own slot.
  void solve(const Eigen::Matrix3Xd& F, Eigen::Matrix3Xd& U,
             const std::function<Eigen::Vector2d(double x, double r)>* body = nullptr, int guess = -1);
  static constexpr int kGuessSlots = 2;

  /// Prescribed wall motion with a free axial translation: the force-free swimmer of a
  /// prescribed wave (docs/axi.md "Prescribed waves"). On the mesh fitted to the rings X, the
  /// wall line's Q2 nodes (vertex and midside, between the two rims) carry the Dirichlet
  /// velocity V + (U, 0), V (3 x n, rows 0/1 axial/radial ring velocity, m/s) interpolated
  /// linearly between the rings; the rest is the plain fluid problem (no loads). By linearity,
  /// on one factorisation: (a) V alone gives the axial force F_a the wall exerts on the fluid,
  /// (b) V = (1, 0) on every ring gives F_b (the drag of the towed tube, N per m/s); the
  /// force-free condition F_a + U F_b = 0 gives U = -F_a / F_b. The force is the sum of the
  /// residuals a(u, phi_i) + b(phi_i, p) of the constrained axial unknowns (the weak traction
  /// jump tested with the wall line's shape functions). The last solution is then V + (U, 0)'s
  /// flow: the queries (velocity, end_disc_flux, dissipation, ...) refer to it.
  /// Always factors (no reuse); a later factor()/solve() pair works as before.
  /// Throws std::invalid_argument for V of the wrong size or not finite, what factor() throws,
  /// and swim::NumericalError for a tube with no drag (F_b not positive and finite).
  struct PrescribedWall {
    double velocity = 0.0;  ///< U, the force-free axial velocity, m/s
    double force = 0.0;     ///< F_a, axial force of V alone (U = 0) on the fluid, N
    double drag = 0.0;      ///< F_b, axial force on the fluid per unit U, N s/m (> 0)
    /// The towed tube's lumen flux: the rear end-disc flux of flow (b) (the rigid tube towed at
    /// U = 1, no radial velocity) relative to the rings, m^3/s per m/s (negative: the lumen's fluid
    /// passes the tube towards -x). A steady flow, for calibrating the 1D tier's end effects.
    double towed_lumen_flux = 0.0;
  };
  PrescribedWall prescribed_wall_velocity(const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& V);

  // ---- queries on the last solution
  /// (u_x, u_r) at any point 0 <= r <= Rc (x wrapped by P).
  Eigen::Vector2d velocity(double x, double r) const;
  /// The P1 pressure of the element containing the point (on a shared edge either side), Pa,
  /// zero volume mean.
  double pressure(double x, double r) const;
  /// Volume flux through the surface spanning the rim circle of end vertex `end` (0: rear,
  /// vertex 0; 1: front, vertex n-1) relative to a frame moving axially at frame_velocity, m^3/s:
  /// the surface of revolution of the vertex column's line from the axis to the rim (a disc
  /// when the line is vertical), int 2 pi r (u_x dr - u_r dx) - V pi r_end^2, exact (3-point
  /// Gauss on the Q2 traces of the line's straight edges). For a divergence-free field it is
  /// the flux through any surface spanning the rim circle. Positive: fluid crossing towards +x.
  double end_disc_flux(int end, double frame_velocity) const;
  /// max over elements |int_e div u dV| / (vol_e max|u| / h_e), h_e = sqrt(area_e); a
  /// dimensionless mass-conservation residual (round-off for a correct solve).
  double lumen_divergence_residual() const;
  /// The structured mesh (std::logic_error on a triangulation).
  const FittedMesh& mesh() const;
  const MeridianMesh& meridian_mesh() const { return *mesh_; }
  int unknowns() const { return n_; }
  std::size_t nonzeros() const { return std::size_t(A_.nonZeros()); }

  struct Timing {
    /// factor: seconds the caller's thread spent factoring or waiting for a background
    /// factorisation; factor_background: seconds the worker threads spent factoring.
    double assemble = 0, factor = 0, solve = 0, factor_background = 0;
    long factorisations = 0, solves = 0;  ///< factorisations: all numeric ones (background too)
    long krylov_iterations = 0;  ///< GMRES iterations over all solves (reuse on)
    long reused = 0;             ///< solves done with the factorisation of an earlier system
  };
  const Timing& timing() const { return timing_; }
  /// The counts and times of a run so far (a resumed run's statistics continue them).
  void set_timing(const Timing& t) { timing_ = t; }

  // ---- additions (diagnostics and tests)
  /// The viscous dissipation a(u, u) of the last solution, W (element-wise quadrature; the
  /// stiffness term is not included).
  double dissipation() const;
  /// int_e div u dV of element e for the last solution, m^3/s.
  double element_divergence(int e) const;
  /// Velocity DOFs and pressure unknowns (unknowns() = velocity + pressure).
  int velocity_unknowns() const { return n_vel_; }
  double viscosity() const { return mu_; }

 private:
  struct Geometry;  // per-element quadrature data
  void element_geometry(int e, Geometry& g) const;
  void assemble(const Eigen::SparseMatrix<double>* K, double scale);
  double dof_value(int dof) const { return dof < 0 ? 0.0 : sol_[dof]; }
  Eigen::Vector2d eval_velocity(int e, double xi, double eta) const;
  double eval_pressure(int e, double x, double r) const;
  int find_position(int row, int col) const;  ///< value index of (row, col) in A_, or -1
  void transfer_weights();                    ///< gw_ from the fitted mesh (consistent coupling)
  /// Factors A_ (symbolic analysis on the first call): the regularised system's Cholesky when
  /// `regularised` and it has not failed, else UMFPACK's LU.
  void numeric_factor(bool regularised);
  void give_up_cholesky();  ///< UMFPACK's LU until forget_factorisation; counts the fallback
  bool cholesky_factor();  ///< the regularised system's Cholesky; false (no factorisation) when it fails
  Eigen::VectorXd cholesky_apply(const Eigen::VectorXd& v) const;  ///< its solve
  /// CHOLMOD's supernodal Cholesky through Eigen, its factor open to the product's own
  /// triangular solves (axi/supernodal_solve.hpp)
  class Cholesky : public Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double, Eigen::ColMajor, int>, Eigen::Lower> {
   public:
    const cholmod_factor* factor() const { return m_cholmodFactor; }
  };
  /// A Cholesky of S with what applying it needs: the factored system's B (A_'s pressure
  /// columns' values) and e.
  struct CholeskySlot {
    std::unique_ptr<Cholesky> factor;
    bool analysed = false;
    std::vector<double> bval;
    double pen = 0.0;
  };
  /// Forms P S P^T from the current A_ into schur_lo_ and factors it into `slot` (its symbolic
  /// analysis on its first use); false when S is not positive definite. Reads A_, writes schur_lo_ and slot
  /// only (safe on a worker thread while the caller's thread reads A_).
  bool factor_into(CholeskySlot& slot) const;
  void launch_background();  ///< spare_ <- the current A_'s Cholesky, on a worker thread
  /// Waits for the worker; `install`: its Cholesky becomes the preconditioner (of the current
  /// A_ when joined before the next assembly), a failed one gives the Cholesky up. Returns true
  /// when a factorisation was installed.
  bool join_background(bool install);
  void refactor_now();  ///< the current A_'s factorisation: the background one if pending, else now
  /// Right-preconditioned GMRES on A_ x = rhs_ into sol_, from x0 scaled to its best multiple (or
  /// from zero: x0 null or empty, or no better than zero); returns true when converged to tol_;
  /// iters and the true relative residual out. fresh: the LU is of A_ itself (then stagnation
  /// ends the solve with the best iterate).
  bool gmres(int max_iterations, bool fresh, int& iters, double& relres, const Eigen::VectorXd* x0 = nullptr);
  void pressure_gauge();  ///< p_mean_ of the current sol_

  std::unique_ptr<MeridianMesh> mesh_;
  mutable std::vector<RimPathEdge> path_;  ///< end_disc_flux's path (work)
  bool triangles_ = false;                 ///< the mesh's elements are P2+ triangles
  double mu_, lref_, ps_;
  int n_ = 0, n_vel_ = 0;
  std::vector<int> dof_x_, dof_r_;  ///< per Q2 node, -1 = Dirichlet
  std::vector<int> loc_;            ///< elements x 21 global unknowns (-1 = eliminated)
  std::vector<int> pos_;            ///< elements x 21 x 21 value positions (-1 = none)
  Coupling coupling_;
  /// G = transfer of vertex k to the membrane trace nodes (slots: V_{k-1}, M_{k-1/2}, V_k,
  /// M_{k+1/2}, V_{k+1}; node -1 = absent): node index and weight.
  std::vector<std::array<int, 5>> gnode_;
  std::vector<std::array<double, 5>> gw_;
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> A_;
  /// Per column of A_, the first entry on or below the diagonal: GMRES's products read the
  /// lower triangle only (multiply).
  std::vector<int> lower_begin_;
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;  ///< y = A_ x (A_'s lower triangle)
  std::unique_ptr<Eigen::UmfPackLU<Eigen::SparseMatrix<double, Eigen::ColMajor, int>>> lu_;
  static std::unique_ptr<Eigen::UmfPackLU<Eigen::SparseMatrix<double, Eigen::ColMajor, int>>> new_lu();
  static std::unique_ptr<Cholesky> new_cholesky();
  CholeskySlot chol_;   ///< the stored (applied) Cholesky
  CholeskySlot spare_;  ///< the one a worker factors into (swapped with chol_ when installed)
  mutable Eigen::VectorXd apply_work_;  ///< the triangular solves' workspace (stepping thread only)
  /// S = A + B^T B / e on the velocity unknowns (pattern fixed: A_'s velocity block)
  /// P S P^T by its lower triangle, the matrix the Cholesky factors (build_schur_pattern)
  mutable Eigen::SparseMatrix<double, Eigen::ColMajor, int> schur_lo_;
  std::vector<int> perm_;        ///< P: row k of P S P^T is row perm_[k] of S
  std::vector<int> lo_src_;      ///< per entry of P S P^T: its entry in A_
  /// The penalty B^T B / e element by element (the pressure is discontinuous: each pressure
  /// unknown couples its own element's velocities only): per element, per pair (i, j) of its
  /// pen_nv_ local velocity unknowns (2 per shape function), the entry of P S P^T it adds to
  /// (-1: eliminated, or an entry of S's upper triangle, not stored)
  std::vector<int> lo_pen_pos_;
  int pen_nv_ = 18;
  void build_schur_pattern();   ///< P (perm_), schur_lo_'s pattern, lo_src_, lo_pen_pos_ (constructor)
  bool background_ = false;
  std::thread worker_;          ///< joinable while a background factorisation is pending
  bool worker_ok_ = false;      ///< set by the worker: its Cholesky succeeded
  double worker_seconds_ = 0.0; ///< set by the worker: its time
  int solves_on_system_ = 0;    ///< solves since the last factor() (the current A_)
  bool use_chol_ = true;  ///< false after a Cholesky failure (UMFPACK until forget_factorisation)
  bool pc_chol_ = false;  ///< the stored factorisation (lu_valid_) is chol_'s, else lu_'s
  long fallbacks_ = 0;
  bool analysed_ = false, factored_ = false, solved_ = false;
  bool reuse_ = true;
  int refactor_after_ = kRefactorAfter;
  double tol_ = kReuseTolerance;
  bool lu_valid_ = false;    ///< a numeric factorisation is stored (of some earlier or the current A_)
  bool lu_current_ = false;  ///< ... of the current A_
  int last_iters_ = 0;
  double last_res_ = -1.0;
  Eigen::MatrixXd kv_, kz_;  ///< GMRES work: Krylov basis and preconditioned basis
  Eigen::VectorXd rhs_, sol_;
  std::array<Eigen::VectorXd, kGuessSlots> guess_;  ///< warm-start solutions per slot (empty = none)
  double p_mean_ = 0.0;  ///< volume mean of the raw pressure (subtracted in queries)
  Timing timing_;
};

}  // namespace swim::axi
