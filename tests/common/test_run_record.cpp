// The run record of both tiers and its one writer (common/run_record.hpp): running figures
// without kept rows, events, the streamed files and their resume, reading a folder back; the
// JSON writer's refusal of non-finite numbers; progress lines in a log file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "common/checksum.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/progress.hpp"
#include "common/run_record.hpp"

namespace fs = std::filesystem;
using namespace swim;
using namespace swim::record;

namespace {

// Scratch folders, removed when the test process ends.
struct Scratch {
  std::vector<fs::path> dirs;
  ~Scratch() {
    std::error_code ec;
    for (const auto& d : dirs) fs::remove_all(d, ec);
  }
};
Scratch scratch;

std::string fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("swim_record_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  scratch.dirs.push_back(d);
  return d.string();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> columns() {
  std::vector<std::string> c = common_series_columns();
  c.push_back("extra_J");
  return c;
}

/// A row at time t of a swimmer moving at v: x = v t, radius dipping at t = 0.3 s.
std::vector<double> row_at(double t, double v = 2e-9) {
  std::vector<double> r(columns().size(), 0.0);
  r[0] = t;
  r[1] = v * t;
  r[2] = v;
  r[3] = 1e-18 * (1 + t);
  r[4] = 1e-7 - 1e-8 * std::exp(-100 * (t - 0.3) * (t - 0.3));
  r[5] = 1.25e-7;
  r[8] = -1e-21 * t;  // volume_rear_m3
  r[11] = t < 0.5 ? 0 : 1;
  r[12] = std::sin(7 * t);
  return r;
}

RunRecord filled(bool keep, int rows = 101) {
  RunRecord r("1d", "test_model", 4e-7, columns(), {1e-7, 2e-7, 3e-7});
  r.keep(keep);
  for (int k = 0; k < rows; ++k) {
    const double t = 0.01 * k;
    if (k == 0) r.cycle_started(0.0);
    if (std::abs(t - 0.55) < 1e-12) {
      r.cycle_ended(0.545);  // between two rows: interpolated
      r.cycle_started(0.545);
    }
    r.add_row(row_at(t));
    const double R[3] = {1e-7, 1.1e-7 + t * 1e-9, 1.2e-7};
    r.add_radius(t, R);
  }
  return r;
}

}  // namespace

TEST(RunRecord, RunningFiguresDoNotNeedTheRows) {
  const RunRecord kept = filled(true), lean = filled(false);
  EXPECT_EQ(kept.series.rows(), 101u);
  EXPECT_EQ(lean.series.rows(), 0u);  // bounded memory: nothing kept
  EXPECT_EQ(lean.series.count(), 101u);
  EXPECT_EQ(lean.radius.count(), 101u);
  EXPECT_TRUE(lean.radius.values().empty());
  for (const auto& c : columns()) {
    const std::vector<double> v = kept.series.column(c);
    EXPECT_EQ(lean.series.min(c), *std::min_element(v.begin(), v.end())) << c;
    EXPECT_EQ(lean.series.max(c), *std::max_element(v.begin(), v.end())) << c;
  }
  EXPECT_EQ(std::vector<double>(lean.series.last().begin(), lean.series.last().end()), row_at(1.0));
  // the summaries of both are the same: the summary never reads the kept rows
  const json a = summary(kept, json::object()), b = summary(lean, json::object());
  EXPECT_EQ(a.dump(), b.dump());
}

TEST(RunRecord, EventsTakeTheDisplacementInterpolatedBetweenTheRowsAroundThem) {
  const RunRecord r = filled(false);
  ASSERT_EQ(r.events.x_at_cycle_start_m.size(), 2u);
  ASSERT_EQ(r.events.x_at_cycle_end_m.size(), 1u);
  // x = v t is linear, so the interpolation between rows is exact
  EXPECT_DOUBLE_EQ(r.events.x_at_cycle_start_m[0], 0.0);
  EXPECT_NEAR(r.events.x_at_cycle_end_m[0], 2e-9 * 0.545, 1e-24);
  EXPECT_NEAR(r.events.x_at_cycle_start_m[1], 2e-9 * 0.545, 1e-24);
  const CycleFigures c = cycle_figures(r);
  ASSERT_TRUE(c.has_cycle);
  EXPECT_EQ(c.cycles_completed, 1);
  EXPECT_NEAR(c.cycle_time_s, 0.545, 1e-15);
  EXPECT_NEAR(c.displacement_per_cycle_m, 2e-9 * 0.545, 1e-24);
  EXPECT_NEAR(c.mean_velocity_per_cycle_m_per_s, 2e-9, 1e-22);
  const json s = summary(r, json::object());
  EXPECT_NEAR(s["displacement_per_cycle_m"].get<double>(), 1.09e-9, 1e-24);
  EXPECT_NEAR(s["body_lengths_per_cycle_per_s"].get<double>(), 2e-9 / 4e-7, 1e-18);
  EXPECT_NEAR(s["pumped_volume_m3"].get<double>(), 1e-21, 1e-36);
  EXPECT_NEAR(s["min_radius_m"].get<double>(), 9e-8, 1e-22);
}

// The cycle's protocol phases: start -> first segment at R_f -> ... -> last -> end, averaged
// over the cycles; they sum to the cycle time. Cycles with different phase counts give none.
TEST(RunRecord, CyclePhasesRunBetweenTheSegmentEventsAndSumToTheCycleTime) {
  RunRecord r("axi", "m", 1e-7, columns(), {0.0});
  r.cycle_started(0.0);
  r.add_row(row_at(0.0));
  r.events.segment_reached_s = {0.1, 0.25, 0.6, 0.72};  // two per cycle, the second cycle's later
  r.cycle_ended(0.5);
  r.cycle_started(0.5);
  r.add_row(row_at(0.5));
  r.cycle_ended(1.1);
  r.add_row(row_at(1.1));
  const CycleFigures c = cycle_figures(r);
  ASSERT_EQ(c.phase_times_s.size(), 3u);
  EXPECT_NEAR(c.phase_times_s[0], (0.1 + 0.1) / 2, 1e-15);
  EXPECT_NEAR(c.phase_times_s[1], (0.15 + 0.12) / 2, 1e-15);
  EXPECT_NEAR(c.phase_times_s[2], (0.25 + 0.38) / 2, 1e-15);
  EXPECT_NEAR(c.phase_times_s[0] + c.phase_times_s[1] + c.phase_times_s[2], c.cycle_time_s, 1e-15);
  r.events.segment_reached_s = {0.1, 0.25, 0.6};  // the second cycle has one event only
  EXPECT_TRUE(cycle_figures(r).phase_times_s.empty());
}

// The centre's displacement over each phase: linear in time between the rows around each
// boundary (not the nearest row's), averaged over the cycles, summing to the displacement per
// cycle; a phase may go backwards. A record that keeps no rows has the phases' times only.
TEST(RunRecord, CyclePhaseDisplacementsInterpolateTheCentreAndSumToTheDisplacementPerCycle) {
  auto build = [](bool keep) {
    RunRecord r("axi", "m", 1e-7, columns(), {0.0});
    r.keep(keep);
    const double ts[] = {0.0, 0.2, 0.4, 0.5, 0.8, 1.1};
    const double xs[] = {0.0, 4e-9, 6e-9, 7e-9, 13e-9, 10e-9};
    r.cycle_started(0.0);
    for (int k = 0; k < 6; ++k) {
      std::vector<double> row = row_at(ts[k]);
      row[1] = xs[k];
      r.add_row(row);
      if (k == 3) {
        r.cycle_ended(0.5);
        r.cycle_started(0.5);
      }
    }
    r.cycle_ended(1.1);
    r.events.segment_reached_s = {0.1, 0.25, 0.6, 0.72};
    return r;
  };
  const CycleFigures c = cycle_figures(build(true));
  ASSERT_EQ(c.phase_displacements_m.size(), 3u);
  // cycle 1: x(0.1) = 2, x(0.25) = 4.5, x(0.5) = 7 nm; cycle 2: x(0.6) = 9, x(0.72) = 11.4,
  // x(1.1) = 10 nm
  EXPECT_NEAR(c.phase_displacements_m[0], (2.0 + 2.0) / 2 * 1e-9, 1e-20);
  EXPECT_NEAR(c.phase_displacements_m[1], (2.5 + 2.4) / 2 * 1e-9, 1e-20);
  EXPECT_NEAR(c.phase_displacements_m[2], (2.5 - 1.4) / 2 * 1e-9, 1e-20);
  EXPECT_NEAR(c.phase_displacements_m[0] + c.phase_displacements_m[1] + c.phase_displacements_m[2],
              c.displacement_per_cycle_m, 1e-20);
  const CycleFigures bare = cycle_figures(build(false));
  EXPECT_EQ(bare.phase_times_s.size(), 3u);
  EXPECT_TRUE(bare.phase_displacements_m.empty());
}

TEST(RunRecord, NoCompletedCycleGivesNullPerCycleFiguresWithTheReason) {
  RunRecord r("3d", "m", 1e-7, columns(), {0.0});
  r.cycle_started(0.0);
  r.add_row(row_at(0.0));
  r.add_row(row_at(0.1));
  const json s = summary(r, json::object());
  EXPECT_TRUE(s["displacement_per_cycle_m"].is_null());
  EXPECT_EQ(s["per_cycle_absent_because"], "no cycle completed within the run's duration");
  r.status = "failed: test";
  EXPECT_EQ(summary(r, json::object())["per_cycle_absent_because"], "the run stopped before completing a cycle");
  r.transit_is_cycle = true;  // a prescribed wave's transit
  r.status = "ok";
  EXPECT_NEAR(summary(r, json::object())["displacement_per_cycle_m"].get<double>(), 2e-10, 1e-25);
}

TEST(RunRecord, ANonFiniteValueIsRefusedNamingTheColumnAndNothingIsAppended) {
  RunRecord r("1d", "m", 1e-7, columns(), {0.0});
  r.add_row(row_at(0.0));
  std::vector<double> bad = row_at(0.1);
  bad[4] = std::nan("");
  try {
    r.add_row(bad);
    FAIL() << "accepted a NaN";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("min_radius_m"), std::string::npos) << e.what();
  }
  EXPECT_EQ(r.series.count(), 1u);
  EXPECT_THROW(Series({"t_s", "x_m"}), std::logic_error);  // the common columns come first
}

