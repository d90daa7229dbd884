#include "reduced1d/protocol.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "reduced1d/internal.hpp"

namespace swim::reduced1d::detail {

namespace {
/// Elastic energy of the tube uniformly at radius R.
double uniform_energy(const Params& p, double R) {
  const double R0 = p.geometry.R0, d = R0 - R;
  const double area = 2.0 * std::numbers::pi * R0 * p.geometry.L;
  return (p.wall.law ? p.wall.law->energy(R) : 0.5 * p.wall.C1 * d * d) * area;
}
}  // namespace

double reference_energy(const Params& p) { return uniform_energy(p, p.protocol.R_f); }

double dead_band_energy(const Params& p) { return uniform_energy(p, p.geometry.R0 - p.protocol.delta); }

double recovery_end_energy(const Params& p) {
  const double level = p.protocol.energy_tol * reference_energy(p);
  return p.protocol.recovery_end == RecoveryEnd::DeadBand ? std::max(level, dead_band_energy(p)) : level;
}

namespace {
/// Radius where w(R) + q(R) + extra = 0 for a continuous, strictly increasing wall load w with
/// the inverse `static_radius` (w(static_radius(load)) = -load) and the actuation law q
/// (continuous, non-decreasing): its constant pieces are solved by the inverse, its ramps by
/// bisection.
template <class W, class Inverse>
double solve_rest_radius(const ActuationLaw& q, const W& w, const Inverse& static_radius, double extra) {
  if (q.n == 0) return static_radius(q.c + extra);
  {  // left constant piece R <= x0
    const double R = static_radius(q.y[0] + extra);
    if (R <= q.x[0]) return R;
  }
  for (int k = 1; k < q.n; ++k) {
    const auto g = [&](double R) { return w(R) + q(R) + extra; };
    if (g(q.x[k - 1]) <= 0 && g(q.x[k]) >= 0) {
      double a = q.x[k - 1], b = q.x[k];
      for (int it = 0; it < 200 && b - a > 1e-15 * (std::abs(a) + std::abs(b)); ++it) {
        const double m = 0.5 * (a + b);
        (g(m) < 0 ? a : b) = m;
      }
      return 0.5 * (a + b);
    }
  }
  return static_radius(q.y[q.n - 1] + extra);  // right constant piece
}
}  // namespace

double ActuationLaw::rest_radius(double R0, double C1, double extra) const {
  return solve_rest_radius(
      *this, [&](double R) { return C1 * (R - R0); }, [&](double load) { return R0 - load / C1; }, extra);
}

double ActuationLaw::rest_radius(const WallLaw& wall, double extra) const {
  if (!wall.law) return rest_radius(wall.R0, wall.C1, extra);
  return solve_rest_radius(
      *this, [&](double R) { return wall(R); }, [&](double load) { return wall.static_radius(load); }, extra);
}

namespace {
// Relay with thresholds t_k and levels v_0 (below t_0), v_1, ..., v_m (above t_{m-1}), each
// jump regularised by a smooth step of width eps_k centred on its threshold.
ActuationLaw regularised_relay(const std::vector<double>& thresholds, const std::vector<double>& levels,
                               const std::vector<double>& eps) {
  ActuationLaw a;
  a.n = 0;
  for (std::size_t k = 0; k < thresholds.size(); ++k) {
    a.x[a.n] = thresholds[k] - 0.5 * eps[k];
    a.y[a.n++] = levels[k];
    a.x[a.n] = thresholds[k] + 0.5 * eps[k];
    a.y[a.n++] = levels[k + 1];
  }
  return a;
}
}  // namespace

ProtocolMachine::ProtocolMachine(const Params& p, std::vector<double> fixed_q)
    : N_(p.numerics.cells), nseg_(p.protocol.segments), Rf_(p.protocol.R_f), fixed_(!fixed_q.empty()) {
  const double R0 = p.geometry.R0, d = p.protocol.delta, q = p.protocol.q;
  const double eps = kRampFraction * d;
  // Wide ramps at 0.5 R0 and 0.8 R0, limited so that neighbouring ramps never overlap.
  const double wide = std::min({kWideRampFraction * R0, 0.3 * R0 - eps, 0.2 * R0 - d - eps});
  seg_a_.assign(N_, 0);
  seg_b_.assign(N_, 0);
  w_.assign(N_, 1.0);
  if (fixed_) {
    nseg_ = 1;
    for (double v : fixed_q) fixed_laws_.push_back(ActuationLaw::constant(v));
  } else {
    const auto ov = segment_overlaps(p);
    for (int i = 0; i < N_; ++i) {
      seg_a_[i] = ov[i].seg_a;
      seg_b_[i] = ov[i].seg_b;
      w_[i] = ov[i].w;
    }
  }
  seg_weight_.assign(nseg_, 0.0);
  seg_first_.assign(nseg_, N_);
  seg_last_.assign(nseg_, -1);
  for (int i = 0; i < N_; ++i) {
    seg_weight_[seg_a_[i]] += w_[i];
    seg_weight_[seg_b_[i]] += 1.0 - w_[i];
    for (int k : {seg_a_[i], seg_b_[i]}) {
      seg_first_[k] = std::min(seg_first_[k], i);
      seg_last_[k] = std::max(seg_last_[k], i);
    }
  }
  active_law_ = ActuationLaw::constant(q);
  idle_law_ = ActuationLaw::constant(0.0);
  held_law_ = regularised_relay({Rf_ - d, Rf_ + d}, {-q, 0.0, q}, {eps, eps});
  recovery_law_ = regularised_relay({0.5 * R0, 0.8 * R0, R0 - d, R0 + d},
                                    {-q, -0.5 * q, -0.1 * q, 0.0, 0.1 * q},
                                    {std::max(wide, eps), std::max(wide, eps), eps, eps});
}

double ProtocolMachine::segment_mean(int k, const double* R) const {
  double s = 0;
  for (int i = seg_first_[k]; i <= seg_last_[k]; ++i) {
    if (seg_a_[i] == k) s += w_[i] * R[i];
    if (seg_b_[i] == k && seg_b_[i] != seg_a_[i]) s += (1.0 - w_[i]) * R[i];
  }
  return s / seg_weight_[k];
}

const ActuationLaw* ProtocolMachine::segment_law(int k) const {
  // Cell law contributed by segment k (the held rule is a segment law, see laws()).
  if (phase_ == 0) return k == active_ ? &active_law_ : &idle_law_;
  if (phase_ == 1) return &recovery_law_;
  return &idle_law_;
}

void ProtocolMachine::laws(std::vector<CellLaw>& law, std::vector<const ActuationLaw*>& seg) const {
  law.assign(N_, CellLaw{&idle_law_, &idle_law_, 1.0});
  seg.assign(nseg_, nullptr);
  for (int i = 0; i < N_; ++i) {
    if (fixed_) {
      law[i] = CellLaw{&fixed_laws_[i], &fixed_laws_[i], 1.0};
    } else {
      law[i] = CellLaw{segment_law(seg_a_[i]), segment_law(seg_b_[i]), w_[i]};
    }
  }
  if (!fixed_ && phase_ == 0)
    for (int k = active_ + 1; k < nseg_; ++k) seg[k] = &held_law_;
}

int ProtocolMachine::root_count() const {
  if (phase_ == 2) return 0;
  if (fixed_) return 1;
  return 2;
}

void ProtocolMachine::reach_active(double t, const double* R, int& switches) {
  while (true) {
    reached_.push_back(t);
    ++switches;
    if (active_ == 0) {
      phase_ = 1;
      return;
    }
    --active_;
    if (segment_mean(active_, R) > Rf_) return;
  }
}

void ProtocolMachine::start_cycle(double t, const double* R) {
  phase_ = 0;
  cycle_completed_ = false;
  active_ = nseg_ - 1;
  if (!fixed_ && segment_mean(active_, R) <= Rf_) {
    int dummy = 0;
    reach_active(t, R, dummy);
  }
}

int ProtocolMachine::apply(double t, const int* found, const double* R) {
  int switches = 0;
  if (found[0]) {
    collapsed_ = true;
    return 0;
  }
  if (fixed_ || root_count() < 2 || !found[1]) return 0;
  if (phase_ == 0) {
    reach_active(t, R, switches);
  } else if (phase_ == 1) {
    cycle_completed_ = true;
    ++switches;
  }
  return switches;
}

}  // namespace swim::reduced1d::detail
