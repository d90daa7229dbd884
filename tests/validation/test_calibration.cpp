// Static calibration of the wall stiffness C1 from the 3D spring-network membrane
// (validation/calibration.hpp) on the paper's amplitude scene at its default grid.
#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.hpp"
#include "common/scene.hpp"
#include "full3d/membrane.hpp"
#include "full3d/scene3d.hpp"
#include "validation/calibration.hpp"
#include "validation/hydraulic.hpp"
#include "paper_scene.hpp"

using namespace swim;

using test::paper_scene;

// The paper's Figure 10 relation: for small uniform loads the fitted C1 is the continuum
// value of the spring network, 2 k_s / (sqrt(3) R0^2), within 2 %, and the response is
// linear (both fits agree, R^2 ~ 1).
TEST(StaticCalibration, SmallLoadC1IsTheSpringNetworkValue) {
  const full3d::Params3d p = paper_scene(24);
  const double q = p.c1_estimate() * (p.R0 - p.protocol.R_f);
  const validation::StaticCalibration c = validation::calibrate_static(p, {0.005 * q, 0.01 * q, 0.02 * q});
  ASSERT_EQ(c.fit.points, 3);
  EXPECT_NEAR(c.fit.c1 / c.spring_network_c1, 1.0, 0.02);
  EXPECT_GT(c.fit.r2, 1.0 - 1e-8);
  EXPECT_NEAR(c.fit.slope / c.fit.c1, 1.0, 1e-3);
  for (const auto& lp : c.loads) {
    EXPECT_TRUE(lp.in_linear_range);
    EXPECT_TRUE(lp.stable());
    EXPECT_LE(lp.iterations, 6);  // Newton on a nearly linear problem
    EXPECT_GT(lp.displacement_m, 0.0);
  }
}

// The calibration measures the round tube: a scene with a seed imperfection (the dynamics'
// start of buckling) calibrates exactly as the same scene without it, where the seeded tube's
// static relaxation stalled (its loads are not symmetric about the axis).
TEST(StaticCalibration, ASeededWallIsCalibratedAsItsRoundTube) {
  const full3d::Params3d p = paper_scene(24);
  full3d::Params3d seeded = p;
  seeded.seed_mode = 8;
  seeded.seed_amplitude = 0.01;
  const double q = p.c1_estimate() * (p.R0 - p.protocol.R_f);
  const std::vector<double> P = {0.005 * q, 0.01 * q, 0.02 * q};
  const validation::StaticCalibration a = validation::calibrate_static(p, P), b = validation::calibrate_static(seeded, P);
  EXPECT_EQ(a.fit.c1, b.fit.c1);
  ASSERT_EQ(a.loads.size(), b.loads.size());
  for (std::size_t i = 0; i < a.loads.size(); ++i) EXPECT_EQ(a.loads[i].displacement_m, b.loads[i].displacement_m);
  EXPECT_EQ(full3d::make_round_mesh(seeded).X0, full3d::make_mesh(p).X0);
}

// Ring buckling: the compressed ring's stiffness against each ring mode cos(n phi) falls
// linearly with the load (geometric stiffness) and changes sign inside the range the paper's
// protocol needs (the static load that holds R_f); such points are reported unstable and left
// out of the fit. On the paper's tube the first modes to go are n = 5..8, at about 15 % of it.
TEST(StaticCalibration, DetectsRingBucklingAndLeavesItOutOfTheFit) {
  const full3d::Params3d p = paper_scene(24);
  const double q = p.c1_estimate() * (p.R0 - p.protocol.R_f);
  const std::vector<double> P = {0.01 * q, 0.02 * q, 0.03 * q, 0.05 * q, 1.0 * q};
  const validation::StaticCalibration c = validation::calibrate_static(p, P);
  ASSERT_EQ(c.loads.size(), 5u);
  // the smallest load is stable, the static load that holds R_f is not
  EXPECT_TRUE(c.loads[0].stable());
  EXPECT_FALSE(c.loads[4].stable());
  EXPECT_LT(c.loads[4].softest_ring_mode_stiffness_N_per_m, 0.0);
  EXPECT_LT(c.loads[4].lowest_eigenvalue_N_per_m, 0.0);  // Lanczos proves it too
  EXPECT_GE(c.loads[4].softest_ring_mode, 2);
  EXPECT_LT(c.fit.points, 5);
  // linear in the load: the slope from loads 1-2 predicts load 3 within 2 %
  const auto k = [&](int i) { return c.loads[std::size_t(i)].ring_mode_stiffness_N_per_m[0]; };  // n = 2
  const auto pr = [&](int i) { return c.loads[std::size_t(i)].pressure_Pa; };
  const double slope = (k(1) - k(0)) / (pr(1) - pr(0));
  EXPECT_LT(slope, 0.0);
  EXPECT_NEAR(k(0) + slope * (pr(2) - pr(0)), k(2), 0.02 * std::abs(k(2)));
}

