#include "axi/run_axi.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include <Eigen/Sparse>

#include "axi/fe_stokes_axi.hpp"
#include "axi/grid_axi.hpp"
#include "axi/ib_axi.hpp"
#include "axi/run_folder_axi.hpp"
#include "axi/stokes_axi.hpp"
#include "axi/tri_mesh.hpp"
#include "axi/wall_axi.hpp"
#include "common/errors.hpp"
#include "common/progress.hpp"
#include "common/si_format.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/protocol3d.hpp"
#include "full3d/run3d_checkpoint.hpp"
#include "full3d/run3d_output.hpp"
#include "common/output.hpp"

namespace swim::axi {

using scene::json;

const std::vector<std::string>& series_columns() {
  static const std::vector<std::string> c = [] {
    std::vector<std::string> v = record::common_series_columns();
    for (const char* k : {"elastic_energy_J", "bending_energy_J", "active_segment", "cycles_completed", "cfl",
                          "max_spacing_m", "dt_s"})
      v.push_back(k);
    return v;
  }();
  return c;
}

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The protocol's view of the wall: a "mesh" of one node per ring (n_theta = 1), with the
/// rings' reference positions and areas, so that the 3D tier's protocol (segments, relays,
/// events, recovery end) drives the rings unchanged.
full3d::CylinderMesh ring_mesh(const AxiWall& wall, double R0, double L, double x_start) {
  full3d::CylinderMesh m;
  m.radius = R0;
  m.length = L;
  m.n_theta = 1;
  m.n_rings = wall.nodes();
  m.ring_spacing = wall.ds0();
  m.axis_start = Eigen::Vector3d(x_start, 0.0, 0.0);
  m.X0 = wall.reference();
  m.X0.row(0).array() += x_start;
  m.node_area = wall.node_area();
  return m;
}

class Runner {
 public:
  Runner(const ParamsAxi& p, const json& resolved, const std::string& out, const RunControlAxi& ctl)
      : p_(p), b_(p.base), resolved_(resolved), out_(out), ctl_(ctl), grid_{p.nr, p.nx, p.h},
        fitted_(p.method == AxiMethod::Fitted), wall_(AxiWallParams{b_.R0, b_.L, p.ks, p.D, p.wall_nodes, p.ring_s0, p.poisson_coupling}),
        mesh_(ring_mesh(wall_, b_.R0, b_.L, p.x_start())), e_ref_(wall_.uniform_energy(b_.protocol.R_f)),
        protocol_(effective(), mesh_, e_ref_),
        rec_("axi", fitted_ ? "axisymmetric_fitted_finite_elements" : "axisymmetric_immersed_boundary", b_.L,
             series_columns(), wall_.reference_positions()) {
    rec_.keep(ctl.keep_rows);
    if (fitted_) {
      // a resumed run's triangulation is the checkpoint's (restore), made once there
      if (!(p_.triangles && ctl.resume)) {
        if (p_.triangles) tri_ = std::make_shared<TriMesh>(tri_mesh_params(p_), mesh_.X0);
        make_solvers();
      }
    } else {
      stokes_ = std::make_unique<AxiStokes>(grid_, b_.fluid.mu);
    }
    X_ = mesh_.X0;
    U_ = Eigen::Matrix3Xd::Zero(3, X_.cols());
    const double q_static = b_.c1_estimate() * (b_.R0 - b_.protocol.R_f);
    e_cap_ = b_.energy_growth * e_ref_ * std::max(1.0, std::pow(b_.protocol.q / q_static, 2));
    t_end_ = b_.duration > 0 ? b_.duration : p_.time_limit;
  }

  RunOutcomeAxi run() {
    const auto t0 = std::chrono::steady_clock::now();
    if (ctl_.resume)
      restore();
    else
      stream_ = open_run_stream(rec_, out_, ctl_);
    Progress progress("axi " + p_.name() + (b_.duration > 0 ? "" : " (auto: until " + std::to_string(b_.protocol.cycles) +
                                                                  (b_.protocol.cycles == 1 ? " cycle" : " cycles") + ", progress against axi.time_limit)"),
                      t_end_, ctl_.progress);
    std::optional<NumericalError> failure;
    long this_process = 0;
    try {
      if (!ctl_.resume) {
        x_center0_ = center(X_);
        protocol_.start(0.0, X_);
        events();
        evaluate(X_, U_, &energy_);
        fluxes(0.0);
        record();
        next_out_ = b_.output_interval;
        next_checkpoint_ = p_.checkpoint_interval;
        dt_ = p_.event_dt;
        save_checkpoint(seconds_since(t0));
      }
      while (!finished()) {
        step();
        ++this_process;
        progress.update(t_);
        const bool event = events();
        if (event || t_ >= next_out_ - 1e-12 * b_.output_interval || finished()) {
          record();
          while (next_out_ <= t_ + 1e-12 * b_.output_interval) next_out_ += b_.output_interval;
        }
        if (!finished() && t_ >= next_checkpoint_ - 1e-12 * p_.checkpoint_interval) {
          while (next_checkpoint_ <= t_ + 1e-12 * p_.checkpoint_interval) next_checkpoint_ += p_.checkpoint_interval;
          save_checkpoint(wall_before_ + seconds_since(t0));
        }
        if (ctl_.stop_after_steps > 0 && this_process >= ctl_.stop_after_steps && !finished()) {
          RunOutcomeAxi stopped;
          stopped.interrupted = true;
          stopped.steps = steps_;
          return stopped;
        }
      }
    } catch (const NumericalError& e) {
      failure = e;
      if (last_recorded_ != steps_ && X_.allFinite() && U_.allFinite()) {
        try {
          record();
        } catch (const NumericalError&) {
        }
      }
    }
    progress.done();
    events();
    return finish_run(rec_, failure, wall_before_ + seconds_since(t0), steps_, out_, resolved_,
                      [this](const std::string& status, double wall) { fill(status, wall); });
  }

