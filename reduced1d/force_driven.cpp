// Force-driven wave: the event loop that runs the model (force_model.hpp) through the
// Section-3 protocol with an integrator (integrator.hpp).
//
//   start: first cycle's laws, integrator at rest, initial sample and checks
//   repeat: advance to the next output time or to a located root;
//           at a root: apply the protocol switch (segment reached R_f, cycle completed,
//                      collapse), install the new laws, restart the integrator;
//           at an output time: record a sample.
#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "common/si_format.hpp"
#include "reduced1d/force_model.hpp"
#include "reduced1d/integrator.hpp"
#include "reduced1d/internal.hpp"
#include "reduced1d/protocol.hpp"
#include "reduced1d/sample_pipe.hpp"
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

// A length in a message, with its SI prefix ("200 nm", "68.75 nm").
std::string metres(double v) { return si(v, "m", 4); }

// ---------------------------------------------------------------------------------------
// Unbounded outer flow: U(t) = slender-body average of the flow induced by the wall motion,
// O(N^2) per evaluation, with no feedback into the radii. It is evaluated once per accepted
// step (not in every right-hand side and Newton iteration), and X, V_rear_lab and
// V_front_lab (their U parts) are integrated along the steps by the quadratic through the
// last three step points (trapezoid on the first step after a restart). The integrand jumps
// at a protocol switch (dA/dt does), so the rule restarts there with the one-sided values.
struct VelocityQuadrature {
  static constexpr int kn = 3;  // X / X_s, U pi Rb0^2 / V_s, U pi RbL^2 / V_s
  using V3 = std::array<double, kn>;
  double t[3] = {0, 0, 0};
  V3 f[3] = {};
  int count = 0;     // points since the last restart (at most 3 kept)
  V3 sum{};          // integral from 0 to t[latest]
  long evaluations = 0;

  V3 integrand(const ForceModel& M, ModelState& s, const double* y) {
    ++evaluations;
    M.unpack(y, s);
    M.fluxes(s);
    return {s.U / M.X_s, s.U * pi * s.Rb0 * s.Rb0 / M.V_s, s.U * pi * s.RbL * s.RbL / M.V_s};
  }
  /// Integral over [a, b] of the interpolant through the kept points (quadratic with three,
  /// linear with two) expressed on the last interval.
  V3 piece(double a, double b) const {
    V3 out{};
    if (count < 2) return out;
    const int i1 = count - 1, i0 = count - 2;
    if (count == 2) {
      for (int k = 0; k < kn; ++k) {
        const double fa = f[i0][k] + (f[i1][k] - f[i0][k]) * (a - t[i0]) / (t[i1] - t[i0]);
        const double fb = f[i0][k] + (f[i1][k] - f[i0][k]) * (b - t[i0]) / (t[i1] - t[i0]);
        out[k] = 0.5 * (b - a) * (fa + fb);
      }
      return out;
    }
    // quadratic through t[0], t[1], t[2]: Simpson on [a, b] is exact for it
    const double m = 0.5 * (a + b);
    for (int k = 0; k < kn; ++k) {
      auto q = [&](double x) {
        return f[0][k] * (x - t[1]) * (x - t[2]) / ((t[0] - t[1]) * (t[0] - t[2])) +
               f[1][k] * (x - t[0]) * (x - t[2]) / ((t[1] - t[0]) * (t[1] - t[2])) +
               f[2][k] * (x - t[0]) * (x - t[1]) / ((t[2] - t[0]) * (t[2] - t[1]));
      };
      out[k] = (b - a) / 6.0 * (q(a) + 4.0 * q(m) + q(b));
    }
    return out;
  }
  /// Start (t = 0) or restart after a switch at tt with the right-hand value fv.
  void restart(double tt, const V3& fv) {
    count = 1;
    t[0] = tt;
    f[0] = fv;
  }
  /// Accepted step to tt with value fv.
  void step(double tt, const V3& fv) {
    if (tt <= t[count - 1]) return;
    if (count == 3) {
      t[0] = t[1], t[1] = t[2], f[0] = f[1], f[1] = f[2];
      count = 2;
    }
    t[count] = tt;
    f[count] = fv;
    ++count;
    const V3 d = piece(t[count - 2], t[count - 1]);
    for (int k = 0; k < kn; ++k) sum[k] += d[k];
  }
  /// Integral from 0 to tt (tt within the last step).
  V3 at(double tt) const {
    V3 out = sum;
    if (count >= 2 && tt < t[count - 1]) {
      const V3 d = piece(tt, t[count - 1]);
      for (int k = 0; k < kn; ++k) out[k] -= d[k];
    }
    return out;
  }
};

