// Force-driven wave: the spatial model (equations in force_model.hpp).
#include "reduced1d/force_model.hpp"

#include <Eigen/Dense>
#include <sunmatrix/sunmatrix_band.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "reduced1d/v4.hpp"

namespace swim::reduced1d::detail {

namespace {
using v4::V4;
using v4::load4;
using v4::store4;

/// Whether every x[k] is finite, without a branch per entry: x * 0 is 0 for a finite x and
/// NaN otherwise, summed in four lanes.
bool all_finite(const double* x, int n) {
  double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    s0 += x[k] * 0.0;
    s1 += x[k + 1] * 0.0;
    s2 += x[k + 2] * 0.0;
    s3 += x[k + 3] * 0.0;
  }
  for (; k < n; ++k) s0 += x[k] * 0.0;
  return (s0 + s1) + (s2 + s3) == 0.0;
}
}  // namespace

using disc::pi;

ForceModel::ForceModel(const Params& P, bool step_velocity)
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
      Rc_eff(P.container.radius_eff),
      period(P.container.period),
      bal(disc::BalanceCoefficients::from(P)),
      tq(P.swimmer.model == SwimmerModel::ForceFree && P.swimmer.short_wave_traction
             ? abs_k_quadrature(P.geometry.L, P.geometry.L / P.numerics.cells)
             : AbsKQuadrature{}),
      J(int(tq.s.size())),
      D_axial(P.wall.D_axial),
      bending(P.wall.D_axial > 0),
      junction(P.swimmer.model == SwimmerModel::ForceFree && P.swimmer.outer == OuterFlow::Confined &&
               P.swimmer.end_junction),
      dae(P.wall.inertia || J > 0 || bending || junction),
      velocity_quadrature(step_velocity && force_free && !confined),
      stride(dae ? 3 + J + (bending ? 1 : 0) : 1),
      Rb0_static(R0),
      RbL_static(R0) {
  wall = wall_law(P);
  drainage_ends = P.numerics.open_end == OpenEnd::Drainage && !bending && !junction;
  ends_follow_cells = bending || (P.numerics.open_end == OpenEnd::Continued && !junction);
  if (!bending) end_w0 = 1.0, end_w1 = 0.0;
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
  if (force_free && !confined) {
    zc.resize(N);
    faces.resize(N + 1);
    for (int i = 0; i < N; ++i) zc[i] = (i + 0.5) * h;
    for (int j = 0; j <= N; ++j) faces[j] = j * h;
  }
  T_s = 0.1 * relaxation_time(P);
  // Band of the interleaved (a, V, p, phi) layout: the continuity row of cell i reaches
  // a_{i-1} (stride + 2 below) and p_{i+1} (stride above); the traction row phi_{i,j}
  // reaches phi_{i+-1,j} (stride) and V_i of its own cell only. V_rear (first) and V_front
  // stay inside.
  band_mu = stride;
  band_ml = stride + 2;
  if (bending) {
    // kappa last in its cell: the wall row reaches kappa_{i+1} (2 stride - 2 above), the
    // kappa row reaches a_{i-1} (2 stride - 1 below); still within the neighbouring cells.
    ik = 3 + J;
    bend_c = D_axial * R0 / (h * h * h * h);
    band_mu = 2 * stride - 2;
    band_ml = 2 * stride;  // and V_front's row reaches a_{N-2} through the free end's radius
  }
  const double f_s = bal.per_length ? pi * C1 * R0 * R0 * R0 / L : C1 * R0 * R0 / (2.0 * L);
  D_s = f_s * T_s;
  X_s = force_free ? R0 : D_s * T_s / (bal.m_eff + bal.c_ext * T_s);
  V_s = pi * R0 * R0 * L;
  Vel_s = R0 / T_s;
  P_s = C1 * R0;
  tr_beta = J > 0 ? P.swimmer.traction_end : 0.0;
  for (int j = 0; j < J; ++j) {
    tr_s2.push_back(tq.s[j] * h * tq.s[j] * h);
    tr_w.push_back(1.0 / (tr_s2.back() + 4.0));
    tr_c.push_back(4.0 * mu * tq.c[j] * Vel_s / P_s);
    tr_csum += tr_c.back();
    // beyond an open end: a wall at rest continues the tube, along which the field decays by
    // r_j per cell, the root below 1 of r^2 - (2 + a) r + 1 = 0 (a = (s_j h)^2); mixed with the
    // mirror's 1 by beta
    const double a = tr_s2.back(), r = 1.0 + 0.5 * a - std::sqrt(a + 0.25 * a * a);
    tr_g.push_back(1.0 - tr_beta + tr_beta * r);
  }
}

ModelState ForceModel::make_state() const {
  ModelState s;
  s.R.assign(N, 0.0);
  s.V.assign(N, 0.0);
  s.p.assign(N, 0.0);
  s.q.assign(N, 0.0);
  s.dq.assign(N, 0.0);
  s.Rb0 = R0;
  s.RbL = R0;
  if (wall.law) {
    s.wv.assign(N, 0.0);
    s.dw.assign(N, 0.0);
  }
  s.r.assign(N + 1, 0.0);
  s.Q.assign(N + 1, 0.0);
  s.cond.assign(N + 1, 0.0);
  if (force_free) {
    std::vector<double> d(N + 1, h);
    d[0] = d[N] = 0.5 * h;
    s.Rpt.assign(N + 2, R0);
    s.Pipt.assign(N + 2, 0.0);
    if (confined) {
      s.sys = std::make_unique<outer::ConfinedSystem>(N + 2, d, mu, a_in, a_out, Rc_eff, period, L);
      s.sys->drainage_ends = drainage_ends;
      if (junction) {
        s.sys->junction = &outer::kCalibratedJunction;
        s.Vpt.assign(N + 2, 0.0);
      }
    } else {
      s.sigma.assign(N, 0.0);
      s.rho.assign(N, R0);
    }
  }
  return s;
}

void ForceModel::set_actuation(const ProtocolMachine& mc, const std::vector<ProtocolMachine::CellLaw>& laws,
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
  // The end cells lie inside the first/last segment (h <= shortest segment): pure laws.
  end0_seg = seg_law[seg_a[0]] != nullptr;
  endL_seg = seg_law[seg_a[N - 1]] != nullptr;
  Rb0_static = law[0].a->rest_radius(wall);
  RbL_static = law[N - 1].a->rest_radius(wall);
}

