#include "reduced1d/outer_flow.hpp"

#include "reduced1d/discretisation.hpp"
#include "reduced1d/v4.hpp"

#include <algorithm>
#include <Eigen/Dense>

namespace swim::reduced1d::outer {

double duct_equivalent_radius(double half_width) {
  double sum = 0;
  for (int n = 1; n < 400; n += 2) sum += std::tanh(n * pi / 2.0) / std::pow(double(n), 5);
  const double k = (4.0 / 3.0) * (1.0 - 192.0 / std::pow(pi, 5) * sum);
  return std::pow(8.0 * k / pi, 0.25) * half_width;
}

double confined_drag_coefficient(double R, double L, double a_in, double a_out, double Rc, double P, double mu) {
  ConfinedSystem sys(2, {L}, mu, a_in, a_out, Rc, P, L);
  const double Rp[2] = {R, R};
  if (!sys.geometry(Rp)) return 0.0;
  const double Pi[2] = {0.0, 0.0};
  sys.transmural(Pi);
  return sys.drag_coefficient();
}

TowedTube confined_tow(double R, double L, double a_in, double a_out, double Rc, double P, double mu,
                       const EndEffects& ends) {
  ConfinedSystem sys(2, {L}, mu, a_in, a_out, Rc, P, L);
  sys.ends = ends;
  const double Rp[2] = {R, R}, s[1] = {0.0};
  TowedTube t;
  if (!sys.geometry(Rp)) return t;
  sys.kinematic(s, 1.0);  // a unit external force: U = 1 / drag
  t.drag = 1.0 / sys.U;
  t.lumen_flux = sys.Q_in[0] / sys.U;
  return t;
}

LumenForce lumen_wall_force(const double* R, const double* p, int npoints) {
  LumenForce f;
  for (int k = 0; k + 1 < npoints; ++k) {
    const double a = R[k], b = R[k + 1], dp = p[k + 1] - p[k];
    f.shear -= pi * dp * (a * a + a * b + b * b) / 3.0;
    // int p d(R^2) for linear p and R on the interval, exactly
    f.taper -= pi * (b - a) * (p[k] * (a + b) + dp * (a + 2.0 * b) / 3.0);
  }
  return f;
}

void induced_axial_velocity(const std::vector<double>& zc, const std::vector<double>& faces,
                            const std::vector<double>& sigma, double m_rear, double m_front,
                            const std::vector<double>& rho, std::vector<double>& u) {
  const int N = int(zc.size());
  u.assign(N, 0.0);
  const double c = 1.0 / (4.0 * pi);
  const double zL = faces.back(), z0 = faces.front();
  // sum_j sigma_j (g_{j+1} - g_j) = sum_f g_f (sigma_{f-1} - sigma_f) over the faces f
  // (sigma = 0 beyond both ends), g_f = 1 / sqrt((z - f)^2 + rho^2). The kernel row is
  // formed in its own loop (vectorised: this file is compiled with -fno-math-errno) and
  // then contracted with four partial sums.
  thread_local std::vector<double> ds, g;
  ds.resize(N + 1);
  g.resize(N + 1);
  ds[0] = -sigma[0];
  for (int f = 1; f < N; ++f) ds[f] = sigma[f - 1] - sigma[f];
  ds[N] = sigma[N - 1];
  for (int i = 0; i < N; ++i) {
    const double r2 = rho[i] * rho[i], z = zc[i];
    const double* F = faces.data();
    double* G = g.data();
    for (int f = 0; f <= N; ++f) {
      const double dz = z - F[f];
      G[f] = 1.0 / std::sqrt(dz * dz + r2);
    }
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    int f = 0;
    for (; f + 3 <= N; f += 4) {
      s0 += G[f] * ds[f];
      s1 += G[f + 1] * ds[f + 1];
      s2 += G[f + 2] * ds[f + 2];
      s3 += G[f + 3] * ds[f + 3];
    }
    for (; f <= N; ++f) s0 += G[f] * ds[f];
    const double s = (s0 + s1) + (s2 + s3);
    const double d0 = z - z0, dL = z - zL;
    const double q0 = d0 * d0 + r2, qL = dL * dL + r2;
    const double k0 = d0 / (q0 * std::sqrt(q0)), kL = dL / (qL * std::sqrt(qL));
    u[i] = c * (s + m_rear * k0 + m_front * kL);
  }
}

double slender_velocity(const std::vector<double>& zc, const std::vector<double>& faces,
                        const std::vector<double>& sigma, double m_rear, double m_front,
                        const std::vector<double>& rho, double L, double mu, std::vector<double>& u) {
  induced_axial_velocity(zc, faces, sigma, m_rear, m_front, rho, u);
  double cu = 0, c = 0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const double ci = slender_drag_per_length(L, rho[i], mu);
    cu += ci * u[i];
    c += ci;
  }
  return cu / c;
}

