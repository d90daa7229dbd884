// Time integration of the force-driven wave: one interface over the two SUNDIALS back-ends.
//
// CVODE (BDF) integrates the inertia-free model dy/dt = f(y); IDA (BDF) the DAE F(t, y, y') = 0
// of the wall-inertia and short-wave-traction models. Both locate the protocol's switches as
// roots of the functions of RootFunctions and solve their Newton systems with the band (CVODE)
// or block-tridiagonal (IDA) LU plus the Woodbury correction of the low-rank segment and
// closure couplings (reduced1d/linear_solvers.hpp).
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "reduced1d/force_model.hpp"
#include "reduced1d/linear_solvers.hpp"
#include "reduced1d/protocol.hpp"

namespace swim::reduced1d::detail {

/// Root functions of the current protocol state (ProtocolMachine::root_count order):
/// collapse (minimum radius - collapse level), then in phase 0 the active segment's mean
/// radius - R_f, in phase 1 the wall energy / energy level - 1.
struct RootFunctions {
  const ForceModel* M = nullptr;
  const ProtocolMachine* machine = nullptr;
  std::vector<double> Rbuf;
  double collapse_level = 0, Rf = 0, energy_level = 1;
  /// The recovery's end (model1d.recovery_end): with Shape the root is max_i |R_i - R0| / delta - 1
  /// (every cell within delta of R0), otherwise E / energy_level - 1 (energy_level taken from the
  /// rule: energy_tol E_ref, or max of that and E_delta for DeadBand).
  bool shape_end = false;
  double R0 = 0, delta = 0;

  void eval(const double* y, double* g);
};

/// Everything the SUNDIALS callbacks need (their user data).
struct Problem {
  ForceModel M;
  ModelState state;  ///< the model at the state of the last callback
  ProtocolMachine machine;
  RootFunctions roots;
  sun::LowRankTerm low_rank;  ///< segment and closure couplings of the Newton matrix
  /// IDACalcIC after a restart: the Newton matrices it has set up and the cj of the first
  /// (IdaIntegrator::restart).
  struct {
    bool active = false;
    int setups = 0;
    double cj = 0;
    long kept = 0;  ///< set-ups that kept the factorisation, over the run
  } ic;
  /// `step_velocity`: ForceModel's velocity quadrature where the model allows it.
  Problem(const Params& P, std::vector<double> fixed_q, bool step_velocity);
};

/// An integrator of the force-driven model, restartable at the protocol's switches.
class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual double* y() = 0;
  /// Restart at t from the current y() after a change of the discrete state.
  virtual void restart(double t) = 0;
  virtual void set_roots(int n) = 0;  ///< n root functions, all reported on falling crossings
  virtual void set_stop_time(double t) = 0;
  void set_max_steps(long n);
  /// Advance to tout or to a root: one solver step per call from t_n, on_step after each
  /// accepted step, y(tout) interpolated within the last step; a root found beyond tout is
  /// held back until the outputs before it are reported. (The solvers' normal modes have the
  /// same step control, but interpolate y and y' at every output and search the rest of the step
  /// for roots again at the next call: 4 % of the demo cycle's instructions at N = 50, whose
  /// 0.5 ms output interval is shorter than most steps; docs/performance-1d.md.)
  /// 0: reached tout, 1: root found, 2: stop time, -1: step budget exhausted; throws
  /// sun::SundialsError otherwise. t: the time reached.
  int advance(double tout, double& t);
  virtual void root_info(int* found) = 0;
  long steps();  ///< steps since the last restart
  /// Add the solver's counters since the last restart to `stats`.
  void harvest(std::map<std::string, long>& stats);
  std::string last_msg;  ///< the solver's last error message
  /// Called after every accepted step with (t_n, y_n), when set.
  std::function<void(double, const double*)> on_step;

 protected:
  /// A solver counter of the statistics (SUNDIALS' Get function) under its key.
  struct Counter {
    const char* key;
    int (*get)(void*, long*);
  };
  /// One step of the solver towards tout (its one-step mode): 0, 1 (root) or 2 (stop time)
  /// as advance(); throws otherwise.
  virtual int solve(double tout, double& t) = 0;
  virtual void interpolate(double tout) = 0;  ///< y(tout) into y() (within the last step)
  virtual double current_time() = 0;          ///< t_n of the last step
  virtual void solver_max_steps(long n) = 0;
  virtual void* memory() = 0;
  /// The counters, "steps" first.
  virtual const std::vector<Counter>& counters() const = 0;
  virtual int size() const = 0;

 private:
  long max_steps_ = 500;
  bool pending_root_ = false;
  double root_t_ = 0;
  std::vector<double> root_y_;
};

/// IDA for the DAE path (ForceModel::dae), CVODE otherwise; initial state at rest (R = R0).
std::unique_ptr<Integrator> make_integrator(Problem& pb, const Params& P);

}  // namespace swim::reduced1d::detail
