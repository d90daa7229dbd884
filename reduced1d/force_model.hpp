// Force-driven wave: the spatial model (right-hand side, residual, Newton-matrix Jacobians).
//
// The conserved variable is the cross-section A_i = pi R_i^2 (state a_i = A_i / (pi R0^2)):
// the tube volume h sum A_i is then a LINEAR function of the state, which BDF preserves
// exactly, so d/dt(volume) = Q_rear - Q_front holds to solver tolerance at every step.
// Without wall inertia (CVODE BDF up to order 5, exact Jacobian = tridiagonal + one rank-1
// term per held segment, band LU + Sherman-Morrison-Woodbury):
//   p_i = C1 (R_i - R0) + q_i,   Q_j = -(p_j - p_{j-1}) / r_j  (p = 0 beyond both ends),
//   dA_i/dt = (Q_i - Q_{i+1}) / h,   q_i = own law(R_i) + sum_k f_ik held law(Rbar_k).
// With wall inertia or the short-wave traction (IDA, index-1 DAE in (a_i, V_i, p_i, phi_ij)
// interleaved per cell):
//   A_i' = 2 pi R_i V_i,   m V_i' = p_i - C1 (R_i - R0) - q_i - T_i,   A_i' + (Q_{i+1} - Q_i)/h = 0
// (band Jacobian analytic with the segment laws frozen, plus the same rank-1 segment terms).
// Both carry the swimmer/flux integrals D, X, V_rear, V_front (and the lab-frame end volumes)
// as extra differential states.
// Force-free model (default): p_i is the transmural pressure Pi_i = p_in - p_out. Confined:
// the lumen fluxes come from the lumen/annulus/free-pipe system of outer_flow.hpp, which also
// gives U and Q_tot (global couplings: two more rank-1 terms in the Newton matrix; four with the
// calibrated end junction, whose closure adds the end points' transmural pressures).
// Unbounded: p_out = 0, the lumen fluxes are local as above and U is the slender-body
// average of the induced axial flow (it does not feed back into the radii).
// State scaling: A/(pi R0^2), V/(R0/T_s), p/(C1 R0), D/D_s, X/X_s, V/(pi R0^2 L).
//
// Actuation of cell i: q_i = law_i(R_i) + sum_k f_ik qs_k(Rbar_k), where law_i is the cell's
// own law (active, idle, recovery), qs_k the law of a held segment k on its length-weighted
// mean radius Rbar_k = sum_i f_ik R_i / W_k, and f_ik the length fraction of cell i in
// segment k. An open end takes the actuation of its end cell at its own radius (quasi-static:
// C1 (R_b - R0) + q = 0), so a held end segment moves the end radius with qs_k.
//
// Three kinds of data, kept apart:
//   ForceModel     configuration, layout of the state vector, scalings (fixed), and the
//                  actuation laws of the current protocol state (set_actuation);
//   ModelState     the model at one state y: radii, pressures, actuation, fluxes, U, and the
//                  outer-flow workspace that computes them (unpack, fluxes);
//   Linearisation  the flux sensitivities at one state (linearise), the input of the
//                  Jacobians (jacobian, residual_low_rank, ida_band).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include <sundials/sundials_matrix.h>

#include "reduced1d/discretisation.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/outer_flow.hpp"
#include "reduced1d/protocol.hpp"