void ForceModel::end_radius_range(double& lo0, double& loL) const {
  lo0 = Rb0_static;
  loL = RbL_static;
  if (end0_seg) lo0 = law[0].a->rest_radius(wall, seg_law[seg_a[0]]->operator()(1e300));
  if (endL_seg) loL = law[N - 1].a->rest_radius(wall, seg_law[seg_a[N - 1]]->operator()(1e300));
}

bool ForceModel::unpack(const double* y, ModelState& s) const {
  bool ok = true;
  for (int i = 0; i < N; ++i) {
    const double a = y[1 + stride * i];
    if (!(a > 0) || !std::isfinite(a)) ok = false;
  }
  // (a separate pass so that the square roots vectorise: -fno-math-errno, CMakeLists.txt)
  double* Rd = s.R.data();
  if (stride == 1) {
    const double* a = y + 1;
    for (int i = 0; i < N; ++i) Rd[i] = R0 * std::sqrt(std::max(a[i], 1e-300));
  } else {
    for (int i = 0; i < N; ++i) Rd[i] = R0 * std::sqrt(std::max(y[1 + stride * i], 1e-300));
  }
  const std::vector<double>& R = s.R;
  if (int(s.qs.size()) != nseg) {
    s.Rbar.assign(nseg, 0.0);
    s.qs.assign(nseg, 0.0);
    s.dqs.assign(nseg, 0.0);
  }
  for (int k = 0; k < nseg; ++k) {
    if (!seg_law[k]) continue;
    double sum = 0;
    for (int i = seg_first[k]; i <= seg_last[k]; ++i) {
      if (seg_a[i] == k) sum += frac[i] * R[i];
      if (seg_b[i] == k && seg_b[i] != seg_a[i]) sum += (1.0 - frac[i]) * R[i];
    }
    s.Rbar[k] = sum / seg_w[k];
    s.qs[k] = seg_law[k]->eval(s.Rbar[k], s.dqs[k]);
  }
  if (ends_follow_cells) {  // a bending wall's free ends, straight through the last two cells (no
                           // curvature), or the continued open ends, the end cells' radii
    s.Rb0 = end_w0 * R[0] + end_w1 * R[1];
    s.RbL = end_w0 * R[N - 1] + end_w1 * R[N - 2];
    if (!(s.Rb0 > 0) || !(s.RbL > 0)) ok = false;
  } else {
    s.Rb0 = end0_seg ? law[0].a->rest_radius(wall, s.qs[seg_a[0]]) : Rb0_static;
    s.RbL = endL_seg ? law[N - 1].a->rest_radius(wall, s.qs[seg_a[N - 1]]) : RbL_static;
  }
  if (wall.law) {  // d Rb / d qs = -1 / w'(Rb) (the end cell of a held segment has no own ramp)
    double d;
    wall.eval(s.Rb0, d);
    s.dRb0 = -1.0 / d;
    wall.eval(s.RbL, d);
    s.dRbL = -1.0 / d;
  }
  for (int i = 0; i < N; ++i) {
    const double Ri = R[i];
    double qi = law[i].eval(Ri, s.dq[i]);
    if (seg_law[seg_a[i]]) qi += frac[i] * s.qs[seg_a[i]];
    if (seg_b[i] != seg_a[i] && seg_law[seg_b[i]]) qi += (1.0 - frac[i]) * s.qs[seg_b[i]];
    s.q[i] = qi;
    if (wall.law) s.wv[i] = wall.law->eval(Ri, s.dw[i]);
    if (dae) {
      s.V[i] = Vel_s * y[1 + stride * i + 1];
      s.p[i] = P_s * y[1 + stride * i + 2];
    } else {
      if (wall.law)
        s.p[i] = s.wv[i] + qi;
      else
        s.p[i] = C1 * (Ri - R0) + qi;
    }
  }
  return ok;
}

void ForceModel::fluxes(ModelState& s, bool derivatives, bool want_velocity) const {
  const std::vector<double>& R = s.R;
  const std::vector<double>& p = s.p;
  std::vector<double>& r = s.r;
  std::vector<double>& Q = s.Q;
  if (confined) {
    outer::ConfinedSystem& sys = *s.sys;
    s.Rpt[0] = s.Rb0;
    s.Rpt[N + 1] = s.RbL;
    for (int i = 0; i < N; ++i) s.Rpt[i + 1] = R[i], s.Pipt[i + 1] = p[i];
    s.geometry_ok = sys.geometry(s.Rpt.data(), derivatives);
    if (!s.geometry_ok) {
      std::fill(Q.begin(), Q.end(), std::nan(""));
      s.U = std::nan("");
      return;
    }
    if (junction) {
      for (int i = 0; i < N; ++i) s.Vpt[i + 1] = s.V[i];
      sys.transmural(s.Pipt.data(), 0.0, s.Vpt.data());
    } else {
      sys.transmural(s.Pipt.data());
    }
    for (int j = 0; j <= N; ++j) {
      Q[j] = sys.Q_in[j];
      r[j] = sys.k[j].rl;
      s.cond[j] = sys.w[j];
    }
    s.U = sys.U;
    return;
  }
  auto end_r = [&](double a, double b) {
    return drainage_ends ? disc::drainage_resistance(mu, 0.5 * h, a, b) : disc::resistance(mu, 0.5 * h, a, b);
  };
  r[0] = end_r(s.Rb0 - a_in, R[0] - a_in);
  Q[0] = -p[0] / r[0];
  for (int j = 1; j < N; ++j) {
    r[j] = disc::resistance(mu, h, R[j - 1] - a_in, R[j] - a_in);
    Q[j] = -(p[j] - p[j - 1]) / r[j];
  }
  r[N] = end_r(R[N - 1] - a_in, s.RbL - a_in);
  Q[N] = p[N - 1] / r[N];
  for (int j = 0; j <= N; ++j) s.cond[j] = 1.0 / r[j];
  if (force_free && (!velocity_quadrature || want_velocity)) {  // unbounded: slender-body average
    for (int i = 0; i < N; ++i) {
      s.sigma[i] = (Q[i] - Q[i + 1]) / h;  // d(pi R^2)/dt per unit length
      s.rho[i] = R[i] + a_out;
    }
    s.U = outer::slender_velocity(zc, faces, s.sigma, -Q[0], Q[N], s.rho, L, mu, s.u_ind);
  }
}

