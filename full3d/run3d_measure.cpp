#include "full3d/run3d_measure.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <utility>
#include <vector>

#include "common/errors.hpp"
#include "full3d/ib.hpp"

namespace swim::full3d {

const std::vector<std::string> kSeriesColumns = [] {
  std::vector<std::string> c = record::common_series_columns();
  for (const char* k : {"elastic_energy_J", "bending_energy_J", "kinetic_energy_J", "active_segment",
                        "cycles_completed", "cfl", "stokes_iterations", "max_divergence_per_s", "max_edge_m", "dt_s", "wrinkle_m",
                        "wrinkle_mode"})
    c.push_back(k);
  return c;
}();

namespace {
// The ring with the largest RMS deviation of its node radii from its mean radius, and that RMS.
std::pair<int, double> most_wrinkled_ring(const CylinderMesh& mesh, const Eigen::VectorXd& node_r,
                                          const Eigen::VectorXd& ring_r) {
  int worst = 0;
  double worst_s2 = 0.0;
  for (int r = 0; r < mesh.n_rings; ++r) {
    double s2 = 0.0;
    for (int i = 0; i < mesh.n_theta; ++i) {
      const double d = node_r[mesh.node(r, i)] - ring_r[r];
      s2 += d * d;
    }
    if (s2 > worst_s2) worst_s2 = s2, worst = r;
  }
  return {worst, std::sqrt(worst_s2 / mesh.n_theta)};
}

// The m in [2, n_theta / 2] with the largest |sum_i (r_i - r_ring) exp(-i m phi_i)| on `ring`.
int lobe_mode(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const Eigen::VectorXd& node_r,
              const Eigen::VectorXd& ring_r, int ring) {
  const int nt = mesh.n_theta;
  double yc = 0.0, zc = 0.0;
  for (int i = 0; i < nt; ++i) yc += X(1, mesh.node(ring, i)), zc += X(2, mesh.node(ring, i));
  yc /= nt, zc /= nt;
  // e^{i m phi_i} by repeated multiplication (one complex product per node and mode)
  std::vector<std::complex<double>> z(nt), w(nt);
  std::vector<double> d(nt);
  for (int i = 0; i < nt; ++i) {
    const int k = mesh.node(ring, i);
    z[i] = std::polar(1.0, std::atan2(X(2, k) - zc, X(1, k) - yc));
    w[i] = z[i];
    d[i] = node_r[k] - ring_r[ring];
  }
  int best = 0;
  double best_a = -1.0;
  for (int m = 2; 2 * m <= nt; ++m) {
    std::complex<double> a = 0.0;
    for (int i = 0; i < nt; ++i) {
      w[i] *= z[i];
      a += d[i] * w[i];
    }
    if (std::norm(a) > best_a) best_a = std::norm(a), best = m;
  }
  return best;
}
}  // namespace

double wall_wrinkle(const CylinderMesh& mesh, const Eigen::VectorXd& node_r, const Eigen::VectorXd& ring_r) {
  return most_wrinkled_ring(mesh, node_r, ring_r).second;
}

WallWrinkle wall_wrinkle_shape(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const Eigen::VectorXd& node_r,
                               const Eigen::VectorXd& ring_r) {
  const auto [ring, rms] = most_wrinkled_ring(mesh, node_r, ring_r);
  return {rms, rms > 1e-9 * ring_r[ring] ? lobe_mode(mesh, X, node_r, ring_r, ring) : 0};
}

void CycleWrinkles::add(int cycle, double amplitude_m, int mode) {
  if (cycles_.empty() || cycles_.back().cycle != cycle) {
    Cycle c;
    c.cycle = cycle;
    cycles_.push_back(c);
  }
  Cycle& c = cycles_.back();
  if (amplitude_m > c.max_wrinkle_m) c.max_wrinkle_m = amplitude_m, c.max_wrinkle_mode = mode;
  if (amplitude_m > threshold_ && mode > 0 && std::find(c.modes.begin(), c.modes.end(), mode) == c.modes.end())
    c.modes.push_back(mode);
}

std::vector<int> CycleWrinkles::modes() const {
  std::vector<int> all;
  for (const Cycle& c : cycles_)
    for (int m : c.modes)
      if (std::find(all.begin(), all.end(), m) == all.end()) all.push_back(m);
  return all;
}

std::vector<double> CycleWrinkles::flat() const {
  std::vector<double> v;
  for (const Cycle& c : cycles_) {
    v.insert(v.end(), {double(c.cycle), c.max_wrinkle_m, double(c.max_wrinkle_mode), double(c.modes.size())});
    for (int m : c.modes) v.push_back(double(m));
  }
  return v;
}

void CycleWrinkles::unflatten(const std::vector<double>& v) {
  cycles_.clear();
  for (std::size_t k = 0; k + 4 <= v.size();) {
    Cycle c;
    c.cycle = int(v[k]);
    c.max_wrinkle_m = v[k + 1];
    c.max_wrinkle_mode = int(v[k + 2]);
    const std::size_t n = std::size_t(v[k + 3]);
    k += 4;
    for (std::size_t i = 0; i < n && k < v.size(); ++i, ++k) c.modes.push_back(int(v[k]));
    cycles_.push_back(std::move(c));
  }
}

void WallSplit::add_step(const IbStepStats& st) {
  add("step_forces", st.time_forces);
  add("step_spread", st.time_spread);
  add("step_fluid", st.time_fluid);
  add("step_interp", st.time_interp);
  // the step's own remainder (copies, guards, CFL) is what the caller's lap adds to "step_other"
  add("step_other", -(st.time_forces + st.time_spread + st.time_fluid + st.time_interp));
}

scene::json WallSplit::to_json() const {
  scene::json j = scene::json::object();
  for (const auto& [k, v] : parts_) j[k] = v;
  return j;
}

record::RunRecord new_record(const RunSetup& run) {
  std::vector<double> z(run.mesh.n_rings);
  for (int r = 0; r < run.mesh.n_rings; ++r) z[r] = r * run.mesh.ring_spacing;
  return record::RunRecord("3d", run.p.dry ? "immersed_boundary_dry" : "immersed_boundary", run.p.L, kSeriesColumns,
                           std::move(z));
}

Measurements::Measurements(const RunSetup& run, record::RunRecord& rec, EnergySource energy)
    : run_(run), rec_(rec), wrinkles_(0.5 * run.p.h), energy_source_(std::move(energy)) {
  const Params3d& p = run.p;
  const double q_static = p.c1_estimate() * (p.R0 - p.protocol.R_f);
  e_cap_ = p.energy_growth * run.e_ref * std::max(1.0, std::pow(p.protocol.q / q_static, 2));
  // Mid-point rule on a polar grid of the unit disc: weights rho d rho d theta.
  const int nr = 6, nth = 16;
  for (int j = 0; j < nr; ++j)
    for (int l = 0; l < nth; ++l) {
      const double rho = (j + 0.5) / nr, th = 2.0 * M_PI * (l + 0.5 * (j % 2)) / nth;
      disc_.push_back({rho * std::cos(th), rho * std::sin(th), rho * (1.0 / nr) * (2.0 * M_PI / nth)});
    }
}

void Measurements::start(const IbState& s) { x_center0_ = s.X.row(0).mean(); }

void Measurements::after_step(const IbStepStats& st, const IbState& s, double dt, const MacGrid* grid) {
  last_cfl_ = st.cfl;
  last_iterations_ = st.stokes_iterations;
  last_divergence_ = st.max_divergence;
  if (st.max_edge > 0.0) max_edge_ = st.max_edge, max_edge_t_ = s.t;  // the step's no-leak guard measured it at s.X
  if (!grid) return;  // the dry swimmer: no fluid
  max_cfl_ = std::max(max_cfl_, st.cfl);
  iterations_total_ += st.stokes_iterations;
  q_rear_ = disc_flux(0, s, *grid);
  q_front_ = disc_flux(run_.mesh.n_rings - 1, s, *grid);
  vol_rear_ += 0.5 * dt * (q_rear_prev_ + q_rear_);
  vol_front_ += 0.5 * dt * (q_front_prev_ + q_front_);
  q_rear_prev_ = q_rear_;
  q_front_prev_ = q_front_;
}

double Measurements::kinetic_energy(const IbState& s) const {
  double k = 0;
  for (Eigen::Index i = 0; i < s.V.cols(); ++i) k += 0.5 * run_.mass[i] * s.V.col(i).squaredNorm();
  return k;
}

std::array<double, 2> Measurements::elastic_parts(const IbState& s) const {
  if (s.t != parts_t_ || s.X.data() != parts_x_) {
    parts_ = energy_source_(s.X);
    parts_t_ = s.t;
    parts_x_ = s.X.data();
  }
  return parts_;
}

double Measurements::wall_energy(const IbState& s) const {
  const auto [es, eb] = elastic_parts(s);
  return es + eb + kinetic_energy(s);
}

void Measurements::guards(double e, const IbState& s) {
  const Params3d& p = run_.p;
  const std::string& dt_key = run_.dt_key;
  if (!std::isfinite(e)) throw NumericalError("non-finite wall energy", "reduce the time step " + dt_key, s.t);
  const double rmin = node_radii(run_.mesh, s.X).minCoeff();
  if (e > e_cap_) {
    // Below about 0.55 R0 of hoop contraction the linear spring lattice has a negative
    // stiffness in the alternate-ring twist mode (docs/full3d.md, "Compressed-lattice
    // instability"): no time step cures that, so say so when the run went that far.
    const double r_lowest = std::min(rmin_seen_, rmin) / p.R0;
    const bool lattice = r_lowest < 0.56;
    throw NumericalError(
        "wall energy " + short_number(e) + " J grew beyond " + short_number(p.energy_growth) +
            " times the reference energy (" + short_number(e_cap_) + " J)" +
            (lattice ? ": nodes had contracted to " + short_number(r_lowest) +
                           " R0, where the compressed spring lattice loses its in-plane stability (alternate-ring "
                           "twist mode, docs/full3d.md); a smaller time step does not help"
                     : ": the explicit coupling is unstable"),
        lattice ? "raise wave.contracted_ratio (>= 0.6), lower the actuation overshoot (protocol.load_factor), or run "
                  "with fluid (full3d.dry = false)"
                : "reduce the time step " + dt_key + " (or raise full3d.energy_growth_limit if the growth is physical)",
        s.t);
  }
  rmin_seen_ = std::min(rmin_seen_, rmin);
  if (rmin < 0.02 * p.R0)
    throw NumericalError("the tube collapsed: a node came within " + short_number(rmin) + " m of the axis",
                         "lower the actuation (protocol.total_force / pressure / load_factor) or reduce " + dt_key, s.t);
}

/// Volume flux through the disc spanned by ring r, relative to the ring's axial
/// motion, positive towards +x (m^3/s).
double Measurements::disc_flux(int ring, const IbState& s, const MacGrid& grid) const {
  const CylinderMesh& mesh = run_.mesh;
  const int nt = mesh.n_theta;
  double xc = 0, vx = 0;
  for (int i = 0; i < nt; ++i) {
    xc += s.X(0, mesh.node(ring, i));
    vx += s.V(0, mesh.node(ring, i));
  }
  xc /= nt;
  vx /= nt;
  const double R = ring_radii(mesh, s.X)[ring];
  const Eigen::Vector3d a = mesh.axis_start;
  Eigen::Matrix3Xd P(3, disc_.size());
  for (size_t k = 0; k < disc_.size(); ++k) P.col(k) = Eigen::Vector3d(xc, a[1] + R * disc_[k][0], a[2] + R * disc_[k][1]);
  Eigen::Matrix3Xd U;
  interpolate(grid, s.u, P, U);
  double q = 0;
  for (size_t k = 0; k < disc_.size(); ++k) q += (U(0, k) - vx) * disc_[k][2] * R * R;
  return q;
}

void Measurements::record(const IbState& s, const ProtocolState& st, long n, double dt_last) {
  const CylinderMesh& mesh = run_.mesh;
  const Eigen::VectorXd rn = node_radii(mesh, s.X);
  const Eigen::VectorXd rr = ring_radii(mesh, rn);
  const auto [es, eb] = elastic_parts(s);
  const double ek = kinetic_energy(s);
  double vol = 0;
  const int nt = mesh.n_theta;
  std::vector<double> xr(mesh.n_rings, 0.0);
  for (int r = 0; r < mesh.n_rings; ++r) {
    for (int i = 0; i < nt; ++i) xr[r] += s.X(0, mesh.node(r, i));
    xr[r] /= nt;
  }
  for (int r = 0; r + 1 < mesh.n_rings; ++r)
    vol += 0.5 * M_PI * (rr[r] * rr[r] + rr[r + 1] * rr[r + 1]) * (xr[r + 1] - xr[r]);
  const WallWrinkle wrinkle = wall_wrinkle_shape(mesh, s.X, rn, rr);
  if (wrinkle.amplitude > max_wrinkle_) max_wrinkle_ = wrinkle.amplitude, max_wrinkle_mode_ = wrinkle.mode;
  // the row at a cycle's end belongs to the cycle that ended there
  const bool at_end = !st.cycle_end.empty() && s.t <= st.cycle_end.back();
  wrinkles_.add(int(st.cycles_completed) + (at_end ? 0 : 1), wrinkle.amplitude, wrinkle.mode);
  const double row[] = {s.t, s.X.row(0).mean() - x_center0_, s.V.row(0).mean(), es + eb + ek, rn.minCoeff(),
                        rn.maxCoeff(), q_rear_, q_front_, vol_rear_, vol_front_, vol, double(st.phase), es, eb, ek,
                        double(st.active), double(st.cycles_completed), last_cfl_, double(last_iterations_),
                        last_divergence_, max_edge_t_ == s.t ? max_edge_ : max_edge_length(mesh, s.X),
                        n > 0 ? dt_last : 0.0,
                        wrinkle.amplitude, double(wrinkle.mode)};
  // a row that passes output.max_bytes ends the run (NumericalError) once it is written: its
  // radius snapshot is still written, and the run's failure path does not record it again
  last_recorded_ = n;
  const std::size_t rows = rec_.series.count();
  try {
    rec_.add_row(row);
  } catch (const NumericalError&) {
    if (rec_.series.count() > rows) rec_.add_radius(s.t, {rr.data(), std::size_t(rr.size())});
    throw;
  }
  rec_.add_radius(s.t, {rr.data(), std::size_t(rr.size())});
}

void Measurements::events(const ProtocolState& st) {
  auto& e = rec_.events;
  while (e.cycle_start_s.size() < st.cycle_start.size()) rec_.cycle_started(st.cycle_start[e.cycle_start_s.size()]);
  while (e.cycle_end_s.size() < st.cycle_end.size()) rec_.cycle_ended(st.cycle_end[e.cycle_end_s.size()]);
}

// --- checkpoint records ------------------------------------------------------------
template <class Self, class F>
void Measurements::records(Self& self, F&& f) {
  f("x_center0", self.x_center0_);
  f("volume_rear", self.vol_rear_);
  f("volume_front", self.vol_front_);
  f("flux_rear", self.q_rear_);
  f("flux_front", self.q_front_);
  f("flux_rear_prev", self.q_rear_prev_);
  f("flux_front_prev", self.q_front_prev_);
  f("max_cfl", self.max_cfl_);
  f("stokes_iterations_total", self.iterations_total_);
  f("last_cfl", self.last_cfl_);
  f("last_stokes_iterations", self.last_iterations_);
  f("last_divergence", self.last_divergence_);
  f("last_recorded", self.last_recorded_);
  f("max_wrinkle", self.max_wrinkle_);
  f("max_wrinkle_mode", self.max_wrinkle_mode_);
}

void Measurements::save(CheckpointWriter& w) const {
  records(*this, CheckpointOut(w));
  w.put("wrinkle_cycles", wrinkles_.flat());
  rec_.save([&](const std::string& name, const std::vector<double>& v) { w.put(name, v); });
}

void Measurements::load(const CheckpointReader& r) {
  records(*this, CheckpointIn(r));
  wrinkles_.unflatten(r.get_vector("wrinkle_cycles"));
  rec_.load([&](const std::string& name) { return r.get_vector(name); });
}

}  // namespace swim::full3d