void end_junction(const EndJunction& j, double R, double Rc, double mu, double M[3][3], double& rim) {
  const double xg = std::clamp(std::log(Rc / R - 1.0), j.xg_min, j.xg_max);
  double v[6];
  for (int k = 0; k < 6; ++k) v[k] = j.b[k][0] + j.b[k][1] * xg;
  const double B[3][3] = {{v[0], 0, 0}, {v[1], v[2], 0}, {v[3], v[4], v[5]}};
  const double S[3] = {std::pow(R, -1.5), std::pow(R, -1.5), std::sqrt(R)};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c <= r; ++c) {
      double bb = 0;
      for (int k = 0; k <= c; ++k) bb += B[r][k] * B[c][k];
      M[r][c] = M[c][r] = mu * S[r] * bb * S[c];
    }
  rim = j.rim[0] + j.rim[1] * xg;
}

void end_junction_d(const EndJunction& j, double R, double Rc, double mu, double M[3][3], double& rim,
                    double dM[3][3], double& drim) {
  end_junction(j, R, Rc, mu, M, rim);
  const double xr = std::log(Rc / R - 1.0);
  const double xg = std::clamp(xr, j.xg_min, j.xg_max);
  const double dxg = (xr > j.xg_min && xr < j.xg_max) ? -Rc / (R * (Rc - R)) : 0.0;
  double v[6], dv[6];
  for (int k = 0; k < 6; ++k) v[k] = j.b[k][0] + j.b[k][1] * xg, dv[k] = j.b[k][1] * dxg;
  const double B[3][3] = {{v[0], 0, 0}, {v[1], v[2], 0}, {v[3], v[4], v[5]}};
  const double dB[3][3] = {{dv[0], 0, 0}, {dv[1], dv[2], 0}, {dv[3], dv[4], dv[5]}};
  const double S[3] = {std::pow(R, -1.5), std::pow(R, -1.5), std::sqrt(R)};
  const double dS[3] = {-1.5 * S[0] / R, -1.5 * S[1] / R, 0.5 * S[2] / R};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c <= r; ++c) {
      double bb = 0, dbb = 0;
      for (int k = 0; k <= c; ++k) bb += B[r][k] * B[c][k], dbb += dB[r][k] * B[c][k] + B[r][k] * dB[c][k];
      dM[r][c] = dM[c][r] = mu * ((dS[r] * S[c] + S[r] * dS[c]) * bb + S[r] * S[c] * dbb);
    }
  drim = j.rim[1] * dxg;
}

ConfinedSystem::ConfinedSystem(int npoints, const std::vector<double>& dd, double mu_, double a_in_, double a_out_,
                               double Rc_, double period, double L_)
    : np(npoints),
      ni(npoints - 1),
      mu(mu_),
      a_in(a_in_),
      a_out(a_out_),
      Rc(Rc_),
      Pd(period),
      L(L_),
      r_free((period - L_) * 8.0 * mu_ / (pi * Rc_ * Rc_ * Rc_ * Rc_)),
      A_c(pi * Rc_ * Rc_),
      d(dd),
      k(npoints - 1),
      Q_in(npoints - 1, 0.0),
      dPi(npoints - 1, 0.0),
      w(npoints - 1, 0.0),
      pts_(npoints),
      dpts_(npoints) {}

