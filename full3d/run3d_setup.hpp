// The fixed context of one 3D run, shared by its parts (full3d/run3d.cpp):
//   Stepper       (run3d_stepper.hpp)     the state and its time steps: solver or dry swimmer,
//                                         protocol events, adaptive step control
//   Measurements  (run3d_measure.hpp)     fluxes, volumes, energies, the guards, the series
//   RunOutput     (run3d_output.hpp)      VTK frames and the result files
//   RunCheckpoint (run3d_checkpoint.hpp)  checkpoint.bin: writing, reading, validation
#pragma once

#include <string>

#include <Eigen/Core>

#include "full3d/membrane.hpp"
#include "full3d/scene3d.hpp"
#include "full3d/world3d.hpp"

namespace swim::full3d {

/// The scene's world (world3d.hpp: parameters, mesh, grid, solver options, protocol) and what
/// a run adds to it.
struct RunSetup : World3d {
  explicit RunSetup(const Params3d& p);

  Eigen::VectorXd mass;      ///< node masses, kg
  bool adaptive;             ///< adaptive step control (full3d.adaptive, fluid-coupled runs only)
  std::string dt_key;        ///< the step key named in messages
  long n_end;                ///< steps of a fixed duration (fixed step), -1 when the duration is auto
  long n_limit;              ///< steps of full3d.time_limit (fixed step)
  // output cadence in steps (fixed step; the adaptive step uses the intervals)
  long out_every, vtk_every, fluid_every, ckpt_every;

  /// The end of the run's time span: time.duration, or full3d.time_limit when it is auto.
  double t_end() const { return n_end > 0 ? p.duration : p.time_limit; }
  /// The largest step the run takes: full3d.adaptive.dt_max or full3d.dt.
  double dt_top() const { return adaptive ? p.adaptive.dt_max : p.dt; }
};

/// A number for messages ("%.4g").
std::string short_number(double v);

}  // namespace swim::full3d