// ---------------------------------------------------------------------------------------
// The event loop shared by the protocol run and the fixed-actuation run.
class EventLoop {
 public:
  EventLoop(const Params& P, std::vector<double> fixed_q, double t_fixed_end, const Output& out,
            bool velocity_in_rhs);
  Result run();

 private:
  void start();
  /// Advance to tout or to the next root (the step budget shared by every restart).
  int advance(double tout);
  /// Apply the located root at t_. Returns true when the run is complete.
  bool switch_protocol();
  void install_laws();
  /// A cycle's start or end for the run record: now, or after the samples before it.
  void cycle_event(bool start, double t);
  void check_end_radii(double t) const;
  /// The output sample at time t of state y: evaluated here, or handed to the sample thread
  /// (false: a non-finite sample, here or, found now, on the sample thread earlier).
  bool record(double t, const double* y);
  /// The velocity quadrature's integrals at t (zero without the quadrature).
  VelocityQuadrature::V3 quadrature_at(double t) const {
    return M_.velocity_quadrature ? vq_.at(t) : VelocityQuadrature::V3{};
  }
  /// The sample at a collapse or at the last cycle's end, on this thread once the sample
  /// thread has caught up (after the switch's events); a non-finite one is left out, and is
  /// not the run's failure.
  void record_here(double t);
  /// Evaluates and emits the sample into the scratch state st (the velocity quadrature's
  /// integrals qv and the protocol's phase taken at t).
  bool sample(const ForceModel& M, double t, const double* y, const VelocityQuadrature::V3& qv, int phase,
              ModelState& st);
  /// Room for the samples a run that keeps them in memory will take, up to the end time or
  /// 8 MB of radius snapshots: growing them by doubling copied and faulted in about twice
  /// their size (8 % of the N = 50 demo cycle, docs/performance-1d.md).
  void reserve_samples(double dt_out);
  /// Waits for the sample thread; false when one of its samples was not finite (a switch in
  /// progress is then taken back). Otherwise hands the switch's events to the run record and
  /// its laws to the sample thread's model.
  bool sync_samples();
  /// The failure a run with its samples on this thread would have stopped on first: the
  /// sample thread's non-finite sample, or what a sample's evaluation or output threw (the
  /// output limit), when it came before e.
  NumericalError first_failure(const NumericalError& e);
  NumericalError non_finite_state(double t) const;
  const double* cell_radii(const double* y);
  NumericalError integrator_failure(const sun::SundialsError& e) const;

  const Params& P_;
  const Output& out_;
  const bool fixed_;
  std::unique_ptr<Problem> pb_;
  ForceModel& M_;
  ProtocolMachine& machine_;
  double t_stop_ = 0;
  bool stop_fails_ = false;  // reaching t_stop is a failure (the protocol's end_time bound)
  double collapse_ = 0;
  int cycles_done_ = 0;
  double t_ = 0;
  long steps_before_ = 0;  // steps of earlier restarts
  std::vector<ProtocolMachine::CellLaw> lawbuf_;
  std::vector<const ActuationLaw*> seglawbuf_;
  std::vector<double> Rcells_;
  std::vector<int> found_;
  std::unique_ptr<Integrator> be_;
  VelocityQuadrature vq_;
  Result res_;
  // The sample thread (numerics1d.threads = 2) and its scratch state; declared last, so that
  // it stops before anything its samples use is destroyed.
  std::unique_ptr<ForceModel> sample_model_;  // the sample thread's model (its own laws)
  ModelState sample_state_;
  // A switch whose samples before it the sample thread has not yet evaluated: its events for
  // the run record, and what it changed, to be taken back if one of those samples fails.
  struct PendingSwitch {
    bool harvested = false;  // the switch has added the integrator's counters to the run's
    std::vector<std::pair<bool, double>> events;  // (cycle start, t) in order; false: cycle end
    ProtocolMachine machine;
    long switches = 0;
    std::size_t cycle_start = 0, cycle_end = 0;
    int cycles_done = 0;
    std::map<std::string, long> stats;  // after the switch's harvest
    explicit PendingSwitch(const ProtocolMachine& m) : machine(m) {}
  };
  std::optional<PendingSwitch> pending_;
  bool taken_back_ = false;  // a switch was taken back after its harvest: the counters stop at its root
  std::vector<double> sample_y_;  // the sample thread's state (the unknowns it reads in place)
  int sample_unknowns_ = 0;       // leading unknowns of a cell that a sample reads
  double sample_failed_at_ = 0;     // time of the sample thread's non-finite sample
  bool sample_not_finite_ = false;  // the sample thread stopped on a non-finite sample (not on an exception)
  std::unique_ptr<SamplePipe> samples_;
};