TEST(RunRecord, AStreamedFolderReadsBackToTheSameRecord) {
  const std::string d = fresh_dir("roundtrip");
  RunRecord r = filled(false);
  {
    RunStream stream(d, r.series.columns());
    RunRecord live("1d", "test_model", 4e-7, columns(), {1e-7, 2e-7, 3e-7});
    live.keep(false);
    live.attach(&stream);
    RunRecord src = filled(true);
    // replay the kept rows through the streaming record, with the same events
    replay(
        live, src.series.rows(), [&](std::size_t k) { return src.series.row(k)[0]; },
        [&](std::size_t k) {
          live.add_row(src.series.row(k));
          live.add_radius(src.radius.times()[k], {src.radius.values().data() + 3 * k, 3});
        },
        src.events.cycle_start_s, src.events.cycle_end_s);
    EXPECT_TRUE(fs::exists(d + "/series.csv.part"));
    EXPECT_FALSE(fs::exists(d + "/series.csv"));
    const json written = write_run(d, live, json{{"name", "x"}});
    EXPECT_EQ(written["series_rows"], 101);
    r = std::move(live);
  }
  EXPECT_FALSE(fs::exists(d + "/series.csv.part"));
  EXPECT_FALSE(fs::exists(d + "/radius.csv.part"));
  const RunRecord back = read_run(d);
  EXPECT_EQ(back.tier, "1d");
  EXPECT_EQ(back.model, "test_model");
  EXPECT_EQ(back.series.rows(), 101u);
  EXPECT_EQ(back.series.columns(), columns());
  const CycleFigures a = cycle_figures(r), b = cycle_figures(back);
  EXPECT_EQ(a.cycles_completed, b.cycles_completed);
  EXPECT_NEAR(a.displacement_per_cycle_m, b.displacement_per_cycle_m, 1e-9 * std::abs(a.displacement_per_cycle_m));
  // radius.csv: 3 lines per snapshot plus the header
  std::ifstream rad(d + "/radius.csv");
  int lines = 0;
  for (std::string l; std::getline(rad, l);) ++lines;
  EXPECT_EQ(lines, 1 + 101 * 3);
  // summary.json lists the two published files with their sizes and checksums
  const json s = json::parse(slurp(d + "/summary.json"));
  int listed = 0;
  for (const auto& f : s["files"]) {
    const std::string name = f["name"];
    if (name == "series.csv" || name == "radius.csv") {
      ++listed;
      EXPECT_EQ(f["bytes"].get<std::uintmax_t>(), fs::file_size(d + "/" + name));
      EXPECT_EQ(f["fnv1a64"], hex64(fnv1a64(slurp(d + "/" + name))));
    }
    EXPECT_EQ(name.find(".part"), std::string::npos) << name;
  }
  EXPECT_EQ(listed, 2);
}