 private:
  /// The fitted method's two solvers on the structured mesh, or on the current triangulation
  /// (their statistics continued from the solvers they replace).
  void make_solvers() {
    const FittedStokes::Timing ts = stage_ ? stage_->timing() : FittedStokes::Timing{};
    const FittedStokes::Timing tf = flow_ ? flow_->timing() : FittedStokes::Timing{};
    stage_.reset();
    flow_.reset();
    if (tri_) {
      stage_ = std::make_unique<FittedStokes>(std::make_unique<TriMesh>(*tri_), b_.fluid.mu);
      flow_ = std::make_unique<FittedStokes>(std::make_unique<TriMesh>(*tri_), b_.fluid.mu);
    } else {
      const FittedMeshParams mp = fitted_mesh_params();
      stage_ = std::make_unique<FittedStokes>(mp, b_.fluid.mu, wall_.nodes());
      flow_ = std::make_unique<FittedStokes>(mp, b_.fluid.mu, wall_.nodes());
    }
    // The steps' linear solves stop at a relative residual of 1e-7 (FittedStokes's own default,
    // 1e-12, is for its tests): the stage velocity's error is then 4-5 orders below the step's
    // error tolerance, and an old factorisation preconditions for longer. On paper_amplitude_0.82
    // (16 cells) the displacement per cycle moved by 1.3e-8 and the cycle time by 1e-7 (relative),
    // with 114 factorisations instead of 431 (docs/performance.md, "Axisymmetric tier").
    for (FittedStokes* f : {stage_.get(), flow_.get()}) {
      f->set_reuse(true, FittedStokes::kRefactorAfter, kStepSolveTolerance);
      f->set_background_factorisation(p_.threads > 1);
    }
    stage_->set_timing(ts);
    flow_->set_timing(tf);
  }

  /// The triangulation made again on the wall X (axi.mesh = triangles), and the solvers on it.
  void remesh(const Eigen::Matrix3Xd& X) {
    const auto t = std::chrono::steady_clock::now();
    tri_ = std::make_shared<TriMesh>(tri_mesh_params(p_), X);
    make_solvers();
    ++remeshes_;
    remesh_times_.push_back(t_);
    split_remesh_ += seconds_since(t);
  }

  /// Keeps the triangulation fitted to the accepted shape X_. With axi.remesh_interval > 0 it is
  /// made again on X_ at every multiple of the interval (the steps land on them), so the shapes
  /// the meshes are made on, and when, do not move with the step sequence; in between only a mesh
  /// that can no longer follow the wall (a triangle inverted, or the smallest angle below half
  /// the threshold below) is made again. With 0 it is made again whenever it has degraded: a
  /// triangle inverted, or the smallest angle below axi.remesh_angle scaled by how far the mesh,
  /// when made, fell short of the mesher's bound (TriMesh::remesh_threshold: a shape whose own
  /// corners cap every triangulation's smallest angle below axi.remesh_angle is not meshed again
  /// at every step).
  void keep_triangles_fit() {
    if (p_.remesh_interval > 0 && t_ >= next_mesh_check_ - 1e-9 * p_.remesh_interval) {
      next_mesh_check_ = (std::floor(t_ / p_.remesh_interval + 1e-6) + 1.0) * p_.remesh_interval;
      if (t_ > 0) {
        remesh(X_);
        return;
      }
    }
    TriMesh probe(*tri_);
    try {
      probe.fit(X_);
    } catch (const NumericalError&) {
      remesh(X_);
      return;
    }
    const double threshold = tri_->remesh_threshold(p_.remesh_angle) * (p_.remesh_interval > 0 ? 0.5 : 1.0);
    if (probe.min_angle() < threshold) remesh(X_);
  }

  /// The next scheduled remesh (axi.remesh_interval), for the step to land on.
  double mesh_check_bound() const {
    if (!tri_ || p_.remesh_interval <= 0) return std::numeric_limits<double>::infinity();
    return std::max(next_mesh_check_ - t_, p_.dt_min);
  }

  // ---- checkpoints ----------------------------------------------------------------------
  /// The run's state between steps, listed once for writing and reading (full3d/checkpoint.hpp).
  template <class Self, class F>
  static void records(Self& self, F&& f) {
    f("t", self.t_);
    f("step", self.steps_);
    f("X", self.X_.data(), std::size_t(self.X_.size()));
    f("U", self.U_.data(), std::size_t(self.U_.size()));
    f("energy", self.energy_.data(), self.energy_.size());
    full3d::protocol_records(self.protocol_.state(), f);
    f("dt_next", self.dt_);
    f("dt_last", self.dt_last_);
    f("dt_min_taken", self.dt_min_taken_);
    f("dt_max_taken", self.dt_max_taken_);
    f("next_output", self.next_out_);
    f("next_checkpoint", self.next_checkpoint_);
    f("x_center0", self.x_center0_);
    f("flux_rear", self.q_rear_);
    f("flux_front", self.q_front_);
    f("volume_rear", self.vol_rear_);
    f("volume_front", self.vol_front_);
    f("step_flux_rear", self.step_q_rear_);
    f("step_flux_front", self.step_q_front_);
    f("split_forces", self.split_forces_);
    f("split_spread", self.split_spread_);
    f("split_fluid", self.split_fluid_);
    f("split_interp", self.split_interp_);
    f("split_stiffness", self.split_stiffness_);
    f("rejected", self.rejected_);
    f("solves", self.solves_);
    f("last_recorded", self.last_recorded_);
    f("event_retakes", self.event_retakes_);
    f("event_tries", self.event_tries_);
    f("event_pending", self.event_pending_);
  }

  /// The fitted solvers' statistics so far, as numbers (they continue in a resumed run).
  static std::vector<double> timing_record(const FittedStokes::Timing& t) {
    return {t.assemble, t.factor, t.solve, double(t.factorisations), double(t.solves), double(t.krylov_iterations),
            double(t.reused), t.factor_background};
  }
  static FittedStokes::Timing timing_of(const std::vector<double>& v) {
    FittedStokes::Timing t;
    t.assemble = v.at(0), t.factor = v.at(1), t.solve = v.at(2);
    t.factorisations = long(v.at(3)), t.solves = long(v.at(4)), t.krylov_iterations = long(v.at(5)),
    t.reused = long(v.at(6));
    t.factor_background = v.at(7);
    return t;
  }

