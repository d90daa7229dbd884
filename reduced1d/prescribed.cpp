// Prescribed Step/Sine waves: the radius is analytic, so the only ODE states are the
// time integrals of the swimmer velocity and of the end fluxes.
// Force-free model: X' = U from the outer flow (confined: the 4 x 4 kinematic closure of
// outer::ConfinedSystem; unbounded: the slender-body average), V' = lumen end fluxes.
// Paper mode: D' = drag integrand, X' = W = (thrust - D - c X) / m_eff; the end fluxes come
// from the open-ended lubrication flow driven by the prescribed wall motion (mass
// conserving); the closure only selects which dp/dz enters W.
// States: (D, X, V_rear, V_front, V_rear_lab, V_front_lab), scaled.
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "reduced1d/discretisation.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/outer_flow.hpp"
#include "reduced1d/sundials.hpp"

namespace swim::reduced1d::detail {

namespace {

using disc::pi;

struct PrescribedModel {
  const Params& P;
  disc::PrescribedShape shape;
  disc::BalanceCoefficients bal;
  int N;
  double L, h, R0, C1, mu;
  bool flow_closure, force_free, confined;
  double a_in, a_out;
  // workspace (sized once)
  std::vector<double> zpt, dpt, Rpt, Rtc, At, r, Q, dp, scum, zc, faces, rho, u_ind, pl;
  std::unique_ptr<outer::ConfinedSystem> sys;
  // state scales: y = (D / D_s, X / X_s, V_rear / V_s, V_front / V_s)
  double D_s = 1, X_s = 1, V_s = 1;

  struct Eval {
    double f = 0, thrust = 0, Q0 = 0, QN = 0;
    double U = 0, p0 = 0, pL = 0, Qt = 0;  // force-free
    bool ok = true;
  };

  explicit PrescribedModel(const Params& p)
      : P(p),
        shape(disc::PrescribedShape::from(p)),
        bal(disc::BalanceCoefficients::from(p)),
        N(p.numerics.cells),
        L(p.geometry.L),
        h(p.geometry.L / p.numerics.cells),
        R0(p.geometry.R0),
        C1(p.wall.C1),
        mu(p.fluid.mu),
        flow_closure(p.swimmer.closure == Closure::Flow),
        force_free(p.swimmer.model == SwimmerModel::ForceFree),
        confined(force_free && p.swimmer.outer == OuterFlow::Confined),
        a_in(force_free ? p.swimmer.a_in : 0.0),
        a_out(force_free ? p.swimmer.a_out : 0.0),
        zpt(N + 2),
        dpt(N + 1),
        Rpt(N + 2),
        Rtc(N),
        At(N),
        r(N + 1),
        Q(N + 1),
        dp(N + 1) {
    zpt[0] = 0;
    for (int i = 0; i < N; ++i) zpt[i + 1] = (i + 0.5) * h;
    zpt[N + 1] = L;
    for (int j = 0; j <= N; ++j) dpt[j] = (j == 0 || j == N) ? 0.5 * h : h;
    const double T = end_time(p);
    const double f_s = bal.per_length ? pi * C1 * R0 * R0 * R0 / L : C1 * R0 * R0 / (2.0 * L);
    D_s = f_s * T;
    X_s = force_free ? R0 : D_s * T / (bal.m_eff + bal.c_ext * T);
    V_s = pi * R0 * R0 * L;
    scum.assign(N + 1, 0.0);
    if (confined) {
      sys = std::make_unique<outer::ConfinedSystem>(N + 2, dpt, mu, a_in, a_out, p.container.radius_eff,
                                                    p.container.period, L);
      sys->ends = {p.swimmer.end_lumen, p.swimmer.end_annulus};
      if (p.swimmer.end_junction) sys->junction = &outer::kCalibratedJunction;
    } else if (force_free) {
      zc.assign(zpt.begin() + 1, zpt.end() - 1);
      faces.resize(N + 1);
      for (int j = 0; j <= N; ++j) faces[j] = j * h;
      rho.assign(N, R0);
    }
  }