TEST(RunRecord, AResumedStreamCutsWhatFollowedTheMarkAndRefusesAChangedFile) {
  const std::string d = fresh_dir("resume");
  std::vector<double> marks;
  std::string at_mark;
  {
    RunStream s(d, columns());
    for (int k = 0; k < 10; ++k) s.row(row_at(0.01 * k));
    marks = s.mark();
    at_mark = slurp(d + "/series.csv.part");
    for (int k = 10; k < 15; ++k) s.row(row_at(0.01 * k));  // written after the checkpoint, then "killed"
    s.mark();
  }
  ASSERT_GT(slurp(d + "/series.csv.part").size(), at_mark.size());
  EXPECT_TRUE(RunStream::matches(d, marks));
  {
    RunStream s(d, marks);
    EXPECT_EQ(slurp(d + "/series.csv.part"), at_mark);  // cut back to the mark
    for (int k = 10; k < 12; ++k) s.row(row_at(0.01 * k));
    s.commit();
  }
  // the same bytes as a stream that was never interrupted
  const std::string e = fresh_dir("resume_ref");
  {
    RunStream s(e, columns());
    for (int k = 0; k < 12; ++k) s.row(row_at(0.01 * k));
    s.commit();
  }
  EXPECT_EQ(slurp(d + "/series.csv"), slurp(e + "/series.csv"));

  // a changed byte before the mark, or a part file shorter than the mark: refused
  const std::string f = fresh_dir("resume_bad");
  std::vector<double> m2;
  {
    RunStream s(f, columns());
    for (int k = 0; k < 5; ++k) s.row(row_at(0.01 * k));
    m2 = s.mark();
  }
  std::string text = slurp(f + "/series.csv.part");
  text[text.size() / 2] ^= 1;
  std::ofstream(f + "/series.csv.part", std::ios::binary) << text;
  EXPECT_FALSE(RunStream::matches(f, m2));
  EXPECT_THROW(RunStream(f, m2), InputError);
  text[text.size() / 2] ^= 1;
  std::ofstream(f + "/series.csv.part", std::ios::binary) << text.substr(0, text.size() - 3);
  EXPECT_FALSE(RunStream::matches(f, m2));
  fs::remove(f + "/series.csv.part");
  EXPECT_THROW(RunStream(f, m2), InputError);
}