bool ConfinedSystem::geometry(const double* Rpt, bool derivatives) {
  const double Ro_max = Rc * (1.0 - 1e-3);
  R_end_[0] = Rpt[0];
  R_end_[1] = Rpt[np - 1];
  if (junction) R_pt_.assign(Rpt, Rpt + np);
  if (derivatives)
    for (int p = 0; p < np; ++p) {
      const double Ro = Rpt[p] + a_out, Ri = Rpt[p] - a_in;
      if (!(Ro < Ro_max) || !(Ri > 0)) return false;
    }
  if (!derivatives) {
    // Two passes: the logarithms, then the arithmetic (independent per point, so the
    // divisions pipeline instead of waiting behind each call). A point whose radius is
    // bitwise the one of the previous call keeps its values (prescribed waves hold most of
    // the tube at R0 or R_min exactly), so the result does not depend on the cache.
    lambda_.resize(np);
    last_Ro_.resize(np, -1.0);
    changed_.clear();
    // One division per point: with n = lambda (Rc^4 - Ro^4) - D2^2 = lambda G_a / c8,
    // 1 / lambda = n / (lambda n) and 1 / G_a = lambda^2 / (c8 lambda n).
    const double iRc = 1.0 / Rc;
    // (an unchanged radius passed the range check before)
    for (int p = 0; p < np; ++p) {
      const double Ro = Rpt[p] + a_out;
      if (Ro == last_Ro_[p]) continue;
      if (!(Ro < Ro_max) || !(Rpt[p] - a_in > 0)) {
        last_Ro_.assign(np, -1.0);  // this call's partial updates leave nothing cached
        interval_valid_ = false;
        return false;
      }
      last_Ro_[p] = Ro;
      lambda_[changed_.size()] = Ro * iRc;
      changed_.push_back(p);
    }
    const int nc = int(changed_.size());
    v4::log_n(lambda_.data(), lambda_.data(), nc);  // lambda_[m] = log(Ro / Rc) of changed_[m]
    const double Rc2 = Rc * Rc, Rc4 = Rc2 * Rc2, ic8 = 8.0 * mu / pi;
    for (int m = 0; m < nc; ++m) {
      const int p = changed_[m];
      const double Ro = Rpt[p] + a_out, Ro2 = Ro * Ro, lam = -lambda_[m];
      const double D2 = Rc2 - Ro2;
      const double n = lam * (Rc4 - Ro2 * Ro2) - D2 * D2;
      const double inv = 1.0 / (lam * n);
      const double il = n * inv;
      const double S = (0.5 * pi) * D2 * il;
      AnnulusPoint<double>& a = pts_[p];
      a.rho = (lam * lam * ic8) * inv;
      a.kappa = (pi * Rc2 - S) * a.rho;
      a.S = S;
      a.e = (2.0 * pi * mu) * il;
    }
  }
  if (derivatives) last_Ro_.assign(np, -1.0);  // the point values below come from another formula
  for (int p = 0; p < np && derivatives; ++p) {
    const double Ro = Rpt[p] + a_out;
    {
      const AnnulusPointD a = annulus_point_d(Ro, Rc, mu);
      pts_[p] = a.f;
      dpts_[p] = a.df;
    }
  }
  // Intervals whose two points kept their radii keep their coefficients (cache above). An
  // interval's coefficients depend on its two points only, so recomputing every interval
  // gives the same values; when at least half the points changed (a Newton iteration moves
  // every cell, and only the end radii may stay), that is cheaper than finding the intervals.
  const bool all = derivatives || 2 * changed_.size() >= std::size_t(np) || !interval_valid_;
  const double kl = 8.0 * mu / (3.0 * pi), ain = a_in;
  const double* dd = d.data();
  const AnnulusPoint<double>* pt = pts_.data();
  IntervalCoef<double>* kc = k.data();
  double* wj = w.data();
  // rl = m / D with m = (8 mu / 3 pi) d (a^2 + ab + b^2), D = (ab)^3; rl and
  // w = 1 / (rl + ra) = D / (m + ra D) share one division.
  auto interval = [&](int j) {
    const double ai = Rpt[j] - ain, bi = Rpt[j + 1] - ain, ab = ai * bi, dj = dd[j];
    IntervalCoef<double>& c = kc[j];
    const auto &pa = pt[j], &pb = pt[j + 1];
    const double ra = 0.5 * dj * (pa.rho + pb.rho);
    c.ra = ra;
    c.c = 0.5 * dj * (pa.kappa + pb.kappa);
    c.S = 0.5 * (pa.S + pb.S);
    c.e = 0.5 * dj * (pa.e + pb.e);
    const double m = kl * dj * (ai * ai + ab + bi * bi), D = ab * ab * ab, sum = m + ra * D;
    const double inv = 1.0 / (D * sum);
    c.rl = m * sum * inv;
    wj[j] = D * D * inv;
  };
  if (all) {
    for (int j = 0; j < ni; ++j) interval(j);
  } else {
    // the intervals touching a changed point (changed_ ascending), each once
    int last = -1;
    for (int p : changed_)
      for (int j = std::max(p - 1, last + 1); j <= std::min(p, ni - 1); ++j) {
        interval(j);
        last = j;
      }
  }
  if (drainage_ends)  // the open ends' half cells: the drainage layer's lumen resistance
    for (int j : {0, ni - 1}) {
      const double M4 = disc::mean_R4(Rpt[j] - ain, Rpt[j + 1] - ain), kd = (8.0 * mu / pi) * dd[j];
      kc[j].rl = kd / M4;
      wj[j] = M4 / (kd + kc[j].ra * M4);
    }
  interval_valid_ = !derivatives;
  return true;
}

