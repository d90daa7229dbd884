// The outer hydraulic offset from a drag coefficient: inversion of the 1D confined drag of the
// straight tube (validation/hydraulic.hpp, outer_offset_from_drag).
#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.hpp"
#include "validation/hydraulic.hpp"

using namespace swim;
using namespace swim::validation;

namespace {
// The paper's tube and container (R0 = 0.125 um, L = 0.4 um, Rc = 2 R0, period 2 um, water).
ConfinedTow paper_tow() { return {0.125e-6, 0.4e-6, 0.25e-6, 2e-6, 1.2e-3}; }
constexpr double kH = 0.5e-6 / 32;  // the default grid's cell
}  // namespace

// The 1D drag grows with a_out over the whole physical range, so the root is unique.
TEST(OuterOffsetFromDrag, OneDimensionalDragGrowsWithTheOuterOffset) {
  for (const ConfinedTow& g : {paper_tow(), ConfinedTow{0.125e-6, 0.4e-6, 0.19e-6, 1e-6, 1e-3}}) {
    double prev = confined_drag(g, kH, 0.0);
    const double top = 0.999 * g.container_radius_m - g.radius_m;
    for (int i = 1; i < 200; ++i) {
      const double z = confined_drag(g, kH, top * i / 200.0);
      EXPECT_GT(z, prev) << i;
      prev = z;
    }
  }
}

// Round trip: fed the drag the 1D model gives at (a_in, a_out), the inversion returns a_out,
// exact to Brent's tolerance (1e-14 relative) up to the conditioning of the drag.
TEST(OuterOffsetFromDrag, RoundTripReturnsTheOffsetItWasGiven) {
  for (const ConfinedTow& g : {paper_tow(), ConfinedTow{0.125e-6, 0.4e-6, 0.19e-6, 1e-6, 1e-3},
                               ConfinedTow{0.1e-6, 1.2e-6, 0.4e-6, 4e-6, 1e-3}})
    for (double a_in : {0.0, 0.5 * kH, 1.15 * kH, 2.0 * kH})
      for (double a_out : {0.0, 0.1 * kH, 1.0 * kH, 2.5 * kH, 0.5 * (g.container_radius_m - g.radius_m)}) {
        const double zeta = confined_drag(g, a_in, a_out);
        ASSERT_GT(zeta, 0.0);
        EXPECT_NEAR(outer_offset_from_drag(g, zeta, a_in), a_out, 1e-12 * g.radius_m)
            << "a_in " << a_in << " a_out " << a_out << " Rc " << g.container_radius_m;
      }
}

// No root in the physical range: a drag below the bare tube's (a_out = 0) or above a tube
// touching the container is an error that says so; a_in outside [0, R0) is an input error.
TEST(OuterOffsetFromDrag, NoRootOutsideThePhysicalRange) {
  const ConfinedTow g = paper_tow();
  const double z0 = confined_drag(g, kH, 0.0);
  EXPECT_THROW(outer_offset_from_drag(g, 0.99 * z0, kH), NumericalError);
  EXPECT_THROW(outer_offset_from_drag(g, 1e6 * z0, kH), NumericalError);
  EXPECT_THROW(outer_offset_from_drag(g, -z0, kH), NumericalError);
  EXPECT_THROW(outer_offset_from_drag(g, z0, g.radius_m), InputError);
  EXPECT_THROW(outer_offset_from_drag(g, z0, -kH), InputError);
  try {
    outer_offset_from_drag(g, 0.99 * z0, kH);
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("below the 1D confined drag"), std::string::npos) << e.what();
  }
  // the reporting variant does not throw: no value, and the reason
  const OuterOffsetFromDrag r = outer_offset_from_drag(g, 0.99 * z0, 0.0, kH, 0.1 * kH);
  EXPECT_FALSE(r.found);
  EXPECT_NE(r.note.find("below the 1D confined drag"), std::string::npos) << r.note;
  EXPECT_EQ(r.a_out_m, 0.0);
  EXPECT_EQ(r.uncertainty_m, 0.0);
}

// The propagated uncertainty is the first-order change of the root: it matches the spread of
// the roots at a_in +- sigma and at zeta +- sigma within 1 %, and combines in quadrature.
TEST(OuterOffsetFromDrag, UncertaintyIsTheLinearisedSpreadOfTheRoot) {
  const ConfinedTow g = paper_tow();
  const double a_in = 1.15 * kH, a_out = 1.0 * kH;
  const double zeta = confined_drag(g, a_in, a_out);
  const double s_in = 0.04 * kH, s_z = 1e-3 * zeta;
  const OuterOffsetFromDrag r = outer_offset_from_drag(g, zeta, s_z, a_in, s_in);
  ASSERT_TRUE(r.found) << r.note;
  EXPECT_NEAR(r.a_out_m, a_out, 1e-12 * g.radius_m);
  const double by_in = 0.5 * std::abs(outer_offset_from_drag(g, zeta, a_in + s_in) - outer_offset_from_drag(g, zeta, a_in - s_in));
  const double by_z = 0.5 * std::abs(outer_offset_from_drag(g, zeta + s_z, a_in) - outer_offset_from_drag(g, zeta - s_z, a_in));
  EXPECT_NEAR(r.from_a_in_m, by_in, 0.01 * by_in);
  EXPECT_NEAR(r.from_drag_m, by_z, 0.01 * by_z);
  EXPECT_NEAR(r.uncertainty_m, std::hypot(by_in, by_z), 0.01 * std::hypot(by_in, by_z));
  // a narrower lumen raises the 1D drag, so a given drag needs a thinner tube
  EXPECT_LT(outer_offset_from_drag(g, zeta, a_in + s_in), a_out);
}
