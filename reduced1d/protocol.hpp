// Discrete state and actuation laws of the Section-3 protocol mapped to 1D (source-equations.md §7).
//
// Contraction (phase 0): segments k = n-1 (rightmost, shortest) down to 0 are driven in turn
// with q = +protocol.q until their MEAN cell radius reaches R_f (a located root: a discrete
// event). Segments that have reached R_f are "held" by the paper's three-way rule applied to
// the SEGMENT ("the radius of the previous segment is checked, and the following force is
// applied to the previous segment(s)"): on the segment's length-weighted mean radius Rbar,
// +q above R_f + delta, -q below R_f - delta, 0 within delta, applied uniformly over the
// segment. Segments left of the active one carry no actuation.
// Recovery (phase 1, from the moment segment 0 reaches R_f): five bands per cell ("at that
// node"), R < 0.5 R0: -q;  [0.5, 0.8) R0: -0.5 q;  [0.8 R0, R0 - delta): -0.1 q;
//   |R - R0| <= delta: 0;  R > R0 + delta: +0.1 q.
// The cycle ends when the wall energy drops below energy_tol * E_ref (a located root).
//
// The held and recovery rules are relays. Applied continuously in time to the diffusive
// wall-flow system they have no classical solution: where the two laws on either side of a
// threshold push the radius towards it, the relay chatters infinitely fast (Filippov sliding
// mode); with a hysteresis band the chattering frequency is set by the cell size and grows like
// N^2 (docs/reduced1d.md, "Why the relays are regularised"). The solver therefore uses the
// Filippov regularisation of each relay: across every threshold the actuation follows a C2
// smooth step of width kRampFraction * delta (the delta-tolerance thresholds R_f +- delta and
// R0 +- delta) or kWideRampFraction * R0 (the band boundaries 0.5 R0 and 0.8 R0) centred on
// the threshold. The actuation is then a continuous, non-decreasing function of the radius,
// the sliding motion is resolved by the integrator, and only the n + 1 protocol events per
// cycle are discrete.
#pragma once

#include <vector>

#include "reduced1d/params.hpp"
#include "reduced1d/tube_law.hpp"

namespace swim::reduced1d::detail {

/// Ramp width of the regularised relays at the delta-tolerance thresholds (R_f +- delta for
/// the hold, R0 +- delta for the recovery) as a fraction of protocol.delta.
inline constexpr double kRampFraction = 0.25;
/// Ramp width of the recovery thresholds at 0.5 R0 and 0.8 R0 as a fraction of R0. These
/// thresholds are band boundaries, not tolerances, so their relays may be smoothed more widely.
inline constexpr double kWideRampFraction = 0.05;

/// Actuation law q(R) [Pa]: levels y_k joined by C2 smooth steps (6 s^5 - 15 s^4 + 10 s^3)
/// over [x_{k-1}, x_k], constant outside [x_0, x_{n-1}] (n = 0: q = c everywhere).
struct ActuationLaw {
  int n = 0;
  double c = 0;
  double x[8] = {}, y[8] = {};

  static ActuationLaw constant(double q) {
    ActuationLaw a;
    a.c = q;
    return a;
  }
  bool is_constant() const { return n == 0; }
  double operator()(double R) const {
    double d;
    return eval(R, d);
  }
  /// q(R) and dq/dR.
  double eval(double R, double& dq) const {
    dq = 0.0;
    if (n == 0) return c;
    if (R <= x[0]) return y[0];
    for (int k = 1; k < n; ++k)
      if (R < x[k]) {
        const double inv = 1.0 / (x[k] - x[k - 1]);
        const double s = (R - x[k - 1]) * inv;
        const double s2 = s * s;
        const double step = s2 * s * (10.0 + s * (-15.0 + 6.0 * s));  // C2 smooth step
        const double dstep = 30.0 * s2 * (1.0 - s) * (1.0 - s);
        dq = (y[k] - y[k - 1]) * dstep * inv;
        return y[k - 1] + (y[k] - y[k - 1]) * step;
      }
    return y[n - 1];
  }
  /// Radius where C1 (R - R0) + q(R) + extra = 0 (the tube law at p = 0; unique since q is
  /// non-decreasing).
  double rest_radius(double R0, double C1, double extra = 0.0) const;
  /// The same for the wall law: w(R) + q(R) + extra = 0 (the linear law: the overload above).
  double rest_radius(const WallLaw& wall, double extra = 0.0) const;
};

class ProtocolMachine {
 public:
  /// Protocol from params. With `fixed_q` non-empty the machine is a constant actuation
  /// q_i = fixed_q[i] (no protocol, only the collapse root).
  ProtocolMachine(const Params& p, std::vector<double> fixed_q = {});

  int phase() const { return phase_; }  ///< 0 contraction, 1 recovery, 2 done
  bool fixed() const { return fixed_; }
  int segments() const { return nseg_; }
  int active() const { return active_; }
  /// Every time a segment reached R_f, in order, over all cycles (the run record's segment
  /// events: the phases of each cycle)
  const std::vector<double>& reached() const { return reached_; }

