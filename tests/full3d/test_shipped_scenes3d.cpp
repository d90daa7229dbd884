// Every shipped scene is a valid 3D scene: it resolves, its membrane satisfies the no-leak
// rule at the shipped resolution, and its first steps run (on a coarser grid, to stay
// quick) without tripping a guard and with finite outputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>

#include "common/errors.hpp"
#include "common/scene.hpp"
#include "full3d/membrane.hpp"
#include "full3d/run3d.hpp"

using namespace swim;
using namespace swim::full3d;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> shipped_scenes() {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(SWIM_SOURCE_DIR "/data/scenes"))
    if (e.path().extension() == ".json") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(ShippedScenes3d, ResolveWithTheMembraneInsideTheNoLeakBound) {
  const auto files = shipped_scenes();
  ASSERT_GE(files.size(), 9u);
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    scene::json sc = scene::load_file(f);
    scene::json resolved;
    const Params3d p = read_scene3d(sc, resolved);
    const CylinderMesh mesh = make_mesh(p);
    const double edge = max_edge_length(mesh, mesh.X0);
    std::printf("%-40s %3dx%2dx%2d h = %.3g nm, %5d nodes, longest edge %.2f h\n",
                fs::path(f).filename().c_str(), p.nx, p.ny, p.nz, 1e9 * p.h, mesh.nodes(), edge / p.h);
    EXPECT_LT(edge, 0.5 * p.h);
    EXPECT_GT(p.dt, 0.0);
  }
}

// A resolved scene read back resolves to itself: run folders keep scene.resolved.json, and
// the validation cache finds a run by resolving that file again with the current reader.
TEST(ShippedScenes3d, ResolvedSceneResolvesToItself) {
  for (const auto& f : shipped_scenes()) {
    SCOPED_TRACE(f);
    scene::json resolved, again;
    const Params3d p = read_scene3d(scene::load_file(f), resolved);
    const Params3d q = read_scene3d(resolved, again);
    EXPECT_EQ(again, resolved);
    EXPECT_EQ(q.nx, p.nx);
    EXPECT_EQ(q.h, p.h);
    EXPECT_EQ(q.dt, p.dt);
    EXPECT_EQ(q.membrane.kb, p.membrane.kb);
  }
  // an older resolution without a key the reader gained resolves to the same scene
  scene::json resolved, again;
  read_scene3d(scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json"), resolved);
  ASSERT_TRUE(resolved["full3d"]["membrane"].contains("axisymmetric"));
  scene::json older = resolved;
  older["full3d"]["membrane"].erase("axisymmetric");
  read_scene3d(older, again);
  EXPECT_EQ(again, resolved);
}

TEST(ShippedScenes3d, FirstStepsRunOnACoarseGrid) {
  for (const auto& f : shipped_scenes()) {
    SCOPED_TRACE(f);
    scene::json sc = scene::load_file(f);
    // the paper-sized scenes on a 16-cells-across grid; the tiny scenes are coarse already
    const bool own_grid = sc.contains("full3d") && sc["full3d"].contains("grid") &&
                          sc["full3d"]["grid"].contains("cell_size");
    if (!own_grid) scene::apply_override(sc, "full3d.grid.cells_across=16");
    for (const char* s : {"time.duration=\"4 ms\"", "time.output_interval=\"1 ms\"",
                          "full3d.checkpoint_interval=\"2 ms\"", "full3d.output.vtk=false"})
      scene::apply_override(sc, s);
    scene::json resolved;
    const Params3d p = read_scene3d(sc, resolved);
    const std::string dir = std::string(SWIM_BINARY_DIR) + "/tests/out_shipped3d/" + fs::path(f).stem().string();
    fs::remove_all(dir);
    fs::create_directories(dir);
    RunControl ctl;
    ctl.progress = 0;
    ctl.quiet_vtk = true;
    const RunOutcome r = run3d(p, resolved, dir, ctl);
    EXPECT_FALSE(r.failed) << r.message;
    EXPECT_GE(r.steps, 4);
    EXPECT_TRUE(std::isfinite(r.summary["displacement_m"].get<double>()));
    EXPECT_TRUE(fs::exists(dir + "/summary.json"));
  }
}

// Every fluid frame falls on a membrane frame: the default fluid interval is a whole multiple
// of the membrane's, and a given interval that is not is refused naming the key.
TEST(ShippedScenes3d, FluidFramesFallOnMembraneFrames) {
  for (const auto& e : std::filesystem::directory_iterator(SWIM_SOURCE_DIR "/data/scenes")) {
    scene::json resolved;
    const Params3d p = read_scene3d(scene::load_file(e.path().string()), resolved);
    const double k = p.fluid_interval / p.vtk_interval;
    EXPECT_NEAR(k, std::round(k), 1e-9 * k) << e.path();
    EXPECT_GE(k, 1.0 - 1e-12) << e.path();
  }
  scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/tiny_3d.json");
  sc["full3d"]["output"]["fluid_interval"] = "15 ms";  // vtk_interval is 10 ms
  scene::json resolved;
  try {
    read_scene3d(sc, resolved);
    ADD_FAILURE() << "15 ms against 10 ms accepted";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("full3d.output.fluid_interval"), std::string::npos) << err.what();
  }
  sc["full3d"]["output"]["fluid_interval"] = "30 ms";
  EXPECT_NO_THROW(read_scene3d(sc, resolved));
}