// output.max_bytes counts both streamed files and the other files of the run (a 3D run's VTK
// frames) in one total: the row or file that passes it throws once, naming the limit and the
// interval key of the largest part; counts added before the limit is set (a resume restoring
// them) are not checked but count from then on.
TEST(RunRecord, TheOutputLimitCountsTheStreamedFilesAndTheFramesInOneTotal) {
  const std::string d = fresh_dir("limit");
  RunStream s(d, columns());
  const std::uintmax_t header = s.bytes();
  EXPECT_GT(header, 0u);
  s.row(row_at(0.0));
  const std::uintmax_t per_row = s.bytes() - header;
  s.add_external(1000, 0.0, "full3d.output.vtk_interval", "membrane frames");
  s.add_external(500, 0.0, "full3d.output.fluid_interval", "fluid frames");
  s.add_external(200, 0.0, "full3d.output.vtk_interval", "membrane frames");
  EXPECT_EQ(s.external("full3d.output.vtk_interval"), 1200u);
  EXPECT_EQ(s.external("full3d.output.fluid_interval"), 500u);
  EXPECT_EQ(s.external("time.output_interval"), 0u);
  EXPECT_EQ(s.bytes(), header + per_row + 1700u);

  // the limit passed by a frame: the frames dominate
  const std::uintmax_t limit = s.bytes() + 1000;
  s.limit(limit);
  s.row(row_at(0.01));  // below the limit yet
  const std::uintmax_t room = limit - s.bytes();
  EXPECT_NO_THROW(s.add_external(room, 0.01, "full3d.output.vtk_interval", "membrane frames"));  // at it
  try {
    s.add_external(1, 0.02, "full3d.output.vtk_interval", "membrane frames");
    FAIL() << "the frame that passes the limit does not end the run";
  } catch (const NumericalError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("output.max_bytes = " + std::to_string(limit) + " bytes"), std::string::npos) << m;
    EXPECT_NE(m.find("membrane frames " + std::to_string(1201 + room) + " bytes"), std::string::npos) << m;
    EXPECT_NE(m.find("fluid frames 500 bytes"), std::string::npos) << m;
    EXPECT_EQ(e.remedy(), "raise full3d.output.vtk_interval or output.max_bytes");
    EXPECT_DOUBLE_EQ(e.time(), 0.02);
  }
  // raised once: the rows that close the run are still written
  EXPECT_NO_THROW(s.row(row_at(0.03)));
  EXPECT_NO_THROW(s.add_external(10, 0.03, "full3d.output.vtk_interval", "membrane frames"));

  // the rows dominate
  const std::string e = fresh_dir("limit_rows");
  RunStream r(e, columns());
  r.add_external(100, 0.0, "full3d.output.vtk_interval", "membrane frames");
  r.row(row_at(0.0));
  r.row(row_at(0.01));
  r.limit(r.bytes() + 1);
  try {
    r.row(row_at(0.02));
    FAIL() << "the row that passes the limit does not end the run";
  } catch (const NumericalError& x) {
    EXPECT_EQ(x.remedy(), "raise time.output_interval or output.max_bytes");
  }
  // a limit below what is written already: raised at the next write
  RunStream q(fresh_dir("limit_restore"), columns());
  q.limit(100);
  EXPECT_THROW(q.row(row_at(0.0)), NumericalError);
  // counts added before the limit is set (a resume restoring them) are checked from then on
  RunStream u(fresh_dir("limit_unset"), columns());
  EXPECT_NO_THROW(u.add_external(1u << 20, 0.0, "full3d.output.vtk_interval", "membrane frames"));
  u.limit(1000);
  EXPECT_THROW(u.row(row_at(0.0)), NumericalError);
}