  /// Radius at the points, flux at the faces, pressure differences, swimmer integrands at t.
  Eval evaluate(double t) {
    // the end points, then the cell centres (uniform spacing h) in one pass
    double Rt_end;
    shape.eval(zpt[0], t, Rpt[0], Rt_end);
    shape.eval(zpt[N + 1], t, Rpt[N + 1], Rt_end);
    shape.eval_uniform(zpt[1], h, N, t, Rpt.data() + 1, Rtc.data());
    for (int i = 0; i < N; ++i) At[i] = 2.0 * pi * Rpt[i + 1] * Rtc[i];
    Eval e;
    if (confined) {
      double S = 0;
      for (int j = 0; j <= N; ++j) {
        scum[j] = S;
        if (j < N) S += h * At[j];
      }
      if (!sys->geometry(Rpt.data())) {
        e.ok = false;
        return e;
      }
      sys->kinematic(scum.data());
      for (int j = 0; j <= N; ++j) Q[j] = sys->Q_in[j];
      sys->lumen_pressure(pl);
      e.Q0 = Q[0], e.QN = Q[N], e.U = sys->U, e.Qt = sys->Q_tot, e.p0 = pl[0], e.pL = pl[N + 1];
      return e;
    }
    // Open-ended flow: Q_j = Q_0 - S_j, S_j = h sum_{i<j} A_t,i, sum_j r_j Q_j = 0.
    double S = 0, sr = 0, srS = 0;
    for (int j = 0; j <= N; ++j) {
      r[j] = disc::resistance(mu, dpt[j], Rpt[j] - a_in, Rpt[j + 1] - a_in);
      Q[j] = S;  // holds S_j for now
      sr += r[j];
      srS += r[j] * S;
      if (j < N) S += h * At[j];
    }
    const double Q0 = srS / sr;
    for (int j = 0; j <= N; ++j) Q[j] = Q0 - Q[j];
    e.Q0 = Q[0];
    e.QN = Q[N];
    if (force_free) {  // unbounded: slender-body average of the induced axial flow
      for (int i = 0; i < N; ++i) rho[i] = Rpt[i + 1] + a_out;
      e.U = outer::slender_velocity(zc, faces, At, -Q[0], Q[N], rho, L, mu, u_ind);
      return e;
    }
    if (flow_closure) {
      for (int j = 0; j <= N; ++j) dp[j] = -r[j] * Q[j];
    } else {
      for (int j = 0; j <= N; ++j) dp[j] = C1 * (Rpt[j + 1] - Rpt[j]);
    }
    const auto I = disc::pressure_integrals(Rpt.data(), dp.data(), N + 2);
    e.f = bal.drag_integrand(I);
    e.thrust = bal.thrust_term(I);
    return e;
  }

