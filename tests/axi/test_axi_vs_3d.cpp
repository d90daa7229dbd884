// The axisymmetric tier against the 3D tier's round wall on the same scene at the same h.
//
// Both are first-order immersed-boundary discretisations of one problem (the same kernel,
// wall law in the continuum limit, protocol, container and period); they differ at O(h): the
// 3D tier's staircase container and Cartesian kernel averaged over each ring, its discrete
// network against the continuum law. So at equal h they must agree to within the first-order
// error itself, which the axisymmetric tier measures as its own change between h and h/1.5:
// 18 % in the displacement per cycle (11.07 -> 13.07 nm) and 20 % in the cycle time
// (0.660 -> 0.531 s) at the default 3D grid (h = 15.6 nm). Measured at that h: 3D 9.97 nm and
// 0.670 s, axi 11.07 nm and 0.660 s (+11 % and -1.5 %).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>

#include "axi/run_axi.hpp"
#include "axi_test_support.hpp"
#include "axi/scene_axi.hpp"
#include "common/scene.hpp"
#include "full3d/run3d.hpp"
#include "full3d/scene3d.hpp"

namespace {
namespace fs = std::filesystem;
using swim::scene::json;

using swim::axi::testing::TempDir;
}  // namespace

TEST(AxiAgainst3d, RoundWallCycleAgreesWithThe3dTierAtTheSameCellSizeWithinTheFirstOrderError) {
  json sc = swim::scene::load_file(std::string(SWIM_SOURCE_DIR) + "/data/scenes/paper_amplitude_0.82.json");
  sc["full3d"]["membrane"]["axisymmetric"] = true;
  sc["full3d"]["recovery_end"] = "shape";
  sc["full3d"]["threads"] = 2;
  sc["axi"]["method"] = "immersed_boundary";  // the 3D tier's own method family
  sc["axi"]["grid"]["cells_across"] = 32;  // the 3D default: h = 15.6 nm in both
  TempDir d3("swim-axi-vs-3d-3d"), da("swim-axi-vs-3d-axi");

  json r3;
  const swim::full3d::Params3d p3 = swim::full3d::read_scene3d(sc, r3);
  swim::full3d::RunControl c3;
  c3.progress = 0;
  c3.quiet_vtk = true;
  const auto o3 = swim::full3d::run3d(p3, r3, d3.path.string(), c3);
  ASSERT_FALSE(o3.failed) << o3.message;

  json ra;
  const swim::axi::ParamsAxi pa = swim::axi::read_scene_axi(sc, ra);
  ASSERT_DOUBLE_EQ(pa.h, p3.h);
  swim::axi::RunControlAxi ca;
  ca.progress = 0;
  const auto oa = swim::axi::run_axi(pa, ra, da.path.string(), ca);
  ASSERT_FALSE(oa.failed) << oa.message;

  const double d_3d = o3.summary["displacement_per_cycle_m"].get<double>();
  const double d_axi = oa.summary["displacement_per_cycle_m"].get<double>();
  const double t_3d = o3.summary["cycle_times_s"][0].get<double>();
  const double t_axi = oa.summary["cycle_times_s"][0].get<double>();
  EXPECT_LT(std::abs(d_axi - d_3d), 0.18 * d_axi) << d_axi << " against " << d_3d;
  EXPECT_LT(std::abs(t_axi - t_3d), 0.20 * t_axi) << t_axi << " against " << t_3d;
}
