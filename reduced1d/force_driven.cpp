// Force-driven wave: the wall radius evolves under the actuation protocol.
//
// The conserved variable is the cross-section A_i = pi R_i^2 (state a_i = A_i / (pi R0^2)):
// the tube volume h sum A_i is then a LINEAR function of the state, which BDF preserves
// exactly, so d/dt(volume) = Q_rear - Q_front holds to solver tolerance at every step.
// Without wall inertia (CVODE BDF up to order 5, exact Jacobian = tridiagonal + one rank-1
// term per held segment, band LU + Sherman-Morrison-Woodbury):
//   p_i = C1 (R_i - R0) + q_i,   Q_j = -(p_j - p_{j-1}) / r_j  (p = 0 beyond both ends),
//   dA_i/dt = (Q_i - Q_{i+1}) / h,   q_i = own law(R_i) + sum_k f_ik held law(Rbar_k).
// With wall inertia (IDA, index-1 DAE in (a_i, V_i, p_i) interleaved per cell):
//   A_i' = 2 pi R_i V_i,   m V_i' = p_i - C1 (R_i - R0) - q_i,   A_i' + (Q_{i+1} - Q_i)/h = 0
// (band Jacobian by central differences with the segment laws frozen, plus the same rank-1
// segment terms, same solver).
// Both carry the swimmer/flux integrals D, X, V_rear, V_front (and the lab-frame end volumes)
// as extra differential states.
// Force-free model (default): p_i is the transmural pressure Pi_i = p_in - p_out. Confined:
// the lumen fluxes come from the lumen/annulus/free-pipe system of outer_flow.hpp, which also
// gives U and Q_tot (global couplings: two more rank-1 terms in the Newton matrix).
// Unbounded: p_out = 0, the lumen fluxes are local as above and U is the slender-body
// average of the induced axial flow (it does not feed back into the radii).
// State scaling: A/(pi R0^2), V/(R0/T_s), p/(C1 R0), D/D_s, X/X_s, V/(pi R0^2 L).
#include <Eigen/Dense>
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <ida/ida.h>
#include <ida/ida_ls.h>
#include <sunmatrix/sunmatrix_band.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "reduced1d/discretisation.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/linear_solvers.hpp"
#include "reduced1d/outer_flow.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/sundials.hpp"

namespace swim::reduced1d::detail {

namespace {

using disc::pi;

/// Maximum BDF order of CVODE and IDA (docs/reduced1d.md, "Integrator settings").
constexpr int kMaxOrder = 5;
/// First step after a protocol switch as a fraction of the step in use before it.
constexpr double kRestartStepFraction = 1e-2;
/// Steps between refreshes of the Jacobian and of the Newton matrix (CVODE).
constexpr int kJacobianAge = 5;

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

// ---------------------------------------------------------------------------------------
// Spatial model shared by both integrators.
//
// Actuation of cell i: q_i = law_i(R_i) + sum_k f_ik qs_k(Rbar_k), where law_i is the cell's
// own law (active, idle, recovery), qs_k the law of a held segment k on its length-weighted
// mean radius Rbar_k = sum_i f_ik R_i / W_k, and f_ik the length fraction of cell i in
// segment k. An open end takes the actuation of its end cell at its own radius (quasi-static:
// C1 (R_b - R0) + q = 0), so a held end segment moves the end radius with qs_k.
//
// Jacobian of the inertia-free right-hand side f(y): tridiagonal part (own laws, fluxes,
// V_rear/V_front, D-X block) plus one rank-1 term U_k V_k^T per held segment (the segment
// law couples every cell of the segment). jacobian() fills both exactly.
struct ForceModel {
  int N;
  double L, h, R0, C1, m, mu;
  bool inertia, flow_closure;
  bool force_free, confined;  // force-free model; confined outer flow
  double a_in, a_out;
  disc::BalanceCoefficients bal;
  AbsKQuadrature tq;   // short-wave traction: |k| quadrature (empty without it)
  int J;               // traction fields per cell (tq nodes)
  bool dae;            // IDA path: wall inertia or short-wave traction
  int stride;          // unknowns per cell: 1 (a) or 3 + J (a, V, p, phi_0..phi_{J-1})
  int band_mu = 0, band_ml = 0;  // IDA band of the interleaved layout
  std::vector<double> tr_s2, tr_c;  // (s_j h)^2 and 4 mu c_j Vel_s / P_s (per scaled phi_j)
  double tr_csum = 0;               // sum_j tr_c[j]
  int iD, iX, iVr, iVf, iVrl, iVfl, n;  // extras and total size
  double T_s, D_s, X_s, V_s, Vel_s, P_s;
  // actuation laws (fixed between protocol events)
  std::vector<ProtocolMachine::CellLaw> law;
  std::vector<const ActuationLaw*> seg_law;
  std::vector<int> seg_a, seg_b;
  std::vector<double> frac, seg_w;
  std::vector<int> seg_first, seg_last;
  int nseg = 0;
  bool end0_seg = false, endL_seg = false;  // end radius follows a segment law
  double Rb0_static, RbL_static;
  // state-dependent quantities at the last unpack
  std::vector<double> q, dq;          // total actuation and d(own law)/dR per cell
  std::vector<double> Rbar, qs, dqs;  // per segment (only where seg_law != nullptr)
  double Rb0, RbL;
  // workspace
  std::vector<double> R, V, p, r, Q;
  std::vector<double> cond;  // dQ_j / d(-dPi_j): 1 / r_j, or 1 / (r_in + r_out) when confined
  // force-free outer flow
  std::unique_ptr<outer::ConfinedSystem> sys;
  std::vector<double> Rpt, Pipt, zc, faces, sigma, rho, u_ind;
  double U = 0;           // swimmer velocity at the last fluxes() [m/s]
  bool geometry_ok = true;
  // Unbounded: U does not feed back into the radii. With velocity_quadrature the right-hand
  // side leaves it out (X and the U parts of the lab-frame volumes are then integrated along
  // the accepted steps, VelocityQuadrature below) and fluxes() computes it only when
  // want_velocity is set.
  bool velocity_quadrature = false;
  bool want_velocity = true;

  explicit ForceModel(const Params& P)
      : N(P.numerics.cells),
        L(P.geometry.L),
        h(P.geometry.L / P.numerics.cells),
        R0(P.geometry.R0),
        C1(P.wall.C1),
        m(P.wall.m),
        mu(P.fluid.mu),
        inertia(P.wall.inertia),
        flow_closure(P.swimmer.closure == Closure::Flow),
        force_free(P.swimmer.model == SwimmerModel::ForceFree),
        confined(P.swimmer.model == SwimmerModel::ForceFree && P.swimmer.outer == OuterFlow::Confined),
        a_in(P.swimmer.model == SwimmerModel::ForceFree ? P.swimmer.a_in : 0.0),
        a_out(P.swimmer.model == SwimmerModel::ForceFree ? P.swimmer.a_out : 0.0),
        bal(disc::BalanceCoefficients::from(P)),
        tq(P.swimmer.model == SwimmerModel::ForceFree && P.swimmer.short_wave_traction
               ? abs_k_quadrature(P.geometry.L, P.geometry.L / P.numerics.cells)
               : AbsKQuadrature{}),
        J(int(tq.s.size())),
        dae(P.wall.inertia || J > 0),
        stride(dae ? 3 + J : 1),
        Rb0_static(R0),
        RbL_static(R0),
        q(N, 0.0),
        dq(N, 0.0),
        Rb0(R0),
        RbL(R0),
        R(N),
        V(N, 0.0),
        p(N),
        r(N + 1),
        Q(N + 1),
        cond(N + 1, 0.0) {
    // Layout [V_rear, cell 0, ..., cell N-1, V_front, D, X]: V_rear/V_front sit next to the
    // end cells they depend on, so their couplings are inside the band of the Newton matrix
    // and BDF keeps the linear invariant h sum A_i - V_rear + V_front exactly.
    iVr = 0;
    iVf = 1 + stride * N;
    iD = iVf + 1;
    iX = iVf + 2;
    iVrl = iVf + 3;
    iVfl = iVf + 4;
    n = iVf + 5;
    if (force_free) {
      std::vector<double> d(N + 1, h);
      d[0] = d[N] = 0.5 * h;
      Rpt.assign(N + 2, R0);
      Pipt.assign(N + 2, 0.0);
      if (confined) {
        sys = std::make_unique<outer::ConfinedSystem>(N + 2, d, mu, a_in, a_out, P.container.radius_eff,
                                                      P.container.period, L);
      } else {
        zc.resize(N);
        faces.resize(N + 1);
        for (int i = 0; i < N; ++i) zc[i] = (i + 0.5) * h;
        for (int j = 0; j <= N; ++j) faces[j] = j * h;
        sigma.assign(N, 0.0);
        rho.assign(N, R0);
      }
    }
    T_s = 0.1 * relaxation_time(P);
    // Band of the interleaved (a, V, p, phi) layout: the continuity row of cell i reaches
    // a_{i-1} (stride + 2 below) and p_{i+1} (stride above); the traction row phi_{i,j}
    // reaches phi_{i+-1,j} (stride) and V_i of its own cell only. V_rear (first) and V_front
    // stay inside.
    band_mu = stride;
    band_ml = stride + 2;
    const double f_s = bal.per_length ? pi * C1 * R0 * R0 * R0 / L : C1 * R0 * R0 / (2.0 * L);
    D_s = f_s * T_s;
    X_s = force_free ? R0 : D_s * T_s / (bal.m_eff + bal.c_ext * T_s);
    V_s = pi * R0 * R0 * L;
    Vel_s = R0 / T_s;
    P_s = C1 * R0;
    for (int j = 0; j < J; ++j) {
      tr_s2.push_back(tq.s[j] * h * tq.s[j] * h);
      tr_c.push_back(4.0 * mu * tq.c[j] * Vel_s / P_s);
      tr_csum += tr_c.back();
    }
  }

  /// Install the actuation laws of the current protocol state.
  void set_actuation(const ProtocolMachine& mc, const std::vector<ProtocolMachine::CellLaw>& laws,
                     const std::vector<const ActuationLaw*>& seg_laws) {
    law = laws;
    seg_law = seg_laws;
    nseg = int(seg_law.size());
    seg_a = mc.seg_a();
    seg_b = mc.seg_b();
    frac = mc.frac();
    seg_w = mc.seg_weight();
    seg_first.resize(nseg);
    seg_last.resize(nseg);
    for (int k = 0; k < nseg; ++k) {
      seg_first[k] = mc.seg_first(k);
      seg_last[k] = mc.seg_last(k);
    }
    Rbar.assign(nseg, 0.0);
    qs.assign(nseg, 0.0);
    dqs.assign(nseg, 0.0);
    // The end cells lie inside the first/last segment (h <= shortest segment): pure laws.
    end0_seg = seg_law[seg_a[0]] != nullptr;
    endL_seg = seg_law[seg_a[N - 1]] != nullptr;
    Rb0_static = law[0].a->rest_radius(R0, C1);
    RbL_static = law[N - 1].a->rest_radius(R0, C1);
    Rb0 = Rb0_static;
    RbL = RbL_static;
  }