void ForceModel::dresistance(double d, double a, double b, double& ra, double& rb) const {
  const double c = (8.0 * mu / pi) * d / 3.0;
  const double a2 = a * a, b2 = b * b, ab = a * b;
  const double a3b3 = a2 * a * b2 * b;
  ra = -c * (a2 + 2.0 * ab + 3.0 * b2) / (a3b3 * a);
  rb = -c * (b2 + 2.0 * ab + 3.0 * a2) / (a3b3 * b);
}

void ForceModel::interval_dresistance(int j, double d, double a, double b, double& ra, double& rb) const {
  if (drainage_ends && (j == 0 || j == N))
    disc::drainage_dresistance(mu, d, a, b, ra, rb);
  else
    dresistance(d, a, b, ra, rb);
}

disc::PressureIntegrals ForceModel::integrals(const ModelState& st) const {
  disc::PressureIntegrals s;
  for (int j = 0; j <= N; ++j) {
    const double a = (j == 0) ? st.Rb0 : st.R[j - 1];
    const double b = (j == N) ? st.RbL : st.R[j];
    const double dp = flow_closure ? -st.r[j] * st.Q[j] : C1 * (b - a);
    s.I1 += dp * disc::mean_R1(a, b);
    s.I2 += dp * disc::mean_R2(a, b);
    s.I4 += dp * disc::mean_R4(a, b);
  }
  return s;
}

double ForceModel::wall_energy(const double* R) const {
  double e = 0;
  if (wall.law) {
    for (int i = 0; i < N; ++i) e += wall.law->energy(R[i]);
    e *= 2.0 * pi * R0 * h;
  } else {
    e = disc::elastic_energy(R, N, R0, C1, h);
  }
  if (bending) {
    double b = 0;
    for (int i = 1; i + 1 < N; ++i) {
      const double c = (R[i + 1] - 2.0 * R[i] + R[i - 1]) / (h * h);
      b += c * c;
    }
    e += 0.5 * D_axial * b * 2.0 * pi * R0 * h;
  }
  return e;
}

double ForceModel::energy(const ModelState& s) const {
  double e = wall_energy(s.R.data());
  if (inertia) {
    double k = 0;
    for (int i = 0; i < N; ++i) k += s.V[i] * s.V[i];
    e += 0.5 * m * k * 2.0 * pi * R0 * h;
  }
  return e;
}

void ForceModel::extras(const ModelState& s, const double* y, double* dd, double* W_out) const {
  double W = s.U;
  if (force_free) {
    dd[0] = 0.0;
  } else {
    const auto I = integrals(s);
    W = bal.velocity(bal.thrust_term(I), y[iD] * D_s, y[iX] * X_s);
    dd[0] = bal.drag_integrand(I) / D_s;
  }
  if (velocity_quadrature) W = 0.0;  // integrated outside the ODE (the event loop's quadrature)
  dd[1] = W / X_s;
  dd[2] = s.Q[0] / V_s;
  dd[3] = s.Q[N] / V_s;
  // lab frame: the lumen fluid crossing the moving end sections, Q + W pi R_end^2
  dd[4] = (s.Q[0] + W * pi * s.Rb0 * s.Rb0) / V_s;
  dd[5] = (s.Q[N] + W * pi * s.RbL * s.RbL) / V_s;
  if (W_out) *W_out = velocity_quadrature ? s.U : W;
}

void ForceModel::end_state(ModelState& s, Sample& out) const {
  if (!force_free) return;
  if (confined) {
    s.sys->lumen_pressure(s.pl);
    out.p_rear = s.pl[0];
    out.p_front = s.pl[N + 1];
    out.Q_total = s.sys->Q_tot;
  }
  // control volume on the lumen: pi [R(0)^2 p(0) - R(L)^2 p(L)]; the outer flow balances it
  out.F_lumen = pi * (s.Rb0 * s.Rb0 * out.p_rear - s.RbL * s.RbL * out.p_front);
  out.F_outer = -out.F_lumen;
}

int ForceModel::rhs(const double* y, double* yd, ModelState& s) const {
  if (!unpack(y, s)) return 1;  // recoverable: the integrator retries with a smaller step
  fluxes(s, false, false);
  const double c = 1.0 / (h * pi * R0 * R0);
  if (!s.geometry_ok) return 1;
  for (int i = 0; i < N; ++i) yd[1 + i] = (s.Q[i] - s.Q[i + 1]) * c;
  double d[6];
  extras(s, y, d);
  yd[iD] = d[0], yd[iX] = d[1], yd[iVr] = d[2], yd[iVf] = d[3], yd[iVrl] = d[4], yd[iVfl] = d[5];
  return all_finite(yd, n) ? 0 : 1;
}