EventLoop::EventLoop(const Params& P, std::vector<double> fixed_q, double t_fixed_end, const Output& out,
                     bool velocity_in_rhs)
    : P_(P),
      out_(out),
      fixed_(!fixed_q.empty()),
      pb_(std::make_unique<Problem>(P, std::move(fixed_q), !velocity_in_rhs)),
      M_(pb_->M),
      machine_(pb_->machine),
      collapse_(collapse_radius(P)),
      Rcells_(M_.N, P.geometry.R0) {
  for (const char* k : {"steps", "rhs_evals", "jac_evals", "lin_setups", "lin_setups_kept", "err_test_fails",
                        "nonlin_iters", "nonlin_conv_fails", "root_evals", "reinits"})
    res_.stats[k] = 0;
  res_.z.resize(M_.N);
  for (int i = 0; i < M_.N; ++i) res_.z[i] = (i + 0.5) * M_.h;
  if (P.numerics.threads >= 2) {
    // A record: the unknowns a sample reads, then t, the quadrature's three integrals and the
    // phase. The sample thread puts the unknowns back in place in a state of its own.
    sample_model_ = std::make_unique<ForceModel>(P, !velocity_in_rhs);
    sample_state_ = sample_model_->make_state();
    sample_y_.assign(M_.n, 0.0);
    sample_unknowns_ = M_.dae ? 3 : 1;
    const int width = 1 + sample_unknowns_ * M_.N + (M_.n - M_.iVf);
    samples_ = std::make_unique<SamplePipe>(std::size_t(width + 5), [this, width](const double* r) {
      const int S = M_.stride, w = sample_unknowns_, N = M_.N;
      double* y = sample_y_.data();
      const double* c = r;
      y[M_.iVr] = *c++;
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < w; ++j) y[1 + S * i + j] = *c++;
      for (int k = M_.iVf; k < M_.n; ++k) y[k] = *c++;
      const double* h = r + width;
      const VelocityQuadrature::V3 qv = {h[1], h[2], h[3]};
      if (sample(*sample_model_, h[0], y, qv, int(h[4]), sample_state_)) return true;
      sample_failed_at_ = h[0];
      sample_not_finite_ = true;
      return false;
    });
  }
  if (fixed_) {
    t_stop_ = t_fixed_end;
  } else if (P.duration > 0) {
    t_stop_ = P.duration;
  } else {
    t_stop_ = end_time(P);
    stop_fails_ = true;
  }
}

Result EventLoop::run() {
  try {
    start();
    const double dt_out = P_.numerics.output_interval;
    if (out_.keep_samples) reserve_samples(dt_out);
    for (long k = 1;;) {
      double tout = std::min(k * dt_out, t_stop_);
      if (t_stop_ - tout < 1e-9 * dt_out) tout = t_stop_;
      if (advance(tout) == 1) {
        if (switch_protocol()) break;
        continue;
      }
      if (!record(t_, be_->y())) throw non_finite_state(t_);
      if (tout >= t_stop_) {
        if (!sync_samples()) throw non_finite_state(t_);
        if (stop_fails_)
          throw NumericalError(
              "the protocol did not complete " + std::to_string(P_.protocol.cycles) +
                  " cycle(s) by t = " + fmt(t_stop_) + " s (the end_time bound; phase " +
                  std::to_string(machine_.phase()) + ")",
              "raise the actuation (protocol.pressure), protocol.tolerance_ratio or protocol.energy_tolerance, or set time.duration", t_);
        break;
      }
      ++k;
    }
    if (!sync_samples()) throw non_finite_state(t_);
  } catch (const NumericalError& e) {
    res_.failure = first_failure(e);
  } catch (const sun::SundialsError& e) {
    res_.failure = first_failure(integrator_failure(e));
  }
  // harvest adds only the counters since the last restart, and every restart is preceded
  // by a harvest: nothing is counted twice.
  if (be_ && !taken_back_) be_->harvest(res_.stats);
  res_.stats["lin_setups_kept"] = pb_->ic.kept;
  res_.segment_reached = machine_.reached();
  if (fixed_) res_.segment_reached.clear();
  return std::move(res_);
}