namespace swim::reduced1d::detail {

/// The model at one state y (filled by ForceModel::unpack and ForceModel::fluxes).
struct ModelState {
  std::vector<double> R, V, p;        ///< cell radii [m], wall velocities [m/s], pressures [Pa]
  std::vector<double> q, dq;          ///< total actuation and d(own law)/dR per cell
  std::vector<double> Rbar, qs, dqs;  ///< per segment (only where a segment law is held)
  double Rb0 = 0, RbL = 0;            ///< end radii
  /// calibrated wall law only: w(R_i), dw/dR per cell, and d Rb / d qs of each end (the
  /// linear law: -1 / C1)
  std::vector<double> wv, dw;
  double dRb0 = 0, dRbL = 0;
  std::vector<double> r, Q;           ///< face resistances and fluxes (faces j = 0..N)
  std::vector<double> cond;           ///< dQ_j / d(-dPi_j): 1 / r_j, or 1 / (r_in + r_out) when confined
  double U = 0;                       ///< swimmer velocity at the last fluxes() [m/s]
  bool geometry_ok = true;            ///< confined: the wall stays inside the container
  // outer-flow workspace
  std::unique_ptr<outer::ConfinedSystem> sys;  ///< confined outer flow (its last geometry is cached)
  std::vector<double> Rpt, Pipt, sigma, rho, u_ind, pl;
  std::vector<double> Vpt;  ///< the wall velocity at the points (the calibrated junction's rim)
};

/// Flux sensitivities at one state: dQ_j/dR_{j-1} (QL[j]) and dQ_j/dR_j (QR[j]), through the
/// pressures' own-law dependence (with_pressure) and the geometry (resistances; confined:
/// lumen and annulus coefficients at fixed U and Q_tot); Qb0 = dQ_0/dRb0, QbL = dQ_N/dRbL.
/// Confined: also the geometric and pressure partials of the two closure residuals g1
/// (periodicity) and g2 (force) per interval (ga, gb, gpi), and the inverse Gi of their 2 x 2
/// matrix in (W, U).
struct Linearisation {
  explicit Linearisation(const ModelState& s) : at(s) {}
  const ModelState& at;
  std::vector<double> QL, QR;
  double Qb0 = 0, QbL = 0;
  std::vector<double> g1a, g1b, g1pi, g2a, g2b, g2pi;  // confined only
  double Gi[2][2] = {{0, 0}, {0, 0}};                  // confined only
  // the calibrated junction: the end rows g3 (rear), g4 (front) per interval (nonzero on the
  // end intervals), and the inverse of the 4 x 4 in (W, U, Pi_0, Pi_L)
  std::vector<double> g3a, g3b, g3pi, g4a, g4b, g4pi;
  double Gi4[4][4] = {};
};

/// Where a Jacobian's band entries go: band(i, j, v) for the entry (i, j). The Jacobians are
/// instantiated (force_model.cpp) for the two integrators' sinks below, inlined into them,
/// and for a general BandSink (the tests).
using BandSink = std::function<void(int, int, double)>;

/// CVODE: a tridiagonal Jacobian stored by rows, rows[3 i + 1 + (j - i)] = J(i, j) (entries
/// outside the n x n matrix are dropped).
struct TridiagonalRows {
  double* rows;
  long n;
  void operator()(int i, int j, double v) const {
    if (i >= 0 && j >= 0 && i < n && j < n) rows[3 * std::size_t(i) + 1 + (j - i)] = v;
  }
};

/// IDA: adds each entry to a SUNDIALS band matrix.
struct AddToBandMatrix {
  SUNMatrix J;
  void operator()(int i, int j, double v) const;
};

struct ForceModel {
  // ---- configuration (fixed)
  // The wall law enters as w(R_i) in place of C1 (R_i - R0) and dw/dR in place of C1 (its
  // value at each cell: wall_slope); with the linear law the expressions are the linear
  // tier's own.
  int N;
  double L, h, R0, C1, m, mu;
  WallLaw wall;  // the static wall law (linear C1 (R - R0) unless wall.law)
  bool inertia, flow_closure;
  bool force_free, confined;  // force-free model; confined outer flow
  double a_in, a_out;
  double Rc_eff, period;      // container (confined outer flow)
  disc::BalanceCoefficients bal;
  AbsKQuadrature tq;   // short-wave traction: |k| quadrature (empty without it)
  int J;               // traction fields per cell (tq nodes)
  // Axial bending D d^4R/dz^4 (P.wall.D_axial > 0): one more algebraic unknown per cell, the
  // scaled curvature kappa_i = (R_{i+1} - 2 R_i + R_{i-1}) / R0 of the interior cells (0 at
  // the two end cells), at offset ik of the cell; the wall row gains
  // (D R0 / h^4) (kappa_{i-1} - 2 kappa_i + kappa_{i+1}), the gradient of the bending energy
  // sum_i (D/2) (R0 kappa_i / h^2)^2 2 pi R0 h (free ends: no moment, no shear).
  double D_axial;
  bool bending;
  // The calibrated end junction (P.swimmer.end_junction, confined): the end points' transmural
  // pressures are closure unknowns and the rims' thrust follows the wall velocities, so it
  // runs on the IDA path (V an unknown) even without the traction.
  bool junction;
  // The open ends' half cells conduct as drainage layers (disc::drainage_resistance).
  bool drainage_ends = false;
  // The end points' radii follow the cells beside them, Rb = end_w0 R_end + end_w1 R_next: the
  // bending wall's straight continuation (1.5, -0.5) or the continued open end (1, 0); else they
  // are the static radii of the end segments' actuation.
  bool ends_follow_cells = false;
  double end_w0 = 1.5, end_w1 = -0.5;
  bool dae;            // IDA path: wall inertia, short-wave traction, axial bending or the junction
  // Unbounded: U does not feed back into the radii. With velocity_quadrature the right-hand
  // side leaves it out (X and the U parts of the lab-frame volumes are then integrated along
  // the accepted steps by the event loop) and fluxes() computes it only when asked to.
  bool velocity_quadrature = false;
  std::vector<double> zc, faces;  // unbounded: cell centres and faces