void ForceModel::flux_sensitivities(Linearisation& s, bool with_pressure) const {
  const ModelState& st = s.at;
  const std::vector<double>& R = st.R;
  s.QL.assign(N + 1, 0.0);
  s.QR.assign(N + 1, 0.0);
  // point radii and dPi/dR at the points (ends: Pi = 0 fixed)
  auto Rp = [&](int k) { return k == 0 ? st.Rb0 : (k == N + 1 ? st.RbL : R[k - 1]); };
  auto dPi = [&](int k) {
    return (k == 0 || k == N + 1 || !with_pressure) ? 0.0 : wall_slope(st, k - 1) + st.dq[k - 1];
  };
  if (confined) {
    const outer::ConfinedSystem& sys = *st.sys;
    s.g1a.assign(N + 1, 0.0), s.g1b.assign(N + 1, 0.0), s.g1pi.assign(N + 1, 0.0);
    s.g2a.assign(N + 1, 0.0), s.g2b.assign(N + 1, 0.0), s.g2pi.assign(N + 1, 0.0);
    const double Qt = sys.Q_tot, Uv = sys.U;
    double Qab[2][2] = {{0, 0}, {0, 0}};  // the end intervals' dQ / d(R_a, R_b) (the junction)
    for (int j = 0; j <= N; ++j) {
      const double a = Rp(j), b = Rp(j + 1), d = (j == 0 || j == N) ? 0.5 * h : h;
      const double dpi = sys.dPi[j];
      const auto& k = sys.k[j];
      const auto &da = sys.point_derivative(j), &db = sys.point_derivative(j + 1);
      double rla, rlb;
      interval_dresistance(j, d, a - a_in, b - a_in, rla, rlb);
      // Q_in = (ra Qt + c U - dPi) / (rl + ra); t1 = rl Q_in; t2 = -S rl Q_in - S dPi + e U
      const double w = sys.w[j], Qj = sys.Q_in[j];
      auto partial = [&](const outer::AnnulusPoint<double>& dp, double drl, double& dQ, double& d1, double& d2) {
        const double dra = 0.5 * d * dp.rho, dc = 0.5 * d * dp.kappa, dS = 0.5 * dp.S, de = 0.5 * d * dp.e;
        dQ = (dra * Qt + dc * Uv - Qj * (drl + dra)) * w;
        d1 = drl * Qj + k.rl * dQ;
        d2 = -dS * k.rl * Qj - k.S * drl * Qj - k.S * k.rl * dQ - dS * dpi + de * Uv;
      };
      double Qa, Qb;
      partial(da, rla, Qa, s.g1a[j], s.g2a[j]);
      partial(db, rlb, Qb, s.g1b[j], s.g2b[j]);
      if (j == 0) Qab[0][0] = Qa, Qab[0][1] = Qb;
      if (j == N) Qab[1][0] = Qa, Qab[1][1] = Qb;
      s.g1pi[j] = -k.rl * w;        // d t1 / d dPi
      s.g2pi[j] = -k.S * k.ra * w;  // d t2 / d dPi
      // dQ/d Pi_j = +w, dQ/d Pi_{j+1} = -w
      s.QL[j] = Qa + w * dPi(j);
      s.QR[j] = Qb - w * dPi(j + 1);
    }
    s.Qb0 = s.QL[0];
    s.QbL = s.QR[N];
    if (junction) {
      // The end rows through the end fluxes Q_0, Q_N (at fixed W, U, Pi_0, Pi_L) and the end
      // radii (the dissipation matrices and the rims' thrust); g1 and g2 gain the same.
      const auto& jc = sys.jc;
      s.g3a.assign(N + 1, 0.0), s.g3b.assign(N + 1, 0.0), s.g3pi.assign(N + 1, 0.0);
      s.g4a.assign(N + 1, 0.0), s.g4b.assign(N + 1, 0.0), s.g4pi.assign(N + 1, 0.0);
      for (int e = 0; e < 2; ++e) {
        const int j = e == 0 ? 0 : N;
        const auto &Me = jc.M[e], &dMe = jc.dM[e];
        const double m0 = Me[0][0] - Me[0][1], m1 = Me[1][0] - Me[1][1], m2 = Me[2][0] - Me[2][1];
        double dx[3];  // (dM_e x_e)_r
        for (int r = 0; r < 3; ++r) dx[r] = dMe[r][0] * jc.x[e][0] + dMe[r][1] * jc.x[e][1] + dMe[r][2] * jc.x[e][2];
        const double wq = -sys.w[j];  // dQ_j / d dPi_j
        std::vector<double>& gea = e == 0 ? s.g3a : s.g4a;
        std::vector<double>& geb = e == 0 ? s.g3b : s.g4b;
        std::vector<double>& gepi = e == 0 ? s.g3pi : s.g4pi;
        const double sg = e == 0 ? 1.0 : -1.0;  // g3 = Pi_0 + (Mx)_0 - (Mx)_1, g4 = Pi_L - (Mx)_0 + (Mx)_1
        s.g1a[j] += m0 * Qab[e][0], s.g1b[j] += m0 * Qab[e][1], s.g1pi[j] += m0 * wq;
        s.g2a[j] += m2 * Qab[e][0], s.g2b[j] += m2 * Qab[e][1], s.g2pi[j] += m2 * wq;
        gea[j] = sg * (m0 - m1) * Qab[e][0], geb[j] = sg * (m0 - m1) * Qab[e][1], gepi[j] = sg * (m0 - m1) * wq;
        // the end radius: point 0 (left of interval 0) or N + 1 (right of interval N)
        std::vector<double>& g1e = e == 0 ? s.g1a : s.g1b;
        std::vector<double>& g2e = e == 0 ? s.g2a : s.g2b;
        std::vector<double>& gee = e == 0 ? s.g3a : s.g4b;
        g1e[j] += dx[0];
        g2e[j] += dx[2] - jc.dthrust[e];
        gee[j] += sg * (dx[0] - dx[1]);
      }
    }
    return;
  }
  for (int j = 0; j <= N; ++j) {
    const double a = Rp(j), b = Rp(j + 1), d = (j == 0 || j == N) ? 0.5 * h : h;
    double ra, rb;
    interval_dresistance(j, d, a - a_in, b - a_in, ra, rb);
    s.QL[j] = dPi(j) / st.r[j] - st.Q[j] / st.r[j] * ra;
    s.QR[j] = -dPi(j + 1) / st.r[j] - st.Q[j] / st.r[j] * rb;
  }
  s.Qb0 = s.QL[0];
  s.QbL = s.QR[N];
}

Linearisation ForceModel::linearise(const double* y, ModelState& st, bool with_pressure) const {
  unpack(y, st);
  fluxes(st, true, false);
  Linearisation lin(st);
  flux_sensitivities(lin, with_pressure);
  if (confined) {
    const auto& G = st.sys->M;
    const double det = G[0][0] * G[1][1] - G[0][1] * G[1][0];
    lin.Gi[0][0] = G[1][1] / det, lin.Gi[0][1] = -G[0][1] / det, lin.Gi[1][0] = -G[1][0] / det,
    lin.Gi[1][1] = G[0][0] / det;
    if (junction) {
      Eigen::Matrix4d A;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) A(r, c) = st.sys->jc.G[r][c];
      const Eigen::Matrix4d Ai = A.inverse();
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) lin.Gi4[r][c] = Ai(r, c);
    }
  }
  return lin;
}

namespace {
/// A segment's load also moves the confined closure (W, U): d(W, U)/dqs_k, and where its
/// column of Vt starts.
struct SegChain {
  double xw, xu;
  std::size_t off;
};
/// The same for the junction's closure z = (W, U, Pi_0, Pi_L): dz/dqs_k.
struct JunctionChain {
  double x[4];
  std::size_t off;
};
}  // namespace