  /// Extreme end radii the current laws can produce (for the collapse check at a switch).
  void end_radius_range(double& lo0, double& loL) const {
    lo0 = Rb0_static;
    loL = RbL_static;
    if (end0_seg) lo0 = law[0].a->rest_radius(R0, C1, seg_law[seg_a[0]]->operator()(1e300));
    if (endL_seg) loL = law[N - 1].a->rest_radius(R0, C1, seg_law[seg_a[N - 1]]->operator()(1e300));
  }

  /// Unpack radii (and V, p) from the scaled state; p from the tube law without inertia.
  /// Returns false if a radius is not positive and finite.
  bool unpack(const double* y) {
    bool ok = true;
    for (int i = 0; i < N; ++i) {
      const double a = y[1 + stride * i];
      if (!(a > 0) || !std::isfinite(a)) ok = false;
    }
    // (a separate pass so that the square roots vectorise: -fno-math-errno, CMakeLists.txt)
    double* Rd = R.data();
    if (stride == 1) {
      const double* a = y + 1;
      for (int i = 0; i < N; ++i) Rd[i] = R0 * std::sqrt(std::max(a[i], 1e-300));
    } else {
      for (int i = 0; i < N; ++i) Rd[i] = R0 * std::sqrt(std::max(y[1 + stride * i], 1e-300));
    }
    for (int k = 0; k < nseg; ++k) {
      if (!seg_law[k]) continue;
      double s = 0;
      for (int i = seg_first[k]; i <= seg_last[k]; ++i) {
        if (seg_a[i] == k) s += frac[i] * R[i];
        if (seg_b[i] == k && seg_b[i] != seg_a[i]) s += (1.0 - frac[i]) * R[i];
      }
      Rbar[k] = s / seg_w[k];
      qs[k] = seg_law[k]->eval(Rbar[k], dqs[k]);
    }
    if (end0_seg) Rb0 = law[0].a->rest_radius(R0, C1, qs[seg_a[0]]);
    if (endL_seg) RbL = law[N - 1].a->rest_radius(R0, C1, qs[seg_a[N - 1]]);
    for (int i = 0; i < N; ++i) {
      const double Ri = R[i];
      double qi = law[i].eval(Ri, dq[i]);
      if (seg_law[seg_a[i]]) qi += frac[i] * qs[seg_a[i]];
      if (seg_b[i] != seg_a[i] && seg_law[seg_b[i]]) qi += (1.0 - frac[i]) * qs[seg_b[i]];
      q[i] = qi;
      if (dae) {
        V[i] = Vel_s * y[1 + stride * i + 1];
        p[i] = P_s * y[1 + stride * i + 2];
      } else {
        p[i] = C1 * (Ri - R0) + qi;
      }
    }
    return ok;
  }

  /// Face resistances and fluxes (faces j = 0..N at z = j h; p = 0 at both ends), and the
  /// swimmer velocity U of the force-free model.
  void fluxes(bool derivatives = false) {
    if (confined) {
      Rpt[0] = Rb0;
      Rpt[N + 1] = RbL;
      for (int i = 0; i < N; ++i) Rpt[i + 1] = R[i], Pipt[i + 1] = p[i];
      geometry_ok = sys->geometry(Rpt.data(), derivatives);
      if (!geometry_ok) {
        std::fill(Q.begin(), Q.end(), std::nan(""));
        U = std::nan("");
        return;
      }
      sys->transmural(Pipt.data());
      for (int j = 0; j <= N; ++j) {
        Q[j] = sys->Q_in[j];
        r[j] = sys->k[j].rl;
        cond[j] = sys->w[j];
      }
      U = sys->U;
      return;
    }
    r[0] = disc::resistance(mu, 0.5 * h, Rb0 - a_in, R[0] - a_in);
    Q[0] = -p[0] / r[0];
    for (int j = 1; j < N; ++j) {
      r[j] = disc::resistance(mu, h, R[j - 1] - a_in, R[j] - a_in);
      Q[j] = -(p[j] - p[j - 1]) / r[j];
    }
    r[N] = disc::resistance(mu, 0.5 * h, R[N - 1] - a_in, RbL - a_in);
    Q[N] = p[N - 1] / r[N];
    for (int j = 0; j <= N; ++j) cond[j] = 1.0 / r[j];
    if (force_free && (!velocity_quadrature || want_velocity)) {  // unbounded: slender-body average
      for (int i = 0; i < N; ++i) {
        sigma[i] = (Q[i] - Q[i + 1]) / h;  // d(pi R^2)/dt per unit length
        rho[i] = R[i] + a_out;
      }
      U = outer::slender_velocity(zc, faces, sigma, -Q[0], Q[N], rho, L, mu, u_ind);
    }
  }

  /// d r / d a and d r / d b for the resistance r(d, a, b) of disc::resistance.
  void dresistance(double d, double a, double b, double& ra, double& rb) const {
    const double c = (8.0 * mu / pi) * d / 3.0;
    const double a2 = a * a, b2 = b * b, ab = a * b;
    const double a3b3 = a2 * a * b2 * b;
    ra = -c * (a2 + 2.0 * ab + 3.0 * b2) / (a3b3 * a);
    rb = -c * (b2 + 2.0 * ab + 3.0 * a2) / (a3b3 * b);
  }

  /// Swimmer integrals over the points {0, z_i, L} with radii {Rb0, R_i, RbL}.
  disc::PressureIntegrals integrals() const {
    disc::PressureIntegrals s;
    for (int j = 0; j <= N; ++j) {
      const double a = (j == 0) ? Rb0 : R[j - 1];
      const double b = (j == N) ? RbL : R[j];
      const double dp = flow_closure ? -r[j] * Q[j] : C1 * (b - a);
      s.I1 += dp * disc::mean_R1(a, b);
      s.I2 += dp * disc::mean_R2(a, b);
      s.I4 += dp * disc::mean_R4(a, b);
    }
    return s;
  }

  double energy() const {
    double e = disc::elastic_energy(R.data(), N, R0, C1, h);
    if (inertia) {
      double k = 0;
      for (int i = 0; i < N; ++i) k += V[i] * V[i];
      e += 0.5 * m * k * 2.0 * pi * R0 * h;
    }
    return e;
  }

  /// Extras' derivatives (scaled) from the current R, p, Q: dd = (D, X, V_rear, V_front,
  /// V_rear_lab, V_front_lab).
  void extras(const double* y, double* dd, double* W_out = nullptr) const {
    double W = U;
    if (force_free) {
      dd[0] = 0.0;
    } else {
      const auto I = integrals();
      W = bal.velocity(bal.thrust_term(I), y[iD] * D_s, y[iX] * X_s);
      dd[0] = bal.drag_integrand(I) / D_s;
    }
    if (velocity_quadrature) W = 0.0;  // integrated outside the ODE (VelocityQuadrature)
    dd[1] = W / X_s;
    dd[2] = Q[0] / V_s;
    dd[3] = Q[N] / V_s;
    // lab frame: the lumen fluid crossing the moving end sections, Q + W pi R_end^2
    dd[4] = (Q[0] + W * pi * Rb0 * Rb0) / V_s;
    dd[5] = (Q[N] + W * pi * RbL * RbL) / V_s;
    if (W_out) *W_out = velocity_quadrature ? U : W;
  }

  /// End pressures, total flux and force split at the last fluxes() (force-free model).
  void end_state(Sample& s) {
    if (!force_free) return;
    if (confined) {
      sys->lumen_pressure(pl_);
      s.p_rear = pl_[0];
      s.p_front = pl_[N + 1];
      s.Q_total = sys->Q_tot;
    }
    // control volume on the lumen: pi [R(0)^2 p(0) - R(L)^2 p(L)]; the outer flow balances it
    s.F_lumen = pi * (Rb0 * Rb0 * s.p_rear - RbL * RbL * s.p_front);
    s.F_outer = -s.F_lumen;
  }
  std::vector<double> pl_;

  void extras_into(const double* y, double* yd) const {
    double d[6];
    extras(y, d);
    yd[iD] = d[0], yd[iX] = d[1], yd[iVr] = d[2], yd[iVf] = d[3], yd[iVrl] = d[4], yd[iVfl] = d[5];
  }

  // Right-hand side without inertia (CVODE).
  int rhs(const double* y, double* yd) {
    if (!unpack(y)) return 1;  // recoverable: the integrator retries with a smaller step
    want_velocity = false;
    fluxes();
    want_velocity = true;
    const double c = 1.0 / (h * pi * R0 * R0);
    if (!geometry_ok) return 1;
    for (int i = 0; i < N; ++i) yd[1 + i] = (Q[i] - Q[i + 1]) * c;
    extras_into(y, yd);
    for (int k = 0; k < n; ++k)
      if (!std::isfinite(yd[k])) return 1;
    return 0;
  }

  /// Flux sensitivities at the current unpack/fluxes: dQ_j/dR_{j-1} (QL[j]) and dQ_j/dR_j (QR[j]),
  /// through the pressures' own-law dependence (with_pressure) and the geometry (resistances;
  /// confined: lumen and annulus coefficients at fixed U and Q_tot); Qb0 = dQ_0/dRb0,
  /// QbL = dQ_N/dRbL. Confined: also the geometric and pressure partials of the two closure
  /// residuals g1 (periodicity) and g2 (force) per interval (ga, gb, gpi).
  struct FluxSens {
    std::vector<double> QL, QR;
    double Qb0 = 0, QbL = 0;
    std::vector<double> g1a, g1b, g1pi, g2a, g2b, g2pi;  // confined only
  };
  FluxSens sens_;           // Jacobian workspace (no allocation after the first call)
  std::vector<double> dQ_;
  void flux_sensitivities(FluxSens& s, bool with_pressure) const {
    s.QL.assign(N + 1, 0.0);
    s.QR.assign(N + 1, 0.0);
    // point radii and dPi/dR at the points (ends: Pi = 0 fixed)
    auto Rp = [&](int k) { return k == 0 ? Rb0 : (k == N + 1 ? RbL : R[k - 1]); };
    auto dPi = [&](int k) { return (k == 0 || k == N + 1 || !with_pressure) ? 0.0 : C1 + dq[k - 1]; };
    if (confined) {
      s.g1a.assign(N + 1, 0.0), s.g1b.assign(N + 1, 0.0), s.g1pi.assign(N + 1, 0.0);
      s.g2a.assign(N + 1, 0.0), s.g2b.assign(N + 1, 0.0), s.g2pi.assign(N + 1, 0.0);
      const double Qt = sys->Q_tot, Uv = sys->U;
      for (int j = 0; j <= N; ++j) {
        const double a = Rp(j), b = Rp(j + 1), d = (j == 0 || j == N) ? 0.5 * h : h;
        const double dpi = sys->dPi[j];
        const auto& k = sys->k[j];
        const auto &da = sys->point_derivative(j), &db = sys->point_derivative(j + 1);
        double rla, rlb;
        dresistance(d, a - a_in, b - a_in, rla, rlb);
        // Q_in = (ra Qt + c U - dPi) / (rl + ra); t1 = rl Q_in; t2 = -S rl Q_in - S dPi + e U
        const double w = sys->w[j], Qj = sys->Q_in[j];
        auto partial = [&](const outer::AnnulusPoint<double>& dp, double drl, double& dQ, double& d1, double& d2) {
          const double dra = 0.5 * d * dp.rho, dc = 0.5 * d * dp.kappa, dS = 0.5 * dp.S, de = 0.5 * d * dp.e;
          dQ = (dra * Qt + dc * Uv - Qj * (drl + dra)) * w;
          d1 = drl * Qj + k.rl * dQ;
          d2 = -dS * k.rl * Qj - k.S * drl * Qj - k.S * k.rl * dQ - dS * dpi + de * Uv;
        };
        double Qa, Qb;
        partial(da, rla, Qa, s.g1a[j], s.g2a[j]);
        partial(db, rlb, Qb, s.g1b[j], s.g2b[j]);
        s.g1pi[j] = -k.rl * w;        // d t1 / d dPi
        s.g2pi[j] = -k.S * k.ra * w;  // d t2 / d dPi
        // dQ/d Pi_j = +w, dQ/d Pi_{j+1} = -w
        s.QL[j] = Qa + w * dPi(j);
        s.QR[j] = Qb - w * dPi(j + 1);
      }
      s.Qb0 = s.QL[0];
      s.QbL = s.QR[N];
      return;
    }
    for (int j = 0; j <= N; ++j) {
      const double a = Rp(j), b = Rp(j + 1), d = (j == 0 || j == N) ? 0.5 * h : h;
      double ra, rb;
      dresistance(d, a - a_in, b - a_in, ra, rb);
      s.QL[j] = dPi(j) / r[j] - Q[j] / r[j] * ra;
      s.QR[j] = -dPi(j + 1) / r[j] - Q[j] / r[j] * rb;
    }
    s.Qb0 = s.QL[0];
    s.QbL = s.QR[N];
  }

