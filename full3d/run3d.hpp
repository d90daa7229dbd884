// The 3D run driver: init, then while (!finished) { step; measure; write; }.
//
// Fluid-coupled run (default): IbSolver (ib_solver.hpp) with the Section-3
// actuation of protocol3d.hpp as the external force F^e of eq. (16).
// Dry run (full3d.dry): the paper's dry swimmer, per node
//     m_i r_i'' + nu A_i r_i' - F_i(r) = F^e_i,   m_i = (mass per area) A_i,
// no fluid; forward_euler = symplectic Euler with implicit damping,
// midpoint = velocity Verlet with trapezoidal damping.
//
// Measured every step: protocol events, the guards, the volume fluxes through
// the two end discs (integrated in time to the pumped volumes). Recorded every
// output step: centre position (mean axial node position) and velocity (mean
// axial node velocity), ring radii, elastic / bending / kinetic energies, fluxes,
// volumes, protocol phase. Written: summary.json, series.csv, radius.csv,
// solver_stats.json, scene.resolved.json, VTK membrane frames + membrane.pvd,
// fluid fields (vtk/fluid_*.vti + fluid.pvd) on request, checkpoint.bin.
//
// Failures (swim::NumericalError from the guards) end the run with the partial
// results written ("status": "failed: ...") and the last checkpoint kept.
//
// The driver's parts (run3d_setup.hpp): Stepper (run3d_stepper.hpp), Measurements
// (run3d_measure.hpp), RunOutput (run3d_output.hpp), RunCheckpoint (run3d_checkpoint.hpp).
#pragma once

#include <string>

#include "common/run_record.hpp"
#include "common/scene.hpp"
#include "full3d/scene3d.hpp"

namespace swim::full3d {

struct RunControl {
  int progress = -1;            ///< -1 auto (terminal), 0 off, 1 on
  bool resume = false;          ///< continue from out_dir/checkpoint.bin
  long stop_after_steps = -1;   ///< testing: stop after this many steps of this process, as if killed
  bool quiet_vtk = false;       ///< testing: suppress VTK output regardless of the scene
  bool keep_rows = false;       ///< keep the record's rows and ring radii in memory (RunOutcome::record)
  std::uintmax_t max_output_bytes = 0;  ///< output.max_bytes for series.csv, radius.csv and the VTK frames (0: none)
};

struct RunOutcome {
  scene::json summary;
  /// The run record (common/run_record.hpp); its rows only with RunControl::keep_rows, and
  /// then those produced by this process (a resumed run's earlier rows are in series.csv).
  record::RunRecord record;
  bool failed = false;          ///< a NumericalError ended the run (exit 3)
  bool interrupted = false;     ///< stop_after_steps reached (nothing final written)
  std::string message;
  long steps = 0;
};

/// Runs the scene into out_dir (created by the caller). Throws InputError for a resume
/// from a checkpoint that is damaged or does not match the scene, OutputError for a result
/// file or checkpoint that cannot be written; numerical failures are reported in the outcome.
RunOutcome run3d(const Params3d& p, const scene::json& resolved, const std::string& out_dir,
                 const RunControl& ctl = {});

/// One step of the paper's dry swimmer, m_i r_i'' + nu_i r_i' - F_i(r) = F^e_i (no fluid):
/// ForwardEuler = symplectic Euler with implicit damping, Midpoint = velocity Verlet with
/// trapezoidal damping. s.X, s.V, s.V_prev, s.t are advanced; throws NumericalError
/// (remedy full3d.dt) on a non-finite state.
void dry_step(const CylinderMesh& mesh, const MembraneParams& membrane, const Eigen::VectorXd& mass,
              const Eigen::VectorXd& damping, const ExternalForceFn& external, IbScheme scheme, IbState& s, double dt);

/// Reads and validates the checkpoint of out_dir for a resume of this scene (format and
/// checks: run3d_checkpoint.hpp) without touching the folder. Throws InputError (key
/// "--resume") naming the file, what is wrong and what to do.
void check_resumable(const Params3d& p, const scene::json& resolved, const std::string& out_dir);

/// Name of the checkpoint file in an output folder.
inline std::string checkpoint_path(const std::string& dir) { return dir + "/checkpoint.bin"; }

}  // namespace swim::full3d
