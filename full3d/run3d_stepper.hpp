// The stepping part of a 3D run: the state (IbState, the fluid solver, the actuation
// protocol) and how it advances by one step. Fluid-coupled runs step the IbSolver (with
// CFL retries and the adaptive step control of full3d.adaptive, docs/full3d.md "Adaptive
// time step"); dry runs step the paper's dry swimmer (dry_step in run3d.hpp). After each
// step the run measures and checks the state (Measurements) and then calls finish_step(),
// which advances the protocol and chooses the next step.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/grid.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/protocol3d.hpp"
#include "full3d/run3d_setup.hpp"

namespace swim::full3d {

class Stepper {
 public:
  explicit Stepper(const RunSetup& run);

  /// A fresh run: the protocol starts at t = 0.
  void start();
  /// Throws NumericalError when an auto-duration run reached full3d.time_limit.
  void check_time_limit() const;
  /// One step of the solver (or the dry swimmer); the solver's statistics (all zero for
  /// the dry swimmer). Throws NumericalError (the adaptive step below dt_min, non-finite
  /// dry state).
  IbStepStats step();
  /// After the measurements and guards of the step: protocol events at the wall energy e,
  /// the cycle marks, the next adaptive step; counts the step.
  void finish_step(double e);

  bool finished() const;
  /// Output cadence: every `every` steps (fixed step) or at each multiple of `interval`
  /// crossed by the last step (adaptive step).
  bool due(long every, double interval) const;

  const IbState& state() const { return s_; }
  const Protocol3d& protocol() const { return protocol_; }
  const MacGrid* grid() const { return grid_ ? &*grid_ : nullptr; }
  /// The fluid pressure of the last step (fluid-coupled runs).
  const ScalarField& pressure() const { return ib_->stokes().pressure(); }
  /// Whether the steps compute the fluid pressure (StokesSolver::compute_pressure): only a
  /// run that writes fluid frames needs it.
  void compute_pressure(bool on) {
    if (ib_) ib_->stokes().compute_pressure(on);
  }
  /// The wall's stretching and bending energies at X, J (fluid-coupled runs: from the
  /// solver's elastic pass, which the next step from X reuses).
  std::array<double, 2> elastic_energy_parts(const Eigen::Matrix3Xd& X) const;
  bool fluid() const { return !run_.p.dry; }
  /// The fluid solver's set-up cost in this process (not across a resume): factorisations of
  /// the Stokes operator (one per time step value not cached), their wall time, and the
  /// number of time step values the cache keeps. A dry run: {}.
  scene::json stokes_setup_summary() const;
  long steps() const { return n_; }
  double dt_last() const { return dt_last_; }
  /// Wall time spent in the adaptive step's stability estimates in this process, s.
  double stability_seconds() const { return stability_seconds_; }

  /// Steps taken by each completed cycle.
  std::vector<long> steps_per_cycle() const;
  /// The time_step record of solver_stats.json.
  scene::json time_step_summary() const;

  void save(CheckpointWriter& w) const;
  void load(const CheckpointReader& r);

 private:
  /// The checkpoint records of the stepping state, f(name, member) (checkpoint.hpp).
  template <class Self, class F>
  static void records(Self& self, F&& f);
  double ladder(double dt) const;
  /// The stages of a step of dt: the fewest whose Chebyshev interval holds dt lambda_
  /// (full3d.scheme = chebyshev), 1 for the other schemes.
  int stages(double dt) const;
  void next_step(int switches);

  const RunSetup& run_;
  Protocol3d protocol_;
  std::optional<MacGrid> grid_;
  std::unique_ptr<IbSolver> ib_;
  IbState s_;
  long n_ = 0;
  double t_prev_ = 0.0;  ///< time before the last step (time-based output cadence)
  // step control (adaptive: full3d.adaptive)
  double dt_next_ = 0.0, dt_last_ = 0.0, dt_before_last_ = 0.0;
  double dt_used_min_ = 1e300, dt_used_max_ = 0.0, last_speed_ = 0.0, last_dv_ = 0.0;
  double lambda_ = 0.0, lambda_max_seen_ = 0.0;  ///< explicit-coupling rate estimates, 1/s
  long lambda_step_ = -1, estimates_ = 0, rejected_ = 0;
  double stability_seconds_ = 0.0;
  long fluid_solves_ = 0;     ///< Stokes solves of the steps in this process (not across a resume)
  int stages_max_used_ = 0;
  bool after_event_ = true;
  double r_active_prev_;
  std::map<std::string, long> bound_count_ = {{"growth", 0}, {"cfl", 0}, {"accuracy", 0}, {"stability", 0}, {"event", 0}};
  std::vector<double> step_marks_;  ///< step index at each cycle start (and the end of the last)
};

}  // namespace swim::full3d
