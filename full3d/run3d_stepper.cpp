#include "full3d/run3d_stepper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "common/errors.hpp"
#include "full3d/run3d.hpp"

namespace swim::full3d {

namespace {

/// Adaptive step: re-estimate the explicit-coupling limit at least every this many steps
/// (and after every protocol event).
constexpr long kStabilityEvery = 200;
/// Power iterations per estimate of the explicit-coupling rate.
constexpr int kStabilityIterations = 10;
/// Stabilised wall update: re-estimates at a smaller step when the first does not hold it.
constexpr int kStabilityRetries = 6;

/// Checkpoint records of the fluid velocity components.
const char* const kVelocityRecords[3] = {"u0", "u1", "u2"};

/// true when (t0, t1] contains a positive multiple of interval (time-based output cadence).
bool crossed(double t0, double t1, double interval) {
  const double eps = 1e-9;
  return std::floor(t1 / interval + eps) > std::floor(t0 / interval + eps);
}

}  // namespace

Stepper::Stepper(const RunSetup& run)
    : run_(run), protocol_(run.protocol()), r_active_prev_(std::numeric_limits<double>::quiet_NaN()) {
  const Params3d& p = run.p;
  if (!p.dry) {
    grid_.emplace(run.grid());
    IbOptions o = run.options;
    o.reject_on_cfl = run.adaptive;
    o.dt_key = run.dt_key;
    if (run.adaptive) o.inertia_step = p.adaptive.dt_max;  // one Stokes factorisation per run
    ib_ = run.solver(o, p.wall_inertia ? run.mass : Eigen::VectorXd());
    ib_->set_external_force([this](double, const Eigen::Matrix3Xd& X) { return protocol_.force(X); });
    s_ = ib_->initial_state();
  } else {
    s_.X = run.mesh.X0;
    s_.V = Eigen::Matrix3Xd::Zero(3, run.mesh.nodes());
    s_.V_prev = s_.V;
  }
  dt_last_ = dt_before_last_ = p.dt;
  if (run.adaptive) dt_next_ = dt_last_ = dt_before_last_ = ladder(p.adaptive.event_dt);
}

std::array<double, 2> Stepper::elastic_energy_parts(const Eigen::Matrix3Xd& X) const {
  if (ib_) return ib_->elastic_energy_parts(X);
  const MembraneParams& m = run_.p.membrane;
  return {stretching_energy(run_.mesh, X, m.ks, run_.p.threads), bending_energy(run_.mesh, X, m.kb, m.bending, run_.p.threads)};
}

void Stepper::start() {
  protocol_.start(0.0, s_.X);
  step_marks_.push_back(0.0);
}

bool Stepper::finished() const {
  if (run_.n_end <= 0) return protocol_.finished();
  return run_.adaptive ? s_.t >= run_.p.duration * (1.0 - 1e-12) : n_ >= run_.n_end;
}

void Stepper::check_time_limit() const {
  const Params3d& p = run_.p;
  if (run_.n_end < 0 && (run_.adaptive ? s_.t >= p.time_limit * (1.0 - 1e-12) : n_ >= run_.n_limit))
    throw NumericalError("the protocol did not complete " + std::to_string(p.protocol.cycles) +
                             " cycle(s) within full3d.time_limit = " + short_number(p.time_limit) + " s",
                         "raise full3d.time_limit, or give a time.duration", s_.t);
}

bool Stepper::due(long every, double interval) const {
  return run_.adaptive ? crossed(t_prev_, s_.t, interval) : n_ % every == 0;
}

int Stepper::stages(double dt) const {
  const Params3d& p = run_.p;
  if (p.scheme != IbScheme::Chebyshev) return 1;
  return chebyshev_stages_for(dt, lambda_, p.adaptive.stability_fraction, p.adaptive.max_stages);
}

/// dt snapped down to the ladder dt_max 2^(-k/4), k >= 0.
double Stepper::ladder(double dt) const {
  const double top = run_.p.adaptive.dt_max;
  if (dt >= top) return top;
  const double k = std::ceil(4.0 * std::log2(top / dt) - 1e-9);
  return top * std::exp2(-k / 4.0);
}

IbStepStats Stepper::step() {
  const Params3d& p = run_.p;
  t_prev_ = s_.t;
  if (p.dry) {
    dry_step(run_.mesh, p.membrane, run_.mass, p.dry_damping * run_.mesh.node_area,
             [this](double, const Eigen::Matrix3Xd& X) { return protocol_.force(X); }, p.scheme, s_, p.dt);
    return {};
  }
  double dt = run_.adaptive ? dt_next_ : p.dt;
  if (run_.adaptive && p.duration > 0) dt = std::min(dt, p.duration - s_.t);  // land on the end
  IbStepStats st;
  for (;;) {
    st = ib_->step(s_, dt, stages(dt));
    if (!st.rejected) break;
    // CFL above the guard: retry from the same state with a step at the CFL target
    ++rejected_;
    dt = ladder(std::min(0.5 * dt, 0.9 * dt * p.adaptive.cfl / st.cfl));
    if (dt < p.adaptive.dt_min)
      throw NumericalError("the adaptive step fell below full3d.adaptive.dt_min = " + short_number(p.adaptive.dt_min) +
                               " s at the CFL limit (nodes at " + short_number(st.max_node_speed) + " m/s)",
                           "lower full3d.adaptive.dt_min, or lower the actuation (protocol.pressure / load_factor)",
                           s_.t);
  }
  dt_before_last_ = dt_last_;
  dt_last_ = dt;
  dt_used_min_ = std::min(dt_used_min_, dt);
  dt_used_max_ = std::max(dt_used_max_, dt);
  last_speed_ = st.max_node_speed;
  last_dv_ = st.max_velocity_change;
  fluid_solves_ += st.fluid_solves;
  stages_max_used_ = std::max(stages_max_used_, st.fluid_solves);
  return st;
}

void Stepper::finish_step(double e) {
  const int cycles_before = protocol_.state().cycles_completed;
  const int switches = protocol_.update(s_.t, s_.X, e);
  if (protocol_.state().cycles_completed > cycles_before) step_marks_.push_back(double(n_ + 1));
  if (run_.adaptive) next_step(switches);
  ++n_;
}

// --- adaptive step (docs/full3d.md, "Adaptive time step") --------------------------
void Stepper::next_step(int switches) {
  const AdaptiveStep& a = run_.p.adaptive;
  const double h = run_.p.h;
  double dt = a.dt_max;
  const char* bound = "growth";
  auto limit = [&](double v, const char* why) {
    if (v < dt) {
      dt = v;
      bound = why;
    }
  };
  if (last_speed_ > 0.0) limit(a.cfl * h / last_speed_, "cfl");
  // local error of the forward-Euler position update, 0.5 dt^2 |X''|, with X'' from the
  // change of node velocity between the last two steps (skipped across a protocol event,
  // where the actuation law changed)
  // (midpoint: X'' from the predictor and corrector velocities of the step itself; the
  // accepted second-order update is then far more accurate than the tolerance)
  if (run_.p.scheme == IbScheme::Midpoint) {
    const double acc = last_dv_ / (0.5 * dt_last_);
    if (acc > 0.0) limit(std::sqrt(2.0 * a.tolerance * h / acc), "accuracy");
  } else if (!after_event_) {
    const double dv = (s_.V - s_.V_prev).colwise().norm().maxCoeff();
    const double acc = dv / dt_before_last_;
    if (acc > 0.0) limit(std::sqrt(2.0 * a.tolerance * h / acc), "accuracy");
  }
  // stability of the explicit coupling: dt lambda_max < 2
  const long step = n_ + 1;
  if (switches > 0 || lambda_step_ < 0 || step - lambda_step_ >= kStabilityEvery) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!ib_->stabilizer()) {
      lambda_ = ib_->explicit_rate(s_, dt_last_, kStabilityIterations);
    } else {
      // the stabilised update's rate falls as its step grows, and dt times it grows (each
      // mode's dt lambda / (1 + dt sigma)): estimated at the step the other bounds allow, dt
      // holds every step up to 2 fraction / lambda once dt lambda(dt) <= 2 fraction, and
      // otherwise the estimate is repeated at the smaller step (warm-started)
      const double top = 2.0 * a.stability_fraction;
      double dtc = ladder(dt);
      Eigen::Matrix3Xd v;
      lambda_ = ib_->explicit_rate(s_, dtc, kStabilityIterations, &v);
      for (int k = 0; k < kStabilityRetries && dtc * lambda_ > top; ++k) {
        dtc = ladder(0.9 * top / lambda_);
        lambda_ = ib_->explicit_rate(s_, dtc, kStabilityIterations / 2, &v);
      }
      if (dtc * lambda_ > top) lambda_ = top / dtc * 2.0;  // not settled: hold half the last step tried
    }
    stability_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    lambda_step_ = step;
    lambda_max_seen_ = std::max(lambda_max_seen_, lambda_);
    ++estimates_;
  }
  // protocol events: the step after an event restarts at event_dt; approaching the next
  // contraction event, the step is cut to land just past it (event times resolved to event_dt)
  const auto& ps = protocol_.state();
  double r_active = std::numeric_limits<double>::quiet_NaN();
  if (ps.phase == 0) r_active = protocol_.segment_radii(s_.X)[ps.active];
  if (switches > 0) {
    limit(a.event_dt, "event");
  } else if (ps.phase == 0 && std::isfinite(r_active_prev_)) {
    const double rate = (r_active_prev_ - r_active) / dt_last_;
    if (rate > 0.0) {
      const double t_event = (r_active - run_.p.protocol.R_f) / rate;
      if (t_event < dt) limit(std::max(a.event_dt, 1.02 * t_event), "event");
    }
  }
  // the stability limit: forward Euler and the midpoint rule hold dt lambda within
  // fraction * 2; Chebyshev stages take the stage count s that advances furthest per fluid
  // solve, min(dt, fraction beta_s / lambda) / s (the fewest on a tie), judged on the bounds
  // other than the growth, which then ramps the step towards it (the step itself takes the
  // fewest stages that hold it, stages())
  if (lambda_ > 0.0) {
    double beta = 2.0;
    if (run_.p.scheme == IbScheme::Chebyshev) {
      double best = 0.0;
      for (int st = 1; st <= a.max_stages; ++st) {
        const double b = chebyshev_stages(st).stability_interval();
        const double per_solve = std::min(dt, a.stability_fraction * b / lambda_) / st;
        if (per_solve > best * (1.0 + 1e-12)) best = per_solve, beta = b;
      }
    }
    limit(a.stability_fraction * beta / lambda_, "stability");
  }
  limit(2.0 * dt_last_, "growth");  // at most 2x per step
  r_active_prev_ = switches > 0 ? std::numeric_limits<double>::quiet_NaN() : r_active;
  after_event_ = switches > 0;
  if (dt < a.dt_min)
    throw NumericalError("the adaptive step (" + short_number(dt) + " s, bound: " + bound +
                             ") fell below full3d.adaptive.dt_min = " + short_number(a.dt_min) + " s",
                         std::string("lower full3d.adaptive.dt_min") +
                             (std::string(bound) == "cfl"         ? ", or raise full3d.adaptive.cfl"
                              : std::string(bound) == "accuracy"  ? ", or raise full3d.adaptive.tolerance"
                              : std::string(bound) == "stability" ? ", or raise full3d.adaptive.stability_fraction"
                              : std::string(bound) == "event"     ? ", or lower full3d.adaptive.event_dt"
                                                                  : ""),
                         s_.t);
  dt_next_ = ladder(dt);
  ++bound_count_[bound];
}

