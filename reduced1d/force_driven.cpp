// Force-driven wave: the wall radius evolves under the actuation protocol.
//
// The conserved variable is the cross-section A_i = pi R_i^2 (state a_i = A_i / (pi R0^2)):
// the tube volume h sum A_i is then a LINEAR function of the state, which BDF preserves
// exactly, so d/dt(volume) = Q_rear - Q_front holds to solver tolerance at every step.
// Without wall inertia (CVODE BDF, banded Jacobian):
//   p_i = C1 (R_i - R0) + q_i(R_i),   Q_j = -(p_j - p_{j-1}) / r_j  (p = 0 beyond both ends),
//   dA_i/dt = (Q_i - Q_{i+1}) / h.
// With wall inertia (IDA, index-1 DAE in (a_i, V_i, p_i) interleaved per cell):
//   A_i' = 2 pi R_i V_i,   m V_i' = p_i - C1 (R_i - R0) - q_i(R_i),   A_i' + (Q_{i+1} - Q_i)/h = 0.
// Both carry the swimmer/flux integrals D, X, V_rear, V_front as extra differential states.
// State scaling: A/(pi R0^2), V/(R0/T_s), p/(C1 R0), D/D_s, X/X_s, V/(pi R0^2 L).
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <ida/ida.h>
#include <ida/ida_ls.h>
#include <sunmatrix/sunmatrix_band.h>

#include <algorithm>
#include <functional>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "reduced1d/discretisation.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/sundials.hpp"

namespace swim::reduced1d::detail {

namespace {

using disc::pi;

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

// ---------------------------------------------------------------------------------------
// Spatial model shared by both integrators.
struct ForceModel {
  int N;
  double L, h, R0, C1, m, mu;
  bool inertia, flow_closure;
  disc::BalanceCoefficients bal;
  int stride;          // unknowns per cell: 1 (R) or 3 (R, V, p)
  int iD, iX, iVr, iVf, n;  // extras and total size
  double T_s, D_s, X_s, V_s, Vel_s, P_s;
  // actuation law of every cell (fixed between protocol events) and the end radii
  std::vector<ProtocolMachine::CellLaw> law;
  std::vector<double> q;  // actuation at the last unpack
  double Rb0, RbL;
  // workspace
  std::vector<double> R, V, p, r, Q;

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
        bal(disc::BalanceCoefficients::from(P)),
        stride(P.wall.inertia ? 3 : 1),
        q(N, 0.0),
        Rb0(R0),
        RbL(R0),
        R(N),
        V(N, 0.0),
        p(N),
        r(N + 1),
        Q(N + 1) {
    // Layout [V_rear, cell 0, ..., cell N-1, V_front, D, X]: V_rear/V_front sit next to the
    // end cells they depend on, so their couplings are inside the band of the Newton matrix
    // and BDF keeps the linear invariant h sum A_i - V_rear + V_front exactly.
    iVr = 0;
    iVf = 1 + stride * N;
    iD = iVf + 1;
    iX = iVf + 2;
    n = iVf + 3;
    T_s = 0.1 * relaxation_time(P);
    const double f_s = bal.per_length ? pi * C1 * R0 * R0 * R0 / L : C1 * R0 * R0 / (2.0 * L);
    D_s = f_s * T_s;
    X_s = D_s * T_s / (bal.m_eff + bal.c_ext * T_s);
    V_s = pi * R0 * R0 * L;
    Vel_s = R0 / T_s;
    P_s = C1 * R0;
  }

  /// Install the cells' actuation laws; the end radii follow from the tube law at p = 0 with
  /// the end cell's law (quasi-static open end).
  void set_actuation(const std::vector<ProtocolMachine::CellLaw>& laws) {
    law = laws;
    // The end cells lie inside the first/last segment (h <= shortest segment): pure laws.
    Rb0 = law[0].a->rest_radius(R0, C1);
    RbL = law[N - 1].a->rest_radius(R0, C1);
  }

  /// Unpack radii (and V, p) from the scaled state; p from the tube law without inertia.
  /// Returns false if a radius is not positive and finite.
  bool unpack(const double* y) {
    bool ok = true;
    for (int i = 0; i < N; ++i) {
      const double a = y[1 + stride * i];
      if (!(a > 0) || !std::isfinite(a)) ok = false;
      const double Ri = R0 * std::sqrt(std::max(a, 1e-300));
      R[i] = Ri;
      q[i] = law[i](Ri);
      if (inertia) {
        V[i] = Vel_s * y[3 * i + 2];
        p[i] = P_s * y[3 * i + 3];
      } else {
        p[i] = C1 * (Ri - R0) + q[i];
      }
    }
    return ok;
  }