  /// Exact Jacobian of rhs() at y (after rhs-equivalent unpack/fluxes): the band part into
  /// `band(i, j, v)` (|i - j| <= 1) and the rank-1 segment terms into Ul/Vt (column-major n x
  /// rank, returns the rank). Entries of D and X with respect to the radii are outside the band
  /// and left out (they do not feed back into the areas).
  template <class Band>
  int jacobian(const double* y, Band band, std::vector<double>& Ul, std::vector<double>& Vt) {
    unpack(y);
    want_velocity = false;
    fluxes(true);
    want_velocity = true;
    FluxSens& s = sens_;
    flux_sensitivities(s, true);
    const double c = 1.0 / (h * pi * R0 * R0);
    for (int i = 0; i < N; ++i) {
      const double dRda = 0.5 * R0 * R0 / R[i];
      // f_i = c (Q_i - Q_{i+1}): Q_i depends on R_{i-1}, R_i; Q_{i+1} on R_i, R_{i+1}
      band(1 + i, 1 + i, c * (s.QR[i] - s.QL[i + 1]) * dRda);
      if (i > 0) band(1 + i, i, c * s.QL[i] * 0.5 * R0 * R0 / R[i - 1]);
      if (i + 1 < N) band(1 + i, 2 + i, -c * s.QR[i + 1] * 0.5 * R0 * R0 / R[i + 1]);
    }
    band(iVr, 1, s.QR[0] * 0.5 * R0 * R0 / R[0] / V_s);
    band(iVf, iVf - 1, s.QL[N] * 0.5 * R0 * R0 / R[N - 1] / V_s);
    if (!force_free) {  // W = (thrust - D - c_ext X) / m_eff
      band(iX, iD, -D_s / (bal.m_eff * X_s));
      band(iX, iX, -bal.c_ext / bal.m_eff);
    }
    // Confined: Q_in,j = alpha_j W + beta_j U - gamma_j with (W, U) solving g(y, W, U) = 0
    // (periodicity, force; W = Q_tot + U pi Rc^2), so d(W, U)/dy = -G^{-1} dg/dy with G the
    // 2 x 2 of outer::ConfinedSystem. fq, fu: df/dW, df/dU; dgpi: dg/dPi at the cell points.
    double Gi[2][2] = {{0, 0}, {0, 0}};
    if (confined) {
      const auto& G = sys->M;
      const double det = G[0][0] * G[1][1] - G[0][1] * G[1][0];
      Gi[0][0] = G[1][1] / det, Gi[0][1] = -G[0][1] / det, Gi[1][0] = -G[1][0] / det, Gi[1][1] = G[0][0] / det;
      fq_.assign(n, 0.0), fu_.assign(n, 0.0);
      std::vector<double>&al = al_, &be = be_;
      al.resize(N + 1), be.resize(N + 1);
      for (int j = 0; j <= N; ++j) {
        const auto& k = sys->k[j];
        al[j] = k.ra * sys->w[j];
        be[j] = (k.c - sys->A_c * k.ra) * sys->w[j];
      }
      for (int i = 0; i < N; ++i) {
        fq_[1 + i] = c * (al[i] - al[i + 1]);
        fu_[1 + i] = c * (be[i] - be[i + 1]);
      }
      fq_[iVr] = al[0] / V_s, fu_[iVr] = be[0] / V_s;
      fq_[iVf] = al[N] / V_s, fu_[iVf] = be[N] / V_s;
      dg1pi_.assign(N, 0.0), dg2pi_.assign(N, 0.0);
      for (int i = 0; i < N; ++i) {  // point i + 1: right end of interval i, left end of i + 1
        dg1pi_[i] = s.g1pi[i] - s.g1pi[i + 1];
        dg2pi_[i] = s.g2pi[i] - s.g2pi[i + 1];
      }
    }
    // rank-1 terms: d f / d qs_k (per unit segment actuation) times d qs_k / d a
    int rank = 0;
    Ul.clear();
    Vt.clear();
    std::vector<double>& dQ = dQ_;
    dQ.resize(N + 1);
    for (int k = 0; k < nseg; ++k) {
      if (!seg_law[k] || dqs[k] == 0.0) continue;
      std::fill(dQ.begin(), dQ.end(), 0.0);
      const int lo = seg_first[k], hi = seg_last[k];
      auto u = [&](int i) -> double {  // dp_i / dqs_k
        if (i < lo || i > hi) return 0.0;
        double v = 0;
        if (seg_a[i] == k) v += frac[i];
        if (seg_b[i] == k && seg_b[i] != seg_a[i]) v += 1.0 - frac[i];
        return v;
      };
      for (int j = std::max(lo, 0); j <= std::min(hi + 1, N); ++j) {
        if (j == 0) dQ[0] = -u(0) * cond[0];
        else if (j == N) dQ[N] = u(N - 1) * cond[N];
        else dQ[j] = -(u(j) - u(j - 1)) * cond[j];
      }
      if (end0_seg && seg_a[0] == k) dQ[0] += s.Qb0 * (-1.0 / C1);
      if (endL_seg && seg_a[N - 1] == k) dQ[N] += s.QbL * (-1.0 / C1);
      const std::size_t off = Ul.size();
      Ul.resize(off + n, 0.0);
      Vt.resize(off + n, 0.0);
      for (int i = std::max(lo - 1, 0); i <= std::min(hi + 1, N - 1); ++i) Ul[off + 1 + i] = c * (dQ[i] - dQ[i + 1]);
      Ul[off + iVr] = dQ[0] / V_s;
      Ul[off + iVf] = dQ[N] / V_s;
      for (int i = lo; i <= hi; ++i) Vt[off + 1 + i] = dqs[k] * u(i) / seg_w[k] * 0.5 * R0 * R0 / R[i];
      if (confined) {  // the segment load also moves W and U: d(W, U)/dqs_k = -G^{-1} dg/dqs_k
        double g1 = 0, g2 = 0;
        for (int i = lo; i <= hi; ++i) {
          g1 += dg1pi_[i] * u(i);
          g2 += dg2pi_[i] * u(i);
        }
        if (end0_seg && seg_a[0] == k) g1 -= s.g1a[0] / C1, g2 -= s.g2a[0] / C1;
        if (endL_seg && seg_a[N - 1] == k) g1 -= s.g1b[N] / C1, g2 -= s.g2b[N] / C1;
        seg_x_.push_back({-(Gi[0][0] * g1 + Gi[0][1] * g2), -(Gi[1][0] * g1 + Gi[1][1] * g2), off});
      }
      ++rank;
    }
    if (confined) {
      // Two rank-1 terms df/dW (dW/dy)^T + df/dU (dU/dy)^T; dW/dy and dU/dy are the direct
      // dependence on every radius plus the segment chains d(W, U)/dqs_k times the segment rows.
      const std::size_t off = Ul.size();
      Ul.resize(off + 2 * std::size_t(n), 0.0);
      Vt.resize(off + 2 * std::size_t(n), 0.0);
      std::copy(fq_.begin(), fq_.end(), Ul.begin() + off);
      std::copy(fu_.begin(), fu_.end(), Ul.begin() + off + n);
      for (int i = 0; i < N; ++i) {
        const double dRda = 0.5 * R0 * R0 / R[i];
        const double g1 = (s.g1b[i] + s.g1a[i + 1] + dg1pi_[i] * (C1 + dq[i])) * dRda;
        const double g2 = (s.g2b[i] + s.g2a[i + 1] + dg2pi_[i] * (C1 + dq[i])) * dRda;
        Vt[off + 1 + i] = -(Gi[0][0] * g1 + Gi[0][1] * g2);
        Vt[off + n + 1 + i] = -(Gi[1][0] * g1 + Gi[1][1] * g2);
      }
      for (const auto& sx : seg_x_)
        for (int row = 0; row < n; ++row) {
          Vt[off + row] += sx.xw * Vt[sx.off + row];
          Vt[off + n + row] += sx.xu * Vt[sx.off + row];
        }
      seg_x_.clear();
      rank += 2;
    }
    return rank;
  }
  struct SegChain {
    double xw, xu;
    std::size_t off;
  };
  std::vector<SegChain> seg_x_;
  std::vector<double> fq_, fu_, dg1pi_, dg2pi_, al_, be_;  // confined Jacobian workspace

  /// Row scalings of the IDA residual (scaled state): cu in F_a = a' - cu R V; cv, the
  /// coefficient of (C1 (R - R0) + q + traction - p) in the wall row, 1 / (m Vel_s) with
  /// inertia (F_V = V' + cv (...)) and 1 / P_s without (an algebraic row); cp the continuity
  /// row's; A0 = pi R0^2.
  struct IdaRows {
    double cu, cv, cp, A0;
  };
  IdaRows ida_rows() const {
    return {2.0 * Vel_s / (R0 * R0), inertia ? 1.0 / (m * Vel_s) : 1.0 / P_s, 1.0 / (2.0 * pi * R0 * Vel_s),
            pi * R0 * R0};
  }