void EventLoop::start() {
  if (!fixed_) {
    machine_.start_cycle(0.0, Rcells_.data());
    res_.cycle_start.push_back(0.0);
    if (out_.record) out_.record->cycle_started(0.0);
  }
  machine_.laws(lawbuf_, seglawbuf_);
  M_.set_actuation(machine_, lawbuf_, seglawbuf_);
  if (sample_model_) sample_model_->set_actuation(machine_, lawbuf_, seglawbuf_);
  be_ = make_integrator(*pb_, P_);
  be_->set_roots(machine_.root_count());
  be_->set_stop_time(t_stop_);
  if (M_.velocity_quadrature) {
    vq_.restart(0.0, vq_.integrand(M_, pb_->state, be_->y()));
    be_->on_step = [this](double tn, const double* y) { vq_.step(tn, vq_.integrand(M_, pb_->state, y)); };
  }
  // (the first sample on this thread: its failure is the initial state's)
  if (!sample(M_, 0.0, be_->y(), quadrature_at(0.0), machine_.phase(),
              pb_->state)) {
    check_end_radii(0.0);  // an open end without a positive rest radius is the usual cause
    throw NumericalError("non-finite initial state", "check the wall and fluid parameters", 0.0);
  }
  check_end_radii(0.0);
  if (!fixed_ && M_.wall.law && P_.protocol.q <= -M_.wall(P_.protocol.R_f)) {
    throw NumericalError(
        "the actuation cannot contract the tube to R_f: under the actuation pressure q = " + fmt(P_.protocol.q) +
            " Pa the static radius of the calibrated tube law, " + metres(M_.wall.static_radius(P_.protocol.q)) +
            ", is not below R_f = " + metres(P_.protocol.R_f),
        "raise the actuation (protocol.pressure) above the law's static load at R_f, " +
            fmt(-M_.wall(P_.protocol.R_f)) + " Pa, or raise wave.contracted_ratio",
        0.0);
  }
  if (!fixed_ && !M_.wall.law && P_.protocol.q <= M_.C1 * (M_.R0 - P_.protocol.R_f)) {
    throw NumericalError(
        "the actuation cannot contract the tube to R_f: under the actuation pressure q = " + fmt(P_.protocol.q) +
            " Pa the static radius R0 - q/C1 = " + metres(M_.R0 - P_.protocol.q / M_.C1) +
            " is not below R_f = " + metres(P_.protocol.R_f),
        "raise the actuation (protocol.pressure) above C1 (R0 - R_f) = " + fmt(M_.C1 * (M_.R0 - P_.protocol.R_f)) +
            " Pa or raise wave.contracted_ratio",
        0.0);
  }
  if (M_.dae) be_->restart(0.0);  // consistent initial derivatives (IDACalcIC)
}

int EventLoop::advance(double tout) {
  const long used = steps_before_ + be_->steps();
  const long remaining = P_.numerics.max_steps - used;
  if (remaining <= 0)
    throw NumericalError("integrator step budget numerics1d.max_steps exhausted",
                         "raise numerics1d.max_steps or loosen numerics1d.rtol", t_);
  be_->set_max_steps(remaining);
  const int st = be_->advance(tout, t_);
  if (st == -1)
    throw NumericalError("integrator step budget numerics1d.max_steps exhausted (" +
                             std::to_string(P_.numerics.max_steps) + " steps)",
                         "raise numerics1d.max_steps or loosen numerics1d.rtol or numerics1d.atol_scale", t_);
  return st;
}

