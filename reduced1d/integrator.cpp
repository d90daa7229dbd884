// The CVODE and IDA back-ends of the force-driven wave (interface in integrator.hpp).
#include "reduced1d/integrator.hpp"

#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <ida/ida.h>
#include <ida/ida_ls.h>
#include <sunmatrix/sunmatrix_band.h>

#include <algorithm>
#include <cmath>

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
/// Newton iterations IDA may take in one step before it calls the iteration failed (IDA's
/// own default is 4). The convergence test is IDA's, unchanged: the extra iterations only
/// let a step through a relay's ramp, where Newton converges slowly, finish instead of being
/// cut to a quarter and set up again (docs/performance-1d.md, "Newton iterations per step").
constexpr int kMaxNewtonIterations = 6;

}  // namespace

void RootFunctions::eval(const double* y, double* g) {
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
  } else if (shape_end) {
    double worst = 0;
    for (int i = 0; i < N; ++i) worst = std::max(worst, std::abs(Rbuf[i] - R0));
    g[1] = worst / delta - 1.0;
  } else {
    double E = M->wall_energy(Rbuf.data());
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

Problem::Problem(const Params& P, std::vector<double> fixed_q, bool step_velocity)
    : M(P, step_velocity), state(M.make_state()), machine(P, std::move(fixed_q)) {
  roots.M = &M;
  roots.machine = &machine;
  roots.Rbuf.assign(M.N, 0.0);
  roots.collapse_level = collapse_radius(P);
  roots.Rf = P.protocol.R_f;
  roots.energy_level = recovery_end_energy(P);
  roots.R0 = P.geometry.R0;
  roots.delta = P.protocol.delta;
  roots.shape_end = P.protocol.recovery_end == RecoveryEnd::Shape;
}

// ---------------------------------------------------------------------------------------
// The common part: advancing to an output time (optionally step by step) and the statistics.

void Integrator::set_max_steps(long n) {
  max_steps_ = n;
  solver_max_steps(n);
}

long Integrator::steps() {
  long v = 0;
  counters().front().get(memory(), &v);
  return v;
}

void Integrator::harvest(std::map<std::string, long>& stats) {
  for (const Counter& c : counters()) {
    long v = 0;
    if (c.get(memory(), &v) >= 0) stats[c.key] += v;
  }
}

int Integrator::advance(double tout, double& t) {
  double tn = current_time();
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
    const int kind = solve(tout, t);
    if (kind == 1) {
      if (t <= tout) return 1;
      if (on_step) on_step(t, y());  // the step up to the root, laws before the switch
      pending_root_ = true;
      root_t_ = t;
      root_y_.assign(y(), y() + size());
      interpolate(tout);
      t = tout;
      return 0;
    }
    tn = t;
    if (on_step) on_step(tn, y());
    if (kind == 2) return 2;
  }
  interpolate(tout);
  t = tout;
  return 0;
}

