#include "full3d/run3d.hpp"

#include <chrono>
#include <cmath>
#include <optional>

#include "common/errors.hpp"
#include "common/progress.hpp"
#include "full3d/run3d_checkpoint.hpp"
#include "full3d/run3d_measure.hpp"
#include "full3d/run3d_output.hpp"
#include "full3d/run3d_setup.hpp"
#include "full3d/run3d_stepper.hpp"

namespace swim::full3d {

using scene::json;

namespace {

/// The run loop: init (fresh or from the checkpoint), then while (!finished) { step;
/// measure; write }. The parts are described in run3d_setup.hpp.
class Runner {
 public:
  Runner(const Params3d& p, const json& resolved, const std::string& out, const RunControl& ctl)
      : p_(p), out_(out), ctl_(ctl), run_(p), rec_(new_record(run_)), stepper_(run_),
        measured_(run_, rec_, [this](const Eigen::Matrix3Xd& X) { return stepper_.elastic_energy_parts(X); }),
        output_(run_, resolved, out, p.vtk && !ctl.quiet_vtk, p.fluid_fields && !p.dry && !ctl.quiet_vtk, rec_),
        checkpoint_(run_, resolved, out) {
    rec_.keep(ctl.keep_rows);
    stepper_.compute_pressure(output_.fluid());
  }

  RunOutcome run() {
    RunOutcome res;
    const auto t0 = std::chrono::steady_clock::now();
    if (ctl_.resume) {
      wall_before_ = checkpoint_.restore(stepper_, measured_, output_, ctl_.max_output_bytes);
    } else {
      stepper_.start();
      measured_.start(stepper_.state());
      output_.start(ctl_.max_output_bytes);
      measured_.events(stepper_.protocol().state());
    }
    Progress progress("3d " + p_.name + (run_.n_end > 0 ? "" : " (auto: until " + std::to_string(p_.protocol.cycles) +
                                                                   (p_.protocol.cycles == 1 ? " cycle" : " cycles") + ", progress against full3d.time_limit)"),
                      run_.t_end(), ctl_.progress);
    long this_process = 0;
    std::optional<NumericalError> failure;
    try {
      if (!ctl_.resume) {  // the initial state; its output may already pass output.max_bytes
        record();
        if (output_.vtk()) output_.write_membrane_frame(stepper_);
        if (output_.fluid()) output_.write_fluid_frame(stepper_);
        save_checkpoint(0.0);
      }
      while (!stepper_.finished()) {
        stepper_.check_time_limit();
        step();
        ++this_process;
        if (stepper_.due(run_.out_every, p_.output_interval)) record();
        Lap lap(split_);
        if (output_.vtk() && stepper_.due(run_.vtk_every, p_.vtk_interval)) output_.write_membrane_frame(stepper_);
        if (output_.fluid() && stepper_.due(run_.fluid_every, p_.fluid_interval)) output_.write_fluid_frame(stepper_);
        lap("vtk_frames");
        if (stepper_.due(run_.ckpt_every, p_.checkpoint_interval)) save_checkpoint(wall_before_ + seconds_since(t0));
        lap("checkpoints");
        progress.update(stepper_.state().t);
        if (ctl_.stop_after_steps > 0 && this_process >= ctl_.stop_after_steps && !stepper_.finished()) {
          res.interrupted = true;
          res.steps = stepper_.steps();
          return res;
        }
      }
      if (measured_.last_recorded() != stepper_.steps()) record();
      if (output_.vtk() && !(stepper_.steps() > 0 && stepper_.due(run_.vtk_every, p_.vtk_interval)))
        output_.write_membrane_frame(stepper_);
    } catch (const NumericalError& e) {
      failure = e;
      // the state is the last step the solver accepted; record it when it is finite
      const IbState& s = stepper_.state();
      if (measured_.last_recorded() != stepper_.steps() && s.X.allFinite() && s.V.allFinite() &&
          std::isfinite(measured_.wall_energy(s)))
        record();
    }
    progress.done();
    const double wall = wall_before_ + seconds_since(t0);
    res.failed = failure.has_value();
    res.message = failure ? failure->what() : "";
    measured_.events(stepper_.protocol().state());
    res.summary = output_.write_results(failure ? "failed: " + std::string(failure->what()) : "ok", wall, stepper_,
                                        measured_);
    res.steps = stepper_.steps();
    rec_.attach(nullptr);
    res.record = std::move(rec_);
    return res;
  }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  /// One time step: advance, measure, check, then the protocol and the next step size.
  void step() {
    Lap lap(split_);
    const IbStepStats st = stepper_.step();
    split_.add_step(st);
    lap("step_other");
    measured_.after_step(st, stepper_.state(), stepper_.dt_last(), stepper_.grid());
    lap("end_fluxes");
    const double e = measured_.wall_energy(stepper_.state());
    measured_.guards(e, stepper_.state());
    lap("wall_energy_and_guards");
    const double before = stepper_.stability_seconds();
    stepper_.finish_step(e);
    measured_.events(stepper_.protocol().state());
    split_.add("stability_estimates", stepper_.stability_seconds() - before);
    lap("protocol_and_step_control", stepper_.stability_seconds() - before);
  }