  static int rhs(double t, N_Vector y, N_Vector ydot, void* user) {
    auto* m = static_cast<PrescribedModel*>(user);
    const double* Y = sun::data(y);
    double* F = sun::data(ydot);
    const Eval e = m->evaluate(t);
    if (!e.ok) return -1;  // the wall reached the container: not recoverable
    const double W = m->velocity(e, Y);
    F[0] = m->force_free ? 0.0 : e.f / m->D_s;
    F[1] = W / m->X_s;
    F[2] = e.Q0 / m->V_s;
    F[3] = e.QN / m->V_s;
    F[4] = (e.Q0 + W * pi * m->Rpt[0] * m->Rpt[0]) / m->V_s;
    F[5] = (e.QN + W * pi * m->Rpt[N_end(m)] * m->Rpt[N_end(m)]) / m->V_s;
    for (int k = 0; k < kStates; ++k)
      if (!std::isfinite(F[k])) return 1;
    return 0;
  }
  static int N_end(const PrescribedModel* m) { return m->N + 1; }
  double velocity(const Eval& e, const double* Y) const {
    return force_free ? e.U : bal.velocity(e.thrust, Y[0] * D_s, Y[1] * X_s);
  }
  static constexpr int kStates = 6;
};

void add_stat(std::map<std::string, long>& s, const char* k, long v) { s[k] += v; }

// ---------------------------------------------------------------------------------------
// Quadrature path (force-free model). The wall motion is prescribed and U, Q_rear, Q_front
// are instantaneous functions of t, so X, V_rear, V_front and the lab-frame volumes are plain
// integrals. They are evaluated on the output grid (whose samples need the evaluations
// anyway): per interval the cubic through four neighbouring output times, checked against a
// second cubic shifted by one node; an interval whose estimate exceeds the integrator's
// tolerance (rtol |y| + atol_scale, on the scaled states) is integrated by adaptive Simpson.

/// Integrands of the five quadrature states (scaled): X, V_rear, V_front, V_rear_lab,
/// V_front_lab.
constexpr int kQuad = 5;
using QVec = std::array<double, kQuad>;

QVec integrands(const PrescribedModel& m, const PrescribedModel::Eval& e) {
  const double Rb0 = m.Rpt[0], RbL = m.Rpt[m.N + 1];
  return {e.U / m.X_s, e.Q0 / m.V_s, e.QN / m.V_s, (e.Q0 + e.U * pi * Rb0 * Rb0) / m.V_s,
          (e.QN + e.U * pi * RbL * RbL) / m.V_s};
}

/// Integral over [x[i1], x[i1 + 1]] of the cubic through the four nodes x[j0 .. j0 + 3]
/// (weights by 3-point Gauss-Legendre on the Lagrange basis, exact for cubics).
QVec cubic_piece(const std::vector<double>& x, const std::vector<QVec>& f, int j0, int i1) {
  const double a = x[i1], b = x[i1 + 1], c = 0.5 * (a + b), r = 0.5 * (b - a);
  const double g = std::sqrt(0.6);
  const double node[3] = {c - g * r, c, c + g * r}, wt[3] = {5.0 / 9.0 * r, 8.0 / 9.0 * r, 5.0 / 9.0 * r};
  QVec out{};
  for (int m = 0; m < 4; ++m) {
    double w = 0;
    for (int q = 0; q < 3; ++q) {
      double l = 1.0;
      for (int n = 0; n < 4; ++n)
        if (n != m) l *= (node[q] - x[j0 + n]) / (x[j0 + m] - x[j0 + n]);
      w += wt[q] * l;
    }
    for (int k = 0; k < kQuad; ++k) out[k] += w * f[j0 + m][k];
  }
  return out;
}

struct QuadratureContext {
  PrescribedModel& model;
  double rtol, atol;
  long evals = 0, pieces = 0;
  long budget = 0;  // numerics.max_steps: evaluations allowed in the refinement
  bool ok = true, exhausted = false;
  double t_fail = 0;

