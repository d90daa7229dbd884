#include "full3d/run3d.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/progress.hpp"
#include "common/vtk.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/ib.hpp"

namespace swim::full3d {

using scene::json;

IbOptions ib_options(const Params3d& p) {
  IbOptions o;
  o.scheme = p.scheme;
  o.max_cfl = p.max_cfl;
  o.dt_key = "full3d.dt";
  o.threads = p.threads;
  o.stokes.fft.threads = p.threads;
  o.stokes.direct_threads = p.threads;
  if (p.container == "cylinder") {
    o.stokes.cylinder.enabled = true;
    o.stokes.cylinder.radius = p.container_radius;
    o.stokes.cylinder.wall = p.cylinder_wall == "ghost_linear"     ? CylinderWall::GhostLinear
                             : p.cylinder_wall == "surface_points" ? CylinderWall::SurfacePoints
                                                                   : CylinderWall::Staircase;
  }
  o.stokes.advection.enabled = p.navier_stokes;
  if (p.threads > 1) fftw_threads_init_once();
  return o;
}

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

long steps_for(double interval, double dt) { return std::max(1L, std::lround(interval / dt)); }

const std::vector<std::string> kSeriesColumns = {
    "t_s", "x_center_m", "velocity_m_per_s", "energy_J", "min_radius_m", "max_radius_m", "flux_rear_m3_per_s",
    "flux_front_m3_per_s", "volume_rear_m3", "volume_front_m3", "tube_volume_m3", "phase", "elastic_energy_J",
    "bending_energy_J", "kinetic_energy_J", "active_segment", "cycles_completed", "cfl", "stokes_iterations",
    "max_divergence_per_s", "max_edge_m", "dt_s"};

/// Adaptive step: re-estimate the explicit-coupling limit at least every this many steps
/// (and after every protocol event).
constexpr long kStabilityEvery = 200;
/// Power iterations per estimate of the explicit-coupling rate.
constexpr int kStabilityIterations = 10;

/// true when (t0, t1] contains a positive multiple of interval (time-based output cadence).
bool crossed(double t0, double t1, double interval) {
  const double eps = 1e-9;
  return std::floor(t1 / interval + eps) > std::floor(t0 / interval + eps);
}

/// The scene as it must match on resume: everything except the keys that only steer
/// output cadence and parallelism.
std::string resume_key(const json& resolved) {
  json r = resolved;
  if (r.contains("full3d") && r["full3d"].is_object()) {
    r["full3d"].erase("checkpoint_interval");
    r["full3d"].erase("threads");
    r["full3d"].erase("time_limit");  // a run stopped by the cap can be continued with a larger one
  }
  return r.dump();
}

class Runner {
 public:
  Runner(const Params3d& p, const json& resolved, std::string out, const RunControl& ctl)
      : p_(p), resolved_(resolved), out_(std::move(out)), ctl_(ctl), mesh_(make_mesh(p)),
        mass_(node_masses(mesh_, p.mass_per_area)),
        e_ref_(uniform_contraction_energy(mesh_, p.membrane, p.protocol.R_f)),
        protocol_(effective_protocol(p, mesh_), mesh_, e_ref_),
        pvd_(out_ + "/membrane.pvd"), fluid_pvd_(out_ + "/fluid.pvd") {
    adaptive_ = p.adaptive.enabled && !p.dry;
    dt_key_ = adaptive_ ? "full3d.adaptive.dt_max" : "full3d.dt";
    const double q_static = p.c1_estimate() * (p.R0 - p.protocol.R_f);
    e_cap_ = p.energy_growth * e_ref_ * std::max(1.0, std::pow(p.protocol.q / q_static, 2));
    out_every_ = steps_for(p.output_interval, p.dt);
    vtk_every_ = steps_for(p.vtk_interval, p.dt);
    fluid_every_ = steps_for(p.fluid_interval, p.dt);
    ckpt_every_ = steps_for(p.checkpoint_interval, p.dt);
    n_end_ = p.duration > 0 ? std::max(1L, std::lround(p.duration / p.dt)) : -1;
    n_limit_ = std::max(1L, std::lround(p.time_limit / p.dt));
    vtk_on_ = p.vtk && !ctl.quiet_vtk;
    fluid_on_ = p.fluid_fields && !p.dry && !ctl.quiet_vtk;
    if (!p.dry) {
      grid_.emplace(p.nx, p.ny, p.nz, p.h, p.container_kind());
      IbOptions o = ib_options(p);
      o.reject_on_cfl = adaptive_;
      o.dt_key = dt_key_;
      const Eigen::VectorXd m = p.wall_inertia ? mass_ : Eigen::VectorXd::Zero(mesh_.nodes());
      ib_ = std::make_unique<IbSolver>(*grid_, p.fluid, mesh_, p.membrane, m, o);
      ib_->set_external_force([this](double, const Eigen::Matrix3Xd& X) { return protocol_.force(X); });
      s_ = ib_->initial_state();
    } else {
      s_.X = mesh_.X0;
      s_.V = Eigen::Matrix3Xd::Zero(3, mesh_.nodes());
      s_.V_prev = s_.V;
    }
    build_discs();
    dt_last_ = dt_before_last_ = p.dt;
    if (adaptive_) dt_next_ = dt_last_ = dt_before_last_ = ladder(p.adaptive.event_dt);
  }

