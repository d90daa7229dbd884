// The axisymmetric tier's driver for the prescribed waves (wave.kind = step | sine, fitted
// method): the force-free swimmer of axi/prescribed_axi.hpp, sampled at the output times, its
// displacement and end-disc volumes integrated between them by adaptive Simpson. Writes the same
// run folder as the force-driven runs (series columns, radius.csv, summary keys); what belongs
// to the protocol (cycles, segments, actuation) is omitted or zero, as in the 1D tier's
// prescribed runs.
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

#include "axi/fe_stokes_axi.hpp"
#include "axi/prescribed_axi.hpp"
#include "axi/run_axi.hpp"
#include "axi/run_folder_axi.hpp"
#include "axi/wall_axi.hpp"
#include "common/errors.hpp"
#include "common/progress.hpp"

namespace swim::axi {

using scene::json;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

class PrescribedRunner {
 public:
  PrescribedRunner(const ParamsAxi& p, const json& resolved, const std::string& out, const RunControlAxi& ctl)
      : p_(p), b_(p.base), resolved_(resolved), out_(out), ctl_(ctl),
        wall_(AxiWallParams{b_.R0, b_.L, p.ks, p.D, p.wall_nodes, p.ring_s0, p.poisson_coupling}),
        rec_("axi", "axisymmetric_fitted_finite_elements", b_.L, series_columns(), wall_.reference_positions()) {
    rec_.keep(ctl.keep_rows);
    t_end_ = b_.duration > 0 ? b_.duration : b_.wave.transit(b_.L);
    swimmer_ = std::make_unique<PrescribedSwimmer>(fitted_mesh_params(p_), b_.fluid.mu, wall_.reference_positions(),
                                                   wave_kinematics(b_.wave, b_.R0, b_.L), p.x_start());
    // the quadrature's tolerances over the whole run: X to axi.tolerance x h, the end volumes to
    // the volume of a lumen slice that thick
    tol_X_ = p_.tolerance * p_.h;
    tol_V_ = tol_X_ * M_PI * b_.R0 * b_.R0;
  }

  RunOutcomeAxi run() {
    const auto t0 = std::chrono::steady_clock::now();
    stream_ = open_run_stream(rec_, out_, ctl_);
    Progress progress("axi " + p_.name() + " (" + b_.wave.kind + " wave)", t_end_, ctl_.progress);
    std::optional<NumericalError> failure;
    try {
      PrescribedState s = swimmer_->evaluate(0.0);
      record(s, 0.0);
      for (long k = 1; s.t < t_end_; ++k) {
        double t = std::min(double(k) * b_.output_interval, t_end_);
        if (t_end_ - t < 1e-9 * b_.output_interval) t = t_end_;
        const PrescribedState next = swimmer_->evaluate(t);
        QuadratureStats qs;
        const double share = (t - s.t) / t_end_;
        const PrescribedIntegrals I = integrate(*swimmer_, s, next, share * tol_X_, share * tol_V_, qs);
        X_ += I.X;
        vol_rear_ += I.V_rear;
        vol_front_ += I.V_front;
        pieces_ += qs.pieces;
        smallest_ = smallest_ > 0 ? std::min(smallest_, qs.smallest) : qs.smallest;
        s = next;
        record(s, qs.smallest);
        progress.update(s.t);
      }
    } catch (const NumericalError& e) {
      failure = e;
    }
    progress.done();
    return finish_run(rec_, failure, seconds_since(t0), pieces_, out_, resolved_,
                      [this](const std::string& status, double wall) { fill(status, wall); });
  }

 private:

  /// One series row and radius snapshot at the state s (the integrals up to s.t accumulated);
  /// dt: the shortest quadrature piece of the interval that ended at s.t (0 at t = 0).
  void record(const PrescribedState& s, double dt) {
    const Eigen::Matrix3Xd X = swimmer_->rings(s.R);
    const std::array<double, 2> e = wall_.energies(X);
    double spacing = 0.0;
    for (Eigen::Index k = 0; k + 1 < X.cols(); ++k) spacing = std::max(spacing, (X.col(k + 1) - X.col(k)).head<2>().norm());
    const double row[] = {s.t,
                          X_,
                          s.velocity,
                          e[0] + e[1],
                          s.R.minCoeff(),
                          s.R.maxCoeff(),
                          s.flux_rear,
                          s.flux_front,
                          vol_rear_,
                          vol_front_,
                          s.volume,
                          double(record::Phase::Contraction),
                          e[0],
                          e[1],
                          -1.0,  // active_segment: a prescribed wave has no protocol segments
                          0.0,   // cycles_completed
                          0.0,   // cfl: no time steps (the shape is prescribed)
                          spacing,
                          dt};
    max_spacing_ = std::max(max_spacing_, spacing);
    const std::vector<double> radius(s.R.data(), s.R.data() + s.R.size());
    const std::size_t rows = rec_.series.count();
    try {
      rec_.add_row(row);
    } catch (const NumericalError&) {
      if (rec_.series.count() > rows) rec_.add_radius(s.t, radius);
      throw;
    }
    rec_.add_radius(s.t, radius);
    if (s.t == 0.0) v0_ = s.volume;
    v_last_ = s.volume;
  }