  /// The partial results (streams flushed, summary.json "running: ..."), then checkpoint.bin,
  /// then summary.json again listing it; the fitted solvers then forget their factorisations.
  void save_checkpoint(double wall) {
    fill("running: last checkpoint at t = " + significant(t_, 4) + " s (resume with --resume " + out_ + ")", wall);
    const std::vector<double> marks = record::write_snapshot(out_, rec_, resolved_);
    full3d::CheckpointWriter w(full3d::RunCheckpoint::scene_hash(resolved_));
    records(*this, full3d::CheckpointOut(w));
    rec_.save([&](const std::string& name, const std::vector<double>& v) { w.put(name, v); });
    if (fitted_) {
      w.put("stage_timing", timing_record(stage_->timing()));
      w.put("flow_timing", timing_record(flow_->timing()));
    }
    if (tri_) {  // the triangulation is made again on its reference shape when the run resumes
      const Eigen::Matrix3Xd& R = tri_->reference();
      w.put("mesh_reference", std::vector<double>(R.data(), R.data() + R.size()));
      w.put("remeshes", std::vector<double>{double(remeshes_), split_remesh_});
      w.put("remesh_times", remesh_times_);
    }
    w.put(full3d::kOutputMarks, marks);
    w.put("wall_time_s", wall);
    w.save(out_ + "/checkpoint.bin");
    output::write_json(out_ + "/summary.json", record::summary(rec_, resolved_));
    if (fitted_) {
      stage_->forget_factorisation();
      flow_->forget_factorisation();
    }
  }

  /// The state of checkpoint.bin (checked first, check_resumable_axi), the streams continued
  /// from its marks.
  void restore() {
    const full3d::CheckpointReader r = open_checkpoint(p_, resolved_, out_);
    records(*this, full3d::CheckpointIn(r));
    rec_.load([&](const std::string& name) { return r.get_vector(name); });
    if (fitted_ && p_.triangles) {
      const std::vector<double> R = r.get_vector("mesh_reference");
      tri_ = std::make_shared<TriMesh>(tri_mesh_params(p_), Eigen::Map<const Eigen::Matrix3Xd>(R.data(), 3, wall_.nodes()));
      make_solvers();
      const std::vector<double> m = r.get_vector("remeshes");
      remeshes_ = long(m.at(0));
      split_remesh_ = m.at(1);
      if (r.has("remesh_times")) remesh_times_ = r.get_vector("remesh_times");
      // a checkpoint lies between steps: a remesh due at its time has not been made yet
      if (p_.remesh_interval > 0)
        next_mesh_check_ = std::ceil(t_ / p_.remesh_interval - 1e-6) * p_.remesh_interval;
    }
    if (fitted_) {
      stage_->set_timing(timing_of(r.get_vector("stage_timing")));
      flow_->set_timing(timing_of(r.get_vector("flow_timing")));
    }
    wall_before_ = r.get_double("wall_time_s");
    stream_ = std::make_unique<record::RunStream>(out_, r.get_vector(full3d::kOutputMarks));
    stream_->limit(ctl_.max_output_bytes);
    rec_.attach(stream_.get());
  }

 public:
  /// checkpoint.bin of a run of this scene in `dir`, read and checked (see run_axi.hpp).
  static full3d::CheckpointReader open_checkpoint(const ParamsAxi& p, const json& resolved, const std::string& dir);

 private:
  full3d::ProtocolParams effective() const {
    full3d::ProtocolParams q = b_.protocol;
    q.end_energy = b_.recovery_end == "dead_band" ? wall_.uniform_energy(b_.R0 - b_.protocol.delta) : 0.0;
    q.dual_cell_segments = p_.method == AxiMethod::Fitted;
    return q;
  }


  bool finished() const {
    if (b_.duration > 0) return t_ >= b_.duration * (1.0 - 1e-12) || protocol_.finished();
    return protocol_.finished();
  }

  /// Ring velocities at positions X for the current protocol state; the wall energies of X.
  void evaluate(const Eigen::Matrix3Xd& X, Eigen::Matrix3Xd& U, std::array<double, 2>* energy) {
    auto t = std::chrono::steady_clock::now();
    Eigen::Matrix3Xd F = wall_.forces(X, energy);
    F += protocol_.force(X);
    if (!F.allFinite()) throw NumericalError("non-finite wall force", "reduce axi.tolerance", t_);
    split_forces_ += seconds_since(t);
    if (fitted_) {
      flow_->factor(X);
      flow_->solve(F, U);
      ++solves_;
      if (!U.allFinite()) throw NumericalError("non-finite wall velocity", "reduce axi.tolerance", t_);
      return;
    }
    t = std::chrono::steady_clock::now();
    spread(grid_, X, F, fr_, fx_);
    split_spread_ += seconds_since(t);
    t = std::chrono::steady_clock::now();
    u_.resize(grid_.u_size());
    w_.resize(grid_.w_size());
    stokes_->solve(fr_.data(), fx_.data(), u_.data(), w_.data());
    split_fluid_ += seconds_since(t);
    t = std::chrono::steady_clock::now();
    interpolate(grid_, X, u_.data(), w_.data(), U);
    split_interp_ += seconds_since(t);
    ++solves_;
    if (!U.allFinite()) throw NumericalError("non-finite wall velocity", "reduce axi.tolerance", t_);
  }

  double max_spacing(const Eigen::Matrix3Xd& X) const {
    double m = 0;
    for (Eigen::Index k = 0; k + 1 < X.cols(); ++k) m = std::max(m, (X.col(k + 1) - X.col(k)).head<2>().norm());
    return m;
  }

  /// The swimmer's axial position: the fitted method's wall is a discretised surface, so its
  /// centre is the area-weighted mean of the rings (the continuum mean over the tube); the
  /// immersed boundary keeps the plain ring mean, as the 3D tier's node mean.
  double center(const Eigen::Matrix3Xd& X) const {
    if (!fitted_) return X.row(0).mean();
    return X.row(0).dot(wall_.node_area().transpose()) / wall_.node_area().sum();
  }