namespace {

// ---------------------------------------------------------------------------------------
// CVODE: BDF on dy/dt = f(y), Newton matrix I - gamma J from the exact analytic Jacobian
// (tridiagonal part + rank-1 segment and closure terms), band LU + Sherman-Morrison-Woodbury.
class CvodeIntegrator final : public Integrator {
 public:
  CvodeIntegrator(Problem& pb, const Params& P) : pb_(pb) {
    const ForceModel& M = pb.M;
    ctx_ = sun::make_context();
    y_ = sun::make_vector(M.n, ctx_.get());
    double* y = sun::data(y_.get());
    for (int i = 0; i < M.N; ++i) y[1 + i] = 1.0;
    mem_ = sun::make_cvode(CV_BDF, ctx_.get());
    void* mem = mem_.get();
    sun::check(CVodeSetErrHandlerFn(mem, sun::capture_error, &last_msg), "CVodeSetErrHandlerFn");
    sun::check(CVodeInit(mem, &CvodeIntegrator::f, 0.0, y_.get()), "CVodeInit");
    sun::check(CVodeSStolerances(mem, P.numerics.rtol, P.numerics.atol_scale), "CVodeSStolerances");
    sun::check(CVodeSetUserData(mem, &pb_), "CVodeSetUserData");
    // Newton matrix: exact tridiagonal Jacobian (areas, V_rear/V_front, D-X block) plus the
    // rank-1 couplings of the held segments, solved by band LU + Sherman-Morrison-Woodbury.
    // D and X depend on all radii; those couplings lie outside the band and are left out
    // (they do not feed back into the areas).
    A_ = sun::make_band_matrix(M.n, 1, 1, ctx_.get());
    pb.low_rank.scale = &CvodeIntegrator::minus_gamma;
    pb.low_rank.scale_ctx = this;
    LS_ = sun::make_low_rank_band_solver(y_.get(), A_.get(), &pb.low_rank, ctx_.get());
    sun::check(CVodeSetLinearSolver(mem, LS_.get(), A_.get()), "CVodeSetLinearSolver");
    // The Newton matrix I - gamma J is assembled here from the stored analytic Jacobian (no
    // SUNMatrix copy/scale calls: the distribution's SUNDIALS kernels are unoptimised).
    jband_.assign(3 * std::size_t(M.n), 0.0);
    sun::check(CVodeSetLinSysFn(mem, &CvodeIntegrator::linsys), "CVodeSetLinSysFn");
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
    sun::check(CVodeRootInit(mem_.get(), n, &CvodeIntegrator::g), "CVodeRootInit");
    dirs_.assign(n, -1);
    if (n > 0) sun::check(CVodeSetRootDirection(mem_.get(), dirs_.data()), "CVodeSetRootDirection");
  }
  void set_stop_time(double t) override { sun::check(CVodeSetStopTime(mem_.get(), t), "CVodeSetStopTime"); }
  void root_info(int* found) override { sun::check(CVodeGetRootInfo(mem_.get(), found), "CVodeGetRootInfo"); }

 protected:
  int solve(double tout, double& t) override {
    const int flag = CVode(mem_.get(), tout, y_.get(), &t, CV_ONE_STEP);
    if (flag == CV_ROOT_RETURN) return 1;
    if (flag == CV_TSTOP_RETURN) return 2;
    sun::check(flag, "CVode", last_msg);
    return 0;
  }
  void interpolate(double tout) override {
    sun::check(CVodeGetDky(mem_.get(), tout, 0, y_.get()), "CVodeGetDky", last_msg);
  }
  double current_time() override {
    double tn = 0;
    CVodeGetCurrentTime(mem_.get(), &tn);
    return tn;
  }
  void solver_max_steps(long n) override { sun::check(CVodeSetMaxNumSteps(mem_.get(), n), "CVodeSetMaxNumSteps"); }
  void* memory() override { return mem_.get(); }
  const std::vector<Counter>& counters() const override {
    static const std::vector<Counter> c = {
        {"steps", CVodeGetNumSteps},
        {"rhs_evals", CVodeGetNumRhsEvals},
        {"rhs_evals", CVodeGetNumLinRhsEvals},
        {"jac_evals", CVodeGetNumJacEvals},
        {"lin_setups", CVodeGetNumLinSolvSetups},
        {"err_test_fails", CVodeGetNumErrTestFails},
        {"nonlin_iters", CVodeGetNumNonlinSolvIters},
        {"nonlin_conv_fails", CVodeGetNumNonlinSolvConvFails},
        {"root_evals", CVodeGetNumGEvals}};
    return c;
  }
  int size() const override { return pb_.M.n; }