TEST(RunRecord, AFullDiskEndsTheStreamAtOnceNamingTheFile) {
  const std::string d = fresh_dir("full");
  ::setenv("SWIM_TEST_FAIL_WRITE", "series.csv:70000", 1);
  RunStream s(d, columns());
  RunRecord r("1d", "m", 1e-7, columns(), {0.0});
  r.keep(false);
  r.attach(&s);
  int written = 0;
  try {
    for (; written < 100000; ++written) {
      r.add_row(row_at(1e-3 * written));
    }
    FAIL() << "no error on a full disk";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("disk full while writing series.csv"), std::string::npos) << e.what();
  }
  ::unsetenv("SWIM_TEST_FAIL_WRITE");
  // the failure surfaces within a buffer (64 KiB) of the limit, not at the end of the run
  EXPECT_LT(written, 2000);
  r.attach(nullptr);
}

TEST(RunRecord, AJsonFileWithANonFiniteNumberIsRefusedNamingWhereItIs) {
  const std::string d = fresh_dir("nonfinite_json");
  json v = {{"cases", json::array({{{"name", "a"}, {"x_m", 1.0}}, {{"name", "b"}, {"models", {{{"x_m", 2.0}}, {{"x_m", std::nan("")}}}}}})}};
  EXPECT_EQ(swim::output::first_non_finite(v), "cases[1].models[1].x_m");
  EXPECT_TRUE(swim::output::first_non_finite(json{{"x", 1.0}, {"y", json::array({1, 2})}}).empty());
  try {
    swim::output::write_json(d + "/report.json", v);
    FAIL() << "wrote a NaN";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("cases[1].models[1].x_m"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(d + "/report.json"));
}

/// What `body` writes to stderr, captured through a log file in `dir` (not a terminal).
static std::string stderr_of(const std::string& dir, const std::function<void()>& body) {
  const std::string path = dir + "/stderr.log";
  std::fflush(stderr);
  const int saved = dup(STDERR_FILENO);
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot open " + path);
  dup2(fileno(f), STDERR_FILENO);
  body();
  std::fflush(stderr);
  dup2(saved, STDERR_FILENO);
  close(saved);
  std::fclose(f);
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Progress forced on with stderr not a terminal (a log file): whole lines, no carriage
// returns, and nothing between two updates closer than 10 s.
TEST(Progress, ToALogFileItWritesWholeLinesOnly) {
  const std::string text = stderr_of(fresh_dir("progress"), [] {
    swim::Progress p("3d test", 1.0, 1);
    for (int k = 1; k <= 100; ++k) p.update(0.01 * k);  // all within 10 s of the start
  });
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;
  EXPECT_EQ(text.rfind("3d test: done in ", 0), 0u) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
}

// A Progress::Context (a run on an MPI rank) puts its prefix before every label its thread makes
// while it lives, nested contexts restore the outer one, and none is left after them.
TEST(Progress, AContextNamesTheRunsOfItsThread) {
  const std::string text = stderr_of(fresh_dir("progress_context"), [] {
    {
      const swim::Progress::Context outer("run 2/9 on rank 1: ", true);
      { swim::Progress p("axi a", 1.0, 1); }
      {
        const swim::Progress::Context inner("run 3/9 on rank 1: ", true);
        swim::Progress p("axi b", 1.0, 1);
      }
      { swim::Progress p("axi c", 1.0, 1); }
    }
    swim::Progress p("axi d", 1.0, 1);
  });
  EXPECT_NE(text.find("\nrun 3/9 on rank 1: axi b: done in "), std::string::npos) << text;
  EXPECT_NE(text.find("\nrun 2/9 on rank 1: axi c: done in "), std::string::npos) << text;
  EXPECT_EQ(text.rfind("run 2/9 on rank 1: axi a: done in ", 0), 0u) << text;
  EXPECT_NE(text.find("\naxi d: done in "), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4) << text;
}

// The Reynolds-number bound of check_plausible: Re = rho max|U| L / mu with the swimmer's fastest
// speed (either direction) and its length. The record's swimmer (L = 0.4 um, |U| up to 2 nm/s
// in water, Re = 8e-10) is plausible; at a viscosity 1e9 times smaller (Re = 0.8, a mistyped
// unit) it is not, the reason naming Re, the bound and the key to check; just below the bound
// it still is, and without the fluid no Reynolds check is made.
TEST(RunRecord, ARunAboveTheCreepingFlowsReynoldsNumberIsImplausible) {
  RunRecord r = filled(false);
  check_plausible(r, {1000.0, 1e-3});
  EXPECT_TRUE(r.implausible.empty());
  check_plausible(r, {1000.0, 1e-12});
  ASSERT_EQ(r.implausible.size(), 1u);
  EXPECT_NE(r.implausible[0].find("Reynolds number rho max|U| L / mu = 0.8 above 0.1"), std::string::npos)
      << r.implausible[0];
  RunRecord fast("1d", "test_model", 4e-7, columns(), {1e-7});
  fast.cycle_started(0.0);
  for (int k = 0; k < 11; ++k) fast.add_row(row_at(0.01 * k, k == 5 ? -2.5e-3 : 1e-3));  // one row backwards, faster
  check_plausible(fast, {1000.0, 1.01e-5});  // Re = 1000 * 2.5e-3 * 4e-7 / 1.01e-5 = 0.099
  EXPECT_TRUE(fast.implausible.empty()) << fast.implausible[0];
  check_plausible(fast, {1000.0, 0.99e-5});  // Re = 0.101: the backward speed counts
  ASSERT_EQ(fast.implausible.size(), 1u);
  check_plausible(fast, {1000.0, 1e-8});  // Re = 100
  ASSERT_EQ(fast.implausible.size(), 1u);
  EXPECT_NE(fast.implausible[0].find("= 100 above 0.1"), std::string::npos) << fast.implausible[0];
  EXPECT_NE(fast.implausible[0].find("fluid.viscosity"), std::string::npos) << fast.implausible[0];
  EXPECT_EQ(summary(fast, json::object())["plausible"], false);
  check_plausible(fast);
  EXPECT_TRUE(fast.implausible.empty());
  EXPECT_EQ(summary(fast, json::object())["plausible"], true);
}