  void record() {
    Lap lap(split_);
    measured_.record(stepper_.state(), stepper_.protocol().state(), stepper_.steps(), stepper_.dt_last());
    lap("series_rows");
  }

  void save_checkpoint(double wall) {
    // partial results first (the streams flushed, summary.json "running"), so that a killed
    // run still has them; the checkpoint then records the streams' marks to continue from
    const std::vector<double> marks =
        output_.write_snapshot("running: last checkpoint at t = " + short_number(stepper_.state().t) +
                                   " s (resume with --resume " + out_ + ")",
                               wall, stepper_, measured_);
    checkpoint_.save(stepper_, measured_, output_, marks, wall);
    // summary.json last, listing checkpoint.bin as it now is
    output_.write_snapshot_summary();
  }

  const Params3d& p_;
  std::string out_;
  RunControl ctl_;
  RunSetup run_;
  record::RunRecord rec_;
  Stepper stepper_;
  Measurements measured_;
  RunOutput output_;
  RunCheckpoint checkpoint_;
  double wall_before_ = 0;
  WallSplit& split_ = measured_.split();
};

}  // namespace

void dry_step(const CylinderMesh& mesh, const MembraneParams& membrane, const Eigen::VectorXd& mass,
              const Eigen::VectorXd& nu, const ExternalForceFn& external, IbScheme scheme, IbState& s, double dt) {
  auto force = [&](const Eigen::Matrix3Xd& X, double t) {
    Eigen::Matrix3Xd F = elastic_forces(mesh, X, membrane);
    if (external) F += external(t, X);
    return F;
  };
  Eigen::Matrix3Xd V = s.V;
  Eigen::Matrix3Xd X;
  if (scheme == IbScheme::ForwardEuler) {  // symplectic Euler, damping implicit
    const Eigen::Matrix3Xd F = force(s.X, s.t);
    for (Eigen::Index i = 0; i < V.cols(); ++i) V.col(i) = (mass[i] * V.col(i) + dt * F.col(i)) / (mass[i] + dt * nu[i]);
    X = s.X + dt * V;
  } else {  // velocity Verlet, damping by the trapezoidal rule on each half kick
    const Eigen::Matrix3Xd F0 = force(s.X, s.t);
    for (Eigen::Index i = 0; i < V.cols(); ++i)
      V.col(i) = (mass[i] * V.col(i) + 0.5 * dt * F0.col(i)) / (mass[i] + 0.5 * dt * nu[i]);
    X = s.X + dt * V;
    const Eigen::Matrix3Xd F1 = force(X, s.t + dt);
    for (Eigen::Index i = 0; i < V.cols(); ++i)
      V.col(i) = (mass[i] * V.col(i) + 0.5 * dt * F1.col(i)) / (mass[i] + 0.5 * dt * nu[i]);
  }
  if (!X.allFinite() || !V.allFinite())
    throw NumericalError("non-finite node position or velocity in the dry swimmer (explicit integration unstable)",
                         "reduce the time step full3d.dt (limit about 2 sqrt(m_i / k_node))", s.t);
  s.V_prev = std::move(s.V);
  s.V = std::move(V);
  s.X = std::move(X);
  s.t += dt;
}

RunOutcome run3d(const Params3d& p, const json& resolved, const std::string& out_dir, const RunControl& ctl) {
  Runner r(p, resolved, out_dir, ctl);
  return r.run();
}

void check_resumable(const Params3d& p, const json& resolved, const std::string& out_dir) {
  const RunSetup run(p);
  RunCheckpoint(run, resolved, out_dir).open();
}

}  // namespace swim::full3d