  // Residual of the IDA path (wall inertia and/or short-wave traction). Per cell
  // (a, V, p, phi_0..phi_{J-1}), phi_j = (s_j h)^2 / ((s_j h)^2 - D2) V in units of Vel_s:
  //   F_a = a' - 2 R V / R0^2,   F_V = [V'] + cv (C1 (R - R0) + q + T - p),
  //   F_p = continuity,          F_phi_j = ((s_j h)^2 (phi_j - V) - D2 phi_j) / ((s_j h)^2 + 4),
  // with T = 4 mu sum_j c_j (V - phi_j) (the traction 2 mu |k| V of each fluid; V - phi_j is
  // the field psi_j = -D2 / ((s_j h)^2 - D2) V of docs/outer-flow-1d.md) and D2 the cell
  // second difference with mirror ends (a uniform wall velocity has no short-wave traction).
  // phi_j rather than psi_j: its row reaches V of its own cell only, which keeps the band
  // of the Newton matrix at stride + 2 below the diagonal instead of 2 stride - 2.
  int res(const double* y, const double* yp, double* F) {
    if (!unpack(y)) return 1;
    want_velocity = false;  // with the velocity quadrature U is integrated along the steps
    fluxes();
    want_velocity = true;
    const auto [cu, cv, cp, A0] = ida_rows();
    const int S = stride;
    for (int i = 0; i < N; ++i) {
      const int k = 1 + S * i;
      double T = tr_csum * y[k + 1];
      for (int j = 0; j < J; ++j) T -= tr_c[j] * y[k + 3 + j];
      F[k] = yp[k] - cu * R[i] * y[k + 1];
      F[k + 1] = (inertia ? yp[k + 1] : 0.0) + cv * (C1 * (R[i] - R0) + q[i] + P_s * T - p[i]);
      F[k + 2] = cp * ((Q[i + 1] - Q[i]) / h + A0 * yp[k]);
      if (J > 0) {
        const int km = i > 0 ? k - S : k, kp = i + 1 < N ? k + S : k;  // mirror ends
        for (int j = 0; j < J; ++j) {
          const double d2p = y[km + 3 + j] - 2.0 * y[k + 3 + j] + y[kp + 3 + j];
          F[k + 3 + j] = (tr_s2[j] * (y[k + 3 + j] - y[k + 1]) - d2p) / (tr_s2[j] + 4.0);
        }
      }
    }
    if (!geometry_ok) return 1;
    double d[6];
    extras(y, d);
    const int idx[6] = {iD, iX, iVr, iVf, iVrl, iVfl};
    for (int k = 0; k < 6; ++k) F[idx[k]] = yp[idx[k]] - d[k];
    for (int k = 0; k < n; ++k)
      if (!std::isfinite(F[k])) return 1;
    return 0;
  }

  /// Band part of the IDA Newton matrix dF/dy + cj dF/dy' at (y, yp), analytic, with the
  /// segment actuation, the end radii and the confined closure (W, U) held (they enter as the
  /// low-rank terms of residual_low_rank, which must be called first at the same y: it leaves
  /// the flux sensitivities this reads). Rows of D, X and the lab-frame volumes keep their own
  /// derivative (and the paper balance's D-X block): their dependence on the cells does not
  /// feed back. `band(i, j, v)` adds v at (i, j).
  template <class Band>
  void ida_band(const double* y, double cj, Band band) const {
    const FluxSens& s = sens_;
    const int S = stride;
    const auto [cu, cv, cp, A0] = ida_rows();
    auto dRda = [&](int i) { return 0.5 * R0 * R0 / R[i]; };
    for (int i = 0; i < N; ++i) {
      const int k = 1 + S * i;
      // F_a = a' - cu R V
      band(k, k, cj - cu * y[k + 1] * dRda(i));
      band(k, k + 1, -cu * R[i]);
      // F_V = [V'] + cv (C1 (R - R0) + q + P_s T - p)
      band(k + 1, k, cv * (C1 + dq[i]) * dRda(i));
      if (inertia) band(k + 1, k + 1, cj);
      if (J > 0) band(k + 1, k + 1, cv * P_s * tr_csum);
      band(k + 1, k + 2, -cv * P_s);
      for (int j = 0; j < J; ++j) band(k + 1, k + 3 + j, -cv * P_s * tr_c[j]);
      // F_p = cp ((Q_{i+1} - Q_i) / h + A0 a'): Q_i on (R_{i-1}, R_i), (p_{i-1}, p_i)
      const double c = cp / h;
      band(k + 2, k, c * (s.QL[i + 1] - s.QR[i]) * dRda(i) + cp * A0 * cj);
      if (i > 0) band(k + 2, k - S, -c * s.QL[i] * dRda(i - 1));
      if (i + 1 < N) band(k + 2, k + S, c * s.QR[i + 1] * dRda(i + 1));
      band(k + 2, k + 2, c * (cond[i + 1] + cond[i]) * P_s);
      if (i > 0) band(k + 2, k + 2 - S, -c * cond[i] * P_s);
      if (i + 1 < N) band(k + 2, k + 2 + S, -c * cond[i + 1] * P_s);
      // F_phi_j = ((s_j h)^2 (phi - V) - D2 phi) / ((s_j h)^2 + 4), mirror ends
      const int nb = (i > 0) + (i + 1 < N);
      for (int j = 0; j < J; ++j) {
        const int row = k + 3 + j;
        const double w = 1.0 / (tr_s2[j] + 4.0);
        band(row, row, (tr_s2[j] + nb) * w);
        band(row, k + 1, -tr_s2[j] * w);
        if (i > 0) band(row, row - S, -w);
        if (i + 1 < N) band(row, row + S, -w);
      }
    }
    // end volumes: F = V' - Q_end / V_s
    band(iVr, iVr, cj);
    band(iVr, 1, -s.QR[0] * dRda(0) / V_s);
    band(iVr, 3, cond[0] * P_s / V_s);
    band(iVf, iVf, cj);
    band(iVf, 1 + S * (N - 1), -s.QL[N] * dRda(N - 1) / V_s);
    band(iVf, 1 + S * (N - 1) + 2, -cond[N] * P_s / V_s);
    for (int i : {iD, iX, iVrl, iVfl}) band(i, i, cj);
    if (!force_free) {  // F_X = X' - W / X_s, W = (thrust - D - c_ext X) / m_eff
      band(iX, iD, D_s / (bal.m_eff * X_s));
      band(iX, iX, bal.c_ext / bal.m_eff);
    }
  }

  /// Rank-1 terms of the IDA residual Jacobian dF/dy (the band part is obtained by difference
  /// quotients with the segment actuation, the end radii and the confined closure (W, U)
  /// frozen): one per held segment, and with the confined outer flow the two closure terms
  /// dF/dW (dW/dy)^T + dF/dU (dU/dy)^T, d(W, U)/dy = -G^{-1} dg/dy. Same layout as jacobian().
  int residual_low_rank(const double* y, std::vector<double>& Ul, std::vector<double>& Vt) {
    unpack(y);
    want_velocity = false;
    fluxes(true);
    want_velocity = true;
    FluxSens& s = sens_;
    flux_sensitivities(s, false);
    const double cv = ida_rows().cv, cp = ida_rows().cp;
    const int S = stride;
    double Gi[2][2] = {{0, 0}, {0, 0}};
    if (confined) {
      const auto& G = sys->M;
      const double det = G[0][0] * G[1][1] - G[0][1] * G[1][0];
      Gi[0][0] = G[1][1] / det, Gi[0][1] = -G[0][1] / det, Gi[1][0] = -G[1][0] / det, Gi[1][1] = G[0][0] / det;
    }
    int rank = 0;
    Ul.clear();
    Vt.clear();
    for (int k = 0; k < nseg; ++k) {
      if (!seg_law[k] || dqs[k] == 0.0) continue;
      const std::size_t off = Ul.size();
      Ul.resize(off + n, 0.0);
      Vt.resize(off + n, 0.0);
      const int lo = seg_first[k], hi = seg_last[k];
      for (int i = lo; i <= hi; ++i) {
        double u = 0;
        if (seg_a[i] == k) u += frac[i];
        if (seg_b[i] == k && seg_b[i] != seg_a[i]) u += 1.0 - frac[i];
        Ul[off + 1 + S * i + 1] = cv * u;  // F_V = [V'] + cv (C1 (R - R0) + q + T - p)
        Vt[off + 1 + S * i] = dqs[k] * u / seg_w[k] * 0.5 * R0 * R0 / R[i];
      }
      double g1 = 0, g2 = 0;  // confined: d g / d qs_k through the end radii
      if (endL_seg && seg_a[N - 1] == k) {  // Q_N depends on RbL = R0 - qs/C1
        const double dQN = s.QbL * (-1.0 / C1);
        Ul[off + 1 + S * (N - 1) + 2] += cp * dQN / h;
        Ul[off + iVf] += -dQN / V_s;
        if (confined) g1 -= s.g1b[N] / C1, g2 -= s.g2b[N] / C1;
      }
      if (end0_seg && seg_a[0] == k) {
        const double dQ0 = s.Qb0 * (-1.0 / C1);
        Ul[off + 1 + 2] += -cp * dQ0 / h;
        Ul[off + iVr] += -dQ0 / V_s;
        if (confined) g1 -= s.g1a[0] / C1, g2 -= s.g2a[0] / C1;
      }
      if (confined && (g1 != 0.0 || g2 != 0.0))
        seg_x_.push_back({-(Gi[0][0] * g1 + Gi[0][1] * g2), -(Gi[1][0] * g1 + Gi[1][1] * g2), off});
      ++rank;
    }
    if (confined) {
      // Q_in,j = alpha_j W + beta_j U - gamma_j (outer::ConfinedSystem::transmural)
      const std::size_t off = Ul.size();
      Ul.resize(off + 2 * std::size_t(n), 0.0);
      Vt.resize(off + 2 * std::size_t(n), 0.0);
      double* fw = Ul.data() + off;
      double* fu = Ul.data() + off + n;
      auto al = [&](int j) { return sys->k[j].ra * sys->w[j]; };
      auto be = [&](int j) { return (sys->k[j].c - sys->A_c * sys->k[j].ra) * sys->w[j]; };
      for (int i = 0; i < N; ++i) {
        fw[1 + S * i + 2] = cp * (al(i + 1) - al(i)) / h;
        fu[1 + S * i + 2] = cp * (be(i + 1) - be(i)) / h;
      }
      // extras: F = y' - d with d = (0, U / X_s, Q_0 / V_s, Q_N / V_s, (Q_0 + U pi Rb0^2) / V_s, ...)
      fw[iVr] = -al(0) / V_s, fu[iVr] = -be(0) / V_s;
      fw[iVf] = -al(N) / V_s, fu[iVf] = -be(N) / V_s;
      fu[iX] = -1.0 / X_s;
      fw[iVrl] = -al(0) / V_s, fu[iVrl] = -(be(0) + pi * Rb0 * Rb0) / V_s;
      fw[iVfl] = -al(N) / V_s, fu[iVfl] = -(be(N) + pi * RbL * RbL) / V_s;
      double* vw = Vt.data() + off;
      double* vu = Vt.data() + off + n;
      for (int i = 0; i < N; ++i) {  // point i + 1 = cell i: right end of interval i, left of i + 1
        const double dRda = 0.5 * R0 * R0 / R[i];
        const double g1a = (s.g1b[i] + s.g1a[i + 1]) * dRda, g2a = (s.g2b[i] + s.g2a[i + 1]) * dRda;
        const double g1p = (s.g1pi[i] - s.g1pi[i + 1]) * P_s, g2p = (s.g2pi[i] - s.g2pi[i + 1]) * P_s;
        vw[1 + S * i] = -(Gi[0][0] * g1a + Gi[0][1] * g2a);
        vu[1 + S * i] = -(Gi[1][0] * g1a + Gi[1][1] * g2a);
        vw[1 + S * i + 2] = -(Gi[0][0] * g1p + Gi[0][1] * g2p);
        vu[1 + S * i + 2] = -(Gi[1][0] * g1p + Gi[1][1] * g2p);
      }
      for (const auto& sx : seg_x_)
        for (int row = 0; row < n; ++row) {
          vw[row] += sx.xw * Vt[sx.off + row];
          vu[row] += sx.xu * Vt[sx.off + row];
        }
      seg_x_.clear();
      rank += 2;
    }
    return rank;
  }
};


// ---------------------------------------------------------------------------------------
// Unbounded outer flow: U(t) = slender-body average of the flow induced by the wall motion,
// O(N^2) per evaluation, with no feedback into the radii. It is evaluated once per accepted
// step (not in every right-hand side and Newton iteration), and X, V_rear_lab and
// V_front_lab (their U parts) are integrated along the steps by the quadratic through the
// last three step points (trapezoid on the first step after a restart). The integrand jumps
// at a protocol switch (dA/dt does), so the rule restarts there with the one-sided values.
struct VelocityQuadrature {
  static constexpr int kn = 3;  // X / X_s, U pi Rb0^2 / V_s, U pi RbL^2 / V_s
  using V3 = std::array<double, kn>;
  double t[3] = {0, 0, 0};
  V3 f[3] = {};
  int count = 0;     // points since the last restart (at most 3 kept)
  V3 sum{};          // integral from 0 to t[latest]
  long evaluations = 0;

