// The actuation protocol of Section 3 of the paper on the 3D spring network.
//
// Per node i the actuation force is  F^e_i = -q A_i s_i e_r,i  (N), with q the
// actuation pressure (F_ext / (2 pi R0 L); for equal node areas this is the
// paper's F_ext / N_n per node), A_i the reference area carried by the node, e_r,i
// the outward radial unit vector from the reference axis and s_i a signed level
// (+1 contracts, -1 expands) set by the protocol state:
//
// Contraction (phase 0). Segments k = 0..n-1 along the reference axis, the
// rightmost (k = n-1) first and of length first_ratio times the others (the
// same segments as the 1D tier). The active segment is driven with s = +1
// until its SEGMENT radius (mean node radius of its nodes) reaches R_f; then
// the next one to the left becomes active. Segments right of the active one
// are held by the three-way rule on their segment radius R_k:
//   s = +1 if R_k > R_f + delta,  -1 if R_k < R_f - delta,  0 within delta.
// Segments left of the active one carry no actuation.
// Recovery (phase 1, once segment 0 has reached R_f): five bands on each
// node's own radius r:  r < 0.5 R0: -1;  [0.5, 0.8) R0: -0.5;
//   [0.8 R0, R0 - delta): -0.1;  |r - R0| <= delta: 0;  r > R0 + delta: +0.1.
// The cycle ends when the wall energy (elastic + bending + kinetic) drops
// below energy_tol * E_ref, E_ref = elastic + bending energy of the tube
// uniformly contracted to R_f (the paper's rule), or, with a positive end_energy,
// below max(energy_tol * E_ref, end_energy), or, with shape_end, once the ring radii
// and axial ring positions are back within delta (docs/full3d.md, "Recovery end");
// the next cycle then starts.
//
// Chattering. As in the 1D tier (reduced1d/protocol.hpp), the relays are
// regularised: across every threshold the level varies by a C2 smooth step
// (6 s^5 - 15 s^4 + 10 s^3) over a width kRampFraction * delta centred on the
// threshold, so the actuation is a continuous, monotone function of the radius
// and an explicit time step cannot flip it back and forth every step. Only the
// protocol events (segment reached, cycle completed) are discrete; they are
// tested after each time step.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "full3d/membrane.hpp"

namespace swim::full3d {

/// Ramp width of the regularised relays as a fraction of delta (same as the 1D tier).
inline constexpr double kRampFraction = 0.25;

struct ProtocolParams {
  double q = 0.32;                 ///< actuation pressure, Pa (inward positive)
  double R_f = 0.55 * 0.125e-6;    ///< target contracted radius, m
  double delta = 0.02 * 0.125e-6;  ///< radius tolerance, m
  int segments = 6;
  double first_ratio = 1.0 / 3.0;  ///< rightmost segment length / other segments' length
  double energy_tol = 1e-3;
  int cycles = 1;
  bool repeat_until_duration = false;  ///< true: cycles repeat (time.duration given)
  /// J. > 0: the recovery ends when the wall energy drops below max(energy_tol E_ref,
  /// end_energy) (full3d.recovery_end = dead_band: end_energy = energy of the tube uniformly
  /// at R0 - delta, the edge of the five-band law's dead band). 0: the paper's energy_tol E_ref.
  double end_energy = 0.0;
  /// true (full3d.recovery_end = shape): the recovery ends when every ring's mean radius is
  /// within delta of R0 and every ring's mean axial position is within delta of its reference
  /// position (after removing the mean axial translation), whatever the energy.
  bool shape_end = false;
  /// false (the 3D tier): a ring belongs to the segment its reference position lies in, and a
  /// segment's radius is the plain mean of its nodes' radii. true (the axisymmetric fitted
  /// method): each ring's reference cell, [s - ds/2, s + ds/2] cut at the tube's ends, is shared
  /// among the segments it overlaps; a ring's level is the overlap-weighted mean of their
  /// levels and a segment's radius is the mean over its length, sum f A r / sum f A (f the
  /// overlap fraction, A the ring's area); during the recovery a ring's level is the five-band
  /// law averaged over its cell (the radius interpolated linearly between the rings). The
  /// actuation is then the integral of the load over each ring's cell, and the discrete
  /// protocol converges to the continuum one instead of jumping as rings cross segment
  /// boundaries or band thresholds.
  bool dual_cell_segments = false;
};

/// Discrete protocol state (checkpointed).
struct ProtocolState {
  int phase = 0;   ///< 0 contraction, 1 recovery, 2 finished
  int active = 0;  ///< active segment in phase 0
  int cycles_completed = 0;
  long switches = 0;
  std::vector<double> cycle_start, cycle_end;
  std::vector<double> segment_reached;  ///< times at which segments reached R_f, in order
};

/// The protocol state's checkpoint records, listed once as calls f(name, member)
/// (full3d/checkpoint.hpp): the 3D and the axisymmetric tiers' checkpoints both use it.
template <class State, class F>
void protocol_records(State& st, F&& f) {
  f("phase", st.phase);
  f("active", st.active);
  f("cycles_completed", st.cycles_completed);
  f("switches", st.switches);
  f("cycle_start", st.cycle_start);
  f("cycle_end", st.cycle_end);
  f("segment_reached", st.segment_reached);
}

class Protocol3d {
 public:
  /// e_ref: energy of the tube uniformly at R_f (J). Throws InputError (key
  /// protocol.segments) when a segment holds no mesh ring.
  Protocol3d(const ProtocolParams& p, const CylinderMesh& mesh, double e_ref);

  /// Starts the first cycle at time t.
  void start(double t, const Eigen::Matrix3Xd& X);
  /// Per-node actuation force (3 x N_n, N) for the current state at positions X.
  Eigen::Matrix3Xd force(const Eigen::Matrix3Xd& X) const;
  /// Signed levels s_i (see header) for the current state at positions X.
  Eigen::VectorXd levels(const Eigen::Matrix3Xd& X) const;
  /// Protocol events after a step to time t: segment reached, cycle completed.
  /// Returns the number of switches.
  int update(double t, const Eigen::Matrix3Xd& X, double wall_energy);

  bool finished() const { return st_.phase == 2; }
  const ProtocolState& state() const { return st_; }
  ProtocolState& state() { return st_; }
  const ProtocolParams& params() const { return p_; }
  double reference_energy() const { return e_ref_; }
  /// true when the tube is back at its reference shape within delta (see shape_end).
  bool shape_recovered(const Eigen::Matrix3Xd& X) const;
  /// Wall energy below which the recovery ends, J.
  double end_threshold() const { return std::max(p_.energy_tol * e_ref_, p_.end_energy); }
  int segment_of(int node) const { return seg_[node]; }
  /// Mean node radius of each segment.
  Eigen::VectorXd segment_radii(const Eigen::Matrix3Xd& X) const;
  /// Segment boundaries along the reference axis (n+1 values from 0 to L), m.
  const std::vector<double>& boundaries() const { return bounds_; }

 private:
  ProtocolParams p_;
  const CylinderMesh* mesh_;
  double e_ref_;
  std::vector<int> seg_;
  std::vector<int> seg_count_;
  /// dual_cell_segments: per ring, (segment, fraction of the ring's cell) pairs
  std::vector<std::vector<std::pair<int, double>>> ring_share_;
  std::vector<double> bounds_;
  ProtocolState st_;
};

/// E_ref: elastic + bending energy of the mesh with every node moved radially to R_f.
double uniform_contraction_energy(const CylinderMesh& mesh, const MembraneParams& m, double R_f);

}  // namespace swim::full3d