std::vector<long> Stepper::steps_per_cycle() const {
  std::vector<long> v;
  for (size_t k = 0; k + 1 < step_marks_.size(); ++k) v.push_back(std::lround(step_marks_[k + 1] - step_marks_[k]));
  return v;
}

scene::json Stepper::time_step_summary() const {
  if (!run_.adaptive) return {{"control", "fixed"}, {"dt_s", run_.p.dt}};
  scene::json bounds = scene::json::object();
  for (const auto& [k, v] : bound_count_) bounds[k] = v;
  return {{"control", "adaptive"},
          {"dt_min_used_s", n_ > 0 ? dt_used_min_ : 0.0},
          {"dt_max_used_s", dt_used_max_},
          {"dt_mean_s", n_ > 0 ? s_.t / double(n_) : 0.0},
          {"rejected_steps", rejected_},
          {"explicit_rate_per_s", lambda_},
          {"explicit_rate_max_per_s", lambda_max_seen_},
          {"explicit_limit_s", lambda_max_seen_ > 0 ? 2.0 / lambda_max_seen_ : 0.0},
          {"stability_estimates", estimates_},
          {"scheme", run_.p.scheme == IbScheme::Chebyshev ? "chebyshev"
                     : run_.p.scheme == IbScheme::Midpoint ? "midpoint"
                                                           : "forward_euler"},
          {"fluid_solves_this_process", fluid_solves_},
          {"stages_max_used", stages_max_used_},
          {"steps_by_bound", bounds}};
}