  /// The step size bound of the next contraction event: the active segment's radius
  /// extrapolated linearly to R_f.
  double event_bound() const {
    const full3d::ProtocolState& st = protocol_.state();
    if (st.phase != 0) return p_.dt_max;
    const int a = st.active;
    double R = 0, V = 0;
    if (fitted_) {  // the protocol's own segment radius (linear in the ring radii)
      constexpr double tau = 1e-6;  // s
      R = protocol_.segment_radii(X_)[a];
      V = (protocol_.segment_radii(X_ + tau * U_)[a] - R) / tau;
    } else {
      int n = 0;
      for (int k = 0; k < wall_.nodes(); ++k)
        if (protocol_.segment_of(k) == a) R += X_(1, k), V += U_(1, k), ++n;
      R /= n, V /= n;
    }
    const double gap = R - b_.protocol.R_f;
    if (!(V < 0.0) || gap <= 0.0) return p_.dt_max;
    return std::max(p_.event_dt, 1.02 * gap / -V);
  }

  FittedMeshParams fitted_mesh_params() const { return axi::fitted_mesh_params(p_); }

  /// Wall and actuation forces at X for the current protocol state; throws on non-finite ones.
  Eigen::Matrix3Xd total_force(const Eigen::Matrix3Xd& X, std::array<double, 2>* energy = nullptr) {
    const auto t = std::chrono::steady_clock::now();
    Eigen::Matrix3Xd F = wall_.forces(X, energy);
    F += protocol_.force(X);
    split_forces_ += seconds_since(t);
    if (!F.allFinite()) throw NumericalError("non-finite wall force", "reduce axi.tolerance", t_);
    return F;
  }

  void step() {
    if (fitted_)
      step_ros2();
    else
      step_heun();
  }

  /// Why the fitted mesh cannot follow the wall's shape X (empty when it can): a ring outside
  /// (0, Rc), or the mesh fitted to X is not valid (a non-positive element Jacobian, the tube's
  /// ends crossed, ...; FittedMesh::fit's cause).
  std::string fold(const Eigen::Matrix3Xd& X) const {
    const int n = wall_.nodes();
    for (int k = 0; k < n; ++k)
      if (!(X(1, k) > 0.0 && X(1, k) < b_.container_radius))
        return "ring " + std::to_string(k) + " at radius " + significant(X(1, k), 4) + " m, outside (0, Rc)";
    if (!fitted_) return {};
    if (tri_) {
      std::string cause;
      return tri_->follows(X, &cause) ? std::string() : cause;
    }
    try {
      FittedMesh probe(fitted_mesh_params(), n);
      probe.fit(X);
    } catch (const NumericalError& e) {
      return e.cause();
    }
    return {};
  }

  /// The protocol's next event as a function of the shape, zero at the event and positive
  /// before it: the active segment's radius minus R_f while contracting; during the recovery
  /// the largest deviation of a ring's radius from R0 or of its axial position from its
  /// reference (mean translation removed) minus delta (full3d.recovery_end = shape), or the wall
  /// energy's excess over the end threshold relative to it (the energy ends). eps: how far past
  /// zero a located event may land.
  struct EventValue {
    bool active = false;
    double g = 0.0, eps = 0.0;
  };
  EventValue event_value(const Eigen::Matrix3Xd& X) const {
    const full3d::ProtocolState& st = protocol_.state();
    const full3d::ProtocolParams& q = protocol_.params();
    EventValue v;
    if (st.phase == 0) {
      v.active = true;
      v.g = protocol_.segment_radii(X)[st.active] - q.R_f;
      v.eps = 1e-3 * q.delta;
    } else if (st.phase == 1 && q.shape_end) {
      const int n = wall_.nodes();
      const double shift = center(X) - center(mesh_.X0);
      double m = 0.0;
      for (int k = 0; k < n; ++k)
        m = std::max({m, std::abs(X(1, k) - b_.R0), std::abs(X(0, k) - mesh_.X0(0, k) - shift)});
      v.active = true;
      v.g = m - q.delta;
      v.eps = 1e-3 * q.delta;
    } else if (st.phase == 1) {
      const std::array<double, 2> e = wall_.energies(X);
      const double thr = protocol_.end_threshold();
      v.active = thr > 0.0;
      v.g = (e[0] + e[1] - thr) / thr;
      v.eps = 1e-4;
    }
    return v;
  }

