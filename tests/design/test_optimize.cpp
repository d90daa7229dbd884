// The optimiser (NLopt COBYLA in scaled coordinates) on smooth analytic objectives with known
// optima: a bounded quadratic, a constrained linear objective, and an optimum on a bound.
#include <gtest/gtest.h>

#include <cmath>

#include "design/optimize.hpp"

using namespace swim::design;

namespace {
SearchOptions box(std::vector<double> lo, std::vector<double> hi, std::vector<double> start, bool maximize = true) {
  SearchOptions o;
  o.lo = std::move(lo);
  o.hi = std::move(hi);
  o.start = std::move(start);
  o.maximize = maximize;
  o.max_evaluations = 400;
  o.xtol_rel = 1e-6;
  return o;
}
void expect_in_box(const SearchResult& r, const SearchOptions& o) {
  for (const auto& e : r.trajectory)
    for (std::size_t i = 0; i < e.x.size(); ++i) {
      EXPECT_GE(e.x[i], o.lo[i]);
      EXPECT_LE(e.x[i], o.hi[i]);
    }
}
}  // namespace

TEST(Optimize, FindsTheMaximumOfABoundedQuadratic) {
  // f = -(x - 3e-7)^2 / 1e-14 - 2 (y - 0.7)^2: maximum at (0.3 um, 0.7), an SI-sized and an O(1) axis
  const SearchOptions o = box({1e-7, 0.2}, {8e-7, 0.9}, {4.5e-7, 0.55});
  const SearchResult r = search(o, [](const std::vector<double>& x) {
    Evaluation e;
    e.objective = -std::pow((x[0] - 3e-7) / 1e-7, 2) - 2 * std::pow(x[1] - 0.7, 2);
    return e;
  });
  ASSERT_GE(r.best, 0);
  EXPECT_NEAR(r.trajectory[r.best].x[0], 3e-7, 1e-10);
  EXPECT_NEAR(r.trajectory[r.best].x[1], 0.7, 1e-3);
  EXPECT_LT(r.trajectory.size(), 400u);  // converged before the budget
  expect_in_box(r, o);
}

TEST(Optimize, HonoursAnInequalityConstraint) {
  // max x + y subject to x^2 + y^2 <= 1 on [0, 2]^2: (1/sqrt 2, 1/sqrt 2)
  SearchOptions o = box({0, 0}, {2, 2}, {0.2, 0.3});
  o.constraints = 1;
  const SearchResult r = search(o, [](const std::vector<double>& x) {
    Evaluation e;
    e.objective = x[0] + x[1];
    e.constraints = {x[0] * x[0] + x[1] * x[1] - 1};
    return e;
  });
  ASSERT_GE(r.best, 0);
  EXPECT_NEAR(r.trajectory[r.best].x[0], std::sqrt(0.5), 2e-3);
  EXPECT_NEAR(r.trajectory[r.best].x[1], std::sqrt(0.5), 2e-3);
  EXPECT_TRUE(r.trajectory[r.best].feasible());
  expect_in_box(r, o);
}

TEST(Optimize, AMinimumOnABoundStaysOnTheBound) {
  // min (x + 1)^2 on [0, 1]: x = 0
  const SearchOptions o = box({0}, {1}, {0.8}, false);
  const SearchResult r = search(o, [](const std::vector<double>& x) {
    Evaluation e;
    e.objective = (x[0] + 1) * (x[0] + 1);
    return e;
  });
  ASSERT_GE(r.best, 0);
  EXPECT_NEAR(r.trajectory[r.best].x[0], 0.0, 1e-6);
  expect_in_box(r, o);
}

TEST(Optimize, FailedEvaluationsAreInfeasibleAndNeverTheBest) {
  // the objective grows with x but evaluations above 0.5 fail: the best is at the edge of failure
  SearchOptions o = box({0}, {1}, {0.3});
  o.max_evaluations = 60;
  const SearchResult r = search(o, [](const std::vector<double>& x) {
    Evaluation e;
    e.ok = x[0] <= 0.5;
    e.objective = e.ok ? x[0] : 0.0;
    return e;
  });
  ASSERT_GE(r.best, 0);
  EXPECT_TRUE(r.trajectory[r.best].ok);
  EXPECT_LE(r.trajectory[r.best].x[0], 0.5);
  EXPECT_GT(r.trajectory[r.best].x[0], 0.4);
}
