// Helpers shared by the tests of the 3D run driver: a shipped scene with overrides, an
// empty output folder, a quiet run control, series.csv read back.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "full3d/run3d.hpp"

namespace swim::full3d::run3d_test {

struct Scene {
  scene::json resolved;
  Params3d p;
};

/// data/scenes/<file> with the `--set` assignments applied, read by the 3D reader.
inline Scene shipped_scene(const std::string& file, const std::vector<std::string>& sets) {
  scene::json sc = scene::load_file(std::string(SWIM_SOURCE_DIR "/data/scenes/") + file);
  for (const auto& s : sets) scene::apply_override(sc, s);
  Scene out;
  out.p = read_scene3d(sc, out.resolved);
  return out;
}

/// An empty folder <build>/tests/<group>/<name>.
inline std::string fresh_dir(const std::string& group, const std::string& name) {
  const std::string d = std::string(SWIM_BINARY_DIR) + "/tests/" + group + "/" + name;
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// No progress line, no VTK frames.
inline RunControl quiet_control() {
  RunControl c;
  c.progress = 0;
  c.quiet_vtk = true;
  return c;
}

/// The rows of a CSV file with a header line.
inline std::vector<std::vector<double>> read_csv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) r.push_back(std::stod(cell));
    rows.push_back(r);
  }
  return rows;
}

}  // namespace swim::full3d::run3d_test