  RunOutcome run() {
    RunOutcome res;
    const auto t0 = std::chrono::steady_clock::now();
    if (ctl_.resume) {
      load_checkpoint();
    } else {
      protocol_.start(0.0, s_.X);
      x_center0_ = s_.X.row(0).mean();
      step_marks_.push_back(0.0);
      record();
      if (vtk_on_) write_vtk_frame();
      if (fluid_on_) write_fluid_frame();
      save_checkpoint(0.0);
    }
    const double t_end = n_end_ > 0 ? p_.duration : p_.time_limit;
    Progress progress("3d " + p_.name + (n_end_ > 0 ? "" : " (auto: until " + std::to_string(p_.protocol.cycles) +
                                                               " cycle(s), progress against full3d.time_limit)"),
                      t_end, ctl_.progress);
    long this_process = 0;
    std::optional<NumericalError> failure;
    try {
      while (!finished()) {
        if (n_end_ < 0 && (adaptive_ ? s_.t >= p_.time_limit * (1.0 - 1e-12) : n_ >= n_limit_))
          throw NumericalError("the protocol did not complete " + std::to_string(p_.protocol.cycles) +
                                   " cycle(s) within full3d.time_limit = " + num(p_.time_limit) + " s",
                               "raise full3d.time_limit, or give a time.duration", s_.t);
        t_prev_ = s_.t;
        advance();
        ++n_;
        ++this_process;
        if (due(out_every_, p_.output_interval)) record();
        if (vtk_on_ && due(vtk_every_, p_.vtk_interval)) write_vtk_frame();
        if (fluid_on_ && due(fluid_every_, p_.fluid_interval)) write_fluid_frame();
        if (due(ckpt_every_, p_.checkpoint_interval)) save_checkpoint(wall_before_ + seconds_since(t0));
        progress.update(s_.t);
        if (ctl_.stop_after_steps > 0 && this_process >= ctl_.stop_after_steps && !finished()) {
          res.interrupted = true;
          res.steps = n_;
          return res;
        }
      }
      if (last_recorded_ != n_) record();
      if (vtk_on_ && !(n_ > 0 && due(vtk_every_, p_.vtk_interval))) write_vtk_frame();
    } catch (const NumericalError& e) {
      failure = e;
      // the state is the last step the solver accepted; record it when it is finite
      if (last_recorded_ != n_ && s_.X.allFinite() && s_.V.allFinite() && std::isfinite(wall_energy())) record();
    }
    progress.done();
    const double wall = wall_before_ + seconds_since(t0);
    res.failed = failure.has_value();
    res.message = failure ? failure->what() : "";
    res.summary = write_outputs(failure ? "failed: " + std::string(failure->what()) : "ok", wall);
    res.steps = n_;
    return res;
  }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  bool finished() const {
    if (n_end_ <= 0) return protocol_.finished();
    return adaptive_ ? s_.t >= p_.duration * (1.0 - 1e-12) : n_ >= n_end_;
  }

  /// Output cadence: every `every` steps (fixed step) or at each multiple of `interval`
  /// crossed by the last step (adaptive step).
  bool due(long every, double interval) const { return adaptive_ ? crossed(t_prev_, s_.t, interval) : n_ % every == 0; }

  /// dt snapped down to the ladder dt_max 2^(-k/4), k >= 0.
  double ladder(double dt) const {
    const double top = p_.adaptive.dt_max;
    if (dt >= top) return top;
    const double k = std::ceil(4.0 * std::log2(top / dt) - 1e-9);
    return top * std::exp2(-k / 4.0);
  }