void ConfinedSystem::transmural(const double* Pi, double F_ext, const double* Rdot) {
  if (junction) {
    transmural_junction(Pi, F_ext, Rdot);
    return;
  }
  // Unknowns W = Q_tot + U A_c (the lab-frame flux through the free pipe) and U; in these the
  // 2 x 2 is well conditioned (Q_tot itself is close to -U A_c).
  //   Q_in,j = alpha_j W + beta_j U - gamma_j,  alpha = ra / (rl + ra),
  //   beta = (c - A_c ra) / (rl + ra),  gamma = dPi / (rl + ra).
  // Periodicity: sum rl Q_in + r_free W = 0.  Force: sum S dp_out + U sum e = F_ext with
  // dp_out = -rl Q_in - dPi.
  double m11 = r_free, m12 = 0, b1 = 0, m21 = 0, m22 = 0, b2 = F_ext;
  for (int j = 0; j < ni; ++j) {
    const auto& c = k[j];
    const double wj = w[j];
    const double alpha = c.ra * wj, beta = (c.c - A_c * c.ra) * wj, dpi = Pi[j + 1] - Pi[j];
    dPi[j] = dpi;
    m11 += c.rl * alpha;
    m12 += c.rl * beta;
    b1 += c.rl * dpi * wj;
    m21 -= c.S * c.rl * alpha;
    m22 += c.e - c.S * c.rl * beta;
    b2 += c.S * alpha * dpi;
  }
  M[0][0] = m11, M[0][1] = m12, M[1][0] = m21, M[1][1] = m22;
  const double det = m11 * m22 - m12 * m21;
  W = (b1 * m22 - m12 * b2) / det;
  U = (m11 * b2 - m21 * b1) / det;
  Q_tot = W - A_c * U;
  dp_tube = 0;
  for (int j = 0; j < ni; ++j) {
    const auto& c = k[j];
    Q_in[j] = (c.ra * W + (c.c - A_c * c.ra) * U - dPi[j]) * w[j];
    dp_tube -= c.rl * Q_in[j];
  }
}