  /// One accepted step of the two-stage Rosenbrock method ROS2 (Verwer et al. 1999; order 2
  /// for any approximation W of the Jacobian, L-stable with gamma = 1 + 1/sqrt 2):
  ///   (I - gamma dt W) k1 = f(X),  (I - gamma dt W) k2 = f(X + dt k1) - 2 k1,
  ///   X+ = X + dt (3/2 k1 + 1/2 k2),  error estimate |X+ - (X + dt k1)| = dt/2 |k1 + k2|.
  /// f(X) = M(X) F(X), M the fluid's mobility on the mesh fitted to X, W = -M(X) K with K the
  /// wall's stiffness -dF_wall/dX at X (the actuation's relays and the mobility's dependence on
  /// the shape are left to the error control). With M^-1 the Schur complement of the
  /// finite-element system on the wall's velocity unknowns, (I + gamma dt M K) k = M F is the
  /// fitted system with gamma dt K added on the wall's unknowns, and
  ///   k2 = g - gamma dt (M^-1 + gamma dt K)^-1 K g,   g = f(X + dt k1) - 2 k1,
  /// reuses the stage's factorisation.
  void step_ros2() {
    const double tol = p_.tolerance * p_.h;
    constexpr double gamma = 1.0 + 0.70710678118654752440;
    if (tri_) keep_triangles_fit();
    dt_ = std::min({dt_, p_.dt_max, event_bound(), mesh_check_bound()});
    if (b_.duration > 0) dt_ = std::min(dt_, b_.duration - t_);
    auto tk = std::chrono::steady_clock::now();
    const Eigen::SparseMatrix<double> K = wall_.stiffness(X_, 1e-6 * b_.R0);
    split_stiffness_ += seconds_since(tk);
    const Eigen::Matrix3Xd F0 = total_force(X_);
    const int n = wall_.nodes();
    const EventValue g0 = event_value(X_);  // X_ is an accepted shape: the mesh follows it
    for (;;) {
      check_dt_min();
      bool valid = true;
      double err = 0;
      try {
        const int last = n - 1;
        stage_->factor(X_, &K, gamma * dt_);
        stage_->solve(F0, k1_, nullptr, 0);
        const double a_rear = stage_->end_disc_flux(0, k1_(0, 0)), a_front = stage_->end_disc_flux(1, k1_(0, last));
        X1_ = X_ + dt_ * k1_;
        const Eigen::Matrix3Xd F1 = total_force(X1_);
        flow_->factor(X1_);
        flow_->solve(F1, U1_, nullptr, 0);
        const double b_rear = flow_->end_disc_flux(0, U1_(0, 0)), b_front = flow_->end_disc_flux(1, U1_(0, last));
        solves_ += 2;
        Eigen::Matrix3Xd g = U1_ - 2.0 * k1_;
        Eigen::VectorXd gv(2 * n);
        for (int k = 0; k < n; ++k) gv(2 * k) = g(0, k), gv(2 * k + 1) = g(1, k);
        const Eigen::VectorXd Kg = K * gv;
        Eigen::Matrix3Xd KgF = Eigen::Matrix3Xd::Zero(3, n);
        for (int k = 0; k < n; ++k) KgF(0, k) = Kg(2 * k), KgF(1, k) = Kg(2 * k + 1);
        stage_->solve(KgF, k2_, nullptr, 1);
        ++solves_;
        const double c_rear = stage_->end_disc_flux(0, k2_(0, 0)), c_front = stage_->end_disc_flux(1, k2_(0, last));
        k2_ = g - (gamma * dt_) * k2_;
        // The end-disc fluxes are linear in the stage fields (each on its own mesh and disc), so
        // the step's mean flux is the same combination as the step's mean velocity.
        step_q_rear_ = 1.5 * a_rear + 0.5 * (b_rear - 2.0 * a_rear - gamma * dt_ * c_rear);
        step_q_front_ = 1.5 * a_front + 0.5 * (b_front - 2.0 * a_front - gamma * dt_ * c_front);
        if (!k1_.allFinite() || !k2_.allFinite()) throw NumericalError("non-finite stage", "reduce axi.tolerance", t_);
        err = 0.5 * dt_ * (k1_ + k2_).cwiseAbs().maxCoeff();
        // the step's end shape must be one the mesh can follow, as the stage's is
        Xn_ = X_ + dt_ * (1.5 * k1_ + 0.5 * k2_);
        if (const std::string bad = fold(Xn_); !bad.empty()) throw NumericalError(bad, "", t_);
      } catch (const NumericalError& e) {
        // a shape the fitted mesh cannot follow (folded or outside the container): retry smaller;
        // a triangulation made on an earlier shape is first made again on this step's start
        valid = false;
        last_rejection_ = e.cause();
        if (tri_ && tri_->reference() != X_ && e.cause().find("non-positive Jacobian") != std::string::npos) {
          ++rejected_;
          remesh(X_);
          continue;
        }
      }
      if (valid && err <= tol) {
        // Protocol events are located, not just detected: a step that carries the event
        // function g (protocol::event_value) past zero by more than its tolerance is taken again,
        // shorter, by the secant through g's values at its two ends.
        if (g0.active && g0.g > 0.0 && event_tries_ < kEventTries) {
          const EventValue g1 = event_value(Xn_);
          if (g1.g < -g1.eps) {
            ++event_tries_;
            ++event_retakes_;
            dt_ *= std::clamp((g0.g + 0.5 * g1.eps) / (g0.g - g1.g), 0.05, 0.999);
            continue;
          }
        }
        event_tries_ = 0;
        accept_and_grow(err, tol);
        return;
      }
      if (valid) last_rejection_ = "local error " + significant(err, 4) + " m above axi.tolerance x h = " + significant(tol, 4) + " m";
      reject(valid && err > tol ? err : -1.0, tol, 0.25);
    }
  }

  /// The step-size floor: a step below axi.dt_min ends the run (unless it only reaches a fixed
  /// duration's end), naming the last rejection's cause when there is one.
  void check_dt_min() const {
    if (dt_ < p_.dt_min && (b_.duration <= 0 || b_.duration - t_ > p_.dt_min))
      throw NumericalError("the step size fell below axi.dt_min = " + significant(p_.dt_min, 4) + " s" +
                               (last_rejection_.empty() ? "" : " (last rejection: " + last_rejection_ + ")"),
                           !fitted_ ? "loosen axi.tolerance or lower axi.dt_min"
                           : tri_   ? "loosen axi.tolerance or lower axi.dt_min; a folding wall needs a finer axi.grid"
                                    : "loosen axi.tolerance or lower axi.dt_min; a folding wall needs a finer axi.grid, "
                                      "and a rim that hooks back over the lumen axi.mesh = \"triangles\"",
                           t_);
  }

  /// Accepts the step of size dt_ to Xn_ with local error err, and sets the next step by the
  /// order-1/2 controller (0.9 sqrt(tol/err), between 0.2 and 2 times).
  void accept_and_grow(double err, double tol) {
    const double dt_done = dt_;
    const double grow = err > 0 ? 0.9 * std::sqrt(tol / err) : 2.0;
    accept(dt_done);
    dt_ = dt_done * std::clamp(grow, 0.2, 2.0);
  }

  /// Rejects the step: shrinks it by the controller when its error err (> 0) was too large,
  /// else by `fallback` (a failed stage, a CFL excess); between 0.1 and 0.5 times.
  void reject(double err, double tol, double fallback) {
    ++rejected_;
    const double shrink = err > 0 ? 0.9 * std::sqrt(tol / err) : fallback;
    dt_ *= std::clamp(shrink, 0.1, 0.5);
  }