  // ---- layout of the state vector
  int stride;          // unknowns per cell: 1 (a) or 3 + J [+ 1] (a, V, p, phi_0..phi_{J-1} [, kappa])
  int ik = 0;          // offset of kappa in a cell (bending only)
  double bend_c = 0;   // D R0 / h^4, Pa per unit scaled curvature
  int band_mu = 0, band_ml = 0;  // IDA band of the interleaved layout
  int iD, iX, iVr, iVf, iVrl, iVfl, n;  // extras and total size

  // ---- scalings
  double T_s, D_s, X_s, V_s, Vel_s, P_s;
  std::vector<double> tr_s2, tr_c;  // (s_j h)^2 and 4 mu c_j Vel_s / P_s (per scaled phi_j)
  std::vector<double> tr_w;         // 1 / ((s_j h)^2 + 4), the scale of the field rows
  std::vector<double> tr_g;         // the fields' ghost factors beyond an open end (1: mirror)
  double tr_beta = 0.0;             // model1d.short_wave_traction_end
  double tr_csum = 0;               // sum_j tr_c[j]

  // ---- actuation laws of the current protocol state (set_actuation)
  std::vector<ProtocolMachine::CellLaw> law;
  std::vector<const ActuationLaw*> seg_law;
  std::vector<int> seg_a, seg_b;
  std::vector<double> frac, seg_w;
  std::vector<int> seg_first, seg_last;
  int nseg = 0;
  bool end0_seg = false, endL_seg = false;  // end radius follows a segment law
  double Rb0_static, RbL_static;            // end radii under pure cell laws

  /// `step_velocity`: the unbounded model's U by quadrature along the accepted steps
  /// (velocity_quadrature) rather than in every right-hand side.
  explicit ForceModel(const Params& P, bool step_velocity = false);

  /// A state sized for this model (radii at R0, no actuation).
  ModelState make_state() const;

  /// Install the actuation laws of the current protocol state.
  void set_actuation(const ProtocolMachine& mc, const std::vector<ProtocolMachine::CellLaw>& laws,
                     const std::vector<const ActuationLaw*>& seg_laws);

  /// Extreme end radii the current laws can produce (for the collapse check at a switch; a
  /// bending wall's ends and the continued open ends follow the wall, and
  /// EventLoop::check_end_radii checks a bending wall's segments).
  void end_radius_range(double& lo0, double& loL) const;

  /// Radii (and V, p) from the scaled state; p from the tube law without inertia.
  /// Returns false if a radius is not positive and finite.
  bool unpack(const double* y, ModelState& s) const;

  /// Face resistances and fluxes (faces j = 0..N at z = j h; p = 0 at both ends), and the
  /// swimmer velocity U of the force-free model (with velocity_quadrature only when
  /// `want_velocity`). `derivatives`: also the confined system's point derivatives.
  void fluxes(ModelState& s, bool derivatives = false, bool want_velocity = true) const;

  /// Swimmer integrals over the points {0, z_i, L} with radii {Rb0, R_i, RbL}.
  disc::PressureIntegrals integrals(const ModelState& s) const;

