// Outer flows of the force-free 1D swimmer (docs/outer-flow-1d.md derives every formula).
//
// Swimmer frame zeta = z - X(t) in [0, L]; the tube moves at U(t) in the lab frame and the
// wall's material points move radially in the swimmer frame. Fluxes are swimmer-frame
// fluxes (relative to the tube's cross-sections).
//
// Confined (lubrication in a rigid periodic pipe of radius Rc and period P):
//   lumen    0 < r < R_i = R - a_in :  Q_in = -G_in p_in'                 G_in = pi R_i^4 / 8 mu
//   annulus  R_o = R + a_out < r < Rc:  Q_out = -G_a p_out' - U K_a
//            (container wall moves at -U in the swimmer frame)
//            G_a = (pi / 8 mu) [Rc^4 - R_o^4 - (Rc^2 - R_o^2)^2 / lambda],  lambda = ln(Rc / R_o)
//            K_a = pi Rc^2 - S,   S = pi (Rc^2 - R_o^2) / (2 lambda)
//   free pipe (L < zeta < P): Q_free = -G_c p' - U pi Rc^2,  G_c = pi Rc^4 / 8 mu
//   tube law p_in - p_out = Pi(zeta) (= C1 (R - R0) + q for a force-driven wave; Pi = 0 at the
//            open ends, where lumen, annulus and free pipe meet at one pressure)
//   Q_in + Q_out = Q_tot uniform along the tube (= Q_free), pressure periodic over P,
//   force on the tube = 0  <=>  int_0^L (S p_out' + 2 pi mu U / lambda) dzeta = F_ext.
//
// Unbounded (slender body): the lumen ends are at the ambient pressure (p_in = Pi), and
//   U = <u_ind>, the body-average of the axial velocity that the line of sources
//   sigma = d(pi R^2)/dt and the end point sources (-Q_in(0) at the rear, +Q_in(L) at the front)
//   induce on the outer surface r = R + a_out; resistive-force drag c_par (U - u_ind) per length
//   with uniform c_par = 2 pi mu / (ln(2 L / R0) - 1/2).
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace swim::reduced1d::outer {

inline constexpr double pi = std::numbers::pi;

/// Point functions of the annulus between R_o and Rc.
template <class T>
struct AnnulusPoint {
  T rho;    ///< 1 / G_a [Pa s / m^4]
  T kappa;  ///< K_a / G_a [Pa s / m^2]
  T S;      ///< pi (Rc^2 - R_o^2) / (2 lambda) [m^2]
  T e;      ///< 2 pi mu / lambda [Pa s]
};

template <class T>
AnnulusPoint<T> annulus_point(T Ro, double Rc, double mu) {
  using std::log;
  const T lambda = log(Rc / Ro);
  const T il = 1.0 / lambda;
  const T D2 = Rc * Rc - Ro * Ro;
  const T Ga = (pi / (8.0 * mu)) * (Rc * Rc * Rc * Rc - Ro * Ro * Ro * Ro - D2 * D2 * il);
  const T S = (0.5 * pi) * D2 * il;
  AnnulusPoint<T> a;
  a.rho = 1.0 / Ga;
  a.kappa = (pi * Rc * Rc - S) * a.rho;
  a.S = S;
  a.e = (2.0 * pi * mu) * il;
  return a;
}

/// Coefficients of one interval [zeta_j, zeta_{j+1}] of length d with the membrane radius
/// linear from a to b: lumen resistance rl (exact mean of R_i^-4), annulus resistance
/// ra = int 1/G_a, Couette coefficient c = int K_a / G_a, force weight S (mean) and Couette drag
/// e = int 2 pi mu / lambda (trapezoid rule on the point functions).
template <class T>
struct IntervalCoef {
  T rl, ra, c, S, e;
};

/// The open ends' flow (docs/outer-flow-1d.md §2b): at each end the lumen and the annulus
/// rejoin the free pipe through a region about a gap long, whose extra resistance lubrication
/// leaves out. Each end then acts as a rigid extension of the lumen by `lumen` R_i and of the
/// annulus by `annulus` (Rc - R_o), at the end's radius (resistance, Couette flux, force weight
/// and drag of the annulus all extended). Zero: the plain lubrication junction.
struct EndEffects {
  double lumen = 0.0;    ///< lumen end length per end / the end's lumen radius R_i
  double annulus = 0.0;  ///< annulus end length per end / the end's gap Rc - R_o
  bool any() const { return lumen > 0.0 || annulus > 0.0; }
};

/// `model1d.end_effects = "open_ends"`, calibrated on a steady flow of the axi tier, the straight
/// tube towed through the container (L/R0 = 6.4 and 12.8, Rc/R0 = 1.5 to 4; tests/axi/
/// test_end_effects.cpp): 0.2 R_i per lumen end, 0.25 gaps per annulus end (the drag's fit,
/// 0.21 to 0.37 gaps). Below the flanged orifice's 3 pi / 16 R_i (Sampson; Dagan, Weinbaum &
/// Pfeffer): the thin tube's end is not a hole in a wall (docs/outer-flow-1d.md §2b).
inline constexpr EndEffects kOpenEnds{0.2, 0.25};

/// The open ends as a calibrated junction (`model1d.end_effects = "junction"`,
/// docs/outer-flow-1d.md §2c). At each end the flow around the rim, which lubrication leaves
/// out, dissipates D = x^T M x / 2 in the end's lumen flux q_l and annulus flux q_a (swimmer
/// frame, towards +zeta) and the tube's velocity U, x = (q_l, q_a, U): the lumen and the
/// annulus each lose dD/dq at the end and the tube feels the force -dD/dU. M is positive
/// semi-definite by construction, M = mu S B B^T S with S = diag(R^-3/2, R^-3/2, R^1/2) (R the
/// end's membrane radius) and B lower triangular, its six entries linear in
/// x_g = ln(Rc / R - 1) (clamped to the fitted range). A radial motion of the wall within a
/// few tenths of R of an end pushes the tube by rim mu R <dR/dt>, <.> the rate weighted by
/// exp(-d / (rim_length R)) / (rim_length R) over the distance d from the end (away from the
/// end for a contraction). The coefficients are fitted to steady flows of the axisymmetric tier
/// only (tools/fit_end_junction.py --rim-bands --min-length 3.2): towed tubes and the swimming
/// velocity of every narrow wall band, the bands at both rims included, on uniform and partly
/// contracted tubes, the protocol's states of an end segment beside a contracted tube, and the
/// resistance to a uniform expansion; L/R0 = 3.2 to 12.8, Rc/R0 = 1.5 to 4. Shorter tubes are
/// left out: their two ends interact, which a junction at each end cannot hold.
struct EndJunction {
  double b[6][2];       ///< B's entries (B00, B10, B11, B20, B21, B22): value at x_g = 0, slope
  double rim[2];        ///< rim thrust coefficient: value at x_g = 0, slope
  double rim_length;    ///< decay length of the rim weight / R
  double xg_min, xg_max;  ///< the fitted range of ln(Rc / R - 1)
};
inline constexpr EndJunction kCalibratedJunction{{{1.8818978, -0.3389392},
                                                  {0.0360621, -0.0191104},
                                                  {0.2472167, -0.1088333},
                                                  {1.8354741, -0.4843892},
                                                  {-2.3705423, 0.3685582},
                                                  {-0.0062389, 0.0030796}},
                                                 {-1.8296007, -1.5365845},
                                                 0.15,
                                                 -0.6931472,
                                                 1.8362112};

/// The junction's dissipation matrix M (row-major 3 x 3, units of q_l, q_a: Pa s / m^3, of U:
/// Pa s m) and rim thrust coefficient at an end of membrane radius R in the container Rc.
void end_junction(const EndJunction& j, double R, double Rc, double mu, double M[3][3], double& rim);
/// The same with the derivatives dM/dR and d rim/dR (zero where x_g is clamped).
void end_junction_d(const EndJunction& j, double R, double Rc, double mu, double M[3][3], double& rim,
                    double dM[3][3], double& drim);

/// The calibrated junction in the force-driven closure (ConfinedSystem::transmural with a
/// junction, docs/outer-flow-1d.md §2c): the unknowns z = (W, U, Pi_0, Pi_L), the transmural
/// pressures at the end points no longer zero, and what the Newton matrix needs of them.
struct JunctionClosure {
  double G[4][4] = {};       ///< d g / d z of the four rows (periodicity, force, rear, front)
  double M[2][3][3] = {};    ///< the ends' dissipation matrices (rear, front)
  double dM[2][3][3] = {};   ///< their derivatives with respect to the end radius
  double rim[2] = {}, drim[2] = {};  ///< rim coefficients and d/dR
  double x[2][3] = {};       ///< the ends' (q_l, q_a, U)
  double Pi0 = 0, PiL = 0;   ///< the end points' transmural pressures
  double thrust = 0;         ///< the rims' thrust on the tube (the force row's right side)
  double dthrust[2] = {};    ///< its derivative with respect to each end radius
  std::vector<double> dthrust_dV;  ///< d thrust / d Rdot at the points (0 at the ends)
};

/// The confined lubrication system on the point set {0, z_0, ..., z_{N-1}, L} (N + 2 points,
/// N + 1 intervals; interval j contains face j). Two ways to close it:
///  - transmural(): force-driven wave, Pi = p_in - p_out known at the points (0 at both ends);
///    unknowns Q_tot and U (2 x 2); with the junction Pi at the two end points joins them
///    (4 x 4 in W, U, Pi_0, Pi_L; JunctionClosure);
///  - kinematic(): prescribed wave, lumen flux known up to its value at the rear,
///    Q_in,j = Q_in,0 - s_j; unknowns Q_in,0, Q_tot, U and the pressure rise pL - p0 (4 x 4).
/// After either, Q_in (per face), the pressures and the force split are available.
class ConfinedSystem {
 public:
  ConfinedSystem(int npoints, const std::vector<double>& d, double mu, double a_in, double a_out, double Rc,
                 double period, double L);

  /// Interval coefficients for the point radii (returns false if the wall reaches the
  /// container or the lumen closes: then nothing else is valid).
  /// `derivatives`: also the d/dR_o of the point functions (for the Newton matrix).
  bool geometry(const double* Rpt, bool derivatives = false);
  /// With `junction` (set before the call) the end points' Pi are unknowns (their given values
  /// are ignored) and `Rdot`, the wall's radial velocity at the points, drives the rim thrust.
  void transmural(const double* Pi, double F_ext = 0.0, const double* Rdot = nullptr);
  /// d/dR_o of the point functions at point p (valid after geometry()).
  const AnnulusPoint<double>& point_derivative(int p) const { return dpts_[p]; }
  /// With `ends` (set before the call) the two ends' extensions join the sums.
  void kinematic(const double* s_cum, double F_ext = 0.0);

  /// Lumen pressures at the points, gauge: mean free-pipe pressure = 0 (the two ends' junction
  /// pressures sum to zero; with end effects the lumen's end points lie an end resistance away).
  void lumen_pressure(std::vector<double>& p) const;
  /// Drag coefficient of the current shape towed rigidly (no wall pressure): F = -zeta U.
  double drag_coefficient() const;

  int np, ni;  ///< points, intervals
  double mu, a_in, a_out, Rc, Pd, L, r_free, A_c;
  std::vector<double> d;
  std::vector<IntervalCoef<double>> k;  ///< per interval
  std::vector<double> Q_in;             ///< lumen flux per face (swimmer frame) [m^3/s]
  std::vector<double> dPi;              ///< Pi_{j+1} - Pi_j used (transmural) [Pa]
  std::vector<double> w;                ///< 1 / (rl + ra) per interval (valid after geometry())
  double U = 0, Q_tot = 0, dp_tube = 0;  ///< velocity, total swimmer-frame flux, pL - p0
  double W = 0;                          ///< Q_tot + U pi Rc^2: lab-frame flux through the free pipe
  EndEffects ends;                       ///< the open ends' extensions (kinematic() only)
  const EndJunction* junction = nullptr;  ///< the calibrated end junction
  JunctionClosure jc;                     ///< transmural() with a junction: its closure
  double M[2][2] = {{0, 0}, {0, 0}};     ///< transmural 2 x 2 (rows: periodicity, force; cols: W, U)
  /// The two end intervals conduct as the open end's drainage layer (disc::drainage_resistance)
  /// rather than as a lumen linear in R (set before geometry(); the force-driven wave only).
  bool drainage_ends = false;

 private:
  std::vector<AnnulusPoint<double>> pts_, dpts_;
  std::vector<double> lambda_, last_Ro_;  // geometry() workspace and the radii of pts_
  double R_end_[2] = {0, 0};               // membrane radius at the two ends (geometry())
  double rl_end_[2] = {0, 0};              // the lumen end resistances of the last kinematic()
  double mouth_[2] = {0, 0};               // the junction's lumen pressure drops of the last closure
  void transmural_junction(const double* Pi, double F_ext, const double* Rdot);
  std::vector<double> R_pt_;               // the point radii of the last geometry() (with a junction)
  std::vector<int> changed_;
  bool interval_valid_ = false;  // k and w match last_Ro_ (set by a plain geometry() call)
};

/// The point functions and their derivatives d/dR_o (analytic), for the Newton matrix.
struct AnnulusPointD {
  AnnulusPoint<double> f, df;
};
inline AnnulusPointD annulus_point_d(double Ro, double Rc, double mu) {
  const double lambda = std::log(Rc / Ro), il = 1.0 / lambda, dl = -1.0 / Ro;
  const double D2 = Rc * Rc - Ro * Ro, dD2 = -2.0 * Ro;
  const double c8 = pi / (8.0 * mu);
  const double G = c8 * (Rc * Rc * Rc * Rc - Ro * Ro * Ro * Ro - D2 * D2 * il);
  const double dG = c8 * (-4.0 * Ro * Ro * Ro - 2.0 * D2 * dD2 * il + D2 * D2 * dl * il * il);
  const double S = (0.5 * pi) * D2 * il, dS = 0.5 * pi * (dD2 * il - D2 * dl * il * il);
  AnnulusPointD a;
  a.f.rho = 1.0 / G;
  a.df.rho = -dG * a.f.rho * a.f.rho;
  a.f.S = S;
  a.df.S = dS;
  a.f.kappa = (pi * Rc * Rc - S) * a.f.rho;
  a.df.kappa = -dS * a.f.rho + (pi * Rc * Rc - S) * a.df.rho;
  a.f.e = (2.0 * pi * mu) * il;
  a.df.e = -2.0 * pi * mu * dl * il * il;
  return a;
}

/// Equivalent circular radius of a square duct of half-width a: the pipe with the same
/// Poiseuille conductance, R = (8 k / pi)^(1/4) a with the duct's k = Q mu / (a^4 G)
/// = (4/3) [1 - (192 / pi^5) sum_{n odd} tanh(n pi / 2) / n^5] = 0.5623.
double duct_equivalent_radius(double half_width);

/// Drag coefficient of a straight tube of radius R (uniform) towed through the confined
/// container: F = -zeta U with lumen carried along and the annulus/free-pipe return flow.
double confined_drag_coefficient(double R, double L, double a_in, double a_out, double Rc, double P, double mu);

/// A straight rigid tube of radius R towed at U through the container by the kinematic (prescribed-
/// wave) system with the end effects `ends`: its drag coefficient (F = -drag U, N s/m) and its lumen
/// flux relative to the tube per unit U (m^3/s per m/s; negative: the lumen's fluid passes towards
/// -z). The two steady figures the end coefficients are checked on (docs/outer-flow-1d.md §2b).
struct TowedTube {
  double drag = 0, lumen_flux = 0;
};
TowedTube confined_tow(double R, double L, double a_in, double a_out, double Rc, double P, double mu,
                       const EndEffects& ends);

/// Resistive-force coefficient per length of a slender body of length L and local radius R,
/// 2 pi mu / (ln(2 L / R) - 1/2); the logarithm is floored at 0.1 (ln(2L/R) - 1/2 reaches 0
/// near L = 0.82 R, where slender-body theory has long lost its meaning).
inline double slender_drag_per_length(double L, double R, double mu) {
  return 2.0 * pi * mu / std::max(std::log(2.0 * L / R) - 0.5, 0.1);
}

/// Swimming velocity of the force-free slender body: with the resistive-force law
/// f(z) = c_par(R_o(z)) (U - u_ind(z)) and int f = 0, U = sum c_i u_i / sum c_i over the cells.
double slender_velocity(const std::vector<double>& zc, const std::vector<double>& faces,
                        const std::vector<double>& sigma, double m_rear, double m_front,
                        const std::vector<double>& rho, double L, double mu, std::vector<double>& u);

/// Lumen force on the tube wall from a linear-in-interval pressure and radius, split into
/// the wall shear -pi int R^2 p' and the pressure on the tapered wall -pi int p (R^2)'. Both
/// are integrated exactly, so shear + taper = pi [R(0)^2 p(0) - R(L)^2 p(L)] to round-off.
struct LumenForce {
  double shear = 0, taper = 0;
};
LumenForce lumen_wall_force(const double* R, const double* p, int npoints);

/// Axial velocity induced on the outer surface of a slender tube at the cell centres by a
/// line of sources sigma_j (per unit length, uniform in cell j = [f_j, f_{j+1}]) and two point
/// sources m_rear at zeta = 0 and m_front at zeta = L; rho_i = regularisation radius at cell i.
/// Exact integration of the regularised source kernel over each cell. O(N^2).
void induced_axial_velocity(const std::vector<double>& zc, const std::vector<double>& faces,
                            const std::vector<double>& sigma, double m_rear, double m_front,
                            const std::vector<double>& rho, std::vector<double>& u);

}  // namespace swim::reduced1d::outer