template <class Band>
int ForceModel::jacobian(const Linearisation& s, const Band& band, std::vector<double>& Ul,
                         std::vector<double>& Vt) const {
  const ModelState& st = s.at;
  const std::vector<double>& R = st.R;
  const std::vector<double>& cond = st.cond;
  const double c = 1.0 / (h * pi * R0 * R0);
  if (junction) throw std::logic_error("the calibrated junction runs on the IDA path (ForceModel::dae)");
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
  const auto& Gi = s.Gi;
  std::vector<double> fq, fu, dg1pi, dg2pi;
  std::vector<SegChain> seg_x;
  if (confined) {
    const outer::ConfinedSystem& sys = *st.sys;
    fq.assign(n, 0.0), fu.assign(n, 0.0);
    std::vector<double> al(N + 1), be(N + 1);
    for (int j = 0; j <= N; ++j) {
      const auto& k = sys.k[j];
      al[j] = k.ra * sys.w[j];
      be[j] = (k.c - sys.A_c * k.ra) * sys.w[j];
    }
    for (int i = 0; i < N; ++i) {
      fq[1 + i] = c * (al[i] - al[i + 1]);
      fu[1 + i] = c * (be[i] - be[i + 1]);
    }
    fq[iVr] = al[0] / V_s, fu[iVr] = be[0] / V_s;
    fq[iVf] = al[N] / V_s, fu[iVf] = be[N] / V_s;
    dg1pi.assign(N, 0.0), dg2pi.assign(N, 0.0);
    for (int i = 0; i < N; ++i) {  // point i + 1: right end of interval i, left end of i + 1
      dg1pi[i] = s.g1pi[i] - s.g1pi[i + 1];
      dg2pi[i] = s.g2pi[i] - s.g2pi[i + 1];
    }
  }
  // rank-1 terms: d f / d qs_k (per unit segment actuation) times d qs_k / d a
  int rank = 0;
  Ul.clear();
  Vt.clear();
  std::vector<double> dQ(N + 1);
  for (int k = 0; k < nseg; ++k) {
    if (!seg_law[k] || st.dqs[k] == 0.0) continue;
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
    if (end0_seg && seg_a[0] == k) dQ[0] += s.Qb0 * end_sensitivity(st, false);
    if (endL_seg && seg_a[N - 1] == k) dQ[N] += s.QbL * end_sensitivity(st, true);
    const std::size_t off = Ul.size();
    Ul.resize(off + n, 0.0);
    Vt.resize(off + n, 0.0);
    for (int i = std::max(lo - 1, 0); i <= std::min(hi + 1, N - 1); ++i) Ul[off + 1 + i] = c * (dQ[i] - dQ[i + 1]);
    Ul[off + iVr] = dQ[0] / V_s;
    Ul[off + iVf] = dQ[N] / V_s;
    for (int i = lo; i <= hi; ++i) Vt[off + 1 + i] = st.dqs[k] * u(i) / seg_w[k] * 0.5 * R0 * R0 / R[i];
    if (confined) {  // the segment load also moves W and U: d(W, U)/dqs_k = -G^{-1} dg/dqs_k
      double g1 = 0, g2 = 0;
      for (int i = lo; i <= hi; ++i) {
        g1 += dg1pi[i] * u(i);
        g2 += dg2pi[i] * u(i);
      }
      if (wall.law) {
        if (end0_seg && seg_a[0] == k) g1 += s.g1a[0] * st.dRb0, g2 += s.g2a[0] * st.dRb0;
        if (endL_seg && seg_a[N - 1] == k) g1 += s.g1b[N] * st.dRbL, g2 += s.g2b[N] * st.dRbL;
      } else {
        if (end0_seg && seg_a[0] == k) g1 -= s.g1a[0] / C1, g2 -= s.g2a[0] / C1;
        if (endL_seg && seg_a[N - 1] == k) g1 -= s.g1b[N] / C1, g2 -= s.g2b[N] / C1;
      }
      seg_x.push_back({-(Gi[0][0] * g1 + Gi[0][1] * g2), -(Gi[1][0] * g1 + Gi[1][1] * g2), off});
    }
    ++rank;
  }
  if (confined) {
    // Two rank-1 terms df/dW (dW/dy)^T + df/dU (dU/dy)^T; dW/dy and dU/dy are the direct
    // dependence on every radius plus the segment chains d(W, U)/dqs_k times the segment rows.
    const std::size_t off = Ul.size();
    Ul.resize(off + 2 * std::size_t(n), 0.0);
    Vt.resize(off + 2 * std::size_t(n), 0.0);
    std::copy(fq.begin(), fq.end(), Ul.begin() + off);
    std::copy(fu.begin(), fu.end(), Ul.begin() + off + n);
    for (int i = 0; i < N; ++i) {
      const double dRda = 0.5 * R0 * R0 / R[i];
      const double g1 = (s.g1b[i] + s.g1a[i + 1] + dg1pi[i] * (wall_slope(st, i) + st.dq[i])) * dRda;
      const double g2 = (s.g2b[i] + s.g2a[i + 1] + dg2pi[i] * (wall_slope(st, i) + st.dq[i])) * dRda;
      Vt[off + 1 + i] = -(Gi[0][0] * g1 + Gi[0][1] * g2);
      Vt[off + n + 1 + i] = -(Gi[1][0] * g1 + Gi[1][1] * g2);
    }
    for (const auto& sx : seg_x)
      for (int row = 0; row < n; ++row) {
        Vt[off + row] += sx.xw * Vt[sx.off + row];
        Vt[off + n + row] += sx.xu * Vt[sx.off + row];
      }
    rank += 2;
  }
  return rank;
}

ForceModel::IdaRows ForceModel::ida_rows() const {
  return {2.0 * Vel_s / (R0 * R0), inertia ? 1.0 / (m * Vel_s) : 1.0 / P_s, 1.0 / (2.0 * pi * R0 * Vel_s),
          pi * R0 * R0};
}