// full3d.membrane.bending_rigidity fixes the wall's bending rigidity D across grids: eq. (8)'s
// k_b is set per mesh (it halves as the edge length doubles), and the resolved scene reads
// back to the same wall. With bending_constant as well the scene is rejected.
TEST(ShippedScenes3d, BendingRigidityIsTheSameWallOnEveryGrid) {
  const double D = 2.0e-24;
  double kb_prev = 0.0, edge_prev = 0.0;
  for (int n : {24, 48}) {
    scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json");
    sc["full3d"]["grid"]["cells_across"] = n;
    sc["full3d"]["membrane"]["bending_rigidity"] = "2e-24 J";
    scene::json resolved;
    const Params3d p = read_scene3d(sc, resolved);
    const CylinderMesh mesh = make_mesh(p);
    EXPECT_NEAR(p.membrane.kb * bending_rigidity_per_kb(mesh, p.membrane.bending), D, 1e-9 * D);
    scene::json again;
    EXPECT_DOUBLE_EQ(read_scene3d(resolved, again).membrane.kb, p.membrane.kb);
    const double edge = mesh.rest_length.mean();
    if (kb_prev > 0) {
      EXPECT_NEAR(p.membrane.kb / kb_prev, edge_prev / edge, 0.05 * edge_prev / edge);
    }
    kb_prev = p.membrane.kb;
    edge_prev = edge;
  }
  scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json");
  sc["full3d"]["membrane"]["bending_rigidity"] = "2e-24 J";
  sc["full3d"]["membrane"]["bending_constant"] = "1e-15 N";
  scene::json resolved;
  try {
    read_scene3d(sc, resolved);
    ADD_FAILURE() << "bending_rigidity with bending_constant accepted";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("full3d.membrane.bending_rigidity"), std::string::npos) << err.what();
  }
}

// Every figure a shipped scene's description states is the scene's own: the grid (NxMxK), the
// cell size (h = N nm), the membrane's node count, R0, L, R_f, the number of cycles and, for
// a scene with a fixed duration, its steps.
TEST(ShippedScenes3d, DescriptionsStateTrueFigures) {
  const auto number = [](const std::string& text, const std::string& pattern, double& v) {
    std::smatch m;
    if (!std::regex_search(text, m, std::regex(pattern))) return false;
    v = std::stod(m[1]);
    return true;
  };
  for (const auto& f : shipped_scenes()) {
    SCOPED_TRACE(f);
    const scene::json sc = scene::load_file(f);
    const std::string d = sc.value("description", std::string());
    ASSERT_FALSE(d.empty()) << "every shipped scene describes itself (swim scenes lists it)";
    scene::json resolved;
    const Params3d p = read_scene3d(sc, resolved);
    std::smatch m;
    if (std::regex_search(d, m, std::regex(R"((\d+)x(\d+)x(\d+))"))) {
      EXPECT_EQ(std::stoi(m[1]), p.nx);
      EXPECT_EQ(std::stoi(m[2]), p.ny);
      EXPECT_EQ(std::stoi(m[3]), p.nz);
    }
    double v = 0;
    if (number(d, R"(h = ([\d.]+) nm)", v)) { EXPECT_NEAR(v, p.h * 1e9, 0.05); }
    if (number(d, R"((\d+) (membrane )?nodes)", v)) { EXPECT_EQ(static_cast<int>(v), make_mesh(p).nodes()); }
    EXPECT_EQ(d.find('~' + std::string("1000 nodes")), std::string::npos);
    // lengths in µm, as in every human-facing text (not "um", the unit syntax of the scene values)
    EXPECT_FALSE(std::regex_search(d, std::regex(R"(\d um\b)"))) << d;
    if (number(d, "R0 = ([\\d.]+) \u00b5m", v)) { EXPECT_NEAR(v * 1e-6, p.R0, 0.005 * p.R0); }
    if (number(d, "\\bL = ([\\d.]+) \u00b5m", v)) { EXPECT_NEAR(v * 1e-6, p.L, 0.005 * p.L); }
    EXPECT_TRUE(std::regex_search(d, std::regex("(R0|L) = [\\d.]+ \u00b5m"))) << "states R0 or L: " << d;
    if (number(d, R"(R_f = ([\d.]+) R0)", v)) { EXPECT_NEAR(v, resolved["wave"]["contracted_ratio"].get<double>(), 1e-9); }
    const int cycles = resolved["protocol"]["cycles"].get<int>();
    if (d.find("one cycle") != std::string::npos || d.find("one complete") != std::string::npos) { EXPECT_EQ(cycles, 1); }
    if (d.find("ten force-driven cycles") != std::string::npos) { EXPECT_EQ(cycles, 10); }
    if (number(d, R"((\d+) steps)", v)) {
      ASSERT_GT(p.duration, 0.0) << "a step count needs a fixed duration";
      EXPECT_NEAR(v, p.duration / p.dt, 0.5);
    }
    if (number(d, R"(first ([\d.]+) ms)", v)) { EXPECT_NEAR(v * 1e-3, p.duration, 1e-12); }
    if (number(d, R"(eps = ([\d.]+))", v)) { EXPECT_NEAR(v, p.R0 / p.L, 0.005 * v); }
    if (number(d, R"(([\d.]+)x the static load)", v)) {
      ASSERT_TRUE(sc["protocol"].contains("load_factor"));
      EXPECT_NEAR(v, sc["protocol"]["load_factor"].get<double>(), 1e-9);
    }
  }
}