  V3 integrand(ForceModel& M, const double* y) {
    ++evaluations;
    M.unpack(y);
    M.fluxes();
    return {M.U / M.X_s, M.U * pi * M.Rb0 * M.Rb0 / M.V_s, M.U * pi * M.RbL * M.RbL / M.V_s};
  }
  /// Integral over [a, b] of the interpolant through the kept points (quadratic with three,
  /// linear with two) expressed on the last interval.
  V3 piece(double a, double b) const {
    V3 out{};
    if (count < 2) return out;
    const int i1 = count - 1, i0 = count - 2;
    if (count == 2) {
      for (int k = 0; k < kn; ++k) {
        const double fa = f[i0][k] + (f[i1][k] - f[i0][k]) * (a - t[i0]) / (t[i1] - t[i0]);
        const double fb = f[i0][k] + (f[i1][k] - f[i0][k]) * (b - t[i0]) / (t[i1] - t[i0]);
        out[k] = 0.5 * (b - a) * (fa + fb);
      }
      return out;
    }
    // quadratic through t[0], t[1], t[2]: Simpson on [a, b] is exact for it
    const double m = 0.5 * (a + b);
    for (int k = 0; k < kn; ++k) {
      auto q = [&](double x) {
        return f[0][k] * (x - t[1]) * (x - t[2]) / ((t[0] - t[1]) * (t[0] - t[2])) +
               f[1][k] * (x - t[0]) * (x - t[2]) / ((t[1] - t[0]) * (t[1] - t[2])) +
               f[2][k] * (x - t[0]) * (x - t[1]) / ((t[2] - t[0]) * (t[2] - t[1]));
      };
      out[k] = (b - a) / 6.0 * (q(a) + 4.0 * q(m) + q(b));
    }
    return out;
  }
  /// Start (t = 0) or restart after a switch at tt with the right-hand value fv.
  void restart(double tt, const V3& fv) {
    count = 1;
    t[0] = tt;
    f[0] = fv;
  }
  /// Accepted step to tt with value fv.
  void step(double tt, const V3& fv) {
    if (tt <= t[count - 1]) return;
    if (count == 3) {
      t[0] = t[1], t[1] = t[2], f[0] = f[1], f[1] = f[2];
      count = 2;
    }
    t[count] = tt;
    f[count] = fv;
    ++count;
    const V3 d = piece(t[count - 2], t[count - 1]);
    for (int k = 0; k < kn; ++k) sum[k] += d[k];
  }
  /// Integral from 0 to tt (tt within the last step).
  V3 at(double tt) const {
    V3 out = sum;
    if (count >= 2 && tt < t[count - 1]) {
      const V3 d = piece(tt, t[count - 1]);
      for (int k = 0; k < kn; ++k) out[k] -= d[k];
    }
    return out;
  }
};

// ---------------------------------------------------------------------------------------
// Root functions of the current protocol state (ProtocolMachine::root_count order).
struct RootEval {
  ForceModel* M = nullptr;
  const ProtocolMachine* machine = nullptr;
  std::vector<double> Rbuf;

  void eval(const double* y, double* g) {
    const int N = M->N, st = M->stride;
    double Rmin = 1e300;
    for (int i = 0; i < N; ++i) {
      Rbuf[i] = M->R0 * std::sqrt(std::max(y[1 + st * i], 0.0));
      Rmin = std::min(Rmin, Rbuf[i]);
    }
    g[0] = (Rmin - collapse_level) / M->R0;
    if (machine->root_count() < 2) return;
    if (machine->phase() == 0) {
      g[1] = (machine->segment_mean(machine->active(), Rbuf.data()) - Rf) / M->R0;
    } else {
      double E = disc::elastic_energy(Rbuf.data(), N, M->R0, M->C1, M->h);
      if (M->inertia) {
        double k = 0;
        for (int i = 0; i < N; ++i) {
          const double v = M->Vel_s * y[1 + st * i + 1];
          k += v * v;
        }
        E += 0.5 * M->m * k * 2.0 * pi * M->R0 * M->h;
      }
      g[1] = E / energy_level - 1.0;
    }
  }
  double collapse_level = 0, Rf = 0, energy_level = 1;
};

/// Everything the SUNDIALS callbacks need (their user data).
struct Problem {
  ForceModel M;
  ProtocolMachine machine;
  RootEval roots;
  sun::LowRankTerm low_rank;  // segment couplings of the Newton matrix
  Problem(const Params& P, std::vector<double> fixed_q) : M(P), machine(P, std::move(fixed_q)) {
    roots.M = &M;
    roots.machine = &machine;
    roots.Rbuf.assign(M.N, 0.0);
    roots.collapse_level = collapse_radius(P);
    roots.Rf = P.protocol.R_f;
    roots.energy_level = P.protocol.energy_tol * reference_energy(P);
  }
};

void add(std::map<std::string, long>& s, const char* k, int (*fn)(void*, long*), void* mem) {
  long v = 0;
  if (fn(mem, &v) >= 0) s[k] += v;
}

// ---------------------------------------------------------------------------------------
// Integrator back-ends with a common interface for the event loop.
class Backend {
 public:
  virtual ~Backend() = default;
  virtual double* y() = 0;
  /// Restart at t from the current y() after a change of the discrete state.
  virtual void restart(double t) = 0;
  virtual void set_roots(int n) = 0;  ///< n root functions, all reported on falling crossings
  virtual void set_stop_time(double t) = 0;
  virtual void set_max_steps(long n) = 0;
  /// 0: reached tout, 1: root found, 2: stop time, -1: step budget exhausted; throws otherwise.
  virtual int advance(double tout, double& t) = 0;
  virtual void root_info(int* found) = 0;
  virtual long steps() = 0;  ///< steps since the last restart
  virtual void harvest(std::map<std::string, long>& stats) = 0;
  std::string last_msg;
  /// Called after every accepted step with (t_n, y_n) (advance then steps one at a time and
  /// interpolates to tout, the same steps as CV_NORMAL / IDA_NORMAL).
  std::function<void(double, const double*)> on_step;

 protected:
  /// advance() with on_step: one step at a time from tn to tout, on_step after each accepted
  /// step, y(tout) interpolated. A root found beyond tout is held back until the outputs
  /// before it are reported, as the NORMAL modes do. one_step(tout, t) takes one step and
  /// returns 1 at a root, 2 at the stop time, 0 otherwise (it throws on failure);
  /// interpolate(tout) writes y(tout) into y(); n is the size of y().
  template <class OneStep, class Interpolate>
  int advance_by_steps(double tout, double& t, double tn, int n, OneStep one_step, Interpolate interpolate) {
    if (pending_root_) {
      if (tout < root_t_) {
        interpolate(tout);
        t = tout;
        return 0;
      }
      pending_root_ = false;
      std::copy(root_y_.begin(), root_y_.end(), y());
      t = root_t_;
      return 1;
    }
    for (long k = 0; tn < tout; ++k) {
      if (k >= max_steps_) return -1;
      const int kind = one_step(tout, t);
      if (kind == 1) {
        if (t <= tout) return 1;
        on_step(t, y());  // the step up to the root, laws before the switch
        pending_root_ = true;
        root_t_ = t;
        root_y_.assign(y(), y() + n);
        interpolate(tout);
        t = tout;
        return 0;
      }
      tn = t;
      on_step(tn, y());
      if (kind == 2) return 2;
    }
    interpolate(tout);
    t = tout;
    return 0;
  }
  long max_steps_ = 500;