  double energy(const ModelState& s) const;
  /// The wall's elastic energy at cell radii R (the static law and the axial bending), J.
  double wall_energy(const double* R) const;

  /// Extras' derivatives (scaled) from the state's R, p, Q: dd = (D, X, V_rear, V_front,
  /// V_rear_lab, V_front_lab); W_out the swimmer velocity.
  void extras(const ModelState& s, const double* y, double* dd, double* W_out = nullptr) const;

  /// End pressures, total flux and force split at the state's last fluxes() (force-free model).
  void end_state(ModelState& s, Sample& out) const;

  /// Right-hand side without inertia (CVODE). Nonzero: recoverable failure.
  int rhs(const double* y, double* yd, ModelState& s) const;

  /// Residual of the IDA path (wall inertia and/or short-wave traction). Nonzero: recoverable.
  int res(const double* y, const double* yp, double* F, ModelState& s) const;

  /// unpack(y), fluxes with derivatives and the flux sensitivities at y (through the
  /// pressures' own-law dependence when `with_pressure`, the CVODE right-hand side; without
  /// it for the IDA residual, whose pressures are unknowns).
  Linearisation linearise(const double* y, ModelState& s, bool with_pressure) const;

  /// Exact Jacobian of rhs() at the linearisation (with_pressure): the band part into
  /// `band` (|i - j| <= 1) and the rank-1 segment terms into Ul/Vt (column-major n x rank,
  /// returns the rank). Entries of D and X with respect to the radii are outside the band
  /// and left out (they do not feed back into the areas).
  template <class Band>
  int jacobian(const Linearisation& lin, const Band& band, std::vector<double>& Ul, std::vector<double>& Vt) const;

  /// Band part of the IDA Newton matrix dF/dy + cj dF/dy' at (y, yp), analytic, with the
  /// segment actuation, the end radii and the confined closure (W, U) held (they enter as the
  /// low-rank terms of residual_low_rank, at the same linearisation, without pressure).
  /// Rows of D, X and the lab-frame volumes keep their own derivative (and the paper
  /// balance's D-X block): their dependence on the cells does not feed back. `band(i, j, v)`
  /// adds v at (i, j).
  template <class Band>
  void ida_band(const Linearisation& lin, const double* y, double cj, const Band& band) const;

  /// Rank-1 terms of the IDA residual Jacobian dF/dy at the linearisation (without
  /// pressure): one per held segment, and with the confined outer flow the two closure terms
  /// dF/dW (dW/dy)^T + dF/dU (dU/dy)^T, d(W, U)/dy = -G^{-1} dg/dy. Same layout as jacobian().
  int residual_low_rank(const Linearisation& lin, std::vector<double>& Ul, std::vector<double>& Vt) const;

 /// dw/dR of cell i at the state (C1 for the linear law).
  double wall_slope(const ModelState& s, int i) const { return wall.law ? s.dw[i] : C1; }
  /// d Rb / d qs of the left (right) end: -1 / w'(Rb).
  double end_sensitivity(const ModelState& s, bool right) const {
    return wall.law ? (right ? s.dRbL : s.dRb0) : -1.0 / C1;
  }

 private:
  /// d r / d a and d r / d b for the resistance r(d, a, b) of disc::resistance.
  void dresistance(double d, double a, double b, double& ra, double& rb) const;
  /// The same for interval j (0..N): the drainage layer's (disc::drainage_dresistance) at the
  /// two open ends when drainage_ends, else dresistance.
  void interval_dresistance(int j, double d, double a, double b, double& ra, double& rb) const;
  void flux_sensitivities(Linearisation& s, bool with_pressure) const;

  /// Row scalings of the IDA residual (scaled state): cu in F_a = a' - cu R V; cv, the
  /// coefficient of (C1 (R - R0) + q + traction - p) in the wall row, 1 / (m Vel_s) with
  /// inertia (F_V = V' + cv (...)) and 1 / P_s without (an algebraic row); cp the continuity
  /// row's; A0 = pi R0^2.
  struct IdaRows {
    double cu, cv, cp, A0;
  };
  IdaRows ida_rows() const;
};

}  // namespace swim::reduced1d::detail
