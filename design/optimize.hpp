// Continuous design optimisation on the 1D tier with NLopt.
//
// Method: COBYLA (NLopt LN_COBYLA, Powell 1994): derivative-free, honours the box bounds and
// nonlinear inequality constraints g(x) <= 0 directly, and needs one model evaluation per step
// (docs/optimize.md says why it was chosen over BOBYQA, Nelder-Mead and the global methods).
// The search runs in coordinates scaled to [0, 1] per parameter, with the objective divided by
// its magnitude at the start, so that the trust region and the merit function see O(1) numbers.
//
// Spec file (docs/optimize.md):
//   { "name": "...", "base": "../scenes/demo.json", "set": {"protocol.total_force": null},
//     "parameters": { "swimmer.length": {"min": "0.2 um", "max": "0.8 um", "start": "0.4 um"},
//                     "protocol.segments": {"min": 2, "max": 8, "integer": true} },
//     "objective": "mean_velocity_m_per_s", "goal": "max",
//     "constraints": {"min_directed_to_diffusive_ratio": 3, "max_load": "1 Pa"},
//     "max_evaluations": 60, "tolerance": 1e-3, "confirm": {"grid": {"cells_across": 16}} }
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "reduced1d/params.hpp"

namespace swim::design {

using scene::json;

/// One evaluated point of a search.
struct Evaluation {
  std::vector<double> x;            ///< the point (the caller's coordinates)
  double objective = 0;             ///< the objective's value
  std::vector<double> constraints;  ///< g_i(x); feasible when every g_i <= 0
  bool ok = true;                   ///< false: the evaluation failed (counted infeasible)
  std::string message;              ///< why it failed
  bool feasible() const;
};

struct SearchOptions {
  std::vector<double> lo, hi, start;  ///< box and start point (start inside the box)
  std::size_t constraints = 0;        ///< number of g_i the evaluation returns
  bool maximize = true;
  int max_evaluations = 60;
  double xtol_rel = 1e-3;             ///< stop when a step changes every scaled coordinate by less
};

struct SearchResult {
  std::vector<Evaluation> trajectory;  ///< every evaluation, in order
  long best = -1;                      ///< index of the best feasible evaluation (-1: none)
  std::string stop_reason;             ///< NLopt's reason ("xtol reached", "max evaluations", ...)
};

/// COBYLA over the box; `evaluate` is called once per point (inside the box).
SearchResult search(const SearchOptions& o, const std::function<Evaluation(const std::vector<double>&)>& evaluate);

/// One optimisation parameter of a spec: a scene key and its range.
struct Parameter {
  std::string key;
  double lo = 0, hi = 0, start = 0;  ///< in the unit written in the spec (`unit`)
  std::string unit;                   ///< the unit of "min" ("" for a number)
  double to_si = 1;                   ///< factor from `unit` to SI
  std::string si_unit;                ///< SI unit ("" dimensionless)
  bool integer = false;               ///< rounded to the nearest integer in the scene
  json scene_value(double v) const;   ///< the value as written into a scene ("0.45 um", 0.55, 4)
};

struct Spec {
  std::string name;
  json base;
  std::string base_dir;
  std::vector<Parameter> parameters;
  std::string objective = "mean_velocity_m_per_s";
  bool maximize = true;
  double min_ratio = 0;  ///< constraint: directed/diffusive ratio per cycle >= min_ratio (0: none)
  double max_load_Pa = std::numeric_limits<double>::infinity();  ///< constraint: actuation pressure q <= this
  int max_evaluations = 60;
  double tolerance = 1e-3;
  json confirm;  ///< the 3D confirmation's section (design/confirm.hpp)
  std::size_t constraint_count() const;
  /// The scene of the point x (one value per parameter, in the parameters' units).
  json design(const std::vector<double>& x) const;
};

/// Objectives a spec may ask for.
const std::vector<std::string>& objective_names();

/// Read and validate a spec: keys, bounds, the start, every corner of the box as a 1D scene, and
/// a load constraint that no corner or the centre of the box meets (an empty feasible set).
/// Throws InputError naming the key.
Spec read_spec(const std::string& path);

/// The 1D design of `scene` run to its end: objective and constraint values of a spec.
Evaluation evaluate_1d(const Spec& spec, const std::vector<double>& x);

}  // namespace swim::design
