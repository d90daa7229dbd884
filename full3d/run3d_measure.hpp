// The measuring part of a 3D run. Every step: the volume fluxes through the two end discs
// (integrated in time to the pumped volumes), the solver statistics, the wall energy and
// the guards (non-finite or runaway energy, collapsed tube: NumericalError naming the
// parameter to change). Every output step: a row of series.csv (centre position and
// velocity, radii, energies, fluxes, volumes, protocol phase, step statistics) and the
// ring radii of radius.csv.
#pragma once

#include <array>
#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "common/run_record.hpp"
#include "full3d/checkpoint.hpp"
#include "full3d/grid.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/protocol3d.hpp"
#include "full3d/run3d_setup.hpp"

namespace swim::full3d {

/// The columns of a 3D run's series.csv: the common ones (record::common_series_columns()),
/// then the energy split, protocol state and step statistics, and the wall wrinkle.
extern const std::vector<std::string> kSeriesColumns;

/// The wall's departure from axisymmetry, m: the largest, over the rings, of the RMS
/// deviation of the node radii from their ring's mean radius. An axisymmetric tube gives
/// 0; a hoop-compressed lattice that buckles into azimuthal lobes (docs/full3d.md, "Wall
/// wrinkling") gives the lobes' RMS amplitude.
double wall_wrinkle(const CylinderMesh& mesh, const Eigen::VectorXd& node_r, const Eigen::VectorXd& ring_r);
/// The wall's wrinkle and its lobe number: `amplitude` as wall_wrinkle, `mode` on that most
/// wrinkled ring the m in [2, n_theta / 2] with the largest Fourier amplitude
/// |sum_i (r_i - r_ring) exp(-i m phi_i)| of the node radii against their angles phi_i about the
/// ring's centroid; 0 when that ring's deviation is below 1e-9 of its radius (a round wall).
struct WallWrinkle {
  double amplitude = 0.0;  ///< m
  int mode = 0;
};
WallWrinkle wall_wrinkle_shape(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const Eigen::VectorXd& node_r,
                               const Eigen::VectorXd& ring_r);

/// The wall's lobes cycle by cycle (docs/full3d.md, "Ring buckling and the seed imperfection"),
/// from the wrinkle of each recorded row: for each protocol cycle (1 = the first; the cycle in
/// progress at the run's end included), the largest wrinkle and its lobe number, and every lobe
/// number the wall showed while its wrinkle exceeded the threshold (half a cell), in the order
/// they first appeared. A seeded wall whose lobes turn from the seed's m to another while
/// buckled (a recovery that leaves a small wrinkle of another shape, which the next contraction
/// grows) shows two modes: the later cycles then belong to another buckled shape.
class CycleWrinkles {
 public:
  struct Cycle {
    int cycle = 0;
    double max_wrinkle_m = 0.0;
    int max_wrinkle_mode = 0;
    std::vector<int> modes;  ///< lobe numbers seen above the threshold, first appearance first
  };
  explicit CycleWrinkles(double threshold_m = 0.0) : threshold_(threshold_m) {}
  /// One recorded row: the cycle it belongs to (cycles completed + 1), the wrinkle (m) and its
  /// lobe number (0: round).
  void add(int cycle, double amplitude_m, int mode);
  const std::vector<Cycle>& cycles() const { return cycles_; }
  /// The lobe numbers seen above the threshold over the whole run, first appearance first.
  std::vector<int> modes() const;
  /// For checkpoints: per cycle [cycle, max wrinkle, its mode, number of modes, the modes...].
  std::vector<double> flat() const;
  void unflatten(const std::vector<double>& v);

 private:
  double threshold_;
  std::vector<Cycle> cycles_;
};

/// An empty record of a 3D run (tier, model, length, columns, reference ring positions).
record::RunRecord new_record(const RunSetup& run);

/// Wall time of the parts of a run in this process, s (summary.json
/// "statistics.wall_time_split_s"; a resumed run counts from its restart): the IB step's own
/// parts (forces, spread, fluid, interp), the stability estimates of the adaptive step, the
/// measurements, the output and the checkpoints.
class WallSplit {
 public:
  void add(const std::string& part, double seconds) { parts_[part] += seconds; }
  /// The timed parts of one IB step.
  void add_step(const IbStepStats& st);
  scene::json to_json() const;