  /// One accepted step of the trapezoidal rule (retried with smaller steps until its local
  /// error estimate passes).
  void step_heun() {
    const double h = p_.h, tol = p_.tolerance * h;
    double umax = 0;
    for (Eigen::Index k = 0; k < U_.cols(); ++k) umax = std::max(umax, U_.col(k).head<2>().norm());
    dt_ = std::min({dt_, p_.dt_max, event_bound()});
    if (umax > 0) dt_ = std::min(dt_, kCfl * h / umax);
    if (b_.duration > 0) dt_ = std::min(dt_, b_.duration - t_);
    for (;;) {
      check_dt_min();
      X1_ = X_ + dt_ * U_;
      std::array<double, 2> e1{};
      evaluate(X1_, U1_, &e1);
      const double err = 0.5 * dt_ * (U1_ - U_).cwiseAbs().maxCoeff();
      double u1max = 0;
      for (Eigen::Index k = 0; k < U1_.cols(); ++k) u1max = std::max(u1max, U1_.col(k).head<2>().norm());
      const double cfl = std::max(umax, u1max) * dt_ / h;
      if (err <= tol && cfl <= kMaxCfl) {
        Xn_ = X_ + (0.5 * dt_) * (U_ + U1_);
        accept_and_grow(err, tol);
        return;
      }
      reject(err > tol ? err : -1.0, tol, 0.5);
    }
  }

  void accept(double dt) {
    X_.swap(Xn_);
    t_ += dt;
    ++steps_;
    dt_last_ = dt;
    dt_min_taken_ = steps_ == 1 ? dt : std::min(dt_min_taken_, dt);
    dt_max_taken_ = std::max(dt_max_taken_, dt);
    if (fitted_) {
      // the step's mean wall velocity and end fluxes (ROS2's combination of its stages): no
      // further solve at the new shape
      U_ = 1.5 * k1_ + 0.5 * k2_;
      energy_ = wall_.energies(X_);
      vol_rear_ += dt * step_q_rear_;
      vol_front_ += dt * step_q_front_;
      q_rear_ = step_q_rear_;
      q_front_ = step_q_front_;
    } else {
      evaluate(X_, U_, &energy_);
      fluxes(dt);
    }
    const double e = energy_[0] + energy_[1];
    if (!std::isfinite(e) || e > e_cap_)
      throw NumericalError("the wall energy grew to " + significant(e, 4) + " J, " + significant(e / e_ref_, 4) +
                               " times that of the tube uniformly at R_f",
                           "reduce axi.tolerance, or raise full3d.energy_growth_limit if the load is meant", t_);
    const double sp = max_spacing(X_);
    if (!fitted_ && !(sp < 0.5 * p_.h))
      throw NumericalError("two wall rings moved " + significant(sp, 4) + " m apart, half a cell or more (h = " + significant(p_.h, 4) +
                               " m): fluid would leak through the wall",
                           "lower axi.spacing_factor", t_);
    const int sw = protocol_.update(t_, X_, e);
    if (sw > 0) {
      evaluate(X_, U_, &energy_);  // the actuation changed
      dt_ = p_.event_dt;
      event_pending_ = true;
    }
    if (b_.duration <= 0 && t_ >= p_.time_limit && !protocol_.finished())
      throw NumericalError("the protocol did not finish within axi.time_limit = " + significant(p_.time_limit, 4) + " s",
                           "raise axi.time_limit (the cycle may be slow to recover: see full3d.recovery_end)", t_);
  }

  /// Volume fluxes through the end discs (relative to the end ring's axial velocity, positive
  /// towards +x), integrated in time by the trapezoidal rule.
  void fluxes(double dt) {
    const int last = wall_.nodes() - 1;
    const double qr = fitted_ ? flow_->end_disc_flux(0, U_(0, 0))
                              : disc_flux(grid_, w_.data(), X_(0, 0), X_(1, 0), U_(0, 0), kDiscPoints);
    const double qf = fitted_ ? flow_->end_disc_flux(1, U_(0, last))
                              : disc_flux(grid_, w_.data(), X_(0, last), X_(1, last), U_(0, last), kDiscPoints);
    if (dt > 0) {
      vol_rear_ += 0.5 * dt * (q_rear_ + qr);
      vol_front_ += 0.5 * dt * (q_front_ + qf);
    }
    q_rear_ = qr;
    q_front_ = qf;
  }

  bool events() {
    const full3d::ProtocolState& st = protocol_.state();
    auto& e = rec_.events;
    bool any = event_pending_;
    event_pending_ = false;
    while (e.cycle_start_s.size() < st.cycle_start.size()) rec_.cycle_started(st.cycle_start[e.cycle_start_s.size()]), any = true;
    while (e.cycle_end_s.size() < st.cycle_end.size()) rec_.cycle_ended(st.cycle_end[e.cycle_end_s.size()]), any = true;
    return any;
  }

  void record() {
    const int n = wall_.nodes();
    double vol = 0;
    for (int k = 0; k + 1 < n; ++k)
      vol += 0.5 * M_PI * (X_(1, k) * X_(1, k) + X_(1, k + 1) * X_(1, k + 1)) * (X_(0, k + 1) - X_(0, k));
    double umax = 0;
    for (Eigen::Index k = 0; k < U_.cols(); ++k) umax = std::max(umax, U_.col(k).head<2>().norm());
    const full3d::ProtocolState& st = protocol_.state();
    const double row[] = {t_,
                          center(X_) - x_center0_,
                          U_.row(0).mean(),
                          energy_[0] + energy_[1],
                          X_.row(1).minCoeff(),
                          X_.row(1).maxCoeff(),
                          q_rear_,
                          q_front_,
                          vol_rear_,
                          vol_front_,
                          vol,
                          double(st.phase),
                          energy_[0],
                          energy_[1],
                          double(st.active),
                          double(st.cycles_completed),
                          umax * dt_last_ / p_.h,
                          max_spacing(X_),
                          steps_ > 0 ? dt_last_ : 0.0};
    last_recorded_ = steps_;
    const std::size_t rows = rec_.series.count();
    std::vector<double> radius(n);
    for (int k = 0; k < n; ++k) radius[k] = X_(1, k);
    try {
      rec_.add_row(row);
    } catch (const NumericalError&) {
      if (rec_.series.count() > rows) rec_.add_radius(t_, radius);
      throw;
    }
    rec_.add_radius(t_, radius);
  }