void ConfinedSystem::transmural_junction(const double* Pi, double F_ext, const double* Rdot) {
  // Unknowns z = (W, U, Pi_0, Pi_L); Q_in,j = alpha_j W + beta_j U - w_j dPi_j with
  // dPi_0 = Pi_1 - Pi_0 and dPi_N = Pi_L - Pi_N. At each end x_e = (Q_in,e, Q_tot - Q_in,e, U)
  // (e = 0: the rear face, N: the front face) and the junction's pressure p_J,e joins the
  // lumen at p_J0 - (M_r x_r)_0 and the annulus at p_J0 - (M_r x_r)_1 (the rear), at
  // p_JL + (M_f x_f)_0 and p_JL + (M_f x_f)_1 (the front). The four rows:
  //   g1 = sum rl Q_in + r_free W + (M_r x_r)_0 + (M_f x_f)_0                       (periodicity)
  //   g2 = sum (-S rl Q_in - S dPi + e U) + (M_r x_r)_2 + (M_f x_f)_2 - F_ext - thrust  (force)
  //   g3 = Pi_0 + (M_r x_r)_0 - (M_r x_r)_1,   g4 = Pi_L - (M_f x_f)_0 + (M_f x_f)_1
  // all affine in z: G z = -g(0).
  JunctionClosure& J = jc;
  const int f = ni - 1;
  // The junction at the end radius held to the fitted range Rc / R = 1 + exp(x_g): a force-driven
  // wave's quasi-static end radius leaves it (a held end segment pinches its end to 0.1 R0 and
  // below), where the fit's R^-3 scale would close the wide annulus's mouth.
  double Rj[2], in[2];
  for (int e = 0; e < 2; ++e) {
    const double lo = Rc / (1.0 + std::exp(junction->xg_max)), hi = Rc / (1.0 + std::exp(junction->xg_min));
    Rj[e] = std::clamp(R_end_[e], lo, hi);
    in[e] = (R_end_[e] > lo && R_end_[e] < hi) ? 1.0 : 0.0;
    end_junction_d(*junction, Rj[e], Rc, mu, J.M[e], J.rim[e], J.dM[e], J.drim[e]);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) J.dM[e][r][c] *= in[e];
    J.drim[e] *= in[e];
  }
  // the rims' thrust: (+ at the rear, - at the front) rim mu R sum_i wt(z_i) Rdot_i h_i
  J.dthrust_dV.assign(np, 0.0);
  J.thrust = 0.0;
  J.dthrust[0] = J.dthrust[1] = 0.0;
  if (junction->rim_length > 0 && Rdot) {
    double z = 0;
    for (int i = 0; i + 2 < np; ++i) {
      z += d[i];
      // the cell's length: the end intervals are half cells (the solver's point set)
      const double hc = (i == 0 ? d[0] : 0.5 * d[i]) + (i + 2 == ni ? d[ni - 1] : 0.5 * d[i + 1]);
      for (int e = 0; e < 2; ++e) {
        const double R = Rj[e], lr = junction->rim_length * R, dist = e == 0 ? z : L - z;
        const double wt = std::exp(-dist / lr) / lr, dwt = wt * (dist / (lr * R) - 1.0 / R);
        const double sg = e == 0 ? 1.0 : -1.0, c = sg * mu * hc;
        J.thrust += c * J.rim[e] * R * wt * Rdot[i + 1];
        J.dthrust_dV[i + 1] += c * J.rim[e] * R * wt;
        J.dthrust[e] += in[e] * c * (J.drim[e] * R * wt + J.rim[e] * wt + J.rim[e] * R * dwt) * Rdot[i + 1];
      }
    }
  }
  // interval sums with Pi_0 = Pi_L = 0 (z = 0)
  double m11 = r_free, m12 = 0, b1 = 0, m21 = 0, m22 = 0, b2 = 0;
  for (int j = 0; j < ni; ++j) {
    const auto& c = k[j];
    const double wj = w[j];
    const double alpha = c.ra * wj, beta = (c.c - A_c * c.ra) * wj;
    const double dpi = (j == 0 ? Pi[1] : (j == f ? -Pi[j] : Pi[j + 1] - Pi[j]));
    m11 += c.rl * alpha;
    m12 += c.rl * beta;
    b1 += c.rl * dpi * wj;
    m21 -= c.S * c.rl * alpha;
    m22 += c.e - c.S * c.rl * beta;
    b2 += c.S * alpha * dpi;
  }
  const double dpi0 = Pi[1], dpiN = -Pi[f];
  const double Q0z = -w[0] * dpi0, QNz = -w[f] * dpiN;  // the end fluxes at z = 0
  // g(0) and G without the ends' dissipation
  double g0[4] = {-b1, -b2 - F_ext - J.thrust, 0.0, 0.0};
  double G[4][4] = {{m11, m12, k[0].rl * w[0], -k[f].rl * w[f]},
                    {m21, m22, k[0].S * k[0].ra * w[0], -k[f].S * k[f].ra * w[f]},
                    {0, 0, 1, 0},
                    {0, 0, 0, 1}};
  // the ends: d(M x_e)_r / dz = (M_r0 - M_r1) n_e + M_r1 (1, -A_c, 0, 0) + M_r2 (0, 1, 0, 0)
  const double ne[2][4] = {{k[0].ra * w[0], (k[0].c - A_c * k[0].ra) * w[0], w[0], 0.0},
                           {k[f].ra * w[f], (k[f].c - A_c * k[f].ra) * w[f], 0.0, -w[f]}};
  const double Qez[2] = {Q0z, QNz};
  // row weights of (M x_e)_0, _1, _2 in g1 .. g4
  const double wr[2][4][3] = {{{1, 0, 0}, {0, 0, 1}, {1, -1, 0}, {0, 0, 0}}, {{1, 0, 0}, {0, 0, 1}, {0, 0, 0}, {-1, 1, 0}}};
  for (int e = 0; e < 2; ++e) {
    const auto& Me = J.M[e];
    for (int r = 0; r < 3; ++r) {
      double dz[4];
      for (int m = 0; m < 4; ++m) dz[m] = (Me[r][0] - Me[r][1]) * ne[e][m];
      dz[0] += Me[r][1];
      dz[1] += -A_c * Me[r][1] + Me[r][2];
      const double v0 = (Me[r][0] - Me[r][1]) * Qez[e];
      for (int row = 0; row < 4; ++row) {
        const double c = wr[e][row][r];
        if (c == 0.0) continue;
        g0[row] += c * v0;
        for (int m = 0; m < 4; ++m) G[row][m] += c * dz[m];
      }
    }
  }
  Eigen::Matrix4d A;
  Eigen::Vector4d b;
  for (int r = 0; r < 4; ++r) {
    for (int m = 0; m < 4; ++m) A(r, m) = J.G[r][m] = G[r][m];
    b(r) = -g0[r];
  }
  const Eigen::Vector4d x = A.partialPivLu().solve(b);
  W = x(0);
  U = x(1);
  J.Pi0 = x(2);
  J.PiL = x(3);
  Q_tot = W - A_c * U;
  M[0][0] = m11, M[0][1] = m12, M[1][0] = m21, M[1][1] = m22;  // the plain 2 x 2 (drag_coefficient)
  dp_tube = 0;
  for (int j = 0; j < ni; ++j) {
    const auto& c = k[j];
    const double Pa = j == 0 ? J.Pi0 : Pi[j], Pb = j == f ? J.PiL : Pi[j + 1];
    dPi[j] = Pb - Pa;
    Q_in[j] = (c.ra * W + (c.c - A_c * c.ra) * U - dPi[j]) * w[j];
    dp_tube -= c.rl * Q_in[j];
  }
  for (int e = 0; e < 2; ++e) {
    const double q = e == 0 ? Q_in[0] : Q_in[f];
    J.x[e][0] = q, J.x[e][1] = Q_tot - q, J.x[e][2] = U;
    const auto& Me = J.M[e];
    mouth_[e] = Me[0][0] * J.x[e][0] + Me[0][1] * J.x[e][1] + Me[0][2] * J.x[e][2];
  }
  // junction pressure rise p_JL - p_J0: the lumen's drop and both mouths
  dp_tube -= mouth_[0] + mouth_[1];
  rl_end_[0] = rl_end_[1] = 0.0;
}