bool EventLoop::switch_protocol() {
  const double t = t_;
  // With a sample thread the samples before the switch may still be in its hands. It
  // evaluates them with a model of its own, so the switch and the restart go on meanwhile;
  // the switch's events reach the run record, and its laws that model, once it has caught up
  // (sync_samples, at the end of the switch), and the switch is taken back if one of those
  // samples fails, where a run on one thread would have stopped.
  if (samples_) {
    if (samples_->failed() && !sync_samples()) throw non_finite_state(t_);
    pending_.emplace(machine_);
    pending_->switches = res_.switches;
    pending_->cycle_start = res_.cycle_start.size();
    pending_->cycle_end = res_.cycle_end.size();
    pending_->cycles_done = cycles_done_;
  }
  // the partial step up to the root, with the laws in force before the switch
  if (M_.velocity_quadrature) vq_.step(t, vq_.integrand(M_, pb_->state, be_->y()));
  found_.assign(std::max(machine_.root_count(), 2), 0);
  be_->root_info(found_.data());
  const double* R = cell_radii(be_->y());
  res_.switches += machine_.apply(t, found_.data(), R);
  if (machine_.collapsed()) {
    const int imin = int(std::min_element(Rcells_.begin(), Rcells_.end()) - Rcells_.begin());
    record_here(t);
    throw NumericalError("tube radius collapsed to zero at z = " + metres(res_.z[imin]),
                         "lower the actuation (protocol.pressure, protocol.total_force or protocol.load_factor) or raise wave.contracted_ratio", t);
  }
  if (machine_.cycle_completed()) {
    res_.cycle_end.push_back(t);
    cycle_event(false, t);
    ++cycles_done_;
    if (fixed_ || (P_.duration <= 0 && cycles_done_ >= P_.protocol.cycles)) {
      machine_.finish();
      record_here(t);
      return true;
    }
    machine_.start_cycle(t, R);
    res_.cycle_start.push_back(t);
    cycle_event(true, t);
  }
  install_laws();
  check_end_radii(t);
  if (M_.velocity_quadrature) vq_.restart(t, vq_.integrand(M_, pb_->state, be_->y()));  // right-hand value
  be_->harvest(res_.stats);
  steps_before_ = res_.stats["steps"];
  if (pending_) {
    pending_->stats = res_.stats;
    pending_->harvested = true;
  }
  be_->restart(t);
  be_->set_roots(machine_.root_count());
  be_->set_stop_time(t_stop_);
  ++res_.stats["reinits"];
  if (!sync_samples()) throw non_finite_state(t_);
  return false;
}

void EventLoop::cycle_event(bool start, double t) {
  if (pending_)
    pending_->events.emplace_back(start, t);
  else if (out_.record)
    start ? out_.record->cycle_started(t) : out_.record->cycle_ended(t);
}

void EventLoop::install_laws() {
  machine_.laws(lawbuf_, seglawbuf_);
  M_.set_actuation(machine_, lawbuf_, seglawbuf_);
}