// Per cell (a, V, p, phi_0..phi_{J-1}), phi_j = (s_j h)^2 / ((s_j h)^2 - D2) V in units of Vel_s:
//   F_a = a' - 2 R V / R0^2,   F_V = [V'] + cv (C1 (R - R0) + q + T - p),
//   F_p = continuity,          F_phi_j = ((s_j h)^2 (phi_j - V) - D2 phi_j) / ((s_j h)^2 + 4),
// with T = 4 mu sum_j c_j (V - phi_j) (the traction 2 mu |k| V of each fluid; V - phi_j is
// the field psi_j = -D2 / ((s_j h)^2 - D2) V of docs/outer-flow-1d.md) and D2 the cell
// second difference with mirror ends (a uniform wall velocity has no short-wave traction).
// phi_j rather than psi_j: its row reaches V of its own cell only, which keeps the band
// of the Newton matrix at stride + 2 below the diagonal instead of 2 stride - 2.
int ForceModel::res(const double* y, const double* yp, double* F, ModelState& s) const {
  if (!unpack(y, s)) return 1;
  fluxes(s, false, false);  // with the velocity quadrature U is integrated along the steps
  const auto [cu, cv, cp, A0] = ida_rows();
  const int S = stride;
  const std::vector<double>& R = s.R;
  for (int i = 0; i < N; ++i) {
    const int k = 1 + S * i;
    double T = tr_csum * y[k + 1];
    for (int j = 0; j < J; ++j) T -= tr_c[j] * y[k + 3 + j];
    F[k] = yp[k] - cu * R[i] * y[k + 1];
    if (wall.law)
      F[k + 1] = (inertia ? yp[k + 1] : 0.0) + cv * (s.wv[i] + s.q[i] + P_s * T - s.p[i]);
    else  // (the linear tier's own expression, for its rounding)
      F[k + 1] = (inertia ? yp[k + 1] : 0.0) + cv * (C1 * (R[i] - R0) + s.q[i] + P_s * T - s.p[i]);
    F[k + 2] = cp * ((s.Q[i + 1] - s.Q[i]) / h + A0 * yp[k]);
    if (J > 0 && tr_beta != 0.0 && (i == 0 || i + 1 == N)) {  // an open end's cell: the ghost value
      for (int j = 0; j < J; ++j) {
        const double phi = y[k + 3 + j];
        const double left = i > 0 ? y[k - S + 3 + j] : tr_g[j] * phi;
        const double right = i + 1 < N ? y[k + S + 3 + j] : tr_g[j] * phi;
        F[k + 3 + j] = (tr_s2[j] * (phi - y[k + 1]) - (left - 2.0 * phi + right)) * tr_w[j];
      }
    } else if (J > 0) {
      const int km = i > 0 ? k - S : k, kp = i + 1 < N ? k + S : k;  // mirror ends
      int j = 0;
      for (; j + 4 <= J; j += 4) {  // four fields at a time (the same operations per field)
        const V4 d2p = load4(y + km + 3 + j) - 2.0 * load4(y + k + 3 + j) + load4(y + kp + 3 + j);
        store4(F + k + 3 + j, (load4(&tr_s2[j]) * (load4(y + k + 3 + j) - y[k + 1]) - d2p) * load4(&tr_w[j]));
      }
      for (; j < J; ++j) {
        const double d2p = y[km + 3 + j] - 2.0 * y[k + 3 + j] + y[kp + 3 + j];
        F[k + 3 + j] = (tr_s2[j] * (y[k + 3 + j] - y[k + 1]) - d2p) * tr_w[j];
      }
    }
    if (bending) {  // kappa = 0 beyond the ends and at the end cells (free ends)
      const double km1 = i > 0 ? y[k - S + ik] : 0.0, kp1 = i + 1 < N ? y[k + S + ik] : 0.0;
      F[k + 1] += cv * bend_c * (km1 - 2.0 * y[k + ik] + kp1);
      F[k + ik] = (i > 0 && i + 1 < N) ? y[k + ik] - (R[i + 1] - 2.0 * R[i] + R[i - 1]) / R0 : y[k + ik];
    }
  }
  if (!s.geometry_ok) return 1;
  double d[6];
  extras(s, y, d);
  const int idx[6] = {iD, iX, iVr, iVf, iVrl, iVfl};
  for (int k = 0; k < 6; ++k) F[idx[k]] = yp[idx[k]] - d[k];
  return all_finite(F, n) ? 0 : 1;
}

void AddToBandMatrix::operator()(int i, int j, double v) const { SM_ELEMENT_B(J, i, j) += v; }

template <class Band>
void ForceModel::ida_band(const Linearisation& s, const double* y, double cj, const Band& band) const {
  const ModelState& st = s.at;
  const std::vector<double>& R = st.R;
  const std::vector<double>& cond = st.cond;
  const int S = stride;
  const auto [cu, cv, cp, A0] = ida_rows();
  auto dRda = [&](int i) { return 0.5 * R0 * R0 / R[i]; };
  for (int i = 0; i < N; ++i) {
    const int k = 1 + S * i;
    // F_a = a' - cu R V
    band(k, k, cj - cu * y[k + 1] * dRda(i));
    band(k, k + 1, -cu * R[i]);
    // F_V = [V'] + cv (C1 (R - R0) + q + P_s T - p)
    band(k + 1, k, cv * (wall_slope(st, i) + st.dq[i]) * dRda(i));
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
    // F_phi_j = ((s_j h)^2 (phi - V) - D2 phi) / ((s_j h)^2 + 4); beyond an open end the ghost
    // value g_j phi (the mirror's g_j = 1: the diagonal's 2 - g_j per end is then the count of
    // neighbours, as written for it)
    const int nb = (i > 0) + (i + 1 < N);
    for (int j = 0; j < J; ++j) {
      const int row = k + 3 + j;
      const double w = tr_w[j];
      if (tr_beta != 0.0)
        band(row, row, (tr_s2[j] + 2.0 - (2 - nb) * tr_g[j]) * w);
      else
        band(row, row, (tr_s2[j] + nb) * w);
      band(row, k + 1, -tr_s2[j] * w);
      if (i > 0) band(row, row - S, -w);
      if (i + 1 < N) band(row, row + S, -w);
    }
    if (bending) {
      band(k + 1, k + ik, -2.0 * cv * bend_c);
      if (i > 0) band(k + 1, k + ik - S, cv * bend_c);
      if (i + 1 < N) band(k + 1, k + ik + S, cv * bend_c);
      band(k + ik, k + ik, 1.0);
      if (i > 0 && i + 1 < N) {
        band(k + ik, k - S, -dRda(i - 1) / R0);
        band(k + ik, k, 2.0 * dRda(i) / R0);
        band(k + ik, k + S, -dRda(i + 1) / R0);
      }
    }
  }
  // end volumes: F = V' - Q_end / V_s
  band(iVr, iVr, cj);
  band(iVr, 1, -s.QR[0] * dRda(0) / V_s);
  band(iVr, 3, cond[0] * P_s / V_s);
  band(iVf, iVf, cj);
  band(iVf, 1 + S * (N - 1), -s.QL[N] * dRda(N - 1) / V_s);
  band(iVf, 1 + S * (N - 1) + 2, -cond[N] * P_s / V_s);
  if (ends_follow_cells) {  // Q_0 and Q_N through the ends' radii Rb = w0 R_end + w1 R_next
    const double c = cp / h;
    for (auto [i, w] : {std::pair{0, end_w0}, std::pair{1, end_w1}}) {
      if (w == 0.0) continue;  // (the continued end's neighbour; outside the band without bending)
      const double d0 = s.Qb0 * w * dRda(i);
      band(1 + 2, 1 + S * i, -c * d0);
      band(iVr, 1 + S * i, -d0 / V_s);
    }
    for (auto [i, w] : {std::pair{N - 1, end_w0}, std::pair{N - 2, end_w1}}) {
      if (w == 0.0) continue;
      const double dN = s.QbL * w * dRda(i);
      band(1 + S * (N - 1) + 2, 1 + S * i, c * dN);
      band(iVf, 1 + S * i, -dN / V_s);
    }
  }
  for (int i : {iD, iX, iVrl, iVfl}) band(i, i, cj);
  if (!force_free) {  // F_X = X' - W / X_s, W = (thrust - D - c_ext X) / m_eff
    band(iX, iD, D_s / (bal.m_eff * X_s));
    band(iX, iX, bal.c_ext / bal.m_eff);
  }
}