  void fill(const std::string& status, double wall) {
    rec_.status = status;
    rec_.wall_time_s = wall;
    rec_.derived = {{"C1_Pa_per_m", b_.c1_estimate()},
                    {"aspect_ratio_R0_over_L", b_.R0 / b_.L},
                    {"contracted_ratio", b_.protocol.R_f / b_.R0},
                    {"actuation_pressure_Pa", b_.protocol.q},
                    {"reference_energy_J", e_ref_},
                    {"recovery_end_energy_J", protocol_.end_threshold()},
                    {"cell_size_m", p_.h},
                    {"method", p_.method_name()},
                    {"grid", tri_ ? json{tri_->elements(), tri_->vertices()}
                                  : fitted_ ? json{p_.cells_inner, p_.cells_outer, wall_.nodes() - 1, p_.gap_columns}
                                            : json{p_.nr, p_.nx}},
                    {"grid_is", tri_ ? "triangles and vertices of the last triangulation (axi.mesh = triangles)"
                                : fitted_ ? "element rows inside and outside the wall, element columns along the tube and "
                                            "across the gap"
                                          : "cells across the radius and along the axis"},
                    {"wall_nodes", wall_.nodes()},
                    {"wall_node_spacing_m", wall_.ds0()},
                    {"wall_end_spacing_m", wall_.min_ds0()},
                    {"spring_constant_N_per_m", p_.ks},
                    {"stretching_modulus_N_per_m", 2.0 * p_.ks / std::sqrt(3.0)},
                    {"bending_rigidity_J", p_.D},
                    {"bending_rigidity_from", p_.bending_source},
                    {"segment_boundaries_m", protocol_.boundaries()}};
    const int cycles = protocol_.state().cycles_completed;
    const long per_cycle = cycles > 0 ? steps_ / cycles : 0;
    rec_.extras = {{"steps", steps_},
                   {"steps_per_cycle", per_cycle},
                   {"max_spacing_over_h", rec_.series.count() ? rec_.series.max("max_spacing_m") / p_.h : 0.0}};
    record::check_plausible(rec_, {b_.fluid.rho, b_.fluid.mu});
    rec_.events.switches = protocol_.state().switches;
    rec_.events.segment_reached_s = protocol_.state().segment_reached;
    rec_.stats = {{"steps", steps_},
                  {"rejected_steps", rejected_},
                  {"event_retakes", event_retakes_},
                  {"stokes_solves", solves_},
                  {"steps_per_cycle", per_cycle},
                  {"dt_min_taken_s", dt_min_taken_},
                  {"dt_max_taken_s", dt_max_taken_},
                  {"dt_mean_s", steps_ > 0 ? t_ / double(steps_) : 0.0},
                  {"protocol_switches", protocol_.state().switches},
                  {"wall_time_s", wall},
                  {"wall_time_split_s", split_json()}};
    if (fitted_) {
      rec_.stats["fitted_unknowns"] = flow_->unknowns();
      rec_.stats["fitted_nonzeros"] = flow_->nonzeros();
      rec_.stats["blas"] = blas_provider();
      // the factorisation that preconditions the steps' GMRES (docs/axi.md, "Linear solves"),
      // and how often it fell back to UMFPACK's LU since the run (or its resumption) started
      const long fallbacks = stage_->factorisation_fallbacks() + flow_->factorisation_fallbacks();
      rec_.stats["preconditioner"] =
          fallbacks == 0 ? "Cholesky of the regularised system (CHOLMOD)"
                         : "Cholesky of the regularised system (CHOLMOD), then LU (UMFPACK) after a failure";
      rec_.stats["factorisation_fallbacks"] = fallbacks;
      rec_.stats["mesh"] = tri_ ? "triangles" : "quadrilaterals";
      if (tri_) {
        rec_.stats["remeshes"] = remeshes_;
        rec_.stats["remesh_times_s"] = remesh_times_;
      }
    }
  }

  json split_json() const {
    if (!fitted_)
      return {{"wall_forces", split_forces_}, {"spread", split_spread_}, {"fluid", split_fluid_}, {"interp", split_interp_}};
    const FittedStokes::Timing& a = stage_->timing();
    const FittedStokes::Timing& b = flow_->timing();
    return {{"wall_forces", split_forces_},
            {"wall_stiffness", split_stiffness_},
            {"meshing", split_remesh_},
            {"assembly", a.assemble + b.assemble},
            {"factorisation", a.factor + b.factor},
            {"factorisation_in_background", a.factor_background + b.factor_background},
            {"solves", a.solve + b.solve},
            {"factorisations", a.factorisations + b.factorisations},
            {"solves_on_an_earlier_factorisation", a.reused + b.reused},
            {"gmres_iterations", a.krylov_iterations + b.krylov_iterations}};
  }

  static constexpr double kCfl = 0.25, kMaxCfl = 0.5;
  static constexpr double kStepSolveTolerance = 1e-7;  ///< relative residual of the steps' linear solves
  static constexpr int kDiscPoints = 32;

  const ParamsAxi& p_;
  const full3d::Params3d& b_;
  const json& resolved_;
  std::string out_;
  RunControlAxi ctl_;
  AxiGrid grid_;
  bool fitted_;
  std::unique_ptr<AxiStokes> stokes_;       ///< immersed boundary: the MAC solver
  std::unique_ptr<FittedStokes> stage_;     ///< fitted: the Rosenbrock stages' system (with gamma dt K)
  std::unique_ptr<FittedStokes> flow_;      ///< fitted: the plain fluid solve (velocities, end fluxes)
  std::shared_ptr<const TriMesh> tri_;      ///< fitted, axi.mesh = triangles: the current triangulation
  long remeshes_ = 0;                       ///< triangulations made after the first
  double split_remesh_ = 0;                 ///< s spent making them and their solvers
  AxiWall wall_;
  full3d::CylinderMesh mesh_;
  double e_ref_;
  full3d::Protocol3d protocol_;
  record::RunRecord rec_;
  std::unique_ptr<record::RunStream> stream_;

