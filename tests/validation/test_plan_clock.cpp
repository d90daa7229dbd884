// The time left of a suite's planned runs under mpirun (validation::PlanClock): each kind of run
// timed by its own computed runs, the work left shared over the ranks but never below the
// longest single run, a running job's elapsed time taken off its estimate.
#include <gtest/gtest.h>

#include "validation/suite.hpp"

using swim::scene::json;
using swim::validation::PlanClock;

namespace {

json plan() {
  json p = json::array();
  for (auto [type, cost] : {std::pair{"3d", 100.0}, {"3d", 200.0}, {"3d", 300.0}, {"axi", 10.0}, {"axi", 20.0}})
    p.push_back({{"job", {{"type", type}}}, {"cost", cost}, {"after", json::array()}, {"label", type}});
  return p;
}

}  // namespace

// Nothing timed yet: no seconds, every job counted as untimed, by kind.
TEST(PlanClock, BeforeAnyRunFinishesTheTimeLeftIsUnknown) {
  const PlanClock c(plan(), 2);
  const PlanClock::Left l = c.left(0.0);
  EXPECT_EQ(l.seconds, 0.0);
  EXPECT_EQ(l.untimed, 5u);
  EXPECT_EQ(l.untimed_kinds, "3d, axi");
  EXPECT_EQ(PlanClock::describe(l), "time left not yet known: 5 run(s) (3d, axi) not yet timed");
}

// A 3D run of cost 100 computed in 50 s times the 3D kind at 0.5 s per unit: the two 3D runs
// left are 100 s and 150 s, 125 s each over two ranks, so the longest (150 s) bounds the time
// left; the axi runs stay untimed. A run read from the cache finishes without timing its kind.
TEST(PlanClock, EachKindIsTimedByItsOwnComputedRuns) {
  PlanClock c(plan(), 2);
  c.started(0, 10.0);
  c.finished(0, 60.0, true);
  PlanClock::Left l = c.left(60.0);
  EXPECT_DOUBLE_EQ(l.seconds, 150.0);
  EXPECT_EQ(l.untimed, 2u);
  EXPECT_EQ(l.untimed_kinds, "axi");
  EXPECT_EQ(PlanClock::describe(l), "about 2.5 min left and 2 run(s) (axi) not yet timed");

  c.started(3, 60.0);
  c.finished(3, 60.5, false);  // from the cache
  l = c.left(60.5);
  EXPECT_EQ(l.untimed, 1u);
  c.started(4, 60.5);
  c.finished(4, 100.5, true);  // 40 s for cost 20
  l = c.left(100.5);
  EXPECT_EQ(l.untimed, 0u);
  EXPECT_DOUBLE_EQ(l.seconds, 150.0);
  EXPECT_EQ(PlanClock::describe(l), "about 2.5 min left");
}

// A running job's elapsed time comes off its estimate, and one past its estimate counts zero;
// with four ranks the work left (100 s + 90 s) is shorter than the longest run (100 s).
TEST(PlanClock, ARunningJobCountsOnlyWhatIsLeftOfIt) {
  PlanClock c(plan(), 4);
  c.started(0, 0.0);
  c.finished(0, 50.0, true);
  c.started(2, 50.0);                        // 150 s estimated
  EXPECT_DOUBLE_EQ(c.left(110.0).seconds, 100.0);  // job 1: 100 s, job 2: 90 s
  c.started(1, 110.0);
  EXPECT_DOUBLE_EQ(c.left(300.0).seconds, 0.0);  // both past their estimates
  EXPECT_EQ(c.left(300.0).untimed, 2u);
  c.finished(1, 310.0, true);  // 200 s for cost 200: the 3D rate becomes 250 s / 300 = 5/6 s per unit
  EXPECT_DOUBLE_EQ(c.left(310.0).seconds, 0.0);  // job 2: 250 s estimated, 260 s gone
}

// Spans read in seconds, minutes (to a tenth below 10 min), then hours.
TEST(PlanClock, TheTimeLeftReadsInSecondsMinutesOrHours) {
  PlanClock::Left l;
  l.seconds = 0.4;
  EXPECT_EQ(PlanClock::describe(l), "less than 1 s left");
  l.seconds = 75;
  EXPECT_EQ(PlanClock::describe(l), "about 75 s left");
  l.seconds = 150;
  EXPECT_EQ(PlanClock::describe(l), "about 2.5 min left");
  l.seconds = 35 * 60;
  EXPECT_EQ(PlanClock::describe(l), "about 35 min left");
  l.seconds = 2.25 * 3600;
  EXPECT_EQ(PlanClock::describe(l), "about 2.2 h left");
}