void EventLoop::check_end_radii(double t) const {
  if (M_.bending) {
    // A bending wall's ends follow the wall. Its active segment, of length l under the load P,
    // deflects like a beam on an elastic foundation (wavenumber beta = 1 / (sqrt 2 l_b),
    // l_b = (D / C1)^(1/4)): at its middle by f P / C1, on its mean by g P / C1, with
    // f = 1 - exp(-x) cos x, x = beta l / 2, and g = 1 - (1 + exp(-2x)(sin 2x - cos 2x)) / (4x).
    // The protocol holds the segment once its mean reaches R_f, so the segment passes that
    // shape on the way to its static one: what must stay open is its middle there, the static
    // radius under (f / g) times the load that holds R_f (or under f q when q cannot bring the
    // mean to R_f: a stall, which the run reports). A middle that closes first would grind the
    // integrator to the step budget against the lubrication's R^-4 resistance.
    // (Held segments are controlled to R_f, not loaded by q.)
    const double ell_b = std::pow(M_.D_axial / M_.C1, 0.25);
    double longest = 0;
    for (double w : machine_.seg_weight()) longest = std::max(longest, w * M_.h);
    const double x = longest / (2.0 * std::sqrt(2.0) * ell_b);
    const double f = 1.0 - std::exp(-x) * std::cos(x);
    const double g = 1.0 - (1.0 + std::exp(-2.0 * x) * (std::sin(2.0 * x) - std::cos(2.0 * x))) / (4.0 * x);
    const double q = P_.protocol.q, hold = -M_.wall(P_.protocol.R_f);
    const double P_mid = f * std::min(hold / g, q);
    const double Rs = M_.wall.static_radius(P_mid);
    if (Rs < collapse_)
      throw NumericalError(
          "tube radius collapsed to zero: under the actuation " + fmt(q) + " Pa a protocol segment of " +
              metres(longest) + " (bending length " + metres(ell_b) + ") closes at its middle (static radius " +
              metres(Rs) + ", below the collapse radius " + metres(collapse_) + ") before its mean reaches R_f = " +
              metres(P_.protocol.R_f),
          "raise wave.contracted_ratio, lower the actuation (protocol.pressure, protocol.total_force or "
          "protocol.load_factor) or raise wall.C1",
          t);
    return;
  }
  // Continued open ends are the end cells: the cells' own collapse root watches them.
  if (M_.ends_follow_cells) return;
  double lo0, loL;
  M_.end_radius_range(lo0, loL);
  // With the short-wave traction the end may be continued from its cell instead, which needs no
  // static end radius (docs/reduced1d.md, "The open ends' half cells").
  const char* or_continued =
      M_.J > 0 && !M_.junction ? "; or set numerics1d.open_end = \"continued\" (the end cell carried to the mouth)" : "";
  if ((lo0 < collapse_ || loL < collapse_) && M_.wall.law) {
    const bool left = lo0 < collapse_;
    throw NumericalError(
        "tube radius collapsed to zero at z = " + metres(left ? 0.0 : M_.L) +
            ": under its actuation the open end's static radius on the calibrated tube law, " +
            metres(left ? lo0 : loL) + ", is below the collapse radius " + metres(collapse_),
        "lower the actuation (protocol.pressure, protocol.total_force or protocol.load_factor) below the law's "
        "static load at the collapse radius, " + fmt(-M_.wall(collapse_)) + " Pa" + or_continued,
        t);
  }
  if (lo0 < collapse_ || loL < collapse_) {
    const bool left = lo0 < collapse_;
    const double lo = left ? lo0 : loL;
    throw NumericalError(
        "tube radius collapsed to zero at z = " + metres(left ? 0.0 : M_.L) +
            (lo > 0 ? ": under its actuation the open end's static radius R0 - q/C1 = " + metres(lo) +
                          " is below the collapse radius " + metres(collapse_)
                    : std::string(": under its actuation the open end has no positive rest radius (R0 - q/C1 <= 0)")),
        "lower the actuation (protocol.pressure, protocol.total_force or protocol.load_factor) below C1 R0 = " +
            fmt(M_.C1 * M_.R0) + " Pa or raise wall.C1" + or_continued,
        t);
  }
}

bool EventLoop::record(double tt, const double* y) {
  const VelocityQuadrature::V3 qv = quadrature_at(tt);
  if (!samples_) return sample(M_, tt, y, qv, machine_.phase(), pb_->state);
  if (samples_->failed()) return sync_samples();
  // The unknowns a sample reads (sample_unknowns_): a cell's cross-section, and its velocity
  // and pressure where they are unknowns, not its traction fields or curvature; a third of
  // the state to carry to the other core.
  double* r = samples_->slot();
  const int S = M_.stride, w = sample_unknowns_, N = M_.N;
  double* c = r;
  *c++ = y[M_.iVr];
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < w; ++j) *c++ = y[1 + S * i + j];
  for (int k = M_.iVf; k < M_.n; ++k) *c++ = y[k];
  double* h = c;
  h[0] = tt;
  h[1] = qv[0], h[2] = qv[1], h[3] = qv[2];
  h[4] = machine_.phase();
  samples_->commit();
  return true;
}

void EventLoop::record_here(double t) {
  if (samples_ && !sync_samples()) throw non_finite_state(t_);
  const VelocityQuadrature::V3 qv = quadrature_at(t);
  sample(M_, t, be_->y(), qv, machine_.phase(), pb_->state);
}

void EventLoop::reserve_samples(double dt_out) {
  constexpr double kMaxSnapshotValues = double(1 << 20);  // 8 MB of radii
  const auto n = std::size_t(std::min(t_stop_ / dt_out + 16.0, kMaxSnapshotValues / M_.N));
  res_.series.reserve(n);
  res_.radius_times.reserve(n);
  res_.radius.reserve(n * std::size_t(M_.N));
}