  /// Face resistances and fluxes (faces j = 0..N at z = j h; p = 0 at both ends).
  void fluxes() {
    r[0] = disc::resistance(mu, 0.5 * h, Rb0, R[0]);
    Q[0] = -p[0] / r[0];
    for (int j = 1; j < N; ++j) {
      r[j] = disc::resistance(mu, h, R[j - 1], R[j]);
      Q[j] = -(p[j] - p[j - 1]) / r[j];
    }
    r[N] = disc::resistance(mu, 0.5 * h, R[N - 1], RbL);
    Q[N] = p[N - 1] / r[N];
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

  /// Extras' derivatives (scaled) from the current R, p, Q.
  void extras(const double* y, double* dD, double* dX, double* dVr, double* dVf, double* W_out = nullptr) const {
    const auto I = integrals();
    const double f = bal.drag_integrand(I);
    const double W = bal.velocity(bal.thrust_term(I), y[iD] * D_s, y[iX] * X_s);
    *dD = f / D_s;
    *dX = W / X_s;
    *dVr = Q[0] / V_s;
    *dVf = Q[N] / V_s;
    if (W_out) *W_out = W;
  }

  // Right-hand side without inertia (CVODE).
  int rhs(const double* y, double* yd) {
    if (!unpack(y)) return 1;  // recoverable: the integrator retries with a smaller step
    fluxes();
    const double c = 1.0 / (h * pi * R0 * R0);
    for (int i = 0; i < N; ++i) yd[1 + i] = (Q[i] - Q[i + 1]) * c;
    extras(y, yd + iD, yd + iX, yd + iVr, yd + iVf);
    for (int k = 0; k < n; ++k)
      if (!std::isfinite(yd[k])) return 1;
    return 0;
  }

  // Residual with inertia (IDA).
  int res(const double* y, const double* yp, double* F) {
    if (!unpack(y)) return 1;
    fluxes();
    const double cu = 2.0 * Vel_s / (R0 * R0);
    const double cv = 1.0 / (m * Vel_s);
    const double cp = 1.0 / (2.0 * pi * R0 * Vel_s);
    const double A0 = pi * R0 * R0;
    for (int i = 0; i < N; ++i) {
      const int k = 1 + 3 * i;
      F[k] = yp[k] - cu * R[i] * y[k + 1];
      F[k + 1] = yp[k + 1] - cv * (p[i] - C1 * (R[i] - R0) - q[i]);
      F[k + 2] = cp * ((Q[i + 1] - Q[i]) / h + A0 * yp[k]);
    }
    double d[4];
    extras(y, d, d + 1, d + 2, d + 3);
    F[iD] = yp[iD] - d[0];
    F[iX] = yp[iX] - d[1];
    F[iVr] = yp[iVr] - d[2];
    F[iVf] = yp[iVf] - d[3];
    for (int k = 0; k < n; ++k)
      if (!std::isfinite(F[k])) return 1;
    return 0;
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
          const double v = M->Vel_s * y[3 * i + 2];
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
    A_ = sun::make_band_matrix(M.n, 1, 1, ctx_.get());
    LS_ = sun::make_band_solver(y_.get(), A_.get(), ctx_.get());
    sun::check(CVodeSetLinearSolver(mem, LS_.get(), A_.get()), "CVodeSetLinearSolver");
    sun::check(CVodeSetNoInactiveRootWarn(mem), "CVodeSetNoInactiveRootWarn");
    // BDF orders 1-2 are A-stable; the steep (regularised) actuation laws and the advective
    // part of the flux Jacobian give eigenvalues off the real axis, where orders 3-5 stall.
    sun::check(CVodeSetMaxOrd(mem, 2), "CVodeSetMaxOrd");
  }
  double* y() override { return sun::data(y_.get()); }
  void restart(double t) override {
    sun::check(CVodeReInit(mem_.get(), t, y_.get()), "CVodeReInit", last_msg);
  }
  void set_roots(int n) override {
    sun::check(CVodeRootInit(mem_.get(), n, &CvodeBackend::g), "CVodeRootInit");
    dirs_.assign(n, -1);
    if (n > 0) sun::check(CVodeSetRootDirection(mem_.get(), dirs_.data()), "CVodeSetRootDirection");
  }
  void set_stop_time(double t) override { sun::check(CVodeSetStopTime(mem_.get(), t), "CVodeSetStopTime"); }
  void set_max_steps(long n) override { sun::check(CVodeSetMaxNumSteps(mem_.get(), n), "CVodeSetMaxNumSteps"); }
  int advance(double tout, double& t) override {
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
      y[1 + 3 * i] = 1.0;       // A = pi R0^2
      id[1 + 3 * i + 2] = 0.0;  // p is algebraic
    }
    ic_step_ = 1e-3 * M.T_s;
    mem_ = sun::make_ida(ctx_.get());
    void* mem = mem_.get();
    sun::check(IDASetErrHandlerFn(mem, sun::capture_error, &last_msg), "IDASetErrHandlerFn");
    sun::check(IDAInit(mem, &IdaBackend::F, 0.0, y_.get(), yp_.get()), "IDAInit");
    sun::check(IDASStolerances(mem, P.numerics.rtol, P.numerics.atol_scale), "IDASStolerances");
    sun::check(IDASetUserData(mem, &pb_), "IDASetUserData");
    sun::check(IDASetId(mem, id_.get()), "IDASetId");
    // Interleaved (a, V, p) per cell: the continuity row of cell i reaches a_{i-1} (5 below)
    // and p_{i+1} (3 above); V_rear (first) and V_front (after the cells) stay inside.
    A_ = sun::make_band_matrix(M.n, 3, 5, ctx_.get());
    LS_ = sun::make_band_solver(y_.get(), A_.get(), ctx_.get());
    sun::check(IDASetLinearSolver(mem, LS_.get(), A_.get()), "IDASetLinearSolver");
    sun::check(IDASetNoInactiveRootWarn(mem), "IDASetNoInactiveRootWarn");
    sun::check(IDASetMaxOrd(mem, 2), "IDASetMaxOrd");  // see CvodeBackend
  }
  double* y() override { return sun::data(y_.get()); }
  void restart(double t) override {
    // Differential derivatives from the residual at yp = 0 (F = yp - g(y)); the algebraic
    // pressures are made consistent by IDACalcIC (they are continuous across a switch, only
    // V' jumps with the actuation).
    double* y = sun::data(y_.get());
    double* yp = sun::data(yp_.get());
    const double* id = sun::data(id_.get());
    if (pb_.M.res(y, zero_.data(), tmp_.data()) != 0)
      throw NumericalError("non-finite state at a protocol switch",
                           "tighten numerics.rtol or lower protocol.q", t);
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
  void set_max_steps(long n) override { sun::check(IDASetMaxNumSteps(mem_.get(), n), "IDASetMaxNumSteps"); }
  int advance(double tout, double& t) override {
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
Result run(const Params& P, std::vector<double> fixed_q, double t_fixed_end, const ProgressFn& progress) {
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
  std::vector<double> Rcells(N, P.geometry.R0);
  std::unique_ptr<Backend> be;
  std::function<void(double)> check_ends;

  auto record = [&](double tt, const double* y) -> bool {
    const bool ok = M.unpack(y);
    M.fluxes();
    double d[4], W = 0;
    M.extras(y, d, d + 1, d + 2, d + 3, &W);
    Sample s;
    s.t = tt;
    s.X = y[M.iX] * M.X_s;
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
    for (double v : {s.X, s.W, s.energy, s.R_min, s.R_max, s.Q_rear, s.Q_front, s.V_rear,
                     s.V_front, s.tube_volume})
      if (!std::isfinite(v)) return false;
    res.series.push_back(s);
    res.radius_times.push_back(tt);
    res.radius.insert(res.radius.end(), M.R.begin(), M.R.end());
    if (progress) progress(tt, t_stop);
    return true;
  };
  auto cells = [&](const double* y) {
    for (int i = 0; i < N; ++i) Rcells[i] = M.R0 * std::sqrt(std::max(y[1 + M.stride * i], 0.0));
    return Rcells.data();
  };
  auto apply_actuation = [&](double tt) {
    machine.laws(lawbuf);
    M.set_actuation(lawbuf);
    check_ends(tt);
  };
  check_ends = [&](double tt) {
    if (M.Rb0 < collapse || M.RbL < collapse) {
      const bool left = M.Rb0 < collapse;
      throw NumericalError(
          "tube radius collapsed to zero at z = " + fmt(left ? 0.0 : M.L) +
              " m: under its actuation the open end has no positive rest radius (R0 - q/C1 <= 0)",
          "lower protocol.q (the actuation pressure / total force) below C1 R0 = " + fmt(M.C1 * M.R0) +
              " Pa or raise wall.C1",
          tt);
    }
  };

  try {
    if (!fixed) {
      machine.start_cycle(0.0, Rcells.data());
      res.cycle_start.push_back(0.0);
    }
    machine.laws(lawbuf);
    M.set_actuation(lawbuf);
    if (M.inertia)
      be = std::make_unique<IdaBackend>(*pb, P);
    else
      be = std::make_unique<CvodeBackend>(*pb, P);
    be->set_roots(machine.root_count());
    be->set_stop_time(t_stop);
    if (!record(0.0, be->y()))
      throw NumericalError("non-finite initial state", "check the wall and fluid parameters", 0.0);
    check_ends(0.0);
    if (!fixed && P.protocol.q <= M.C1 * (M.R0 - P.protocol.R_f)) {
      throw NumericalError(
          "the actuation cannot contract the tube to R_f: under protocol.q = " + fmt(P.protocol.q) +
              " Pa the static radius R0 - q/C1 = " + fmt(M.R0 - P.protocol.q / M.C1) +
              " m is not below R_f = " + fmt(P.protocol.R_f) + " m",
          "raise protocol.q above C1 (R0 - R_f) = " + fmt(M.C1 * (M.R0 - P.protocol.R_f)) +
              " Pa or raise protocol.R_f",
          0.0);
    }
    if (M.inertia) be->restart(0.0);  // consistent initial derivatives (IDACalcIC)

    long steps_before = 0;  // steps of earlier restarts
    std::vector<int> found;
    long k = 1;
    bool done = false;
    while (!done) {
      double tout = std::min(k * dt_out, t_stop);
      if (t_stop - tout < 1e-9 * dt_out) tout = t_stop;
      const long used = steps_before + be->steps();
      const long remaining = P.numerics.max_steps - used;
      if (remaining <= 0) throw NumericalError("integrator step budget numerics.max_steps exhausted",
                                               "raise numerics.max_steps or loosen numerics.rtol", t);
      be->set_max_steps(remaining);
      const int st = be->advance(tout, t);
      if (st == -1)
        throw NumericalError("integrator step budget numerics.max_steps exhausted (" +
                                 std::to_string(P.numerics.max_steps) + " steps)",
                             "raise numerics.max_steps or loosen numerics.rtol/atol_scale", t);
      if (st == 1) {
        found.assign(std::max(machine.root_count(), 2), 0);
        be->root_info(found.data());
        const double* R = cells(be->y());
        res.switches += machine.apply(t, found.data(), R);
        if (machine.collapsed()) {
          const int imin = int(std::min_element(Rcells.begin(), Rcells.end()) - Rcells.begin());
          record(t, be->y());
          throw NumericalError("tube radius collapsed to zero at z = " + fmt(res.z[imin]) + " m",
                               "lower protocol.q (pressure / total force) or raise protocol.R_f", t);
        }
        if (machine.cycle_completed()) {
          res.cycle_end.push_back(t);
          ++cycles_done;
          if (fixed || (P.duration <= 0 && cycles_done >= P.protocol.cycles)) {
            machine.finish();
            record(t, be->y());
            break;
          }
          machine.start_cycle(t, R);
          res.cycle_start.push_back(t);
        }
        apply_actuation(t);
        be->harvest(res.stats);
        steps_before = res.stats["steps"];
        be->restart(t);
        be->set_roots(machine.root_count());
        be->set_stop_time(t_stop);
        ++res.stats["reinits"];
        continue;
      }
      if (!record(t, be->y()))
        throw NumericalError("non-finite state", "tighten numerics.rtol or refine numerics.cells", t);
      if (tout >= t_stop) {
        if (stop_fails)
          throw NumericalError(
              "the protocol did not complete " + std::to_string(P.protocol.cycles) +
                  " cycle(s) by t = " + fmt(t_stop) + " s (the end_time bound; phase " +
                  std::to_string(machine.phase()) + ")",
              "raise protocol.q, protocol.delta or protocol.energy_tol, or set duration", t);
        done = true;
      }
      ++k;
    }
  } catch (const NumericalError& e) {
    res.failure = e;
  } catch (const sun::SundialsError& e) {
    res.failure = NumericalError(
        std::string(M.inertia ? "IDA" : "CVODE") + " failed: " + e.what(),
        "tighten numerics.rtol/atol_scale or raise numerics.cells; if the radius nearly closes, "
        "lower protocol.q or raise protocol.R_f",
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

Result solve_force_driven(const Params& p, const ProgressFn& progress) { return run(p, {}, 0.0, progress); }

Result solve_fixed_actuation(const Params& p, const std::vector<double>& q_cells, double t_end,
                             const ProgressFn& progress) {
  validate(p);
  if (static_cast<int>(q_cells.size()) != p.numerics.cells)
    throw InputError("q_cells", std::to_string(q_cells.size()), "one actuation value per cell");
  return run(p, q_cells, t_end, progress);
}

}  // namespace swim::reduced1d::detail