 private:
  bool pending_root_ = false;
  double root_t_ = 0;
  std::vector<double> root_y_;
};

class CvodeBackend final : public Backend {
 public:
  CvodeBackend(Problem& pb, const Params& P) : pb_(pb) {
    const ForceModel& M = pb.M;
    ctx_ = sun::make_context();
    y_ = sun::make_vector(M.n, ctx_.get());
    double* y = sun::data(y_.get());
    for (int i = 0; i < M.N; ++i) y[1 + i] = 1.0;
    mem_ = sun::make_cvode(CV_BDF, ctx_.get());
    void* mem = mem_.get();
    sun::check(CVodeSetErrHandlerFn(mem, sun::capture_error, &last_msg), "CVodeSetErrHandlerFn");
    sun::check(CVodeInit(mem, &CvodeBackend::f, 0.0, y_.get()), "CVodeInit");
    sun::check(CVodeSStolerances(mem, P.numerics.rtol, P.numerics.atol_scale), "CVodeSStolerances");
    sun::check(CVodeSetUserData(mem, &pb_), "CVodeSetUserData");
    // Tridiagonal in the areas (V_rear/V_front included). D and X depend on all radii; those
    // couplings lie outside the band and are left out of the Newton matrix (they do not feed
    // back into the areas).
    // Newton matrix: exact tridiagonal Jacobian (areas, V_rear/V_front, D-X block) plus the
    // rank-1 couplings of the held segments, solved by band LU + Sherman-Morrison-Woodbury.
    // D and X depend on all radii; those couplings are left out (they do not feed back).
    A_ = sun::make_band_matrix(M.n, 1, 1, ctx_.get());
    pb.low_rank.scale = &CvodeBackend::minus_gamma;
    pb.low_rank.scale_ctx = this;
    LS_ = sun::make_low_rank_band_solver(y_.get(), A_.get(), &pb.low_rank, ctx_.get());
    sun::check(CVodeSetLinearSolver(mem, LS_.get(), A_.get()), "CVodeSetLinearSolver");
    // The Newton matrix I - gamma J is assembled here from the stored analytic Jacobian (no
    // SUNMatrix copy/scale calls: the distribution's SUNDIALS kernels are unoptimised).
    jband_.assign(3 * std::size_t(M.n), 0.0);
    sun::check(CVodeSetLinSysFn(mem, &CvodeBackend::linsys), "CVodeSetLinSysFn");
    sun::check(CVodeSetNoInactiveRootWarn(mem), "CVodeSetNoInactiveRootWarn");
    sun::check(CVodeSetMaxOrd(mem, kMaxOrder), "CVodeSetMaxOrd");
    // The analytic Jacobian costs about one right-hand side: refresh it and the Newton matrix
    // every kJacobianAge steps (CVODE default 51/20). Cells entering a ramp of an actuation law
    // change their diagonal entry by up to 235 x C1, and a stale matrix then fails to converge.
    sun::check(CVodeSetJacEvalFrequency(mem, kJacobianAge), "CVodeSetJacEvalFrequency");
    sun::check(CVodeSetLSetupFrequency(mem, kJacobianAge), "CVodeSetLSetupFrequency");
  }
  double* y() override { return sun::data(y_.get()); }
  void restart(double t) override {
    // The step size in use before a switch is a good scale for the first step after it: the
    // switch changes the actuation of one segment, and CVODE's own estimate from the new
    // derivative is orders of magnitude smaller (about 200 steps per restart to recover).
    double h_last = 0;
    CVodeGetCurrentStep(mem_.get(), &h_last);
    sun::check(CVodeReInit(mem_.get(), t, y_.get()), "CVodeReInit", last_msg);
    if (h_last > 0) sun::check(CVodeSetInitStep(mem_.get(), kRestartStepFraction * h_last), "CVodeSetInitStep");
  }
  void set_roots(int n) override {
    sun::check(CVodeRootInit(mem_.get(), n, &CvodeBackend::g), "CVodeRootInit");
    dirs_.assign(n, -1);
    if (n > 0) sun::check(CVodeSetRootDirection(mem_.get(), dirs_.data()), "CVodeSetRootDirection");
  }
  void set_stop_time(double t) override { sun::check(CVodeSetStopTime(mem_.get(), t), "CVodeSetStopTime"); }
  void set_max_steps(long n) override {
    max_steps_ = n;
    sun::check(CVodeSetMaxNumSteps(mem_.get(), n), "CVodeSetMaxNumSteps");
  }
  int advance(double tout, double& t) override {
    if (on_step) {
      void* mem = mem_.get();
      double tn = 0;
      CVodeGetCurrentTime(mem, &tn);
      return advance_by_steps(
          tout, t, tn, pb_.M.n,
          [&](double to, double& tt) {
            const int flag = CVode(mem, to, y_.get(), &tt, CV_ONE_STEP);
            if (flag == CV_ROOT_RETURN) return 1;
            sun::check(flag, "CVode", last_msg);
            return flag == CV_TSTOP_RETURN ? 2 : 0;
          },
          [&](double to) { sun::check(CVodeGetDky(mem, to, 0, y_.get()), "CVodeGetDky", last_msg); });
    }
    const int flag = CVode(mem_.get(), tout, y_.get(), &t, CV_NORMAL);
    if (flag == CV_ROOT_RETURN) return 1;
    if (flag == CV_TSTOP_RETURN) return 2;
    if (flag == CV_TOO_MUCH_WORK) return -1;
    sun::check(flag, "CVode", last_msg);
    return 0;
  }
  void root_info(int* found) override { sun::check(CVodeGetRootInfo(mem_.get(), found), "CVodeGetRootInfo"); }
  long steps() override {
    long v = 0;
    CVodeGetNumSteps(mem_.get(), &v);
    return v;
  }
  void harvest(std::map<std::string, long>& s) override {
    void* mem = mem_.get();
    add(s, "steps", CVodeGetNumSteps, mem);
    add(s, "rhs_evals", CVodeGetNumRhsEvals, mem);
    add(s, "rhs_evals", CVodeGetNumLinRhsEvals, mem);
    add(s, "jac_evals", CVodeGetNumJacEvals, mem);
    add(s, "lin_setups", CVodeGetNumLinSolvSetups, mem);
    add(s, "err_test_fails", CVodeGetNumErrTestFails, mem);
    add(s, "nonlin_iters", CVodeGetNumNonlinSolvIters, mem);
    add(s, "nonlin_conv_fails", CVodeGetNumNonlinSolvConvFails, mem);
    add(s, "root_evals", CVodeGetNumGEvals, mem);
  }

 private:
  static int f(double, N_Vector y, N_Vector yd, void* user) {
    return static_cast<Problem*>(user)->M.rhs(sun::data(y), sun::data(yd));
  }
  // Newton matrix A = I - gamma J. The exact Jacobian (tridiagonal part in jband_, rank-1
  // segment terms in pb.low_rank) is re-evaluated when CVODE asks for it (jok false).
  static int linsys(double, N_Vector y, N_Vector, SUNMatrix A, booleantype jok, booleantype* jcur,
                    double gamma, void* user, N_Vector, N_Vector, N_Vector) {
    auto* pb = static_cast<Problem*>(user);
    auto* self = static_cast<CvodeBackend*>(pb->low_rank.scale_ctx);
    const long nn = pb->M.n;
    std::vector<double>& jb = self->jband_;
    if (!jok) {
      std::fill(jb.begin(), jb.end(), 0.0);
      auto band = [&jb, nn](int i, int j, double v) {
        if (i >= 0 && j >= 0 && i < nn && j < nn) jb[3 * std::size_t(i) + 1 + (j - i)] = v;
      };
      pb->low_rank.rank = pb->M.jacobian(sun::data(y), band, pb->low_rank.U, pb->low_rank.V);
      for (double v : jb)
        if (!std::isfinite(v)) return 1;
      for (double v : pb->low_rank.U)
        if (!std::isfinite(v)) return 1;
      *jcur = SUNTRUE;
    } else {
      *jcur = SUNFALSE;
    }
    self->gamma_ = gamma;
    std::fill(SM_DATA_B(A), SM_DATA_B(A) + SM_LDATA_B(A), 0.0);
    for (long i = 0; i < nn; ++i) {
      if (i > 0) SM_ELEMENT_B(A, i, i - 1) = -gamma * jb[3 * i];
      SM_ELEMENT_B(A, i, i) = 1.0 - gamma * jb[3 * i + 1];
      if (i + 1 < nn) SM_ELEMENT_B(A, i, i + 1) = -gamma * jb[3 * i + 2];
    }
    return 0;
  }
  static double minus_gamma(void* self) { return -static_cast<CvodeBackend*>(self)->gamma_; }
  std::vector<double> jband_;  // row i: J(i, i-1), J(i, i), J(i, i+1)
  double gamma_ = 0;
  static int g(double, N_Vector y, double* gout, void* user) {
    static_cast<Problem*>(user)->roots.eval(sun::data(y), gout);
    return 0;
  }
  Problem& pb_;
  sun::Context ctx_;
  sun::Vector y_;
  sun::CvodeMem mem_;
  sun::Matrix A_;
  sun::LinearSolver LS_;
  std::vector<int> dirs_;
};

class IdaBackend final : public Backend {
 public:
  IdaBackend(Problem& pb, const Params& P) : pb_(pb) {
    const ForceModel& M = pb.M;
    ctx_ = sun::make_context();
    y_ = sun::make_vector(M.n, ctx_.get());
    yp_ = sun::make_vector(M.n, ctx_.get());
    id_ = sun::make_vector(M.n, ctx_.get());
    tmp_.assign(M.n, 0.0);
    zero_.assign(M.n, 0.0);
    double* y = sun::data(y_.get());
    double* id = sun::data(id_.get());
    for (int k = 0; k < M.n; ++k) id[k] = 1.0;
    for (int i = 0; i < M.N; ++i) {
      const int k = 1 + M.stride * i;
      y[k] = 1.0;                            // A = pi R0^2
      if (!M.inertia) id[k + 1] = 0.0;       // V is algebraic without wall inertia
      id[k + 2] = 0.0;                       // p is algebraic
      for (int j = 0; j < M.J; ++j) id[k + 3 + j] = 0.0;  // traction fields are algebraic
    }
    ic_step_ = 1e-3 * M.T_s;
    mem_ = sun::make_ida(ctx_.get());
    void* mem = mem_.get();
    sun::check(IDASetErrHandlerFn(mem, sun::capture_error, &last_msg), "IDASetErrHandlerFn");
    sun::check(IDAInit(mem, &IdaBackend::F, 0.0, y_.get(), yp_.get()), "IDAInit");
    sun::check(IDASStolerances(mem, P.numerics.rtol, P.numerics.atol_scale), "IDASStolerances");
    sun::check(IDASetUserData(mem, &pb_), "IDASetUserData");
    sun::check(IDASetId(mem, id_.get()), "IDASetId");
    A_ = sun::make_band_matrix(M.n, M.band_mu, M.band_ml, ctx_.get());
    pb.low_rank.scale = nullptr;  // IDA: J = dF/dy + cj dF/dy', the segment terms are in dF/dy
    // The Newton matrix is block tridiagonal over the cells (stride unknowns each) with the
    // swimmer integrals as a border: factored by blocks (docs/performance-1d.md).
    LS_ = sun::make_low_rank_block_solver(y_.get(), A_.get(), &pb.low_rank, sun::CellBlocks{1, M.stride, M.N},
                                          ctx_.get());
    sun::check(IDASetLinearSolver(mem, LS_.get(), A_.get()), "IDASetLinearSolver");
    sun::check(IDASetJacFn(mem, &IdaBackend::jac), "IDASetJacFn");
    sun::check(IDASetNoInactiveRootWarn(mem), "IDASetNoInactiveRootWarn");
    sun::check(IDASetMaxOrd(mem, kMaxOrder), "IDASetMaxOrd");
    // Index 1: the algebraic unknowns (p; V and the traction fields without wall inertia)
    // are functions of the differential ones, so only the differential unknowns enter the
    // local error test (docs/reduced1d.md, section 5). The algebraic ones jump with the
    // actuation at every relay ramp and protocol event; in the test they took 3.7 times the
    // steps for the same displacement and cycle time.
    sun::check(IDASetSuppressAlg(mem, SUNTRUE), "IDASetSuppressAlg");
  }
  double* y() override { return sun::data(y_.get()); }
  void restart(double t) override {
    // Differential derivatives from the residual at yp = 0 (F = yp - g(y)); the algebraic
    // unknowns (p; V and the traction fields without inertia) are made consistent by
    // IDACalcIC.
    double* y = sun::data(y_.get());
    double* yp = sun::data(yp_.get());
    const double* id = sun::data(id_.get());
    if (pb_.M.res(y, zero_.data(), tmp_.data()) != 0)
      throw NumericalError("non-finite state at a protocol switch",
                           "tighten numerics1d.rtol or lower the actuation (protocol.pressure)", t);
    for (int k = 0; k < pb_.M.n; ++k) yp[k] = id[k] > 0 ? -tmp_[k] : 0.0;
    void* mem = mem_.get();
    sun::check(IDAReInit(mem, t, y_.get(), yp_.get()), "IDAReInit", last_msg);
    sun::check(IDACalcIC(mem, IDA_YA_YDP_INIT, t + ic_step_), "IDACalcIC", last_msg);
    sun::check(IDAGetConsistentIC(mem, y_.get(), yp_.get()), "IDAGetConsistentIC");
  }
  void set_roots(int n) override {
    sun::check(IDARootInit(mem_.get(), n, &IdaBackend::g), "IDARootInit");
    dirs_.assign(n, -1);
    if (n > 0) sun::check(IDASetRootDirection(mem_.get(), dirs_.data()), "IDASetRootDirection");
  }
  void set_stop_time(double t) override { sun::check(IDASetStopTime(mem_.get(), t), "IDASetStopTime"); }
  void set_max_steps(long n) override {
    max_steps_ = n;
    sun::check(IDASetMaxNumSteps(mem_.get(), n), "IDASetMaxNumSteps");
  }
  int advance(double tout, double& t) override {
    if (on_step) {
      void* mem = mem_.get();
      double tn = 0;
      IDAGetCurrentTime(mem, &tn);
      return advance_by_steps(
          tout, t, tn, pb_.M.n,
          [&](double to, double& tt) {
            const int flag = IDASolve(mem, to, &tt, y_.get(), yp_.get(), IDA_ONE_STEP);
            if (flag == IDA_ROOT_RETURN) return 1;
            sun::check(flag, "IDASolve", last_msg);
            return flag == IDA_TSTOP_RETURN ? 2 : 0;
          },
          [&](double to) { sun::check(IDAGetDky(mem, to, 0, y_.get()), "IDAGetDky", last_msg); });
    }
    const int flag = IDASolve(mem_.get(), tout, &t, y_.get(), yp_.get(), IDA_NORMAL);
    if (flag == IDA_ROOT_RETURN) return 1;
    if (flag == IDA_TSTOP_RETURN) return 2;
    if (flag == IDA_TOO_MUCH_WORK) return -1;
    sun::check(flag, "IDASolve", last_msg);
    return 0;
  }
  void root_info(int* found) override { sun::check(IDAGetRootInfo(mem_.get(), found), "IDAGetRootInfo"); }
  long steps() override {
    long v = 0;
    IDAGetNumSteps(mem_.get(), &v);
    return v;
  }
  void harvest(std::map<std::string, long>& s) override {
    void* mem = mem_.get();
    add(s, "steps", IDAGetNumSteps, mem);
    add(s, "rhs_evals", IDAGetNumResEvals, mem);
    add(s, "rhs_evals", IDAGetNumLinResEvals, mem);
    add(s, "jac_evals", IDAGetNumJacEvals, mem);
    add(s, "lin_setups", IDAGetNumLinSolvSetups, mem);
    add(s, "err_test_fails", IDAGetNumErrTestFails, mem);
    add(s, "nonlin_iters", IDAGetNumNonlinSolvIters, mem);
    add(s, "nonlin_conv_fails", IDAGetNumNonlinSolvConvFails, mem);
    add(s, "root_evals", IDAGetNumGEvals, mem);
  }

