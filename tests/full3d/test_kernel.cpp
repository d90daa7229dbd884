// Peskin 4-point kernel (paper eq. 18): support and moment conditions.
#include <gtest/gtest.h>

#include <cmath>

#include "full3d/kernel.hpp"

using swim::full3d::peskin_4pt;

namespace {
// Sums over the integer shifts j of g(a - j) for the offsets a in [0, 1).
template <class G>
double shift_sum(double a, G g, int parity = -1) {
  double s = 0.0;
  for (int j = -4; j <= 5; ++j) {
    if (parity >= 0 && ((j % 2 + 2) % 2) != parity) continue;
    s += g(a - j);
  }
  return s;
}
}  // namespace

TEST(PeskinKernel, SupportAndShape) {
  EXPECT_DOUBLE_EQ(peskin_4pt(2.0), 0.0);
  EXPECT_DOUBLE_EQ(peskin_4pt(-2.5), 0.0);
  EXPECT_DOUBLE_EQ(peskin_4pt(7.0), 0.0);
  EXPECT_NEAR(peskin_4pt(0.0), 0.5, 1e-15);
  EXPECT_NEAR(peskin_4pt(1.0), 0.25, 1e-15);  // so that 1/2 + 2 (1/4) = 1 at a = 0
  EXPECT_GT(peskin_4pt(1.999), 0.0);
  for (double r = 0.0; r < 2.0; r += 0.01) {
    EXPECT_DOUBLE_EQ(peskin_4pt(r), peskin_4pt(-r));
    EXPECT_GE(peskin_4pt(r), peskin_4pt(r + 0.01));  // monotone on [0, 2]
  }
  // continuity at |r| = 1 from both branches
  EXPECT_NEAR(peskin_4pt(1.0 - 1e-12), peskin_4pt(1.0 + 1e-12), 1e-10);
}

TEST(PeskinKernel, MomentConditionsForAnyOffset) {
  for (double a = 0.0; a < 1.0; a += 0.0371) {
    EXPECT_NEAR(shift_sum(a, peskin_4pt), 1.0, 1e-14) << "a=" << a;
    EXPECT_NEAR(shift_sum(a, peskin_4pt, 0), 0.5, 1e-14) << "a=" << a;
    EXPECT_NEAR(shift_sum(a, peskin_4pt, 1), 0.5, 1e-14) << "a=" << a;
    EXPECT_NEAR(shift_sum(a, [](double r) { return r * peskin_4pt(r); }), 0.0, 1e-14) << "a=" << a;
    EXPECT_NEAR(shift_sum(a, [](double r) { return peskin_4pt(r) * peskin_4pt(r); }), 3.0 / 8.0, 1e-14)
        << "a=" << a;
  }
}
