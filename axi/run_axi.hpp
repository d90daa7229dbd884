// The axisymmetric reference tier's run driver: init, then while (!finished) { step;
// measure; write }.
//
// The wall is a chain of rings (axi/wall_axi.hpp) in the meridian plane of the rigid
// cylinder container, coupled to steady Stokes flow (axi/stokes_axi.hpp) by the
// axisymmetric immersed boundary (axi/ib_axi.hpp). Each ring moves with the fluid:
//     dX_k/dt = I[ S( spread( F_wall(X) + F_act(t, X) ) ) ](X_k),
// with the Section-3 actuation of the 3D tier (full3d/protocol3d.hpp, applied to the rings:
// per ring F = -q A_k s_k e_r, A_k the ring's reference area). Time stepping: the explicit
// trapezoidal rule (Heun) with its embedded Euler step as the local error estimate; a step is
// accepted when that estimate is below axi.tolerance * h, and the next step follows from
// the error (order 1/2 controller), the CFL bound and the predicted time to the next
// contraction event. Protocol events are tested after every accepted step.
//
// Measured and written as by the other tiers (common/run_record.hpp): summary.json,
// series.csv, radius.csv, solver_stats.json, scene.resolved.json. Failures
// (swim::NumericalError) end the run with the partial results written ("status": "failed: ...").
//
// Checkpoints (protocol-driven runs): every axi.checkpoint_interval of simulated time the
// partial results are flushed and checkpoint.bin is written (the 3D tier's format,
// full3d/checkpoint.hpp): the stepping state, the protocol's, the record's running figures and
// the streams' marks. The fitted solvers then drop their factorisations, which a resumed run's
// new solvers do not have, so that a run resumed from any checkpoint repeats the uninterrupted
// one bit for bit.
#pragma once

#include <cstdint>
#include <string>

#include "axi/scene_axi.hpp"
#include "common/run_record.hpp"
#include "common/scene.hpp"

namespace swim::axi {

struct RunControlAxi {
  int progress = -1;                    ///< -1 auto (terminal), 0 off, 1 on
  bool keep_rows = false;               ///< keep the record's rows in memory (RunOutcomeAxi::record)
  std::uintmax_t max_output_bytes = 0;  ///< output.max_bytes (0: none)
  bool resume = false;                  ///< continue from out_dir/checkpoint.bin (protocol-driven runs)
  long stop_after_steps = 0;            ///< tests: stop after this many steps of this process (0: never)
};

struct RunOutcomeAxi {
  scene::json summary;
  record::RunRecord record;
  bool failed = false;   ///< a NumericalError ended the run (exit 3)
  bool interrupted = false;  ///< stopped by RunControlAxi::stop_after_steps (no results written)
  std::string message;
  long steps = 0;
};

/// Runs the scene into out_dir (created by the caller). Throws OutputError for a result file
/// that cannot be written; numerical failures are reported in the outcome.
RunOutcomeAxi run_axi(const ParamsAxi& p, const scene::json& resolved, const std::string& out_dir,
                      const RunControlAxi& ctl = {});

/// Checks that out_dir/checkpoint.bin continues this scene's protocol-driven run (structure,
/// checksum, scene hash, values, and the partial results beside it) without touching the
/// folder. Throws InputError (key "--resume") naming what is wrong.
void check_resumable_axi(const ParamsAxi& p, const scene::json& resolved, const std::string& out_dir);

/// A prescribed wave (wave.kind = step | sine; fitted method): the force-free swimmer of the
/// given R(z, t) (axi/prescribed_axi.hpp), written as run_axi writes. run_axi dispatches to it.
RunOutcomeAxi run_prescribed_axi(const ParamsAxi& p, const scene::json& resolved, const std::string& out_dir,
                                 const RunControlAxi& ctl = {});

/// The columns of an axisymmetric run's series.csv: the common ones, then the energy split,
/// the protocol state and the step statistics.
const std::vector<std::string>& series_columns();

}  // namespace swim::axi