  // --- one time step -------------------------------------------------------
  void advance() {
    if (p_.dry) {
      dry_step();
      last_cfl_ = 0;
      last_iterations_ = 0;
      last_divergence_ = 0;
    } else {
      double dt = adaptive_ ? dt_next_ : p_.dt;
      if (adaptive_ && p_.duration > 0) dt = std::min(dt, p_.duration - s_.t);  // land on the end
      IbStepStats st;
      for (;;) {
        st = ib_->step(s_, dt);
        if (!st.rejected) break;
        // CFL above the guard: retry from the same state with a step at the CFL target
        ++rejected_;
        dt = ladder(std::min(0.5 * dt, 0.9 * dt * p_.adaptive.cfl / st.cfl));
        if (dt < p_.adaptive.dt_min)
          throw NumericalError("the adaptive step fell below full3d.adaptive.dt_min = " + num(p_.adaptive.dt_min) +
                                   " s at the CFL limit (nodes at " + num(st.max_node_speed) + " m/s)",
                               "lower full3d.adaptive.dt_min, or lower the actuation (protocol.pressure / load_factor)",
                               s_.t);
      }
      dt_before_last_ = dt_last_;
      dt_last_ = dt;
      dt_used_min_ = std::min(dt_used_min_, dt);
      dt_used_max_ = std::max(dt_used_max_, dt);
      last_speed_ = st.max_node_speed;
      last_dv_ = st.max_velocity_change;
      last_cfl_ = st.cfl;
      last_iterations_ = st.stokes_iterations;
      last_divergence_ = st.max_divergence;
      max_cfl_ = std::max(max_cfl_, st.cfl);
      iterations_total_ += st.stokes_iterations;
      measure_fluxes();
      vol_rear_ += 0.5 * dt * (q_rear_prev_ + q_rear_);
      vol_front_ += 0.5 * dt * (q_front_prev_ + q_front_);
      q_rear_prev_ = q_rear_;
      q_front_prev_ = q_front_;
    }
    const double e = wall_energy();
    guards(e);
    const int cycles_before = protocol_.state().cycles_completed;
    const int switches = protocol_.update(s_.t, s_.X, e);
    if (protocol_.state().cycles_completed > cycles_before) step_marks_.push_back(double(n_ + 1));
    if (adaptive_) next_step(switches);
  }