 private:
  static int f(double, N_Vector y, N_Vector yd, void* user) {
    auto* pb = static_cast<Problem*>(user);
    return pb->M.rhs(sun::data(y), sun::data(yd), pb->state);
  }
  // Newton matrix A = I - gamma J. The exact Jacobian (tridiagonal part in jband_, rank-1
  // segment terms in pb.low_rank) is re-evaluated when CVODE asks for it (jok false).
  static int linsys(double, N_Vector y, N_Vector, SUNMatrix A, booleantype jok, booleantype* jcur,
                    double gamma, void* user, N_Vector, N_Vector, N_Vector) {
    auto* pb = static_cast<Problem*>(user);
    auto* self = static_cast<CvodeIntegrator*>(pb->low_rank.scale_ctx);
    const long nn = pb->M.n;
    std::vector<double>& jb = self->jband_;
    if (!jok) {
      std::fill(jb.begin(), jb.end(), 0.0);
      const Linearisation lin = pb->M.linearise(sun::data(y), pb->state, true);
      pb->low_rank.rank = pb->M.jacobian(lin, TridiagonalRows{jb.data(), nn}, pb->low_rank.U, pb->low_rank.V);
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
  static double minus_gamma(void* self) { return -static_cast<CvodeIntegrator*>(self)->gamma_; }
  static int g(double, N_Vector y, double* gout, void* user) {
    static_cast<Problem*>(user)->roots.eval(sun::data(y), gout);
    return 0;
  }
  std::vector<double> jband_;  // row i: J(i, i-1), J(i, i), J(i, i+1)
  double gamma_ = 0;
  Problem& pb_;
  sun::Context ctx_;
  sun::Vector y_;
  sun::CvodeMem mem_;
  sun::Matrix A_;
  sun::LinearSolver LS_;
  std::vector<int> dirs_;
};

// ---------------------------------------------------------------------------------------
// IDA: BDF on F(t, y, y') = 0 (index 1), Newton matrix dF/dy + cj dF/dy' from the analytic
// band part plus the low-rank segment and closure terms, block-tridiagonal LU + Woodbury.
class IdaIntegrator final : public Integrator {
 public:
  IdaIntegrator(Problem& pb, const Params& P) : pb_(pb) {
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
      if (M.bending) id[k + M.ik] = 0.0;                     // so is the curvature
    }
    ic_step_ = 1e-3 * M.T_s;
    mem_ = sun::make_ida(ctx_.get());
    void* mem = mem_.get();
    sun::check(IDASetErrHandlerFn(mem, sun::capture_error, &last_msg), "IDASetErrHandlerFn");
    sun::check(IDAInit(mem, &IdaIntegrator::F, 0.0, y_.get(), yp_.get()), "IDAInit");
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
    sun::check(IDASetJacFn(mem, &IdaIntegrator::jac), "IDASetJacFn");
    sun::check(IDASetNoInactiveRootWarn(mem), "IDASetNoInactiveRootWarn");
    sun::check(IDASetMaxOrd(mem, kMaxOrder), "IDASetMaxOrd");
    sun::check(IDASetMaxNonlinIters(mem, kMaxNewtonIterations), "IDASetMaxNonlinIters");
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
    if (pb_.M.res(y, zero_.data(), tmp_.data(), pb_.state) != 0)
      throw NumericalError("non-finite state at a protocol switch",
                           "tighten numerics1d.rtol or lower the actuation (protocol.pressure)", t);
    for (int k = 0; k < pb_.M.n; ++k) yp[k] = id[k] > 0 ? -tmp_[k] : 0.0;
    void* mem = mem_.get();
    // As in CVODE: the first step after a switch is a fraction of the step in use before it.
    // IDA's own choice, 1e-3 of the distance to the next output time (about 2e-7 s), then
    // takes 8 to 10 doublings, none limited by the error test (docs/performance-1d.md).
    // Not with wall inertia, whose velocities are differential and oscillate on the wall's
    // period: there the error test then failed down to the minimum step after a switch
    // (Reduced1dForceDriven.ConservesVolumeWithAndWithoutInertia), so IDA keeps its own.
    double h_last = 0;
    IDAGetCurrentStep(mem, &h_last);
    sun::check(IDAReInit(mem, t, y_.get(), yp_.get()), "IDAReInit", last_msg);
    // IDACalcIC solves twice: once with the error weights of the state before the switch,
    // then again with those of its solution, each solve after a matrix set-up. The second
    // starts from the first's converged point with the same cj, where the first's matrix is
    // as good a Newton matrix: its set-up keeps the first's factorisation (one factorisation
    // fewer per switch; IDA still counts the set-up). A retry at a smaller step (another cj)
    // factors; so does every set-up after the second (a first solve that converged slowly
    // retries once on the kept matrix, then on a new one).
    pb_.ic.active = true;
    pb_.ic.setups = 0;
    struct IcEnd {
      Problem& pb;
      ~IcEnd() {
        pb.ic.active = false;
        pb.low_rank.keep_factorisation = false;
      }
    } ic_end{pb_};
    sun::check(IDACalcIC(mem, IDA_YA_YDP_INIT, t + ic_step_), "IDACalcIC", last_msg);
    sun::check(IDAGetConsistentIC(mem, y_.get(), yp_.get()), "IDAGetConsistentIC");
    if (t > 0 && h_last > 0 && !pb_.M.inertia) sun::check(IDASetInitStep(mem, kRestartStepFraction * h_last), "IDASetInitStep");
  }
  void set_roots(int n) override {
    sun::check(IDARootInit(mem_.get(), n, &IdaIntegrator::g), "IDARootInit");
    dirs_.assign(n, -1);
    if (n > 0) sun::check(IDASetRootDirection(mem_.get(), dirs_.data()), "IDASetRootDirection");
  }
  void set_stop_time(double t) override { sun::check(IDASetStopTime(mem_.get(), t), "IDASetStopTime"); }
  void root_info(int* found) override { sun::check(IDAGetRootInfo(mem_.get(), found), "IDAGetRootInfo"); }

 protected:
  int solve(double tout, double& t) override {
    const int flag = IDASolve(mem_.get(), tout, &t, y_.get(), yp_.get(), IDA_ONE_STEP);
    if (flag == IDA_ROOT_RETURN) return 1;
    if (flag == IDA_TSTOP_RETURN) return 2;
    sun::check(flag, "IDASolve", last_msg);
    return 0;
  }
  void interpolate(double tout) override {
    sun::check(IDAGetDky(mem_.get(), tout, 0, y_.get()), "IDAGetDky", last_msg);
  }
  double current_time() override {
    double tn = 0;
    IDAGetCurrentTime(mem_.get(), &tn);
    return tn;
  }
  void solver_max_steps(long n) override { sun::check(IDASetMaxNumSteps(mem_.get(), n), "IDASetMaxNumSteps"); }
  void* memory() override { return mem_.get(); }
  const std::vector<Counter>& counters() const override {
    static const std::vector<Counter> c = {
        {"steps", IDAGetNumSteps},
        {"rhs_evals", IDAGetNumResEvals},
        {"rhs_evals", IDAGetNumLinResEvals},
        {"jac_evals", IDAGetNumJacEvals},
        {"lin_setups", IDAGetNumLinSolvSetups},
        {"err_test_fails", IDAGetNumErrTestFails},
        {"nonlin_iters", IDAGetNumNonlinSolvIters},
        {"nonlin_conv_fails", IDAGetNumNonlinSolvConvFails},
        {"root_evals", IDAGetNumGEvals}};
    return c;
  }
  int size() const override { return pb_.M.n; }

 private:
  static int F(double, N_Vector y, N_Vector yp, N_Vector r, void* user) {
    auto* pb = static_cast<Problem*>(user);
    return pb->M.res(sun::data(y), sun::data(yp), sun::data(r), pb->state);
  }
  // Band part analytic (ForceModel::ida_band) with the segment actuation, the end radii and
  // the confined closure held; their couplings are the exact low-rank terms.
  static int jac(double, double cj, N_Vector yv, N_Vector, N_Vector, SUNMatrix J, void* user, N_Vector,
                 N_Vector, N_Vector) {
    auto* pb = static_cast<Problem*>(user);
    pb->low_rank.keep_factorisation = pb->ic.active && pb->ic.setups++ == 1 && cj == pb->ic.cj;
    if (pb->ic.active && pb->ic.setups == 1) pb->ic.cj = cj;
    if (pb->low_rank.keep_factorisation) {
      ++pb->ic.kept;
      return 0;
    }
    const Linearisation lin = pb->M.linearise(sun::data(yv), pb->state, false);
    pb->low_rank.rank = pb->M.residual_low_rank(lin, pb->low_rank.U, pb->low_rank.V);
    // IDALS zeroes J before this call (checked: every call finds it zero)
    pb->M.ida_band(lin, sun::data(yv), cj, AddToBandMatrix{J});
    return 0;
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

}  // namespace

std::unique_ptr<Integrator> make_integrator(Problem& pb, const Params& P) {
  if (pb.M.dae) return std::make_unique<IdaIntegrator>(pb, P);
  return std::make_unique<CvodeIntegrator>(pb, P);
}

}  // namespace swim::reduced1d::detail