  Eigen::Matrix3Xd X_, U_, X1_, U1_, Xn_, k1_, k2_;
  std::vector<double> fr_, fx_, u_, w_;
  std::array<double, 2> energy_{};
  double t_ = 0, dt_ = 0, dt_last_ = 0, dt_min_taken_ = 0, dt_max_taken_ = 0, t_end_ = 0, next_out_ = 0;
  double next_mesh_check_ = 0;  ///< s: the triangulation's next scheduled remesh (axi.remesh_interval)
  std::vector<double> remesh_times_;  ///< s: when the triangulations after the first were made
  double e_cap_ = 0, x_center0_ = 0, next_checkpoint_ = 0, wall_before_ = 0;
  double q_rear_ = 0, q_front_ = 0, vol_rear_ = 0, vol_front_ = 0, step_q_rear_ = 0, step_q_front_ = 0;
  long steps_ = 0, rejected_ = 0, solves_ = 0, last_recorded_ = -1, event_retakes_ = 0;
  int event_tries_ = 0;
  std::string last_rejection_;  ///< why the last fitted step was rejected (for the dt_min message)
  static constexpr int kEventTries = 12;
  bool event_pending_ = false;
  double split_forces_ = 0, split_spread_ = 0, split_fluid_ = 0, split_interp_ = 0, split_stiffness_ = 0;
};

full3d::CheckpointReader Runner::open_checkpoint(const ParamsAxi& p, const json& resolved, const std::string& dir) {
  if (p.base.wave.prescribed())
    throw InputError("--resume", dir, "a prescribed wave's run (wave.kind = " + p.base.wave.kind +
                                          ") writes no checkpoint; run it again");
  full3d::CheckpointReader r(dir + "/checkpoint.bin", full3d::RunCheckpoint::scene_hash(resolved));
  const auto count = [](std::int64_t v) { return std::to_string(v); };
  const auto int_in = [&](const char* name, std::int64_t lo, std::int64_t hi, const std::string& what) {
    const std::int64_t v = r.get_int(name);
    if (v < lo || v > hi)
      r.damaged("the checkpoint's " + what + " ('" + name + "') is " + count(v) + ", outside [" + count(lo) + ", " +
                count(hi) + "]");
    return v;
  };
  const auto expect_size = [&](const char* name, std::size_t n, const std::string& what) {
    if (r.size_of(name) != n)
      r.damaged("the checkpoint's '" + std::string(name) + "' has " + std::to_string(r.size_of(name)) +
                " values, this scene's " + what + " needs " + std::to_string(n) + " (a different grid or wall)");
  };
  if (const std::string bad = r.first_non_finite(); !bad.empty())
    r.damaged("the checkpoint's record '" + bad + "' holds a NaN or infinite value");
  const double t = r.get_double("t");
  const double t_end = p.base.duration > 0 ? p.base.duration : p.time_limit;
  if (t < 0.0 || t > t_end)
    r.damaged("the checkpoint's simulated time t = " + significant(t, 4) + " s lies outside this run's [0, " +
              significant(t_end, 4) + "] s (time.duration, or axi.time_limit when the duration is auto)");
  const std::int64_t big = std::int64_t(1) << 53;
  const std::int64_t n = int_in("step", 0, big, "step count");
  int_in("last_recorded", -1, n, "last output step");
  int_in("phase", 0, 1, "protocol phase (a finished run has no checkpoint to continue)");
  int_in("active", 0, p.base.protocol.segments - 1, "active segment");
  int_in("cycles_completed", 0, n, "completed cycles");
  for (const char* name : {"switches", "rejected", "solves", "event_retakes"}) int_in(name, 0, big, "counter");
  int_in("event_tries", 0, 1000, "event retries");
  int_in("event_pending", 0, 1, "event flag");
  const std::size_t rings = std::size_t(p.wall_nodes);
  expect_size("X", 3 * rings, "wall rings");
  expect_size("U", 3 * rings, "wall rings");
  expect_size("energy", 2, "wall energies");
  if (p.method == AxiMethod::Fitted) {
    expect_size("stage_timing", 8, "solver statistics");
    expect_size("flow_timing", 8, "solver statistics");
  }
  if (p.method == AxiMethod::Fitted && p.triangles) {
    expect_size("mesh_reference", 3 * std::size_t(p.wall_nodes), "triangulation's reference shape");
    expect_size("remeshes", 2, "triangulation statistics");
  }
  expect_size(full3d::kOutputMarks, 6, "output streams (size and checksum of series.csv.part and radius.csv.part)");
  const std::vector<double> X = r.get_vector("X");
  const double Rc = p.base.container_radius;
  for (std::size_t k = 0; k < rings; ++k)
    if (!(X[3 * k + 1] > 0.0 && X[3 * k + 1] < Rc))
      r.damaged("the checkpoint's ring " + std::to_string(k) + " lies at radius " + significant(X[3 * k + 1], 4) +
                " m, outside the container (0, " + significant(Rc, 4) + " m)");
  if (r.get_double("wall_time_s") < 0.0) r.damaged("the checkpoint's wall time is negative");
  if (!record::RunStream::matches(dir, r.get_vector(full3d::kOutputMarks)))
    r.damaged("the partial results series.csv.part and radius.csv.part next to it are missing or do not match it "
              "(changed, or shorter than at the checkpoint)");
  return r;
}

}  // namespace

void check_resumable_axi(const ParamsAxi& p, const json& resolved, const std::string& out_dir) {
  Runner::open_checkpoint(p, resolved, out_dir);
}

RunOutcomeAxi run_axi(const ParamsAxi& p, const json& resolved, const std::string& out_dir, const RunControlAxi& ctl) {
  if (p.base.wave.prescribed()) {
    if (ctl.resume) Runner::open_checkpoint(p, resolved, out_dir);  // refused, naming why
    return run_prescribed_axi(p, resolved, out_dir, ctl);
  }
  Runner r(p, resolved, out_dir, ctl);
  return r.run();
}

}  // namespace swim::axi