  /// Actuation of one cell: q = w a(R) + (1 - w) b(R) (a cell straddling a segment boundary
  /// mixes the two segments' laws by length fraction).
  struct CellLaw {
    const ActuationLaw* a = nullptr;
    const ActuationLaw* b = nullptr;
    double w = 1.0;
    double operator()(double R) const { return w >= 1.0 ? (*a)(R) : w * (*a)(R) + (1.0 - w) * (*b)(R); }
    /// q(R) and dq/dR.
    double eval(double R, double& dq) const {
      if (w >= 1.0) return a->eval(R, dq);
      double da, db;
      const double v = w * a->eval(R, da) + (1.0 - w) * b->eval(R, db);
      dq = w * da + (1.0 - w) * db;
      return v;
    }
  };
  /// Actuation laws for the current discrete state (pointers stay valid for the lifetime of
  /// the machine): a law of every cell on its own radius, and a law of every segment on the
  /// segment's length-weighted mean radius (nullptr where none), applied uniformly to the
  /// segment (cell i receives its length fraction in the segment times the segment's q).
  /// Held segments carry a segment law; the active, idle and recovery rules are cell laws.
  void laws(std::vector<CellLaw>& law_of_cell, std::vector<const ActuationLaw*>& law_of_segment) const;

  /// Cell-segment overlaps: cell i lies in segment seg_a(i) with length fraction w(i) and in
  /// seg_b(i) with 1 - w(i); weight(k) = sum of the fractions of segment k.
  const std::vector<int>& seg_a() const { return seg_a_; }
  const std::vector<int>& seg_b() const { return seg_b_; }
  const std::vector<double>& frac() const { return w_; }
  const std::vector<double>& seg_weight() const { return seg_weight_; }
  int seg_first(int k) const { return seg_first_[k]; }
  int seg_last(int k) const { return seg_last_[k]; }

  /// Start a contraction at time t with cell radii R (cascades if the rightmost segment is
  /// already at or below R_f).
  void start_cycle(double t, const double* R);

  /// Root functions of the current discrete state, in this order: collapse (always), then in
  /// phase 0 the active segment's mean radius - R_f, in phase 1 E / (energy_tol E_ref) - 1.
  int root_count() const;

  /// Apply the located roots (flags from CVODE/IDA root info) at time t with cell radii R.
  /// Returns the number of protocol switches (segment reached R_f, or cycle completed).
  int apply(double t, const int* found, const double* R);

  /// Test hook: put the machine into phase `phase` with `active` as the active segment.
  void set_state(int phase, int active) {
    phase_ = phase;
    active_ = active;
  }

  bool collapsed() const { return collapsed_; }
  bool cycle_completed() const { return cycle_completed_; }
  void finish() { phase_ = 2; }

  /// Length-weighted mean radius of segment k for cell radii R.
  double segment_mean(int k, const double* R) const;

 private:
  void reach_active(double t, const double* R, int& switches);
  const ActuationLaw* segment_law(int k) const;

  int N_, nseg_;
  double Rf_;
  bool fixed_ = false;
  std::vector<int> seg_a_, seg_b_;
  std::vector<double> w_;
  std::vector<double> seg_weight_;
  std::vector<int> seg_first_, seg_last_;
  std::vector<ActuationLaw> fixed_laws_;
  ActuationLaw active_law_, idle_law_, held_law_, recovery_law_;
  int phase_ = 0;
  int active_ = -1;
  std::vector<double> reached_;
  bool collapsed_ = false;
  bool cycle_completed_ = false;
};

/// E_ref = (1/2) C1 (R0 - R_f)^2 2 pi R0 L: elastic energy of the tube uniformly at R_f
/// (with a calibrated law, int_{R0}^{R_f} w dR 2 pi R0 L).
double reference_energy(const Params& p);

/// E_delta: the elastic energy of the tube uniformly at R0 - delta, the floor of the recovery's
/// end energy with model1d.recovery_end = "dead_band" (the wall stores it with every cell inside
/// the protocol's tolerance band, where the recovery law applies no load).
double dead_band_energy(const Params& p);

/// The energy the recovery ends below: energy_tol E_ref, or with model1d.recovery_end =
/// "dead_band" the larger of that and E_delta (not used with "shape").
double recovery_end_energy(const Params& p);

/// The wall law of the parameters (linear when p.wall.law is null).
inline WallLaw wall_law(const Params& p) { return {p.geometry.R0, p.wall.C1, p.wall.law.get()}; }

/// Radius below which the tube counts as collapsed: 1e-3 R0.
/// Radius at which the tube counts as collapsed: the lumen (R - a_in in the force-free model)
/// is within 1e-3 R0 of closing.
inline double collapse_radius(const Params& p) {
  const double a_in = p.swimmer.model == SwimmerModel::ForceFree ? p.swimmer.a_in : 0.0;
  return a_in + 1e-3 * p.geometry.R0;
}

}  // namespace swim::reduced1d::detail
