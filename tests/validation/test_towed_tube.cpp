// The tube towed through its container (validation/hydraulic.hpp, measure_towed_tube): the
// second, drag-based measure of the outer hydraulic offset, on coarse grids of the paper's scene.
#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.hpp"
#include "validation/hydraulic.hpp"
#include "paper_scene.hpp"

using namespace swim;
using namespace swim::validation;

// Steady Stokes flow is linear in the towing speed: the drag force scales with U and changes
// sign with it, to the conjugate gradients' tolerance (2.5 is not a power of two, so the
// floating-point path differs).
TEST(TowedTube, DragIsLinearAndOddInTheSpeed) {
  const full3d::Params3d p = test::paper_scene(16);
  const double U = 1e-6;
  const TowedTube t1 = measure_towed_tube(p, U);
  const TowedTube t2 = measure_towed_tube(p, 2.5 * U);
  const TowedTube tm = measure_towed_tube(p, -U);
  ASSERT_GT(t1.force_N, 0.0);
  EXPECT_NEAR(t2.force_N, 2.5 * t1.force_N, 1e-6 * t1.force_N);
  EXPECT_NEAR(tm.force_N, -t1.force_N, 1e-6 * t1.force_N);
  EXPECT_NEAR(t2.drag_coefficient_N_s_per_m, t1.drag_coefficient_N_s_per_m, 1e-6 * t1.drag_coefficient_N_s_per_m);
  EXPECT_NEAR(tm.drag_coefficient_N_s_per_m, t1.drag_coefficient_N_s_per_m, 1e-6 * t1.drag_coefficient_N_s_per_m);
  EXPECT_NEAR(t2.net_flux_m3_per_s, 2.5 * t1.net_flux_m3_per_s, 1e-6 * std::abs(t1.net_flux_m3_per_s));
  EXPECT_NEAR(tm.net_flux_m3_per_s, -t1.net_flux_m3_per_s, 1e-6 * std::abs(t1.net_flux_m3_per_s));
  // the wall is held at U: the CG converged on the ring modes, the nodes slip by < 1 %
  EXPECT_LT(t1.cg_relative_residual, 1e-5);
  EXPECT_LT(t1.max_slip_m_per_s, 1e-2 * U);
  EXPECT_LT(t1.drag_coefficient_uncertainty_N_s_per_m, 1e-5 * t1.drag_coefficient_N_s_per_m);
  EXPECT_THROW(measure_towed_tube(p, 0.0), InputError);
}

// Against the 1D confined model of the straight tube (reduced1d confined_drag_coefficient): the
// smeared 3D wall drags more than the bare tube (no offsets) and less than a tube fattened and
// narrowed by the kernel's whole half-width, 2h on each side; the inverted a_out is of order h,
// and the 1D model's net flux at the inverted offsets is the 3D one within 25 % (lubrication
// without end corrections, L = 3.2 (Rc - R0)).
TEST(TowedTube, DragLiesBetweenTheBareTubeAndTheFullySmearedOne) {
  for (int cells : {16, 20}) {
    const full3d::Params3d p = test::paper_scene(cells);
    const TowedTube t = measure_towed_tube(p, 1e-6);
    const ConfinedTow& g = t.geometry;
    EXPECT_DOUBLE_EQ(g.container_radius_m, p.container_radius);
    EXPECT_DOUBLE_EQ(g.period_m, p.period);
    const double z = t.drag_coefficient_N_s_per_m;
    EXPECT_GT(z, confined_drag(g, 0.0, 0.0)) << cells;
    EXPECT_LT(z, confined_drag(g, 2.0 * p.h, 2.0 * p.h)) << cells;
    const OuterOffsetFromDrag a = outer_offset_from_drag(g, z, t.drag_coefficient_uncertainty_N_s_per_m, p.h, 0.1 * p.h);
    ASSERT_TRUE(a.found) << a.note;
    EXPECT_GT(a.a_out_m, 0.3 * p.h) << cells;
    EXPECT_LT(a.a_out_m, 1.5 * p.h) << cells;
    const double w1d = confined_tow_flux_per_speed(g, p.h, a.a_out_m) * t.speed_m_per_s;
    EXPECT_GT(t.net_flux_m3_per_s, 0.0);
    EXPECT_NEAR(t.net_flux_m3_per_s / w1d, 1.0, 0.25) << cells << ": 3D " << t.net_flux_m3_per_s << ", 1D " << w1d;
    RecordProperty("net_flux_ratio_3d_over_1d_" + std::to_string(cells), std::to_string(t.net_flux_m3_per_s / w1d));
  }
}

// Lorentz reciprocity between the two rigid-tube problems on one grid: the held tube in the
// flow driven by the body force g, and the towed tube without it. With f_1 = g e_x + spread F_1
// (wall at rest) and f_2 = spread F_2 (wall at U), int f_1 . u_2 = int f_2 . u_1 gives
// g P Q_2 + U sum F_1,x = 0: the towed tube's net flux per speed equals -sum F_1,x / (g P).
// With both solves on the ring forces it is an identity of the discrete operators (J =
// spread^T, S symmetric, each constraint met on the other's force space) up to the CG
// tolerance; with the held tube's forces free node by node, its holding force has not
// converged and misses by about 10 %.
TEST(TowedTube, NetFluxIsReciprocalToTheHeldTubesForce) {
  const full3d::Params3d p = test::paper_scene(20);
  const TowedTube tow = measure_towed_tube(p, 1e-6);
  const double q_towed = tow.net_flux_m3_per_s / tow.speed_m_per_s;
  const HydraulicRadii held = measure_hydraulic_radii(p, true);
  ASSERT_LT(held.holding_force_N, 0.0);  // the wall holds the fluid back
  const double q_reciprocal = -held.holding_force_N / (held.body_force_N_per_m3 * p.period);
  EXPECT_NEAR(q_towed / q_reciprocal, 1.0, 1e-4) << "towed " << q_towed << " m^2, reciprocal " << q_reciprocal << " m^2";
  const HydraulicRadii held_nodes = measure_hydraulic_radii(p, false);
  const double q_nodes = -held_nodes.holding_force_N / (held_nodes.body_force_N_per_m3 * p.period);
  EXPECT_GT(std::abs(q_towed / q_nodes - 1.0), 0.03);  // the node-by-node holding force is not converged
}