// A load the tube cannot carry statically (here twice the load that would flatten it
// linearly, C1 R0) ends the series: the loads before it are kept and fitted, and the
// calibration names the load and the reason. Before three loads have converged it is an error.
TEST(StaticCalibration, ALoadWithoutStaticStateEndsTheSeries) {
  const full3d::Params3d p = paper_scene(24);
  const double q = p.c1_estimate() * (p.R0 - p.protocol.R_f), flat = p.c1_estimate() * p.R0;
  const validation::StaticCalibration c =
      validation::calibrate_static(p, {0.005 * q, 0.01 * q, 0.02 * q, 2.0 * flat, 3.0 * flat});
  ASSERT_EQ(c.loads.size(), 3u);
  EXPECT_EQ(c.fit.points, 3);
  EXPECT_NEAR(c.fit.c1 / c.spring_network_c1, 1.0, 0.02);
  EXPECT_DOUBLE_EQ(c.no_static_state_from_Pa, 2.0 * flat);
  EXPECT_FALSE(c.no_static_state_reason.empty());
  EXPECT_THROW(validation::calibrate_static(p, {0.005 * q, 2.0 * flat}), NumericalError);
}

TEST(StaticCalibration, RejectsNonPositiveLoads) {
  const full3d::Params3d p = paper_scene();
  EXPECT_THROW(validation::calibrate_static(p, {0.0}), InputError);
  EXPECT_THROW(validation::calibrate_static(p, {-1.0}), InputError);
}

// Hydraulic radii of the immersed wall at the paper's default grid: the no-slip surfaces the
// flow sees lie about one cell inside and outside R0 (the 4-point kernel's smearing), and the
// fitted lumen Poiseuille profile carries the measured lumen flux.
TEST(HydraulicRadii, HeldTubeInPaperCylinder) {
  const full3d::Params3d p = paper_scene();
  const validation::HydraulicRadii r = validation::measure_hydraulic_radii(p);
  EXPECT_GT(r.a_in_m, 0.5 * p.h);
  EXPECT_LT(r.a_in_m, 2.0 * p.h);
  EXPECT_GT(r.a_out_m, 0.5 * p.h);
  EXPECT_LT(r.a_out_m, 2.0 * p.h);
  EXPECT_LT(r.a_in_uncertainty_m, 0.2 * r.a_in_m);
  EXPECT_LT(r.a_out_uncertainty_m, 0.2 * r.a_out_m);
  EXPECT_NEAR(r.lumen_flux_poiseuille_m3_per_s / r.lumen_flux_m3_per_s, 1.0, 0.05);
  EXPECT_LT(r.max_node_speed_m_per_s, 1e-2 * r.max_fluid_speed_m_per_s);  // the wall is held
  // the container's no-slip surface is within a cell of its nominal radius
  EXPECT_NEAR(r.container_radius_effective_m, p.container_radius, p.h);
}

// A grid whose lumen is too coarse for the Poiseuille fit (tiny_3d_cycle: 12 cells across
// the duct, R0 = 3.1 h, one distinct radius inside R0 - 2h) is refused before the held-tube
// solve, for that reason and with the remedy that helps (a finer grid), rather than by the
// solve's slip check with the opposite advice.
TEST(HydraulicRadii, ALumenTooCoarseForTheFitIsRefusedBeforeTheSolve) {
  scene::json resolved;
  const full3d::Params3d p =
      full3d::read_scene3d(scene::load_file(SWIM_SOURCE_DIR "/data/scenes/tiny_3d_cycle.json"), resolved);
  try {
    validation::measure_hydraulic_radii(p);
    FAIL() << "the hydraulic radii were measured on a lumen of " << p.R0 / p.h << " cells";
  } catch (const NumericalError& e) {
    EXPECT_NE(e.cause().find("distinct radii"), std::string::npos) << e.what();
    EXPECT_NE(e.remedy().find("refine"), std::string::npos) << e.what();
  }
}

// The wet confirmation of a static load: the immersed tube, its wall held axisymmetric (the
// branch the static path computes), settles on the static displacement. Coarse grid, 5 % of
// the load that holds R_f.
TEST(WetConfirmation, TheImmersedRoundTubeSettlesOnTheStaticDisplacement) {
  full3d::Params3d p = paper_scene(16);
  p.threads = 2;
  // the paper's fixed k_b (full3d.membrane.bending_model = "fixed_kb"): on this coarse mesh a
  // stiffer wall than the default one (D held at the paper's wall on the default grid), whose
  // round equilibrium at 5 % of the load is already unstable to ring buckling
  p.bending_model = full3d::Params3d::BendingModel::FixedKb;
  p.membrane.kb = 1e-15;
  p.bending_rigidity = p.membrane.kb * full3d::bending_rigidity_per_kb(full3d::make_mesh(p), p.membrane.bending);
  const double q = 0.05 * p.c1_estimate() * (p.R0 - p.protocol.R_f);
  const validation::StaticCalibration c = validation::calibrate_static(p, {q});
  ASSERT_EQ(c.loads.size(), 1u);
  const validation::WetConfirmation w = validation::confirm_wet(p, q, c.loads[0].displacement_m);
  std::printf("static %.4g m, wet %.4g m (%+.2f %%), %d steps of %.3g s, %.1f s\n", w.static_displacement_m,
              w.displacement_m, 100 * w.relative_difference, w.steps, w.dt_s, w.wall_time_s);
  EXPECT_TRUE(w.axisymmetric_wall);
  EXPECT_TRUE(w.steady);
  EXPECT_NEAR(w.relative_difference, 0.0, 0.02);
}