bool EventLoop::sync_samples() {
  if (!samples_) return true;
  std::exception_ptr error;  // what a sample's evaluation or output threw (the output limit)
  try {
    samples_->drain();
  } catch (...) {
    error = std::current_exception();
  }
  std::optional<PendingSwitch> sw = std::move(pending_);
  pending_.reset();
  if (samples_->failed()) {
    if (sw) {  // a sample before the switch failed or threw: a run on one thread stopped there
      machine_ = std::move(sw->machine);
      res_.switches = sw->switches;
      res_.cycle_start.resize(sw->cycle_start);
      res_.cycle_end.resize(sw->cycle_end);
      cycles_done_ = sw->cycles_done;
      if (sw->harvested) {
        res_.stats = std::move(sw->stats);
        taken_back_ = true;
      }
    }
    if (error) std::rethrow_exception(error);
    t_ = sample_failed_at_;
    return false;
  }
  if (sw) {
    if (out_.record)
      for (const auto& [start, t] : sw->events) start ? out_.record->cycle_started(t) : out_.record->cycle_ended(t);
    sample_model_->set_actuation(machine_, lawbuf_, seglawbuf_);
  }
  return true;
}

NumericalError EventLoop::non_finite_state(double t) const {
  return NumericalError("non-finite state",
                        P_.numerics.cells < 100000 ? "tighten numerics1d.rtol or refine numerics1d.cells"
                                                   : "tighten numerics1d.rtol",
                        t);
}

NumericalError EventLoop::first_failure(const NumericalError& e) {
  if (!samples_) return e;
  try {
    if (!sync_samples() && sample_not_finite_ && (e.time() < 0 || sample_failed_at_ <= e.time()))
      return non_finite_state(sample_failed_at_);
  } catch (const NumericalError& s) {
    return s;
  }
  return e;
}

bool EventLoop::sample(const ForceModel& M, double tt, const double* y, const VelocityQuadrature::V3& qv, int phase,
                       ModelState& st) {
  const int N = M.N;
  const bool ok = M.unpack(y, st);
  M.fluxes(st);
  if (!st.geometry_ok) return false;
  double d[6], W = 0;
  M.extras(st, y, d, &W);
  Sample s;
  M.end_state(st, s);
  s.V_rear_lab = (y[M.iVrl] + qv[1]) * M.V_s;
  s.V_front_lab = (y[M.iVfl] + qv[2]) * M.V_s;
  s.t = tt;
  s.X = (y[M.iX] + qv[0]) * M.X_s;
  s.W = W;
  s.energy = M.energy(st);
  s.R_min = *std::min_element(st.R.begin(), st.R.end());
  s.R_max = *std::max_element(st.R.begin(), st.R.end());
  s.Q_rear = st.Q[0];
  s.Q_front = st.Q[N];
  s.V_rear = y[M.iVr] * M.V_s;
  s.V_front = y[M.iVf] * M.V_s;
  double vol = 0;
  for (int i = 0; i < N; ++i) vol += st.R[i] * st.R[i];
  s.tube_volume = pi * vol * M.h;
  s.phase = phase;
  if (!ok || (out_.reject_sample && out_.reject_sample(tt))) return false;
  if (!finite(s)) return false;
  emit(res_, out_, s, st.R.data(), N, t_stop_);
  return true;
}

const double* EventLoop::cell_radii(const double* y) {
  for (int i = 0; i < M_.N; ++i) Rcells_[i] = M_.R0 * std::sqrt(std::max(y[1 + M_.stride * i], 0.0));
  return Rcells_.data();
}

NumericalError EventLoop::integrator_failure(const sun::SundialsError& e) const {
  if (M_.confined && !pb_->state.geometry_ok)
    return NumericalError(
        "the tube wall reached the container wall (outer hydraulic radius R + a_out >= container radius)",
        "raise container.radius or lower the actuation (protocol.pressure) (the recovery overshoots R0)", t_);
  return NumericalError(
      std::string(M_.dae ? "IDA" : "CVODE") + " failed: " + e.what(),
      "tighten numerics1d.rtol or numerics1d.atol_scale or raise numerics1d.cells; if the radius nearly closes, "
      "lower the actuation (protocol.pressure) or raise wave.contracted_ratio",
      t_);
}

}  // namespace

Result solve_force_driven(const Params& p, const Output& out, bool velocity_in_rhs) {
  return EventLoop(p, {}, 0.0, out, velocity_in_rhs).run();
}

Result solve_fixed_actuation(const Params& p, const std::vector<double>& q_cells, double t_end,
                             const Output& out) {
  validate(p);
  if (static_cast<int>(q_cells.size()) != p.numerics.cells)
    throw InputError("q_cells", std::to_string(q_cells.size()), "one actuation value per cell");
  return EventLoop(p, q_cells, t_end, out, false).run();
}

}  // namespace swim::reduced1d::detail
