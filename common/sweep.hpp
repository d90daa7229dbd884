// Design sweeps: a base scene and a grid of values for any scene keys.
//
//   { "base": "../scenes/demo.json",            // path (relative to the sweep file) or an inline scene
//     "vary": { "swimmer.length": {"from": "0.2 um", "to": "0.8 um", "count": 4, "spacing": "linear"},
//               "wave.contracted_ratio": {"values": [0.35, 0.55, 0.82]} },
//     "metric": "mean_velocity_m_per_s", "goal": "max",
//     "confirm": {"grid": {"cells_across": 16}} }     // optional: the 3D grid of swim screen --confirm
//
// The designs are the Cartesian product of the axes, in row-major order (last axis fastest).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "common/scene.hpp"

namespace swim::sweep {

using scene::json;

struct Axis {
  std::string key;
  std::vector<json> values;  ///< scene values as they are written into the scene ("0.3 um", 0.55)
  std::vector<double> si;    ///< the same values in SI base units
  std::string si_unit;       ///< base unit of si ("" dimensionless, "m", "m-1.kg.s-1", ...; "index" for
                             ///< categorical values such as "step", whose si is the list position)
};

struct Sweep {
  std::string name;          ///< the sweep's "name", or its file name without extension
  json base;                 ///< the base scene
  std::string base_dir;      ///< directory for relative paths inside the base scene
  std::vector<Axis> axes;
  std::string metric;
  bool maximize = true;
  json confirm;              ///< the 3D confirmation's settings ("confirm": {"grid": ...}); null when absent
  size_t count() const;
  /// Scene of design `index`, with the axis values applied.
  json design(size_t index) const;
  /// Axis value indices of design `index`.
  std::vector<size_t> indices(size_t index) const;
};

/// The "base" of a sweep or optimisation file in the folder `dir`: the scene (a path relative to that folder,
/// or an inline scene) and the folder its relative paths start from. `what` names the file kind
/// in messages. Throws InputError (key "base").
std::pair<json, std::string> read_base(const json& file, const std::string& dir, const std::string& what);

/// Read and validate a sweep file. `metrics` lists the allowed metric names.
/// Throws InputError naming the key.
Sweep read_sweep(const std::string& path, const std::vector<std::string>& metrics);
/// The same for a sweep document already read: `dir` is the folder of relative base paths,
/// `stem` the name when the sweep has none.
Sweep parse_sweep(const json& j, const std::string& dir, const std::string& stem, const std::vector<std::string>& metrics);

}  // namespace swim::sweep