  void fill(const std::string& status, double wall) {
    rec_.status = status;
    rec_.wall_time_s = wall;
    rec_.transit_is_cycle = status == "ok" && rec_.series.count() > 0 && rec_.t_end() >= t_end_ * (1 - 1e-9);
    const scene::WaveSpec& w = b_.wave;
    rec_.derived = {{"aspect_ratio_R0_over_L", b_.R0 / b_.L},
                    {"contracted_ratio", w.R_f / b_.R0},
                    {"wave", w.kind},
                    {"wave_speed_m_per_s", w.speed},
                    {"wave_end_time_s", t_end_},
                    {"cell_size_m", p_.h},
                    {"method", p_.method_name()},
                    {"grid", json{p_.cells_inner, p_.cells_outer, wall_.nodes() - 1, p_.gap_columns}},
                    {"grid_is", "element rows inside and outside the wall, element columns along the tube and "
                                "across the gap"},
                    {"wall_nodes", wall_.nodes()},
                    {"wall_node_spacing_m", wall_.ds0()},
                    {"wall_end_spacing_m", wall_.min_ds0()},
                    {"spring_constant_N_per_m", p_.ks},
                    {"bending_rigidity_J", p_.D},
                    {"bending_rigidity_from", p_.bending_source}};
    if (w.kind == "step") rec_.derived["wave_width_m"] = w.width;
    if (w.kind == "sine") rec_.derived["wave_length_m"] = w.wavelength;
    // the lumen's volume change against the net inflow through the end discs (the quadrature's
    // mass balance; the instantaneous balance is exact)
    const double balance = (v_last_ - v0_) - (vol_rear_ - vol_front_);
    rec_.extras = {{"quadrature_pieces", pieces_},
                   {"volume_balance_error_m3", rec_.series.count() > 0 ? balance : 0.0},
                   {"max_spacing_over_h", max_spacing_ / p_.h}};
    record::check_plausible(rec_, {b_.fluid.rho, b_.fluid.mu});
    const FittedStokes::Timing& tm = swimmer_->stokes().timing();
    rec_.stats = {{"steps", pieces_},
                  {"quadrature_pieces", pieces_},
                  {"shortest_piece_s", smallest_},
                  {"prescribed_solves", swimmer_->evaluations()},
                  {"stokes_solves", tm.solves},
                  {"fitted_unknowns", swimmer_->stokes().unknowns()},
                  {"fitted_nonzeros", swimmer_->stokes().nonzeros()},
                  {"blas", blas_provider()},
                  {"quadrature_tolerance_m", tol_X_},
                  {"wall_time_s", wall},
                  {"wall_time_split_s",
                   {{"assembly", tm.assemble}, {"factorisation", tm.factor}, {"solves", tm.solve},
                    {"factorisations", tm.factorisations}}}};
  }

  const ParamsAxi& p_;
  const full3d::Params3d& b_;
  const json& resolved_;
  std::string out_;
  RunControlAxi ctl_;
  AxiWall wall_;
  record::RunRecord rec_;
  std::unique_ptr<record::RunStream> stream_;
  std::unique_ptr<PrescribedSwimmer> swimmer_;
  double t_end_ = 0, tol_X_ = 0, tol_V_ = 0;
  double X_ = 0, vol_rear_ = 0, vol_front_ = 0, v0_ = 0, v_last_ = 0, smallest_ = 0, max_spacing_ = 0;
  long pieces_ = 0;
};

}  // namespace

RunOutcomeAxi run_prescribed_axi(const ParamsAxi& p, const json& resolved, const std::string& out_dir,
                                 const RunControlAxi& ctl) {
  PrescribedRunner r(p, resolved, out_dir, ctl);
  return r.run();
}

}  // namespace swim::axi