  // --- adaptive step (docs/full3d.md, "Adaptive time step") --------------------------
  void next_step(int switches) {
    const AdaptiveStep& a = p_.adaptive;
    const double h = p_.h;
    double dt = std::min(a.dt_max, 2.0 * dt_last_);  // growth at most 2x per step
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
    if (p_.scheme == IbScheme::Midpoint) {
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
      lambda_ = ib_->explicit_rate(s_, dt_last_, kStabilityIterations);
      lambda_step_ = step;
      lambda_max_seen_ = std::max(lambda_max_seen_, lambda_);
      ++estimates_;
    }
    if (lambda_ > 0.0) limit(a.stability_fraction * 2.0 / lambda_, "stability");
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
        const double t_event = (r_active - p_.protocol.R_f) / rate;
        if (t_event < dt) limit(std::max(a.event_dt, 1.02 * t_event), "event");
      }
    }
    r_active_prev_ = switches > 0 ? std::numeric_limits<double>::quiet_NaN() : r_active;
    after_event_ = switches > 0;
    if (dt < a.dt_min)
      throw NumericalError("the adaptive step (" + num(dt) + " s, bound: " + bound +
                               ") fell below full3d.adaptive.dt_min = " + num(a.dt_min) + " s",
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

  void dry_step() {
    full3d::dry_step(mesh_, p_.membrane, mass_, p_.dry_damping * mesh_.node_area,
                     [this](double, const Eigen::Matrix3Xd& X) { return protocol_.force(X); }, p_.scheme, s_, p_.dt);
  }

  // --- measurements ----------------------------------------------------------
  double kinetic_energy() const {
    double k = 0;
    for (Eigen::Index i = 0; i < s_.V.cols(); ++i) k += 0.5 * mass_[i] * s_.V.col(i).squaredNorm();
    return k;
  }
  double wall_energy() const { return elastic_energy(mesh_, s_.X, p_.membrane) + kinetic_energy(); }

  void guards(double e) {
    if (!std::isfinite(e))
      throw NumericalError("non-finite wall energy", "reduce the time step " + dt_key_, s_.t);
    const double rmin = node_radii(mesh_, s_.X).minCoeff();
    if (e > e_cap_) {
      // Below about 0.55 R0 of hoop contraction the linear spring lattice has a negative
      // stiffness in the alternate-ring twist mode (docs/full3d.md, "Compressed-lattice
      // instability"): no time step cures that, so say so when the run went that far.
      const double r_lowest = std::min(rmin_seen_, rmin) / p_.R0;
      const bool lattice = r_lowest < 0.56;
      throw NumericalError(
          "wall energy " + num(e) + " J grew beyond " + num(p_.energy_growth) + " times the reference energy (" +
              num(e_cap_) + " J)" +
              (lattice ? ": nodes had contracted to " + num(r_lowest) +
                             " R0, where the compressed spring lattice loses its in-plane stability (alternate-ring "
                             "twist mode, docs/full3d.md); a smaller time step does not help"
                       : ": the explicit coupling is unstable"),
          lattice ? "raise wave.contracted_ratio (>= 0.6), lower the actuation overshoot (protocol.load_factor), or run "
                    "with fluid (full3d.dry = false)"
                  : "reduce the time step " + dt_key_ + " (or raise full3d.energy_growth_limit if the growth is physical)",
          s_.t);
    }
    rmin_seen_ = std::min(rmin_seen_, rmin);
    if (rmin < 0.02 * p_.R0)
      throw NumericalError("the tube collapsed: a node came within " + num(rmin) + " m of the axis",
                           "lower the actuation (protocol.total_force / pressure / load_factor) or reduce " + dt_key_,
                           s_.t);
  }

  void build_discs() {
    // Mid-point rule on a polar grid of the unit disc: weights rho d rho d theta.
    const int nr = 6, nth = 16;
    for (int j = 0; j < nr; ++j)
      for (int l = 0; l < nth; ++l) {
        const double rho = (j + 0.5) / nr, th = 2.0 * M_PI * (l + 0.5 * (j % 2)) / nth;
        disc_.push_back({rho * std::cos(th), rho * std::sin(th), rho * (1.0 / nr) * (2.0 * M_PI / nth)});
      }
  }

  /// Volume flux through the disc spanned by ring r, relative to the ring's axial
  /// motion, positive towards +x (m^3/s).
  double disc_flux(int ring) const {
    const int nt = mesh_.n_theta;
    double xc = 0, vx = 0;
    for (int i = 0; i < nt; ++i) {
      xc += s_.X(0, mesh_.node(ring, i));
      vx += s_.V(0, mesh_.node(ring, i));
    }
    xc /= nt;
    vx /= nt;
    const double R = ring_radii(mesh_, s_.X)[ring];
    const Eigen::Vector3d a = mesh_.axis_start;
    Eigen::Matrix3Xd P(3, disc_.size());
    for (size_t k = 0; k < disc_.size(); ++k) P.col(k) = Eigen::Vector3d(xc, a[1] + R * disc_[k][0], a[2] + R * disc_[k][1]);
    Eigen::Matrix3Xd U;
    interpolate(*grid_, s_.u, P, U);
    double q = 0;
    for (size_t k = 0; k < disc_.size(); ++k) q += (U(0, k) - vx) * disc_[k][2] * R * R;
    return q;
  }

  void measure_fluxes() {
    q_rear_ = disc_flux(0);
    q_front_ = disc_flux(mesh_.n_rings - 1);
  }

  void record() {
    const Eigen::VectorXd rr = ring_radii(mesh_, s_.X);
    const Eigen::VectorXd rn = node_radii(mesh_, s_.X);
    const double es = stretching_energy(mesh_, s_.X, p_.membrane.ks);
    const double eb = bending_energy(mesh_, s_.X, p_.membrane.kb, p_.membrane.bending);
    const double ek = kinetic_energy();
    double vol = 0;
    const int nt = mesh_.n_theta;
    std::vector<double> xr(mesh_.n_rings, 0.0);
    for (int r = 0; r < mesh_.n_rings; ++r) {
      for (int i = 0; i < nt; ++i) xr[r] += s_.X(0, mesh_.node(r, i));
      xr[r] /= nt;
    }
    for (int r = 0; r + 1 < mesh_.n_rings; ++r)
      vol += 0.5 * M_PI * (rr[r] * rr[r] + rr[r + 1] * rr[r + 1]) * (xr[r + 1] - xr[r]);
    const auto& st = protocol_.state();
    series_.push_back({s_.t, s_.X.row(0).mean() - x_center0_, s_.V.row(0).mean(), es + eb + ek, rn.minCoeff(),
                       rn.maxCoeff(), q_rear_, q_front_, vol_rear_, vol_front_, vol, double(st.phase), es, eb, ek,
                       double(st.active), double(st.cycles_completed), last_cfl_, double(last_iterations_),
                       last_divergence_, max_edge_length(mesh_, s_.X), n_ > 0 ? dt_last_ : 0.0});
    radius_times_.push_back(s_.t);
    radius_.insert(radius_.end(), rr.data(), rr.data() + rr.size());
    last_recorded_ = n_;
  }

  // --- VTK -------------------------------------------------------------------
  void write_vtk_frame() {
    std::filesystem::create_directories(out_ + "/vtk");
    char name[64];
    std::snprintf(name, sizeof name, "vtk/membrane_%06d.vtp", int(pvd_.frames().size()));
    const int nn = mesh_.nodes();
    std::vector<double> xyz(s_.X.data(), s_.X.data() + 3 * nn);
    vtk::PointArray vel{"velocity_m_per_s", 3, std::vector<double>(s_.V.data(), s_.V.data() + 3 * nn)};
    const Eigen::Matrix3Xd Fe = protocol_.force(s_.X);
    vtk::PointArray act{"actuation_force_N", 3, std::vector<double>(Fe.data(), Fe.data() + 3 * nn)};
    const Eigen::VectorXd r = node_radii(mesh_, s_.X);
    vtk::PointArray rad{"radius_m", 1, std::vector<double>(r.data(), r.data() + nn)};
    vtk::PointArray seg{"segment", 1, std::vector<double>(nn)};
    for (int i = 0; i < nn; ++i) seg.values[i] = protocol_.segment_of(i);
    vtk::write_polydata(out_ + "/" + name, xyz, mesh_.triangles, {vel, act, rad, seg});
    pvd_.add(s_.t, name);
    pvd_.write();
  }

  void write_fluid_frame() {
    std::filesystem::create_directories(out_ + "/vtk");
    char name[64];
    std::snprintf(name, sizeof name, "vtk/fluid_%06d.vti", int(fluid_pvd_.frames().size()));
    const MacGrid& g = *grid_;
    const int nx = g.nx(), ny = g.ny(), nz = g.nz();
    const auto du = g.dims(0), dv = g.dims(1), dw = g.dims(2);
    vtk::PointArray vel{"velocity_m_per_s", 3, std::vector<double>(3 * std::size_t(nx) * ny * nz)};
    std::size_t q = 0;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {  // cell-centre averages of the face values
          const int ip = (i + 1) % nx;
          const int jp = g.periodic(1) ? (j + 1) % ny : j + 1;
          const int kp = g.periodic(2) ? (k + 1) % nz : k + 1;
          vel.values[q++] = 0.5 * (s_.u.c[0][MacGrid::index(du, i, j, k)] + s_.u.c[0][MacGrid::index(du, ip, j, k)]);
          vel.values[q++] = 0.5 * (s_.u.c[1][MacGrid::index(dv, i, j, k)] + s_.u.c[1][MacGrid::index(dv, i, jp, k)]);
          vel.values[q++] = 0.5 * (s_.u.c[2][MacGrid::index(dw, i, j, k)] + s_.u.c[2][MacGrid::index(dw, i, j, kp)]);
        }
    vtk::PointArray pr{"pressure_Pa", 1, ib_->stokes().pressure().v};
    vtk::write_image_data(out_ + "/" + name, {nx, ny, nz}, g.h(), {vel, pr});
    fluid_pvd_.add(s_.t, name);
    fluid_pvd_.write();
  }

  // --- checkpoints -------------------------------------------------------------
  void save_checkpoint(double wall) {
    CheckpointWriter w;
    w.put("scene", resume_key(resolved_));
    w.put("step", std::int64_t(n_));
    w.put("t", s_.t);
    w.put("X", s_.X.data(), s_.X.size());
    w.put("V", s_.V.data(), s_.V.size());
    w.put("V_prev", s_.V_prev.data(), s_.V_prev.size());
    if (!p_.dry) {
      for (int c = 0; c < 3; ++c) w.put("u" + std::to_string(c), s_.u.c[c]);
      w.put("p", ib_->stokes().pressure().v);
    }
    const auto& st = protocol_.state();
    w.put("phase", std::int64_t(st.phase));
    w.put("active", std::int64_t(st.active));
    w.put("cycles_completed", std::int64_t(st.cycles_completed));
    w.put("switches", std::int64_t(st.switches));
    w.put("cycle_start", st.cycle_start);
    w.put("cycle_end", st.cycle_end);
    w.put("segment_reached", st.segment_reached);
    const std::vector<double> acc = {x_center0_, vol_rear_,  vol_front_,        q_rear_,   q_front_,
                                     q_rear_prev_, q_front_prev_, max_cfl_, double(iterations_total_), wall,
                                     last_cfl_, double(last_iterations_), last_divergence_};
    w.put("accumulators", acc);
    std::vector<double> flat;
    for (const auto& row : series_) flat.insert(flat.end(), row.begin(), row.end());
    w.put("series", flat);
    w.put("radius_times", radius_times_);
    w.put("radius", radius_);
    w.put("last_recorded", std::int64_t(last_recorded_));
    std::vector<double> ft;
    for (const auto& f : pvd_.frames()) ft.push_back(f.first);
    w.put("vtk_frames", ft);
    ft.clear();
    for (const auto& f : fluid_pvd_.frames()) ft.push_back(f.first);
    w.put("fluid_frames", ft);
    // step control and per-cycle step counts, by name
    w.put("dt_next", dt_next_);
    w.put("dt_last", dt_last_);
    w.put("dt_before_last", dt_before_last_);
    w.put("dt_used_min", dt_used_min_);
    w.put("dt_used_max", dt_used_max_);
    w.put("last_speed", last_speed_);
    w.put("lambda", lambda_);
    w.put("lambda_max_seen", lambda_max_seen_);
    w.put("lambda_step", std::int64_t(lambda_step_));
    w.put("estimates", std::int64_t(estimates_));
    w.put("rejected", std::int64_t(rejected_));
    w.put("after_event", std::int64_t(after_event_ ? 1 : 0));
    w.put("r_active_prev", std::isfinite(r_active_prev_) ? r_active_prev_ : -1.0);
    w.put("step_marks", step_marks_);
    {
      std::vector<double> counts;
      for (const auto& [k, v] : bound_count_) counts.push_back(double(v));
      w.put("bound_counts", counts);
    }
    w.save(checkpoint_path(out_));
    // partial results next to the checkpoint, so that a killed run still has them
    write_outputs("running: last checkpoint at t = " + num(s_.t) + " s (resume with --resume " + out_ + ")", wall);
  }

  void load_checkpoint() {
    CheckpointReader r(checkpoint_path(out_));
    // the stored key is re-normalised, so that checkpoints written before a key was allowed
    // to change still match
    json stored;
    try {
      stored = json::parse(r.get_string("scene"));
    } catch (const std::exception&) {
      throw InputError("--resume", out_, "the checkpoint's scene record is not valid JSON");
    }
    if (resume_key(stored) != resume_key(resolved_))
      throw InputError("--resume", out_, "the checkpoint was written for a different scene (only "
                                         "full3d.checkpoint_interval, full3d.threads and full3d.time_limit may change on resume)");
    n_ = r.get_int("step");
    s_.t = r.get_double("t");
    r.get_into("X", s_.X.data(), s_.X.size());
    r.get_into("V", s_.V.data(), s_.V.size());
    r.get_into("V_prev", s_.V_prev.data(), s_.V_prev.size());
    if (!p_.dry) {
      for (int c = 0; c < 3; ++c) r.get_into("u" + std::to_string(c), s_.u.c[c].data(), s_.u.c[c].size());
      // The duct's PCG is warm-started from the previous pressure: restore it so that the
      // resumed run repeats the uninterrupted one to round-off.
      ScalarField pr = ib_->stokes().pressure();
      r.get_into("p", pr.v.data(), pr.v.size());
      ib_->stokes().set_pressure(pr);
    }
    auto& st = protocol_.state();
    st.phase = int(r.get_int("phase"));
    st.active = int(r.get_int("active"));
    st.cycles_completed = int(r.get_int("cycles_completed"));
    st.switches = r.get_int("switches");
    st.cycle_start = r.get_vector("cycle_start");
    st.cycle_end = r.get_vector("cycle_end");
    st.segment_reached = r.get_vector("segment_reached");
    const auto acc = r.get_vector("accumulators");
    if (acc.size() != 13) throw InputError("--resume", out_, "checkpoint accumulators of the wrong size");
    x_center0_ = acc[0];
    vol_rear_ = acc[1];
    vol_front_ = acc[2];
    q_rear_ = acc[3];
    q_front_ = acc[4];
    q_rear_prev_ = acc[5];
    q_front_prev_ = acc[6];
    max_cfl_ = acc[7];
    iterations_total_ = long(acc[8]);
    wall_before_ = acc[9];
    last_cfl_ = acc[10];
    last_iterations_ = long(acc[11]);
    last_divergence_ = acc[12];
    const auto flat = r.get_vector("series");
    const size_t nc = kSeriesColumns.size();
    series_.clear();
    if (flat.size() % nc != 0) throw InputError("--resume", out_, "the checkpoint's series has another column layout");
    for (size_t k = 0; k + nc <= flat.size(); k += nc) series_.emplace_back(flat.begin() + k, flat.begin() + k + nc);
    radius_times_ = r.get_vector("radius_times");
    radius_ = r.get_vector("radius");
    last_recorded_ = r.get_int("last_recorded");
    for (double t : r.get_vector("vtk_frames")) {
      char name[64];
      std::snprintf(name, sizeof name, "vtk/membrane_%06d.vtp", int(pvd_.frames().size()));
      pvd_.add(t, name);
    }
    for (double t : r.get_vector("fluid_frames")) {
      char name[64];
      std::snprintf(name, sizeof name, "vtk/fluid_%06d.vti", int(fluid_pvd_.frames().size()));
      fluid_pvd_.add(t, name);
    }
    dt_next_ = r.get_double("dt_next");
    dt_last_ = r.get_double("dt_last");
    dt_before_last_ = r.get_double("dt_before_last");
    dt_used_min_ = r.get_double("dt_used_min");
    dt_used_max_ = r.get_double("dt_used_max");
    last_speed_ = r.get_double("last_speed");
    lambda_ = r.get_double("lambda");
    lambda_max_seen_ = r.get_double("lambda_max_seen");
    lambda_step_ = r.get_int("lambda_step");
    estimates_ = r.get_int("estimates");
    rejected_ = r.get_int("rejected");
    after_event_ = r.get_int("after_event") != 0;
    const double rp = r.get_double("r_active_prev");
    r_active_prev_ = rp >= 0.0 ? rp : std::numeric_limits<double>::quiet_NaN();
    step_marks_ = r.get_vector("step_marks");
    {
      const auto counts = r.get_vector("bound_counts");
      if (counts.size() != bound_count_.size()) throw InputError("--resume", out_, "checkpoint step-control record of the wrong size");
      size_t k = 0;
      for (auto& [name, v] : bound_count_) v = long(counts[k++]);
    }
    t_prev_ = s_.t;
    if (vtk_on_) pvd_.write();
    if (fluid_on_) fluid_pvd_.write();
  }

  // --- outputs -----------------------------------------------------------------
  json write_outputs(const std::string& status, double wall) {
    const auto& st = protocol_.state();
    json s = json::object();
    s["tier"] = "3d";
    s["scene"] = resolved_;
    s["status"] = status;
    const auto& last = series_.back();
    const double t_end = last[0];
    s["t_end_s"] = t_end;
    s["displacement_m"] = last[1];
    s["cycles_completed"] = st.cycles_completed;
    std::vector<double> ct;
    for (size_t k = 0; k < st.cycle_end.size() && k < st.cycle_start.size(); ++k)
      ct.push_back(st.cycle_end[k] - st.cycle_start[k]);
    s["cycle_times_s"] = ct;
    s["cycle_start_times_s"] = st.cycle_start;
    s["cycle_end_times_s"] = st.cycle_end;
    const double vmean = t_end > 0 ? last[1] / t_end : 0.0;
    s["mean_velocity_m_per_s"] = vmean;
    s["body_lengths_per_s"] = vmean / p_.L;
    s["final_velocity_m_per_s"] = last[2];
    double vmax = -1e300, rmin = 1e300, emax = 0, xmax = 0;
    for (const auto& row : series_) {
      vmax = std::max(vmax, row[2]);
      xmax = std::max(xmax, row[1]);
      rmin = std::min(rmin, row[4]);
      emax = std::max(emax, row[20]);
    }
    s["max_edge_over_h"] = emax / p_.h;  // at the output steps; the no-leak guard needs < 0.5
    s["max_velocity_m_per_s"] = vmax;
    s["max_displacement_m"] = xmax;  // largest centre displacement at the output steps
    s["pumped_volume_m3"] = -vol_rear_;
    s["min_radius_m"] = rmin;
    s["protocol_switches"] = st.switches;
    s["segment_reached_s"] = st.segment_reached;
    s["steps"] = n_;
    s["steps_per_cycle"] = steps_per_cycle();
    s["derived"] = {{"C1_estimate_Pa_per_m", p_.c1_estimate()},
                    {"mass_per_area_kg_per_m2", p_.mass_per_area},
                    {"mass_per_length_kg_per_m", p_.mass_per_area * 2.0 * M_PI * p_.R0},
                    {"aspect_ratio_R0_over_L", p_.R0 / p_.L},
                    {"contracted_ratio", p_.protocol.R_f / p_.R0},
                    {"actuation_pressure_Pa", p_.protocol.q},
                    {"force_per_node_N", p_.protocol.q * 2.0 * M_PI * p_.R0 * p_.L / mesh_.nodes()},
                    {"reference_energy_J", e_ref_},
                    {"recovery_end_energy_J", protocol_.end_threshold()},
                    {"cell_size_m", p_.h},
                    {"grid", {p_.nx, p_.ny, p_.nz}},
                    {"nodes", mesh_.nodes()},
                    {"n_theta", mesh_.n_theta},
                    {"rings", mesh_.n_rings},
                    {"ring_spacing_m", mesh_.ring_spacing},
                    {"max_edge_m", max_edge_length(mesh_, mesh_.X0)},
                    {"segment_boundaries_m", protocol_.boundaries()}};
    s["wall_time_s"] = wall;
    {
      output::CsvWriter csv(out_ + "/series.csv", kSeriesColumns);
      for (const auto& row : series_) csv.row(row);
    }
    {
      output::CsvWriter csv(out_ + "/radius.csv", {"t_s", "z_m", "radius_m"});
      const int nr = mesh_.n_rings;
      for (size_t k = 0; k < radius_times_.size(); ++k)
        for (int r = 0; r < nr; ++r) csv.row({radius_times_[k], r * mesh_.ring_spacing, radius_[k * nr + r]});
    }
    json time_step = json::object();
    if (adaptive_) {
      json bounds = json::object();
      for (const auto& [k, v] : bound_count_) bounds[k] = v;
      time_step = {{"control", "adaptive"},
                   {"dt_min_used_s", n_ > 0 ? dt_used_min_ : 0.0},
                   {"dt_max_used_s", dt_used_max_},
                   {"dt_mean_s", n_ > 0 ? s_.t / double(n_) : 0.0},
                   {"rejected_steps", rejected_},
                   {"explicit_rate_per_s", lambda_},
                   {"explicit_rate_max_per_s", lambda_max_seen_},
                   {"explicit_limit_s", lambda_max_seen_ > 0 ? 2.0 / lambda_max_seen_ : 0.0},
                   {"stability_estimates", estimates_},
                   {"steps_by_bound", bounds}};
    } else {
      time_step = {{"control", "fixed"}, {"dt_s", p_.dt}};
    }
    json stats = {{"steps", n_},
                  {"steps_per_cycle", steps_per_cycle()},
                  {"time_step", time_step},
                  {"dt_s", adaptive_ ? (n_ > 0 ? s_.t / double(n_) : 0.0) : p_.dt},
                  {"mode", p_.dry ? "dry" : "fluid"},
                  {"stokes_iterations_total", iterations_total_},
                  {"max_cfl", max_cfl_},
                  {"protocol_switches", st.switches},
                  {"wall_time_s", wall},
                  {"steps_per_s", wall > 0 ? n_ / wall : 0.0},
                  {"output_every_steps", out_every_},
                  {"checkpoint_every_steps", ckpt_every_}};
    output::write_json(out_ + "/solver_stats.json", stats);
    output::write_json(out_ + "/scene.resolved.json", resolved_);
    output::write_json(out_ + "/summary.json", s);
    return s;
  }

  /// Steps taken by each completed cycle.
  std::vector<long> steps_per_cycle() const {
    std::vector<long> v;
    for (size_t k = 0; k + 1 < step_marks_.size(); ++k) v.push_back(std::lround(step_marks_[k + 1] - step_marks_[k]));
    return v;
  }

  const Params3d& p_;
  const json& resolved_;
  std::string out_;
  RunControl ctl_;
  CylinderMesh mesh_;
  Eigen::VectorXd mass_;
  double e_ref_;
  Protocol3d protocol_;
  std::optional<MacGrid> grid_;
  std::unique_ptr<IbSolver> ib_;
  IbState s_;
  vtk::Collection pvd_, fluid_pvd_;
  std::vector<std::array<double, 3>> disc_;

  long n_ = 0, out_every_ = 1, vtk_every_ = 1, fluid_every_ = 1, ckpt_every_ = 1, n_end_ = -1, n_limit_ = 1;
  long last_recorded_ = -1;
  bool vtk_on_ = true, fluid_on_ = false;
  double e_cap_ = 0;
  double x_center0_ = 0, vol_rear_ = 0, vol_front_ = 0, q_rear_ = 0, q_front_ = 0, q_rear_prev_ = 0, q_front_prev_ = 0;
  double rmin_seen_ = 1e300;
  double max_cfl_ = 0, last_cfl_ = 0, last_divergence_ = 0, wall_before_ = 0;
  long iterations_total_ = 0, last_iterations_ = 0;
  // step control (adaptive: full3d.adaptive)
  bool adaptive_ = false;
  std::string dt_key_ = "full3d.dt";
  double t_prev_ = 0.0;  ///< time before the last step (time-based output cadence)
  double dt_next_ = 0.0, dt_last_ = 0.0, dt_before_last_ = 0.0;
  double dt_used_min_ = 1e300, dt_used_max_ = 0.0, last_speed_ = 0.0, last_dv_ = 0.0;
  double lambda_ = 0.0, lambda_max_seen_ = 0.0;  ///< explicit-coupling rate estimates, 1/s
  long lambda_step_ = -1, estimates_ = 0, rejected_ = 0;
  bool after_event_ = true;
  double r_active_prev_ = std::numeric_limits<double>::quiet_NaN();
  std::map<std::string, long> bound_count_ = {{"growth", 0}, {"cfl", 0}, {"accuracy", 0}, {"stability", 0}, {"event", 0}};
  std::vector<double> step_marks_;  ///< step index at each cycle start (and the end of the last)
  std::vector<std::vector<double>> series_;
  std::vector<double> radius_times_, radius_;
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

}  // namespace swim::full3d