void ConfinedSystem::kinematic(const double* s_cum, double F_ext) {
  // Unknowns x = (Q_in0, Q_tot, U, dp) with Q_in,j = Q_in0 - s_j, Q_out,j = Q_tot - Q_in,j:
  //   lumen   dp = -sum rl (Q_in0 - s)
  //   annulus dp = -sum ra (Q_tot - Q_in0 + s) - U sum c
  //   free    dp = r_free (Q_tot + U A_c)
  //   force   sum S (-ra (Q_tot - Q_in0 + s) - c U) + U sum e = F_ext
  double RL = 0, RLs = 0, RA = 0, RAs = 0, C = 0, SRA = 0, SRAs = 0, SC = 0, E = 0;
  for (int j = 0; j < ni; ++j) {
    const auto& c = k[j];
    RL += c.rl, RLs += c.rl * s_cum[j];
    RA += c.ra, RAs += c.ra * s_cum[j];
    C += c.c;
    SRA += c.S * c.ra, SRAs += c.S * c.ra * s_cum[j];
    SC += c.S * c.c;
    E += c.e;
  }
  rl_end_[0] = rl_end_[1] = 0.0;
  if (ends.any()) {
    // each end: a rigid extension at the end's radius, through which the end's fluxes pass
    // unchanged (s = 0 at the rear, the whole displaced flux s_N at the front)
    for (int b = 0; b < 2; ++b) {
      const double s = b == 0 ? 0.0 : s_cum[ni - 1];
      const double Ri = R_end_[b] - a_in, Ro = R_end_[b] + a_out;
      const AnnulusPoint<double>& a = pts_[b == 0 ? 0 : np - 1];
      const double rl = (8.0 * mu / pi) * ends.lumen / (Ri * Ri * Ri);  // 8 mu (c R_i) / (pi R_i^4)
      const double da = ends.annulus * (Rc - Ro);
      const double ra = da * a.rho, cc = da * a.kappa;
      rl_end_[b] = rl;
      RL += rl, RLs += rl * s;
      RA += ra, RAs += ra * s;
      C += cc;
      SRA += a.S * ra, SRAs += a.S * ra * s;
      SC += a.S * cc;
      E += da * a.e;
    }
  }
  Eigen::Matrix4d A;
  Eigen::Vector4d b;
  A << RL, 0, 0, 1, /**/ -RA, RA, C, 1, /**/ 0, -r_free, -r_free * A_c, 1, /**/ SRA, -SRA, E - SC, 0;
  b << RLs, -RAs, 0, F_ext + SRAs;
  double Mj[2][3][3];
  if (junction) {
    // At each end x_e = (q_l, q_a, U) = (Q_in0 - s_e, Q_tot - Q_in0 + s_e, U) with s_e = 0 at the
    // rear and the whole displaced flux at the front: dD/dq_l joins the lumen row, dD/dq_a the
    // annulus row and dD/dU the force row (each a resistance term on the rows' left side).
    const double sN = s_cum[ni - 1];
    double z = 0;  // cell centres (points 1 .. np - 2) from the rear end
    double rim_rate[2] = {0, 0}, rim[2] = {0, 0};
    for (int e = 0; e < 2; ++e) end_junction(*junction, R_end_[e], Rc, mu, Mj[e], rim[e]);
    const double lr[2] = {junction->rim_length * R_end_[0], junction->rim_length * R_end_[1]};
    for (int i = 0; i + 2 < np && junction->rim_length > 0; ++i) {
      z += d[i];
      const double Rdot_h = (s_cum[i + 1] - s_cum[i]) / (2.0 * pi * R_pt_[i + 1]);  // dR/dt times the cell length
      rim_rate[0] += std::exp(-z / lr[0]) / lr[0] * Rdot_h;
      rim_rate[1] += std::exp(-(L - z) / lr[1]) / lr[1] * Rdot_h;
    }
    const int rows[3] = {0, 1, 3};
    for (int e = 0; e < 2; ++e) {
      const double se = e == 0 ? 0.0 : sN;
      const auto& Me = Mj[e];
      for (int r = 0; r < 3; ++r) {
        A(rows[r], 0) += Me[r][0] - Me[r][1];
        A(rows[r], 1) += Me[r][1];
        A(rows[r], 2) += Me[r][2];
        b(rows[r]) -= (Me[r][1] - Me[r][0]) * se;
      }
      // the rim's thrust: away from the end for a contraction next to it
      b(3) += (e == 0 ? 1.0 : -1.0) * rim[e] * mu * R_end_[e] * rim_rate[e];
    }
  }
  const Eigen::Vector4d x = A.partialPivLu().solve(b);
  mouth_[0] = mouth_[1] = 0.0;
  if (junction)
    for (int e = 0; e < 2; ++e) {
      const double se = e == 0 ? 0.0 : s_cum[ni - 1];
      mouth_[e] = Mj[e][0][0] * (x(0) - se) + Mj[e][0][1] * (x(1) - x(0) + se) + Mj[e][0][2] * x(2);
    }
  Q_tot = x(1);
  U = x(2);
  W = Q_tot + A_c * U;
  dp_tube = x(3);
  for (int j = 0; j < ni; ++j) Q_in[j] = x(0) - s_cum[j];
}

void ConfinedSystem::lumen_pressure(std::vector<double>& p) const {
  p.resize(np);
  p[0] = -0.5 * dp_tube - rl_end_[0] * Q_in[0] - mouth_[0];
  for (int j = 0; j < ni; ++j) p[j + 1] = p[j] - k[j].rl * Q_in[j];
}

double ConfinedSystem::drag_coefficient() const {
  // Rigid tow (dPi = 0) by an external force F_ext: W = -M12 U / M11 from the periodicity
  // row, so F_ext = (M22 - M21 M12 / M11) U; the fluid's drag on the tube is -zeta U.
  return M[1][1] - M[1][0] * M[0][1] / M[0][0];
}

}  // namespace swim::reduced1d::outer