scene::json Stepper::stokes_setup_summary() const {
  if (!ib_) return scene::json::object();
  const StokesSolver& st = ib_->stokes();
  return {{"factorizations", st.factorizations()},
          {"factorization_time_s", st.factorization_seconds()},
          {"cached_time_steps", st.cached_time_steps()},
          {"factor_bytes", st.factor_bytes()}};
}

// --- checkpoint records ------------------------------------------------------------
template <class Self, class F>
void Stepper::records(Self& self, F&& f) {
  f("step", self.n_);
  f("t", self.s_.t);
  f("X", self.s_.X.data(), std::size_t(self.s_.X.size()));
  f("V", self.s_.V.data(), std::size_t(self.s_.V.size()));
  f("V_prev", self.s_.V_prev.data(), std::size_t(self.s_.V_prev.size()));
  if (self.ib_)
    for (int c = 0; c < 3; ++c) f(kVelocityRecords[c], self.s_.u.c[c].data(), self.s_.u.c[c].size());
  protocol_records(self.protocol_.state(), f);
  f("step_marks", self.step_marks_);
  f("dt_next", self.dt_next_);
  f("dt_last", self.dt_last_);
  f("dt_before_last", self.dt_before_last_);
  f("dt_used_min", self.dt_used_min_);
  f("dt_used_max", self.dt_used_max_);
  f("last_speed", self.last_speed_);
  f("last_dv", self.last_dv_);
  f("lambda", self.lambda_);
  f("lambda_max_seen", self.lambda_max_seen_);
  f("lambda_step", self.lambda_step_);
  f("estimates", self.estimates_);
  f("rejected", self.rejected_);
  f("after_event", self.after_event_);
  for (auto& [k, v] : self.bound_count_) f("steps_by_bound." + k, v);
}

void Stepper::save(CheckpointWriter& w) const {
  records(*this, CheckpointOut(w));
  // The pressure of the last step (the fluid-field output between steps); the step itself does
  // not depend on it (the Stokes solvers are exact), so the resumed run repeats the uninterrupted one.
  if (ib_) w.put("p", ib_->stokes().pressure().v);
  w.put("r_active_prev", std::isfinite(r_active_prev_) ? r_active_prev_ : -1.0);  // NaN: none
}

void Stepper::load(const CheckpointReader& r) {
  records(*this, CheckpointIn(r));
  if (ib_) {
    ScalarField pr = ib_->stokes().pressure();
    r.get_into("p", pr.v.data(), pr.v.size());
    ib_->stokes().set_pressure(pr);
  }
  const double rp = r.get_double("r_active_prev");
  r_active_prev_ = rp >= 0.0 ? rp : std::numeric_limits<double>::quiet_NaN();
  t_prev_ = s_.t;
}

}  // namespace swim::full3d
