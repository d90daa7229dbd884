// Sweep expansion: Cartesian product order, ranges in the unit of `from`, log spacing,
// null values removing keys, and rejection of malformed sweeps.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"
#include "common/sweep.hpp"

namespace fs = std::filesystem;
using swim::scene::json;

namespace {
std::string write_tmp(const json& j, const std::string& name) {
  const fs::path p = fs::temp_directory_path() / name;
  std::ofstream(p) << j.dump();
  return p.string();
}
const std::vector<std::string> kMetrics = {"displacement_m", "mean_velocity_m_per_s"};
}  // namespace

TEST(Sweep, CartesianProductWithLastAxisFastest) {
  json j = {{"base", {{"name", "b"}}},
            {"vary",
             {{"swimmer.length", {{"from", "0.2 um"}, {"to", "400 nm"}, {"count", 3}}},
              {"wave.contracted_ratio", {{"values", {0.35, 0.82}}}}}}};
  const auto sw = swim::sweep::read_sweep(write_tmp(j, "sweep_a.json"), kMetrics);
  ASSERT_EQ(sw.count(), 6u);
  EXPECT_EQ(sw.axes[0].values[1], "0.3 um");  // "to" converted into the unit of "from"
  EXPECT_NEAR(sw.axes[0].si[2], 0.4e-6, 1e-18);
  EXPECT_EQ(sw.axes[0].si_unit, "m");
  const json d = sw.design(3);  // indices (1, 1)
  EXPECT_EQ(d["swimmer"]["length"], "0.3 um");
  EXPECT_EQ(d["wave"]["contracted_ratio"], 0.82);
  EXPECT_EQ(d["name"], "b");
}

TEST(Sweep, LogSpacingIsGeometricAndNullRemovesKeys) {
  json j = {{"base", {{"protocol", {{"total_force", "0.1 pN"}}}}},
            {"vary",
             {{"fluid.viscosity", {{"from", "1e-4 Pa*s"}, {"to", "1e-1 Pa*s"}, {"count", 4}, {"spacing", "log"}}},
              {"protocol.total_force", {{"values", {nullptr}}}}}}};
  const auto sw = swim::sweep::read_sweep(write_tmp(j, "sweep_b.json"), kMetrics);
  for (size_t k = 1; k < 4; ++k) EXPECT_NEAR(sw.axes[0].si[k] / sw.axes[0].si[k - 1], 10.0, 1e-9);
  EXPECT_FALSE(sw.design(0)["protocol"].contains("total_force"));
}

TEST(Sweep, NumericRangesReadAsWrittenAndTheSweepKeepsItsName) {
  // 0.35 + 0.1 * 1 is 0.44999999999999996 in binary; the sweep writes the value a user
  // would type, so that designs.csv, screen.json and the printed best design read 0.45.
  json j = {{"name", "ratios"},
            {"base", json::object()},
            {"vary", {{"wave.contracted_ratio", {{"from", 0.35}, {"to", 0.85}, {"count", 6}}}}}};
  const auto sw = swim::sweep::read_sweep(write_tmp(j, "sweep_c.json"), kMetrics);
  ASSERT_EQ(sw.axes[0].values.size(), 6u);
  const char* expected[] = {"0.35", "0.45", "0.55", "0.65", "0.75", "0.85"};
  for (size_t k = 0; k < 6; ++k) EXPECT_EQ(sw.axes[0].values[k].dump(), expected[k]) << k;
  EXPECT_EQ(sw.name, "ratios");
  j.erase("name");
  EXPECT_EQ(swim::sweep::read_sweep(write_tmp(j, "sweep_d.json"), kMetrics).name, "sweep_d");
}

TEST(Sweep, MalformedSweepsNameTheKey) {
  struct Case {
    json j;
    std::string key;
  };
  const std::vector<Case> cases = {
      {{{"vary", {{"a", {1}}}}}, "base"},
      {{{"base", json::object()}}, "vary"},
      {{{"base", json::object()}, {"vary", {{"a", {{"from", 1}, {"count", 2}}}}}}, "vary.a.to"},
      {{{"base", json::object()}, {"vary", {{"a", {{"from", 1}, {"to", 2}, {"count", 0}}}}}}, "vary.a.count"},
      {{{"base", json::object()}, {"vary", {{"a", {{"from", "1 um"}, {"to", "2 s"}, {"count", 2}}}}}}, "vary.a.to"},
      {{{"base", json::object()}, {"vary", {{"a", {1}}}}, {"metric", "speed"}}, "metric"},
      {{{"base", json::object()}, {"vary", {{"a", {1}}}}, {"goal", "best"}}, "goal"},
      {{{"base", json::object()}, {"vary", {{"a", {1}}}}, {"extra", 1}}, "extra"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    try {
      swim::sweep::read_sweep(write_tmp(cases[i].j, "sweep_bad.json"), kMetrics);
      ADD_FAILURE() << "case " << i << " accepted";
    } catch (const swim::InputError& e) {
      EXPECT_EQ(e.key(), cases[i].key) << e.what();
    }
  }
}
