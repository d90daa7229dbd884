// Rank agreement against hand-computed values (ties in 3D, ties from error bars, a perfect
// ranking), and the rule that picks the designs to confirm.
#include <gtest/gtest.h>

#include <cmath>

#include "design/rank_agreement.hpp"

using namespace swim::design;

namespace {
// x = 1D, y = 3D: pairs (10): 8 concordant, 1 discordant (designs 1, 2), 1 tied in y (3, 4).
const std::vector<double> kX = {1, 2, 3, 4, 5};
const std::vector<double> kY = {1, 3, 2, 4, 4};
}  // namespace

TEST(RankAgreement, KendallTauBAndSpearmanRhoWithATieMatchTheHandComputedValues) {
  const RankAgreement a = rank_agreement(kX, kY);
  EXPECT_EQ(a.concordant, 8u);
  EXPECT_EQ(a.discordant, 1u);
  EXPECT_EQ(a.tied_y, 1u);
  EXPECT_EQ(a.tied_x, 0u);
  // tau_b = (8 - 1) / sqrt(10 * (10 - 1))
  EXPECT_NEAR(a.kendall_tau, 7.0 / std::sqrt(90.0), 1e-12);
  // y's mid-ranks 1, 3, 2, 4.5, 4.5: rho = 8.5 / sqrt(10 * 9.5)
  EXPECT_NEAR(a.spearman_rho, 8.5 / std::sqrt(95.0), 1e-12);
  ASSERT_EQ(a.misranked.size(), 1u);
  EXPECT_EQ(a.misranked[0], std::make_pair(std::size_t(1), std::size_t(2)));
  // Fisher z: tanh(atanh(tau) -+ 1.96 sqrt(0.437 / (5 - 4))), tanh(atanh(rho) -+ 1.96 sqrt(1.06 / 2))
  EXPECT_NEAR(a.kendall_ci.lo, -0.336267, 1e-5);
  EXPECT_NEAR(a.kendall_ci.hi, 0.977650, 1e-5);
  EXPECT_NEAR(a.spearman_ci.lo, -0.084963, 1e-5);
  EXPECT_NEAR(a.spearman_ci.hi, 0.992156, 1e-5);
}

TEST(RankAgreement, APairWithinItsThreeDErrorBarsIsTiedNotMisranked) {
  // |3 - 2| = 1 <= 0.6 + 0.6: designs 1 and 2 are tied in 3D
  const RankAgreement a = rank_agreement(kX, kY, {0, 0.6, 0.6, 0, 0});
  EXPECT_TRUE(a.misranked.empty());
  EXPECT_EQ(a.tied_by_error_bars, 1u);
  EXPECT_EQ(a.tied_y, 2u);
  EXPECT_NEAR(a.kendall_tau, 8.0 / std::sqrt(80.0), 1e-12);
  // error bars that do not reach leave the pair misranked
  EXPECT_EQ(rank_agreement(kX, kY, {0, 0.4, 0.4, 0, 0}).misranked.size(), 1u);
}

TEST(RankAgreement, EveryPairTiedByItsErrorBarsLeavesKendallTauUndefined) {
  // every 3D difference within the error bars: tau-b is 0/0, not 0
  const RankAgreement a = rank_agreement(kX, kY, {5, 5, 5, 5, 5});
  EXPECT_FALSE(a.kendall_defined);
  EXPECT_EQ(a.tied_y, 10u);
  EXPECT_EQ(a.tied_by_error_bars, 9u);  // the pair equal in y is tied without its error bars
  EXPECT_TRUE(a.misranked.empty());
  EXPECT_DOUBLE_EQ(a.kendall_ci.lo, -1.0);
  EXPECT_DOUBLE_EQ(a.kendall_ci.hi, 1.0);
  EXPECT_TRUE(rank_agreement(kX, kY).kendall_defined);
}

TEST(RankAgreement, MidRanksShareTheMeanRankOfEqualValues) {
  EXPECT_EQ(mid_ranks({3.0, 1.0, 3.0, 2.0}), (std::vector<double>{3.5, 1.0, 3.5, 2.0}));
}

TEST(RankAgreement, APerfectRankingHasAnIntervalUpToOneBelowIt) {
  const std::vector<double> x = {1, 2, 3, 4, 5, 6, 7, 8}, y = {10, 20, 30, 40, 50, 60, 70, 80};
  const RankAgreement a = rank_agreement(x, y);
  EXPECT_DOUBLE_EQ(a.kendall_tau, 1.0);
  EXPECT_NEAR(a.spearman_rho, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(a.kendall_ci.hi, 1.0);
  // the far end: the interval of tau = 1 - 2/28 (one adjacent swap among 8 designs)
  EXPECT_NEAR(a.kendall_ci.lo, fisher_interval(1.0 - 2.0 / 28.0, 8, 0.437, 4).lo, 1e-12);
  EXPECT_LT(a.kendall_ci.lo, 0.9);
  EXPECT_GT(a.kendall_ci.lo, 0.5);
  // reversed: tau = -1, its interval mirrored
  const RankAgreement b = rank_agreement(x, {8, 7, 6, 5, 4, 3, 2, 1});
  EXPECT_DOUBLE_EQ(b.kendall_tau, -1.0);
  EXPECT_DOUBLE_EQ(b.kendall_ci.lo, -1.0);
  EXPECT_NEAR(b.kendall_ci.hi, -a.kendall_ci.lo, 1e-12);
  EXPECT_EQ(b.misranked.size(), 28u);
}

TEST(RankAgreement, TooFewDesignsGiveTheWholeRange) {
  const RankAgreement a = rank_agreement({1, 2, 3}, {1, 3, 2});
  EXPECT_DOUBLE_EQ(a.kendall_ci.lo, -1.0);
  EXPECT_DOUBLE_EQ(a.kendall_ci.hi, 1.0);
  EXPECT_DOUBLE_EQ(a.spearman_ci.lo, -1.0);
}

TEST(ConfirmSelection, HalfTheBestThenHalfSpreadOverTheRestEndingAtTheWorst) {
  const std::vector<std::size_t> ranked = {9, 8, 7, 6, 5, 4, 3, 2, 1, 0};  // design indices, best first
  // K = 4: the 2 best, then 2 of the other 8 at positions 3 and 7 of them
  EXPECT_EQ(select_for_confirmation(ranked, 4), (std::vector<std::size_t>{9, 8, 4, 0}));
  // K = 5: the 3 best, then 2 of the other 7 at positions 2 and 6
  EXPECT_EQ(select_for_confirmation(ranked, 5), (std::vector<std::size_t>{9, 8, 7, 4, 0}));
  // K = 10: everything, in ranking order; K larger than the ranking is clamped
  EXPECT_EQ(select_for_confirmation(ranked, 10), ranked);
  EXPECT_EQ(select_for_confirmation(ranked, 12), ranked);
  EXPECT_EQ(select_for_confirmation(ranked, 1), (std::vector<std::size_t>{9}));
}