 private:
  static int F(double, N_Vector y, N_Vector yp, N_Vector r, void* user) {
    return static_cast<Problem*>(user)->M.res(sun::data(y), sun::data(yp), sun::data(r));
  }
  // Band part analytic (ForceModel::ida_band) with the segment actuation, the end radii and
  // the confined closure held; their couplings are the exact low-rank terms.
  static int jac(double, double cj, N_Vector yv, N_Vector ypv, N_Vector rv, SUNMatrix J, void* user,
                 N_Vector, N_Vector, N_Vector) {
    auto* pb = static_cast<Problem*>(user);
    pb->low_rank.rank = pb->M.residual_low_rank(sun::data(yv), pb->low_rank.U, pb->low_rank.V);
    // IDALS zeroes J before this call (checked: every call finds it zero)
    pb->M.ida_band(sun::data(yv), cj, [J](int i, int j, double v) { SM_ELEMENT_B(J, i, j) += v; });
    return 0;
  }

 private:
  static int g(double, N_Vector y, N_Vector, double* gout, void* user) {
    static_cast<Problem*>(user)->roots.eval(sun::data(y), gout);
    return 0;
  }
  Problem& pb_;
  sun::Context ctx_;
  sun::Vector y_, yp_, id_;
  std::vector<double> tmp_, zero_;
  double ic_step_ = 0;
  sun::IdaMem mem_;
  sun::Matrix A_;
  sun::LinearSolver LS_;
  std::vector<int> dirs_;
};

// ---------------------------------------------------------------------------------------
// Event loop shared by the protocol run and the fixed-actuation run.
Result run(const Params& P, std::vector<double> fixed_q, double t_fixed_end, const Output& out,
           bool velocity_in_rhs = false) {
  Result res;
  for (const char* k : {"steps", "rhs_evals", "jac_evals", "lin_setups", "err_test_fails",
                        "nonlin_iters", "nonlin_conv_fails", "root_evals", "reinits"})
    res.stats[k] = 0;
  const bool fixed = !fixed_q.empty();
  auto pb = std::make_unique<Problem>(P, std::move(fixed_q));
  ForceModel& M = pb->M;
  ProtocolMachine& machine = pb->machine;
  const int N = M.N;
  res.z.resize(N);
  for (int i = 0; i < N; ++i) res.z[i] = (i + 0.5) * M.h;

  double t_stop;
  bool stop_fails = false;
  if (fixed) {
    t_stop = t_fixed_end;
  } else if (P.duration > 0) {
    t_stop = P.duration;
  } else {
    t_stop = end_time(P);
    stop_fails = true;
  }
  const double dt_out = P.numerics.output_interval;
  const double collapse = collapse_radius(P);
  int cycles_done = 0;
  double t = 0;
  std::vector<ProtocolMachine::CellLaw> lawbuf;
  std::vector<const ActuationLaw*> seglawbuf;
  std::vector<double> Rcells(N, P.geometry.R0);
  std::unique_ptr<Backend> be;
  std::function<void(double)> check_ends;

  M.velocity_quadrature = M.force_free && !M.confined && !velocity_in_rhs;
  VelocityQuadrature vq;
  auto record = [&](double tt, const double* y) -> bool {
    const bool ok = M.unpack(y);
    M.fluxes();
    if (!M.geometry_ok) return false;
    double d[6], W = 0;
    M.extras(y, d, &W);
    Sample s;
    M.end_state(s);
    const VelocityQuadrature::V3 qv = M.velocity_quadrature ? vq.at(tt) : VelocityQuadrature::V3{};
    s.V_rear_lab = (y[M.iVrl] + qv[1]) * M.V_s;
    s.V_front_lab = (y[M.iVfl] + qv[2]) * M.V_s;
    s.t = tt;
    s.X = (y[M.iX] + qv[0]) * M.X_s;
    s.W = W;
    s.energy = M.energy();
    s.R_min = *std::min_element(M.R.begin(), M.R.end());
    s.R_max = *std::max_element(M.R.begin(), M.R.end());
    s.Q_rear = M.Q[0];
    s.Q_front = M.Q[N];
    s.V_rear = y[M.iVr] * M.V_s;
    s.V_front = y[M.iVf] * M.V_s;
    double vol = 0;
    for (int i = 0; i < N; ++i) vol += M.R[i] * M.R[i];
    s.tube_volume = pi * vol * M.h;
    s.phase = machine.phase();
    if (!ok) return false;
    if (!finite(s)) return false;
    emit(res, out, s, M.R.data(), N, t_stop);
    return true;
  };
  auto cells = [&](const double* y) {
    for (int i = 0; i < N; ++i) Rcells[i] = M.R0 * std::sqrt(std::max(y[1 + M.stride * i], 0.0));
    return Rcells.data();
  };
  auto apply_actuation = [&](double tt) {
    machine.laws(lawbuf, seglawbuf);
    M.set_actuation(machine, lawbuf, seglawbuf);
    check_ends(tt);
  };
  check_ends = [&](double tt) {
    double lo0, loL;
    M.end_radius_range(lo0, loL);
    if (lo0 < collapse || loL < collapse) {
      const bool left = lo0 < collapse;
      throw NumericalError(
          "tube radius collapsed to zero at z = " + fmt(left ? 0.0 : M.L) +
              " m: under its actuation the open end has no positive rest radius (R0 - q/C1 <= 0)",
          "lower the actuation (protocol.pressure, protocol.total_force or protocol.load_factor) below C1 R0 = " + fmt(M.C1 * M.R0) +
              " Pa or raise wall.C1",
          tt);
    }
  };

  try {
    if (!fixed) {
      machine.start_cycle(0.0, Rcells.data());
      res.cycle_start.push_back(0.0);
      if (out.record) out.record->cycle_started(0.0);
    }
    machine.laws(lawbuf, seglawbuf);
    M.set_actuation(machine, lawbuf, seglawbuf);
    if (M.dae)
      be = std::make_unique<IdaBackend>(*pb, P);
    else
      be = std::make_unique<CvodeBackend>(*pb, P);
    be->set_roots(machine.root_count());
    be->set_stop_time(t_stop);
    if (M.velocity_quadrature) {
      vq.restart(0.0, vq.integrand(M, be->y()));
      be->on_step = [&](double tn, const double* y) { vq.step(tn, vq.integrand(M, y)); };
    }
    if (!record(0.0, be->y())) {
      check_ends(0.0);  // an open end without a positive rest radius is the usual cause
      throw NumericalError("non-finite initial state", "check the wall and fluid parameters", 0.0);
    }
    check_ends(0.0);
    if (!fixed && P.protocol.q <= M.C1 * (M.R0 - P.protocol.R_f)) {
      throw NumericalError(
          "the actuation cannot contract the tube to R_f: under the actuation pressure q = " + fmt(P.protocol.q) +
              " Pa the static radius R0 - q/C1 = " + fmt(M.R0 - P.protocol.q / M.C1) +
              " m is not below R_f = " + fmt(P.protocol.R_f) + " m",
          "raise the actuation (protocol.pressure) above C1 (R0 - R_f) = " + fmt(M.C1 * (M.R0 - P.protocol.R_f)) +
              " Pa or raise wave.contracted_ratio",
          0.0);
    }
    if (M.dae) be->restart(0.0);  // consistent initial derivatives (IDACalcIC)

    long steps_before = 0;  // steps of earlier restarts
    std::vector<int> found;
    long k = 1;
    bool done = false;
    while (!done) {
      double tout = std::min(k * dt_out, t_stop);
      if (t_stop - tout < 1e-9 * dt_out) tout = t_stop;
      const long used = steps_before + be->steps();
      const long remaining = P.numerics.max_steps - used;
      if (remaining <= 0) throw NumericalError("integrator step budget numerics1d.max_steps exhausted",
                                               "raise numerics1d.max_steps or loosen numerics1d.rtol", t);
      be->set_max_steps(remaining);
      const int st = be->advance(tout, t);
      if (st == -1)
        throw NumericalError("integrator step budget numerics1d.max_steps exhausted (" +
                                 std::to_string(P.numerics.max_steps) + " steps)",
                             "raise numerics1d.max_steps or loosen numerics1d.rtol or numerics1d.atol_scale", t);
      if (st == 1) {
        // the partial step up to the root, with the laws in force before the switch
        if (M.velocity_quadrature) vq.step(t, vq.integrand(M, be->y()));
        found.assign(std::max(machine.root_count(), 2), 0);
        be->root_info(found.data());
        const double* R = cells(be->y());
        res.switches += machine.apply(t, found.data(), R);
        if (machine.collapsed()) {
          const int imin = int(std::min_element(Rcells.begin(), Rcells.end()) - Rcells.begin());
          record(t, be->y());
          throw NumericalError("tube radius collapsed to zero at z = " + fmt(res.z[imin]) + " m",
                               "lower the actuation (protocol.pressure, protocol.total_force or protocol.load_factor) or raise wave.contracted_ratio", t);
        }
        if (machine.cycle_completed()) {
          res.cycle_end.push_back(t);
          if (out.record) out.record->cycle_ended(t);
          ++cycles_done;
          if (fixed || (P.duration <= 0 && cycles_done >= P.protocol.cycles)) {
            machine.finish();
            record(t, be->y());
            break;
          }
          machine.start_cycle(t, R);
          res.cycle_start.push_back(t);
          if (out.record) out.record->cycle_started(t);
        }
        apply_actuation(t);
        if (M.velocity_quadrature) vq.restart(t, vq.integrand(M, be->y()));  // right-hand value
        be->harvest(res.stats);
        steps_before = res.stats["steps"];
        be->restart(t);
        be->set_roots(machine.root_count());
        be->set_stop_time(t_stop);
        ++res.stats["reinits"];
        continue;
      }
      if (!record(t, be->y()))
        throw NumericalError("non-finite state", P.numerics.cells < 100000
                                                     ? "tighten numerics1d.rtol or refine numerics1d.cells"
                                                     : "tighten numerics1d.rtol",
                             t);
      if (tout >= t_stop) {
        if (stop_fails)
          throw NumericalError(
              "the protocol did not complete " + std::to_string(P.protocol.cycles) +
                  " cycle(s) by t = " + fmt(t_stop) + " s (the end_time bound; phase " +
                  std::to_string(machine.phase()) + ")",
              "raise the actuation (protocol.pressure), protocol.tolerance_ratio or protocol.energy_tolerance, or set time.duration", t);
        done = true;
      }
      ++k;
    }
  } catch (const NumericalError& e) {
    res.failure = e;
  } catch (const sun::SundialsError& e) {
    if (M.confined && !M.geometry_ok)
      res.failure = NumericalError(
          "the tube wall reached the container wall (outer hydraulic radius R + a_out >= container radius)",
          "raise container.radius or lower the actuation (protocol.pressure) (the recovery overshoots R0)", t);
    else res.failure = NumericalError(
        std::string(M.dae ? "IDA" : "CVODE") + " failed: " + e.what(),
        "tighten numerics1d.rtol or numerics1d.atol_scale or raise numerics1d.cells; if the radius nearly closes, "
        "lower the actuation (protocol.pressure) or raise wave.contracted_ratio",
        t);
  }
  if (be) be->harvest(res.stats);
  // steps_before bookkeeping double counts nothing: harvest adds only the counters since the
  // last restart, and every restart is preceded by a harvest.
  res.segment_reached = machine.reached();
  if (fixed) res.segment_reached.clear();
  return res;
}

}  // namespace

AbsKQuadrature abs_k_quadrature(double L, double h) {
  // Nodes: log-spaced, step <= 1.5 in ln s, from (pi/L)/e to (2/h) e (the tube's lowest
  // mode and the grid's highest discrete wavenumber, one unit of ln s beyond each). Weights:
  // least squares on the relative error at 200 log-spaced wavenumbers over [pi/L, 2/h]
  // (Householder QR). The trapezoid rule in ln s on the same nodes, (2/pi) ds_j s_j, is the
  // exact quadrature of |k| = (2/pi) int_0^inf k^2 / (k^2 + s^2) ds apart from its two
  // truncated tails; the fit corrects the tails and the end nodes, so that 5-10 nodes reach
  // < 1 % where the plain rule needs twice as many. All weights come out positive (the
  // operator stays dissipative); a fit that did not would be refused.
  const double k_lo = pi / L, k_hi = 2.0 / h;
  const double lo = std::log(k_lo) - 1.0, hi = std::log(k_hi) + 1.0;
  const int n = int(std::ceil((hi - lo) / 1.5)) + 1;
  const double d = (hi - lo) / (n - 1);
  AbsKQuadrature q;
  for (int j = 0; j < n; ++j) q.s.push_back(std::exp(lo + j * d));
  constexpr int kSamples = 200;
  Eigen::MatrixXd A(kSamples, n);
  Eigen::VectorXd ones = Eigen::VectorXd::Ones(kSamples);
  for (int r = 0; r < kSamples; ++r) {
    const double k = std::exp(std::log(k_lo) + (std::log(k_hi) - std::log(k_lo)) * r / (kSamples - 1));
    for (int j = 0; j < n; ++j) A(r, j) = k / (k * k + q.s[j] * q.s[j]);  // (k^2 / (k^2 + s^2)) / k
  }
  const Eigen::VectorXd c = A.householderQr().solve(ones);
  for (int j = 0; j < n; ++j) {
    if (!(c[j] > 0.0))
      throw NumericalError("the short-wave traction's |k| quadrature has a non-positive weight at N = " +
                               std::to_string(int(std::lround(L / h))) + " cells",
                           "use another numerics1d.cells or model1d.short_wave_traction = false", 0.0);
    q.c.push_back(c[j]);
  }
  return q;
}

JacobianCheck check_jacobian(const Params& P, int phase, int active, unsigned seed) {
  validate(P);
  Problem pb(P, {});
  ForceModel& M = pb.M;
  pb.machine.set_state(phase, active);
  std::vector<ProtocolMachine::CellLaw> laws;
  std::vector<const ActuationLaw*> seg;
  pb.machine.laws(laws, seg);
  M.set_actuation(pb.machine, laws, seg);
  const int n = M.n, N = M.N;
  std::uint64_t st = 0x9E3779B97F4A7C15ull * (seed + 1);
  auto uni = [&]() {  // splitmix64 -> [0, 1)
    st += 0x9E3779B97F4A7C15ull;
    std::uint64_t z = st;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  const double R0 = P.geometry.R0, Rf = P.protocol.R_f, d = P.protocol.delta;
  std::vector<double> y(n, 0.0), yp(n, 0.0);
  for (int i = 0; i < N; ++i) {
    const bool held = seg[M.seg_a[i]] != nullptr;
    const double Ri = held ? Rf + d * (4.0 * uni() - 2.0) : R0 * (0.45 + 0.6 * uni());
    y[1 + M.stride * i] = (Ri / R0) * (Ri / R0);
    if (M.dae)
      for (int k = 1; k < M.stride; ++k) y[1 + M.stride * i + k] = uni() - 0.5;
  }
  // Shift each held segment so that its mean radius sits on a ramp of the held law (a few
  // passes: cells straddling two segments couple neighbouring means).
  std::vector<double> target(seg.size());
  for (auto& v : target) v = (uni() < 0.5 ? Rf + d : Rf - d) + 0.1 * d * (uni() - 0.5);
  for (int pass = 0; pass < 20; ++pass)
  for (int k = 0; k < int(seg.size()); ++k) {
    if (!seg[k]) continue;
    M.unpack(y.data());
    const double shift = target[k] - M.Rbar[k];
    for (int i = M.seg_first[k]; i <= M.seg_last[k]; ++i) {
      const double Ri = R0 * std::sqrt(y[1 + M.stride * i]) + shift;
      y[1 + M.stride * i] = (Ri / R0) * (Ri / R0);
    }
  }
  for (int k = 0; k < n; ++k) yp[k] = uni() - 0.5;
  y[M.iD] = uni();
  y[M.iX] = uni();

  // analytic (band + low rank), dense
  std::vector<double> J(std::size_t(n) * n, 0.0);  // row-major
  std::vector<double> U, Vt;
  int rank = 0;
  const double cj = 1e3;
  if (!M.dae) {
    rank = M.jacobian(y.data(), [&](int i, int j, double v) { J[std::size_t(i) * n + j] = v; }, U, Vt);
  } else {
    rank = M.residual_low_rank(y.data(), U, Vt);
    // band part: the backend's analytic band on a band matrix (an entry outside the band
    // the matrix was sized for is an error)
    auto ctx = sun::make_context();
    auto A = sun::make_band_matrix(n, M.band_mu, M.band_ml, ctx.get());
    SUNMatZero(A.get());
    M.ida_band(y.data(), cj, [&](int i, int j, double v) {
      if (j - i > M.band_mu || i - j > M.band_ml)
        throw std::logic_error("IDA band entry (" + std::to_string(i) + ", " + std::to_string(j) + ") outside the band");
      SM_ELEMENT_B(A.get(), i, j) += v;
    });
    for (int i = 0; i < n; ++i)
      for (int j = std::max(0, i - M.band_ml); j <= std::min(n - 1, i + M.band_mu); ++j)
        J[std::size_t(i) * n + j] = SM_ELEMENT_B(A.get(), i, j);
  }
  for (int k = 0; k < rank; ++k)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) J[std::size_t(i) * n + j] += U[std::size_t(k) * n + i] * Vt[std::size_t(k) * n + j];

  // central differences of the full model
  std::vector<double> Jfd(std::size_t(n) * n, 0.0), fp(n), fm(n), yy = y, yyp = yp;
  for (int j = 0; j < n; ++j) {
    const double inc = 1e-6 * std::max(std::abs(y[j]), 1e-2);
    yy[j] = y[j] + inc;
    yyp[j] = yp[j] + cj * inc;
    if (M.dae) M.res(yy.data(), yyp.data(), fp.data()); else M.rhs(yy.data(), fp.data());
    yy[j] = y[j] - inc;
    yyp[j] = yp[j] - cj * inc;
    if (M.dae) M.res(yy.data(), yyp.data(), fm.data()); else M.rhs(yy.data(), fm.data());
    yy[j] = y[j];
    yyp[j] = yp[j];
    for (int i = 0; i < n; ++i) Jfd[std::size_t(i) * n + j] = (fp[i] - fm[i]) / (2.0 * inc);
  }
  JacobianCheck out;
  out.rank = rank;
  for (int i = 0; i < n; ++i) {
    // D, X and lab-volume rows: radii couplings left out by design (no feedback)
    if (i == M.iD || i == M.iX || i == M.iVrl || i == M.iVfl) continue;
    double rowmax = 0;
    for (int j = 0; j < n; ++j) rowmax = std::max(rowmax, std::abs(Jfd[std::size_t(i) * n + j]));
    if (rowmax == 0) continue;
    for (int j = 0; j < n; ++j) {
      const double a = J[std::size_t(i) * n + j], b = Jfd[std::size_t(i) * n + j];
      if (a != 0 || b != 0) ++out.entries;
      out.max_rel_error = std::max(out.max_rel_error, std::abs(a - b) / rowmax);
    }
  }
  // D-X block (inside the band)
  for (int i : {M.iD, M.iX})
    for (int j : {M.iD, M.iX}) {
      const double a = J[std::size_t(i) * n + j], b = Jfd[std::size_t(i) * n + j];
      const double sc = std::max({std::abs(b), std::abs(Jfd[std::size_t(M.iX) * n + M.iD]), 1e-300});
      if (a != 0 || b != 0) ++out.entries;
      out.max_rel_error = std::max(out.max_rel_error, std::abs(a - b) / sc);
    }
  return out;
}

Result solve_force_driven(const Params& p, const Output& out, bool velocity_in_rhs) {
  return run(p, {}, 0.0, out, velocity_in_rhs);
}

Result solve_fixed_actuation(const Params& p, const std::vector<double>& q_cells, double t_end,
                             const Output& out) {
  validate(p);
  if (static_cast<int>(q_cells.size()) != p.numerics.cells)
    throw InputError("q_cells", std::to_string(q_cells.size()), "one actuation value per cell");
  return run(p, q_cells, t_end, out);
}

}  // namespace swim::reduced1d::detail