 private:
  std::map<std::string, double> parts_;
};

/// Times consecutive parts: each call adds the time since the previous one (or the
/// construction) to `part`, less `exclude` (a sub-part already counted elsewhere).
class Lap {
 public:
  explicit Lap(WallSplit& w) : w_(w), t_(std::chrono::steady_clock::now()) {}
  void operator()(const char* part, double exclude = 0.0) {
    const auto now = std::chrono::steady_clock::now();
    w_.add(part, std::chrono::duration<double>(now - t_).count() - exclude);
    t_ = now;
  }

 private:
  WallSplit& w_;
  std::chrono::steady_clock::time_point t_;
};

class Measurements {
 public:
  /// The wall's stretching and bending energies at X, J (the stepper's elastic pass, shared
  /// with the next step's forces).
  using EnergySource = std::function<std::array<double, 2>(const Eigen::Matrix3Xd& X)>;
  /// Rows and ring radii go into `rec`; the wall energies come from `energy`.
  Measurements(const RunSetup& run, record::RunRecord& rec, EnergySource energy);
  /// A fresh run: the reference of the centre displacement.
  void start(const IbState& s);
  /// After a step: solver statistics, end-disc fluxes and volumes (fluid-coupled runs).
  void after_step(const IbStepStats& st, const IbState& s, double dt, const MacGrid* grid);
  double wall_energy(const IbState& s) const;
  /// Throws NumericalError when the wall energy e is not finite or ran away, or the tube collapsed.
  void guards(double e, const IbState& s);
  /// The protocol's cycle events since the last call, into the record.
  void events(const ProtocolState& st);
  /// One output row at step n (dt_last: the step that led to it).
  void record(const IbState& s, const ProtocolState& st, long n, double dt_last);

  long last_recorded() const { return last_recorded_; }
  double pumped_volume() const { return -vol_rear_; }
  double max_cfl() const { return max_cfl_; }
  long stokes_iterations() const { return iterations_total_; }
  /// The largest wall wrinkle of the recorded rows (m) and its lobe number (wall_wrinkle_shape).
  double max_wrinkle() const { return max_wrinkle_; }
  int max_wrinkle_mode() const { return int(max_wrinkle_mode_); }
  /// The wall's lobes cycle by cycle (threshold: half a cell).
  const CycleWrinkles& cycle_wrinkles() const { return wrinkles_; }
  WallSplit& split() { return split_; }
  const WallSplit& split() const { return split_; }

  void save(CheckpointWriter& w) const;
  void load(const CheckpointReader& r);

 private:
  /// The checkpoint records of the measurements, f(name, member) (checkpoint.hpp).
  template <class Self, class F>
  static void records(Self& self, F&& f);
  double kinetic_energy(const IbState& s) const;
  /// Stretching and bending energy of the wall in state s; kept for the state at s.t, which the
  /// energy guard and the output row of one step both ask for.
  std::array<double, 2> elastic_parts(const IbState& s) const;
  double disc_flux(int ring, const IbState& s, const MacGrid& grid) const;

  const RunSetup& run_;
  record::RunRecord& rec_;
  double e_cap_;
  std::vector<std::array<double, 3>> disc_;  ///< unit-disc quadrature: y, z, weight
  double x_center0_ = 0, vol_rear_ = 0, vol_front_ = 0, q_rear_ = 0, q_front_ = 0, q_rear_prev_ = 0, q_front_prev_ = 0;
  double rmin_seen_ = 1e300;
  double max_edge_ = 0.0, max_edge_t_ = -1.0;  ///< longest edge after the last step, and the time of that state
  double max_cfl_ = 0, last_cfl_ = 0, last_divergence_ = 0;
  long iterations_total_ = 0, last_iterations_ = 0;
  long last_recorded_ = -1;
  double max_wrinkle_ = 0.0, max_wrinkle_mode_ = 0.0;
  CycleWrinkles wrinkles_;
  mutable double parts_t_ = -1.0;
  mutable const double* parts_x_ = nullptr;
  mutable std::array<double, 2> parts_{};
  WallSplit split_;
  EnergySource energy_source_;
};

}  // namespace swim::full3d