template int ForceModel::jacobian(const Linearisation&, const TridiagonalRows&, std::vector<double>&,
                                  std::vector<double>&) const;
template int ForceModel::jacobian(const Linearisation&, const BandSink&, std::vector<double>&,
                                  std::vector<double>&) const;
template void ForceModel::ida_band(const Linearisation&, const double*, double, const AddToBandMatrix&) const;
template void ForceModel::ida_band(const Linearisation&, const double*, double, const BandSink&) const;

int ForceModel::residual_low_rank(const Linearisation& s, std::vector<double>& Ul, std::vector<double>& Vt) const {
  const ModelState& st = s.at;
  const std::vector<double>& R = st.R;
  const double cv = ida_rows().cv, cp = ida_rows().cp;
  const int S = stride;
  const auto& Gi = s.Gi;
  std::vector<SegChain> seg_x;
  std::vector<JunctionChain> seg_j;
  int rank = 0;
  Ul.clear();
  Vt.clear();
  for (int k = 0; k < nseg; ++k) {
    if (!seg_law[k] || st.dqs[k] == 0.0) continue;
    const std::size_t off = Ul.size();
    Ul.resize(off + n, 0.0);
    Vt.resize(off + n, 0.0);
    const int lo = seg_first[k], hi = seg_last[k];
    for (int i = lo; i <= hi; ++i) {
      double u = 0;
      if (seg_a[i] == k) u += frac[i];
      if (seg_b[i] == k && seg_b[i] != seg_a[i]) u += 1.0 - frac[i];
      Ul[off + 1 + S * i + 1] = cv * u;  // F_V = [V'] + cv (C1 (R - R0) + q + T - p)
      Vt[off + 1 + S * i] = st.dqs[k] * u / seg_w[k] * 0.5 * R0 * R0 / R[i];
    }
    double g1 = 0, g2 = 0;  // confined: d g / d qs_k through the end radii (static ends only)
    if (endL_seg && seg_a[N - 1] == k && !ends_follow_cells) {  // Q_N depends on RbL (linear law: R0 - qs/C1)
      const double dQN = s.QbL * end_sensitivity(st, true);
      Ul[off + 1 + S * (N - 1) + 2] += cp * dQN / h;
      Ul[off + iVf] += -dQN / V_s;
      if (confined) {
        if (wall.law) g1 += s.g1b[N] * st.dRbL, g2 += s.g2b[N] * st.dRbL;
        else g1 -= s.g1b[N] / C1, g2 -= s.g2b[N] / C1;
      }
    }
    if (end0_seg && seg_a[0] == k && !ends_follow_cells) {
      const double dQ0 = s.Qb0 * end_sensitivity(st, false);
      Ul[off + 1 + 2] += -cp * dQ0 / h;
      Ul[off + iVr] += -dQ0 / V_s;
      if (confined) {
        if (wall.law) g1 += s.g1a[0] * st.dRb0, g2 += s.g2a[0] * st.dRb0;
        else g1 -= s.g1a[0] / C1, g2 -= s.g2a[0] / C1;
      }
    }
    if (junction) {  // the end rows through the end radii too
      double g[4] = {g1, g2, 0.0, 0.0};
      if (endL_seg && seg_a[N - 1] == k && !ends_follow_cells) g[3] += s.g4b[N] * end_sensitivity(st, true);
      if (end0_seg && seg_a[0] == k && !ends_follow_cells) g[2] += s.g3a[0] * end_sensitivity(st, false);
      if (g[0] != 0.0 || g[1] != 0.0 || g[2] != 0.0 || g[3] != 0.0) {
        JunctionChain jx{{}, off};
        for (int c = 0; c < 4; ++c)
          for (int l = 0; l < 4; ++l) jx.x[c] -= s.Gi4[c][l] * g[l];
        seg_j.push_back(jx);
      }
    } else if (confined && (g1 != 0.0 || g2 != 0.0)) {
      seg_x.push_back({-(Gi[0][0] * g1 + Gi[0][1] * g2), -(Gi[1][0] * g1 + Gi[1][1] * g2), off});
    }
    ++rank;
  }
  if (confined && junction) {
    // Four rank-1 terms dF/dz_m (dz_m/dy)^T for z = (W, U, Pi_0, Pi_L) of the junction's
    // closure (outer::ConfinedSystem::transmural): Q_in,j = alpha_j W + beta_j U - w_j dPi_j,
    // dPi_0 = Pi_1 - Pi_0, dPi_N = Pi_L - Pi_N; dz/dy = -G^{-1} dg/dy.
    const outer::ConfinedSystem& sys = *st.sys;
    const std::size_t off = Ul.size();
    Ul.resize(off + 4 * std::size_t(n), 0.0);
    Vt.resize(off + 4 * std::size_t(n), 0.0);
    double* f[4] = {Ul.data() + off, Ul.data() + off + n, Ul.data() + off + 2 * n, Ul.data() + off + 3 * n};
    auto al = [&](int j) { return sys.k[j].ra * sys.w[j]; };
    auto be = [&](int j) { return (sys.k[j].c - sys.A_c * sys.k[j].ra) * sys.w[j]; };
    for (int i = 0; i < N; ++i) {
      f[0][1 + S * i + 2] = cp * (al(i + 1) - al(i)) / h;
      f[1][1 + S * i + 2] = cp * (be(i + 1) - be(i)) / h;
    }
    f[0][iVr] = -al(0) / V_s, f[1][iVr] = -be(0) / V_s;
    f[0][iVf] = -al(N) / V_s, f[1][iVf] = -be(N) / V_s;
    f[1][iX] = -1.0 / X_s;
    f[0][iVrl] = -al(0) / V_s, f[1][iVrl] = -(be(0) + pi * st.Rb0 * st.Rb0) / V_s;
    f[0][iVfl] = -al(N) / V_s, f[1][iVfl] = -(be(N) + pi * st.RbL * st.RbL) / V_s;
    // dQ_0 / dPi_0 = w_0, dQ_N / dPi_L = -w_N
    const double w0 = sys.w[0], wN = sys.w[N];
    f[2][1 + 2] = -cp * w0 / h;
    f[2][iVr] = -w0 / V_s, f[2][iVrl] = -w0 / V_s;
    f[3][1 + S * (N - 1) + 2] = -cp * wN / h;
    f[3][iVf] = wN / V_s, f[3][iVfl] = wN / V_s;
    // dg/dy, dense per row g_l
    std::vector<double> dg(4 * std::size_t(n), 0.0);
    const std::vector<double>* ga[4] = {&s.g1a, &s.g2a, &s.g3a, &s.g4a};
    const std::vector<double>* gb[4] = {&s.g1b, &s.g2b, &s.g3b, &s.g4b};
    const std::vector<double>* gp[4] = {&s.g1pi, &s.g2pi, &s.g3pi, &s.g4pi};
    for (int l = 0; l < 4; ++l) {
      double* d = dg.data() + l * std::size_t(n);
      const auto &A = *ga[l], &B = *gb[l], &P = *gp[l];
      for (int i = 0; i < N; ++i) {  // point i + 1 = cell i: right end of interval i, left of i + 1
        d[1 + S * i] = (B[i] + A[i + 1]) * 0.5 * R0 * R0 / R[i];
        d[1 + S * i + 2] = (P[i] - P[i + 1]) * P_s;
      }
      if (ends_follow_cells) {  // the end points' radii follow the cells beside them
        for (auto [i, w] : {std::pair{0, end_w0}, std::pair{1, end_w1}}) d[1 + S * i] += A[0] * w * 0.5 * R0 * R0 / R[i];
        for (auto [i, w] : {std::pair{N - 1, end_w0}, std::pair{N - 2, end_w1}})
          d[1 + S * i] += B[N] * w * 0.5 * R0 * R0 / R[i];
      }
    }
    for (int i = 0; i < N; ++i) dg[n + 1 + S * i + 1] = -sys.jc.dthrust_dV[i + 1] * Vel_s;  // g2 = ... - thrust
    for (int iz = 0; iz < 4; ++iz) {
      double* v = Vt.data() + off + iz * std::size_t(n);
      for (int l = 0; l < 4; ++l) {
        const double c = s.Gi4[iz][l];
        const double* d = dg.data() + l * std::size_t(n);
        for (int row = 0; row < n; ++row) v[row] -= c * d[row];
      }
      for (const auto& sx : seg_j)
        for (int row = 0; row < n; ++row) v[row] += sx.x[iz] * Vt[sx.off + row];
    }
    rank += 4;
  } else if (confined) {
    const outer::ConfinedSystem& sys = *st.sys;
    // Q_in,j = alpha_j W + beta_j U - gamma_j (outer::ConfinedSystem::transmural)
    const std::size_t off = Ul.size();
    Ul.resize(off + 2 * std::size_t(n), 0.0);
    Vt.resize(off + 2 * std::size_t(n), 0.0);
    double* fw = Ul.data() + off;
    double* fu = Ul.data() + off + n;
    auto al = [&](int j) { return sys.k[j].ra * sys.w[j]; };
    auto be = [&](int j) { return (sys.k[j].c - sys.A_c * sys.k[j].ra) * sys.w[j]; };
    for (int i = 0; i < N; ++i) {
      fw[1 + S * i + 2] = cp * (al(i + 1) - al(i)) / h;
      fu[1 + S * i + 2] = cp * (be(i + 1) - be(i)) / h;
    }
    // extras: F = y' - d with d = (0, U / X_s, Q_0 / V_s, Q_N / V_s, (Q_0 + U pi Rb0^2) / V_s, ...)
    fw[iVr] = -al(0) / V_s, fu[iVr] = -be(0) / V_s;
    fw[iVf] = -al(N) / V_s, fu[iVf] = -be(N) / V_s;
    fu[iX] = -1.0 / X_s;
    fw[iVrl] = -al(0) / V_s, fu[iVrl] = -(be(0) + pi * st.Rb0 * st.Rb0) / V_s;
    fw[iVfl] = -al(N) / V_s, fu[iVfl] = -(be(N) + pi * st.RbL * st.RbL) / V_s;
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
    if (ends_follow_cells) {  // the end points' radii follow the cells beside them
      auto add = [&](int i, double g1, double g2) {
        vw[1 + S * i] -= Gi[0][0] * g1 + Gi[0][1] * g2;
        vu[1 + S * i] -= Gi[1][0] * g1 + Gi[1][1] * g2;
      };
      for (auto [i, w] : {std::pair{0, end_w0}, std::pair{1, end_w1}}) {
        const double f = w * 0.5 * R0 * R0 / R[i];
        add(i, s.g1a[0] * f, s.g2a[0] * f);
      }
      for (auto [i, w] : {std::pair{N - 1, end_w0}, std::pair{N - 2, end_w1}}) {
        const double f = w * 0.5 * R0 * R0 / R[i];
        add(i, s.g1b[N] * f, s.g2b[N] * f);
      }
    }
    for (const auto& sx : seg_x)
      for (int row = 0; row < n; ++row) {
        vw[row] += sx.xw * Vt[sx.off + row];
        vu[row] += sx.xu * Vt[sx.off + row];
      }
    rank += 2;
  }
  return rank;
}

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

}  // namespace swim::reduced1d::detail
