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
  std::vector<double> zpt, dpt, Rpt, At, r, Q, dp, scum, zc, faces, rho, u_ind, pl;
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
    } else if (force_free) {
      zc.assign(zpt.begin() + 1, zpt.end() - 1);
      faces.resize(N + 1);
      for (int j = 0; j <= N; ++j) faces[j] = j * h;
      rho.assign(N, R0);
    }
  }

  /// Radius at the points, flux at the faces, pressure differences, swimmer integrands at t.
  Eval evaluate(double t) {
    for (int k = 0; k < N + 2; ++k) {
      double R, Rt;
      shape.eval(zpt[k], t, R, Rt);
      Rpt[k] = R;
      if (k >= 1 && k <= N) At[k - 1] = 2.0 * pi * R * Rt;
    }
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

}  // namespace

Result solve_prescribed(const Params& p, const ProgressFn& progress) {
  Result res;
  PrescribedModel model(p);
  const int N = model.N;
  res.z.assign(model.zpt.begin() + 1, model.zpt.end() - 1);
  for (const char* k : {"steps", "rhs_evals", "jac_evals", "lin_setups", "err_test_fails",
                        "nonlin_iters", "nonlin_conv_fails", "root_evals", "reinits"})
    res.stats[k] = 0;

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
    if (model.force_free) {
      s.p_rear = e.p0, s.p_front = e.pL, s.Q_total = e.Qt;
      const double Rb0 = model.Rpt[0], RbL = model.Rpt[N + 1];
      s.F_lumen = pi * (Rb0 * Rb0 * e.p0 - RbL * RbL * e.pL);
      s.F_outer = -s.F_lumen;
    }
    const double* R = model.Rpt.data() + 1;
    s.energy = disc::elastic_energy(R, N, model.R0, model.C1, model.h);
    s.R_min = *std::min_element(R, R + N);
    s.R_max = *std::max_element(R, R + N);
    s.Q_rear = e.Q0;
    s.Q_front = e.QN;
    s.V_rear = Y[2] * model.V_s;
    s.V_front = Y[3] * model.V_s;
    double vol = 0;
    for (int i = 0; i < N; ++i) vol += R[i] * R[i];
    s.tube_volume = pi * vol * model.h;
    s.phase = 0;
    if (!finite(s)) return false;
    res.series.push_back(s);
    res.radius_times.push_back(t);
    res.radius.insert(res.radius.end(), R, R + N);
    if (progress) progress(t, t_end);
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