  bool eval(double t, QVec& f) {
    if (++evals > budget) {
      ok = false;
      exhausted = true;
      t_fail = t;
      return false;
    }
    const auto e = model.evaluate(t);
    if (!e.ok) {
      ok = false;
      t_fail = t;
      return false;
    }
    f = integrands(model, e);
    for (double v : f)
      if (!std::isfinite(v)) {
        ok = false;
        t_fail = t;
        return false;
      }
    return true;
  }
  static bool within(const QVec& err, const QVec& tol) {
    for (int k = 0; k < kQuad; ++k)
      if (!(std::abs(err[k]) <= tol[k])) return false;
    return true;
  }
  /// Adaptive Simpson on [a, b] with f(a), f(b), f(m) known; tolerance per component.
  QVec simpson(double a, double b, const QVec& fa, const QVec& fm, const QVec& fb, const QVec& whole,
               const QVec& tol, int depth) {
    const double m = 0.5 * (a + b), h = b - a;
    QVec fl, fr;
    if (!eval(0.5 * (a + m), fl) || !eval(0.5 * (m + b), fr)) return whole;
    QVec left, right, sum, err;
    for (int k = 0; k < kQuad; ++k) {
      left[k] = h / 12.0 * (fa[k] + 4.0 * fl[k] + fm[k]);
      right[k] = h / 12.0 * (fm[k] + 4.0 * fr[k] + fb[k]);
      sum[k] = left[k] + right[k];
      err[k] = (sum[k] - whole[k]) / 15.0;
    }
    ++pieces;
    if (depth >= 40 || within(err, tol) || h <= 1e-14 * std::max(std::abs(a), std::abs(b))) {
      for (int k = 0; k < kQuad; ++k) sum[k] += err[k];
      return sum;
    }
    QVec half;
    for (int k = 0; k < kQuad; ++k) half[k] = 0.5 * tol[k];
    const QVec l = simpson(a, m, fa, fl, fm, left, half, depth + 1);
    if (!ok) return whole;
    const QVec r = simpson(m, b, fm, fr, fb, right, half, depth + 1);
    QVec out;
    for (int k = 0; k < kQuad; ++k) out[k] = l[k] + r[k];
    return out;
  }
  QVec adaptive(double a, double b, const QVec& fa, const QVec& fb, const QVec& tol) {
    QVec fm;
    if (!eval(0.5 * (a + b), fm)) return QVec{};
    QVec whole;
    for (int k = 0; k < kQuad; ++k) whole[k] = (b - a) / 6.0 * (fa[k] + 4.0 * fm[k] + fb[k]);
    return simpson(a, b, fa, fm, fb, whole, tol, 0);
  }
};

/// A Result with the cell centres and zeroed integrator statistics.
Result prepared_result(const PrescribedModel& model) {
  Result res;
  res.z.assign(model.zpt.begin() + 1, model.zpt.end() - 1);
  for (const char* k : {"steps", "rhs_evals", "jac_evals", "lin_setups", "err_test_fails",
                        "nonlin_iters", "nonlin_conv_fails", "root_evals", "reinits"})
    res.stats[k] = 0;
  return res;
}

/// The wall quantities of a sample from an evaluation at the model's current radius: the
/// force split (force-free model), energy, radius extremes, end fluxes and the tube volume.
void fill_wall_sample(const PrescribedModel& model, const PrescribedModel::Eval& e, Sample& s) {
  const int N = model.N;
  if (model.force_free) {
    s.p_rear = e.p0, s.p_front = e.pL, s.Q_total = e.Qt;
    const double Rb0 = model.Rpt[0], RbL = model.Rpt[N + 1];
    s.F_lumen = pi * (Rb0 * Rb0 * e.p0 - RbL * RbL * e.pL);
    s.F_outer = -s.F_lumen;
  }
  // one pass for the four reductions (each summed in the order of disc::elastic_energy and
  // the volume sum, so the values are those of separate passes)
  const double* R = model.Rpt.data() + 1;
  const double R0 = model.R0;
  double de2 = 0, vol = 0, lo = R[0], hi = R[0];
  for (int i = 0; i < N; ++i) {
    const double Ri = R[i];
    de2 += (Ri - R0) * (Ri - R0);
    vol += Ri * Ri;
    lo = Ri < lo ? Ri : lo;
    hi = Ri > hi ? Ri : hi;
  }
  s.energy = 0.5 * model.C1 * de2 * 2.0 * pi * R0 * model.h;
  s.R_min = lo;
  s.R_max = hi;
  s.Q_rear = e.Q0;
  s.Q_front = e.QN;
  s.tube_volume = pi * vol * model.h;
}

Result solve_by_quadrature(const Params& p, PrescribedModel& model, const Output& out) {
  Result res = prepared_result(model);
  const int N = model.N;
  const double t_end = end_time(p);
  const double dt_out = p.numerics.output_interval;
  QuadratureContext qc{model, p.numerics.rtol, p.numerics.atol_scale};
  qc.budget = p.numerics.max_steps;

  // 1. The samples at the output times (everything but the integrated states).
  std::vector<double> tk;
  std::vector<QVec> fk;
  std::vector<Sample> samples;
  std::vector<double> radius;  // the snapshots, until the integrals are known
  const std::size_t expect = std::size_t(std::max(0.0, std::ceil(t_end / dt_out))) + 2;
  tk.reserve(expect), fk.reserve(expect), samples.reserve(expect);
  radius.reserve(expect * std::size_t(N));
  for (long k = 0;; ++k) {
    double t = std::min(double(k) * dt_out, t_end);
    if (t_end - t < 1e-9 * dt_out) t = t_end;
    ++qc.evals;
    const auto e = model.evaluate(t);
    Sample s;
    s.t = t;
    s.W = e.U;
    fill_wall_sample(model, e, s);
    const double* R = model.Rpt.data() + 1;
    const QVec f = integrands(model, e);
    bool fin = e.ok && finite(s);
    for (double v : f) fin = fin && std::isfinite(v);
    if (!fin) {
      res.failure = NumericalError(k == 0 ? "non-finite swimmer quantities at t = 0" : "non-finite swimmer quantities",
                                   k == 0 ? "check the wave parameters (radius must stay positive)"
                                          : "tighten numerics1d.rtol or check the wave parameters",
                                   t);
      break;
    }
    tk.push_back(t);
    fk.push_back(f);
    samples.push_back(s);
    radius.insert(radius.end(), R, R + N);
    if (t >= t_end) break;
  }

  // 2. The integrals per output interval, accumulated into the samples.
  const int n = int(tk.size());
  const double scale_tol = p.numerics.atol_scale;
  QVec Y{};
  if (n > 0) {
    Sample& s0 = samples[0];
    s0.X = 0, s0.V_rear = 0, s0.V_front = 0, s0.V_rear_lab = 0, s0.V_front_lab = 0;
  }
  for (int i = 0; i + 1 < n && qc.ok; ++i) {
    // candidates: cubics through nodes j0 .. j0 + 3 with j0 in [i - 2, i]; the most central
    // one is the value, the next one the error estimate
    QVec I{}, err{};
    bool have = false;
    if (n >= 5) {
      const int jc = std::clamp(i - 1, 0, n - 4);
      const int ja = (jc - 1 >= std::max(0, i - 2)) ? jc - 1 : jc + 1;
      if (ja >= 0 && ja + 3 < n && ja <= i && ja + 3 >= i + 1) {
        I = cubic_piece(tk, fk, jc, i);
        const QVec J = cubic_piece(tk, fk, ja, i);
        for (int k = 0; k < kQuad; ++k) err[k] = I[k] - J[k];
        have = true;
      }
    }
    QVec tol;
    for (int k = 0; k < kQuad; ++k) tol[k] = qc.rtol * std::abs(Y[k] + I[k]) + scale_tol;
    ++res.stats["steps"];
    if (!have || !QuadratureContext::within(err, tol)) {
      I = qc.adaptive(tk[i], tk[i + 1], fk[i], fk[i + 1], tol);
      if (!qc.ok) break;
    }
    for (int k = 0; k < kQuad; ++k) Y[k] += I[k];
    Sample& s = samples[i + 1];
    s.X = Y[0] * model.X_s;
    s.V_rear = Y[1] * model.V_s;
    s.V_front = Y[2] * model.V_s;
    s.V_rear_lab = Y[3] * model.V_s;
    s.V_front_lab = Y[4] * model.V_s;
  }
  int kept = n;
  if (!qc.ok) {
    // the failing evaluation lies inside an interval: keep the samples before it
    kept = int(std::upper_bound(tk.begin(), tk.end(), qc.t_fail) - tk.begin()) - 1;
    kept = std::max(kept, 1);
    if (qc.exhausted)
      res.failure = NumericalError("integrator step budget numerics1d.max_steps exhausted (" +
                                       std::to_string(p.numerics.max_steps) + " closure evaluations in the quadrature)",
                                   "raise numerics1d.max_steps or loosen numerics1d.rtol or numerics1d.atol_scale", qc.t_fail);
    else
      res.failure = NumericalError("the prescribed wave left the model's range during the quadrature (the wall reached the container or the lumen closed)",
                                   "check the wave parameters or raise container.radius", qc.t_fail);
  }
  for (int i = 0; i < kept; ++i) emit(res, out, samples[i], radius.data() + std::size_t(i) * N, N, t_end);
  res.stats["rhs_evals"] = qc.evals;
  res.stats["steps"] += qc.pieces;
  return res;
}

}  // namespace

Result solve_prescribed(const Params& p, const Output& out, PrescribedPath path) {
  PrescribedModel model(p);
  if (model.force_free && path != PrescribedPath::Integrated) return solve_by_quadrature(p, model, out);
  Result res = prepared_result(model);
  const int N = model.N;

  const double t_end = end_time(p);
  const double dt_out = p.numerics.output_interval;
  const bool stiff = !model.force_free && model.bal.c_ext > 0;  // external drag: X relaxes on m/c, stiff
  std::string last_msg;

  auto record = [&](double t, const double* Y) -> bool {
    const auto e = model.evaluate(t);
    if (!e.ok) return false;
    Sample s;
    s.t = t;
    s.X = Y[1] * model.X_s;
    s.W = model.velocity(e, Y);
    s.V_rear_lab = Y[4] * model.V_s;
    s.V_front_lab = Y[5] * model.V_s;
    fill_wall_sample(model, e, s);
    const double* R = model.Rpt.data() + 1;
    s.V_rear = Y[2] * model.V_s;
    s.V_front = Y[3] * model.V_s;
    s.phase = 0;
    if (!finite(s)) return false;
    emit(res, out, s, R, N, t_end);
    return true;
  };

  double t = 0;
  try {
    auto ctx = sun::make_context();
    auto y = sun::make_vector(PrescribedModel::kStates, ctx.get());
    auto cv = sun::make_cvode(stiff ? CV_BDF : CV_ADAMS, ctx.get());
    void* mem = cv.get();
    sun::check(CVodeSetErrHandlerFn(mem, sun::capture_error, &last_msg), "CVodeSetErrHandlerFn");
    sun::check(CVodeInit(mem, PrescribedModel::rhs, 0.0, y.get()), "CVodeInit");
    sun::check(CVodeSStolerances(mem, p.numerics.rtol, p.numerics.atol_scale), "CVodeSStolerances");
    sun::check(CVodeSetUserData(mem, &model), "CVodeSetUserData");
    sun::check(CVodeSetStopTime(mem, t_end), "CVodeSetStopTime");
    sun::check(CVodeSetMaxStep(mem, t_end / 20.0), "CVodeSetMaxStep");
    sun::Matrix A;
    sun::LinearSolver LS;
    sun::NonlinearSolver NLS;
    if (stiff) {
      A = sun::make_dense_matrix(PrescribedModel::kStates, ctx.get());
      LS = sun::make_dense_solver(y.get(), A.get(), ctx.get());
      sun::check(CVodeSetLinearSolver(mem, LS.get(), A.get()), "CVodeSetLinearSolver");
    } else {
      NLS = sun::make_fixed_point_solver(y.get(), 0, ctx.get());
      sun::check(CVodeSetNonlinearSolver(mem, NLS.get()), "CVodeSetNonlinearSolver");
    }

    if (!record(0.0, sun::data(y.get())))
      throw NumericalError("non-finite swimmer quantities at t = 0",
                           "check the wave parameters (radius must stay positive)", 0.0);
    long k = 1;
    while (t < t_end) {
      double tout = std::min(k * dt_out, t_end);
      if (t_end - tout < 1e-9 * dt_out) tout = t_end;
      long nst = 0;
      CVodeGetNumSteps(mem, &nst);
      const long remaining = p.numerics.max_steps - nst;
      if (remaining <= 0)
        throw NumericalError("integrator step budget exhausted",
                             "raise numerics1d.max_steps or loosen numerics1d.rtol or numerics1d.atol_scale", t);
      sun::check(CVodeSetMaxNumSteps(mem, remaining), "CVodeSetMaxNumSteps");
      int flag = CVode(mem, tout, y.get(), &t, CV_NORMAL);
      if (flag == CV_TOO_MUCH_WORK)
        throw NumericalError("integrator step budget numerics1d.max_steps exhausted",
                             "raise numerics1d.max_steps or loosen numerics1d.rtol or numerics1d.atol_scale", t);
      sun::check(flag, "CVode", last_msg);
      if (!record(t, sun::data(y.get())))
        throw NumericalError("non-finite swimmer quantities",
                             "tighten numerics1d.rtol or check the wave parameters", t);
      if (tout >= t_end) break;
      ++k;
    }

    long v = 0;
    CVodeGetNumSteps(mem, &v), add_stat(res.stats, "steps", v);
    CVodeGetNumRhsEvals(mem, &v), add_stat(res.stats, "rhs_evals", v);
    CVodeGetNumLinSolvSetups(mem, &v), add_stat(res.stats, "lin_setups", v);
    CVodeGetNumErrTestFails(mem, &v), add_stat(res.stats, "err_test_fails", v);
    CVodeGetNumNonlinSolvIters(mem, &v), add_stat(res.stats, "nonlin_iters", v);
    CVodeGetNumNonlinSolvConvFails(mem, &v), add_stat(res.stats, "nonlin_conv_fails", v);
    if (stiff) {
      CVodeGetNumJacEvals(mem, &v), add_stat(res.stats, "jac_evals", v);
      CVodeGetNumLinRhsEvals(mem, &v), add_stat(res.stats, "rhs_evals", v);
    }
  } catch (const NumericalError& e) {
    res.failure = e;
  } catch (const sun::SundialsError& e) {
    res.failure = NumericalError("CVODE failed on the prescribed-wave quadratures: " + std::string(e.what()),
                                 "tighten or loosen numerics1d.rtol or numerics1d.atol_scale, or check the wave parameters", t);
  }
  return res;
}

}  // namespace swim::reduced1d::detail
