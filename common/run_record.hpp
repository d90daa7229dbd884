// One run record for both tiers, and its one writer.
//
// Each tier fills a RunRecord while it runs: the time series (named columns, rows stored
// contiguously), the radius field R(z, t), the protocol events, the status, the derived
// values and the wall time. The same code then writes every run folder (write_run:
// series.csv, radius.csv, solver_stats.json, scene.resolved.json, summary.json last), so
// both tiers' files carry the same keys and columns, and validation/ and calibrate read
// the same record in memory.
//
// Streaming: with a RunStream attached, every row and radius snapshot goes to disk as it is
// produced (series.csv.part, radius.csv.part, renamed at the end), and the record need not
// keep them in memory (Series::keep(false)): the summary is computed from running figures
// (per-column minimum and maximum, the first and last rows, the centre displacement at each
// protocol event), never from the kept rows. Memory then stays bounded however long the run.
//
// series.csv columns: the common columns (common_series_columns()) come first, in this order,
// in both tiers; each tier's own columns follow (docs/outputs.md lists them all). The integer
// `phase` column is a Phase code.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/atomic_file.hpp"

namespace swim::record {

using json = nlohmann::ordered_json;

/// The `phase` column: where the force-driven protocol is (prescribed waves: Contraction
/// throughout).
enum class Phase : int {
  Contraction = 0,  ///< segments driven in turn towards R_f
  Recovery = 1,     ///< actuation released band by band; the wall relaxes towards R0
  Done = 2,         ///< the requested cycles are complete
};

/// The columns every series.csv starts with, in this order.
const std::vector<std::string>& common_series_columns();

/// A run's time series: named columns; the kept rows stored contiguously (row-major). Over
/// every row appended (kept or not) it tracks each column's minimum and maximum and the first
/// and last rows.
class Series {
 public:
  Series() = default;
  /// The columns must start with common_series_columns().
  explicit Series(std::vector<std::string> columns);

  const std::vector<std::string>& columns() const { return columns_; }
  std::size_t width() const { return columns_.size(); }
  /// Index of a column; std::logic_error when there is none of that name.
  std::size_t index(std::string_view name) const;
  bool has(std::string_view name) const;

  /// Keep the rows in memory (default) or only the running figures.
  void keep(bool k) { keep_ = k; }
  bool keeps() const { return keep_; }

  /// Append a row of width() values. Throws NumericalError naming the column when a value is
  /// not finite (nothing is appended then).
  void append(std::span<const double> row);

  /// Rows appended in total.
  std::size_t count() const { return count_; }
  /// Rows kept in memory.
  std::size_t rows() const { return data_.size() / std::max<std::size_t>(width(), 1); }
  std::span<const double> row(std::size_t k) const { return {data_.data() + k * width(), width()}; }
  double at(std::size_t k, std::string_view name) const { return data_[k * width() + index(name)]; }
  /// One column of the kept rows.
  std::vector<double> column(std::string_view name) const;
  const std::vector<double>& data() const { return data_; }

  double min(std::string_view name) const { return min_[index(name)]; }
  double max(std::string_view name) const { return max_[index(name)]; }
  /// The first and the last row appended (empty before any).
  std::span<const double> first() const { return {first_.data(), first_.size()}; }
  std::span<const double> last() const { return {last_.data(), last_.size()}; }
  /// The row appended before the last one (empty before two).
  std::span<const double> previous() const { return {prev_.data(), prev_.size()}; }

  /// The running figures and the kept rows, for checkpoints: named arrays of numbers.
  void save(const std::function<void(const std::string&, const std::vector<double>&)>& put) const;
  void load(const std::function<std::vector<double>(const std::string&)>& get);

 private:
  std::vector<std::string> columns_;
  bool keep_ = true;
  std::size_t count_ = 0;
  std::vector<double> data_, min_, max_, first_, last_, prev_;
};

/// The radius field R(z, t): snapshots at the output times on a fixed set of positions.
class RadiusField {
 public:
  RadiusField() = default;
  explicit RadiusField(std::vector<double> z_m) : z_(std::move(z_m)) {}
  const std::vector<double>& z() const { return z_; }
  void keep(bool k) { keep_ = k; }
  /// Throws NumericalError when a value is not finite.
  void append(double t, std::span<const double> radius);
  std::size_t count() const { return count_; }
  /// Kept snapshots: times and row-major values (radius[k * z().size() + i]).
  const std::vector<double>& times() const { return times_; }
  const std::vector<double>& values() const { return values_; }
  void save(const std::function<void(const std::string&, const std::vector<double>&)>& put) const;
  void load(const std::function<std::vector<double>(const std::string&)>& get);

 private:
  std::vector<double> z_;
  bool keep_ = true;
  std::size_t count_ = 0;
  std::vector<double> times_, values_;
};

/// The protocol's events. The centre displacement at an event is interpolated linearly
/// between the rows around it (the last row when the run ends before a later one).
struct Events {
  std::vector<double> cycle_start_s, cycle_end_s;
  std::vector<double> x_at_cycle_start_m, x_at_cycle_end_m;
  /// Force-driven: the time each segment (index 0 = rear) first reached R_f in the last cycle
  /// started; -1 where not reached.
  std::vector<double> segment_reached_s;
  long switches = 0;  ///< protocol force switches over the run
};

class RunStream;

/// What a tier returns: everything a run produced.
class RunRecord {
 public:
  RunRecord() = default;
  /// tier "1d" or "3d"; model: which model produced it; length: the swimmer's length [m];
  /// z: the positions of the radius field [m].
  RunRecord(std::string tier, std::string model, double length_m, std::vector<std::string> series_columns,
            std::vector<double> z_m);

  std::string tier, model;
  double length_m = 0;
  Series series;
  RadiusField radius;
  Events events;
  /// A prescribed wave has no protocol cycle: its per-cycle figures are those of the whole
  /// transit (set when the run reached its end).
  bool transit_is_cycle = false;
  std::string status = "ok";                   ///< "ok", "running: ...", "failed: ..."
  std::vector<std::string> implausible;        ///< physically impossible results, if any
  json derived = json::object();               ///< derived inputs (C1, masses, ratios, grid, ...)
  json stats = json::object();                 ///< solver statistics (solver_stats.json)
  json extras = json::object();                ///< tier-specific summary keys
  double wall_time_s = 0;

  /// Keep rows and snapshots in memory (true) or only the running figures.
  void keep(bool k);
  /// Stream every row and snapshot to disk from now on (nullptr: stop).
  void attach(RunStream* stream) { stream_ = stream; }
  RunStream* stream() const { return stream_; }

  /// A series row (width series.width()); streamed when a stream is attached.
  void add_row(std::span<const double> row);
  void add_radius(double t, std::span<const double> radius_at_z);
  void cycle_started(double t);
  void cycle_ended(double t);

  /// The centre displacement of the last row, and so on: shorthands of the common columns.
  double t_end() const;
  double displacement() const;

  /// Checkpoint records (named arrays of numbers) of the series, radius field and events.
  void save(const std::function<void(const std::string&, const std::vector<double>&)>& put) const;
  void load(const std::function<std::vector<double>(const std::string&)>& get);

 private:
  void resolve_pending(std::span<const double> prev, std::span<const double> row);
  RunStream* stream_ = nullptr;
  std::size_t pending_start_ = 0, pending_end_ = 0;  ///< events whose displacement is not known yet
};

/// Replay finished rows into a record with their protocol events, each event placed before
/// the first row at or after its time, as the run produced them: add_row(k) appends row k
/// (and whatever goes with it); time(k) is its time.
void replay(RunRecord& r, std::size_t rows, const std::function<double(std::size_t)>& time,
            const std::function<void(std::size_t)>& add_row, const std::vector<double>& cycle_starts,
            const std::vector<double>& cycle_ends);

/// Per-cycle figures of a record.
struct CycleFigures {
  bool has_cycle = false;
  std::string absent_because;  ///< when !has_cycle
  int cycles_completed = 0;
  std::vector<double> cycle_times_s, cycle_displacements_m;
  double displacement_per_cycle_m = 0, cycle_time_s = 0, mean_velocity_per_cycle_m_per_s = 0;
  /// The protocol's phases, s, averaged over the completed cycles: from a cycle's start to the
  /// first segment reaching R_f, between successive segments reaching it, and from the last one
  /// to the cycle's end (the recovery); they sum to cycle_time_s. Empty when no cycle completed
  /// from events or the cycles do not all have the same number of phases.
  std::vector<double> phase_times_s;
  /// The centre's displacement over each of those phases, m, averaged over the same cycles
  /// (linear in time between the kept rows around each boundary); they sum to
  /// displacement_per_cycle_m. Empty when phase_times_s is, or the rows were not kept.
  std::vector<double> phase_displacements_m;
};
CycleFigures cycle_figures(const RunRecord& r);

/// The fluid a run swam in, for the Reynolds-number bound of check_plausible (0: not checked).
struct FluidProperties {
  double density_kg_per_m3 = 0, viscosity_Pa_s = 0;
};
/// The Reynolds number Re = rho max|U| L / mu above which a run's creeping flow is not trusted:
/// the tiers solve Stokes flow, whose error grows in proportion to Re.
inline constexpr double kMaxReynolds = 0.1;

/// The plausibility check of every tier: a peristaltic swimmer in Stokes flow cannot outrun
/// its wave, and per cycle the wave crosses the tube once, so |displacement per cycle| <=
/// the swimmer's length; and the flow must be creeping, Re = rho max|U| L / mu <= kMaxReynolds
/// (with the swimmer's fastest speed over the run and its length; checked where `fluid` is
/// given). Sets r.implausible (cleared first).
void check_plausible(RunRecord& r, const FluidProperties& fluid = {});

/// The summary of a record: the keys common to both tiers, then r.extras. `resolved` is the
/// resolved scene it ran.
json summary(const RunRecord& r, const json& resolved);

/// Streams a record's rows and snapshots into a run folder: series.csv.part and
/// radius.csv.part, renamed to series.csv and radius.csv by commit().
class RunStream {
 public:
  /// A fresh stream of a series with these columns (headers written). Throws OutputError.
  RunStream(const std::string& dir, const std::vector<std::string>& columns);
  /// Continue the part files of an interrupted run from a checkpoint's marks (mark()).
  /// Throws InputError (key "--resume") when they do not match.
  RunStream(const std::string& dir, const std::vector<double>& marks);
  ~RunStream();

  /// A bound on the run's output (output.max_bytes): the two files and the other files
  /// counted by add_external. The row, snapshot or file that passes it ends the run like a
  /// numerical failure (NumericalError naming the key and the interval that dominates: exit
  /// 3, the results so far written and marked failed). It is raised once: the rows that close
  /// the run after it (its last state) are still written. Runs with a known duration are
  /// refused before they start when their estimate exceeds it; this catches the others (a
  /// force-driven run that lasts until its cycles complete).
  void limit(std::uintmax_t max_bytes) { limit_ = max_bytes; }
  void row(std::span<const double> values);
  void radius(double t, std::span<const double> z, std::span<const double> radius);
  /// Count `bytes` of another file the run wrote at time t (a 3D run's VTK frames, and what
  /// their .pvd collections grew by) toward the limit, under the interval key that sets how
  /// often they are written (e.g. "full3d.output.vtk_interval"); `what` names them in the
  /// message ("membrane frames"). Checked like a row; before limit() (a resume restoring
  /// its counts) nothing is checked.
  void add_external(std::uintmax_t bytes, double t, const std::string& key, const std::string& what);
  /// The bytes counted under `key` so far (0 when none), for a checkpoint.
  std::uintmax_t external(const std::string& key) const;
  /// The bytes counted toward the limit so far: both files (written and buffered) and the
  /// other files.
  std::uintmax_t bytes() const;
  /// Flush and check both files, record them in the folder's ledger; their marks (size and
  /// checksum of each) for a checkpoint. Throws OutputError.
  std::vector<double> mark();
  /// Publish series.csv and radius.csv. Throws OutputError.
  void commit();
  /// True when the part files in `dir` match a checkpoint's marks.
  static bool matches(const std::string& dir, const std::vector<double>& marks);

 private:
  void check_limit(double t);
  struct External {
    std::string key, what;
    std::uintmax_t bytes = 0;
  };
  std::unique_ptr<output::PartFile> series_, radius_;
  std::vector<External> external_;
  std::uintmax_t limit_ = 0;  ///< 0: none
  bool passed_ = false;       ///< the limit was passed (and raised)
};

/// Write the run folder of a record: series.csv and radius.csv (committed from the attached
/// stream, else written from the kept rows), solver_stats.json, scene.resolved.json and
/// summary.json last. Returns the summary. Throws OutputError (exit 3).
json write_run(const std::string& dir, RunRecord& r, const json& resolved);

/// A running run's snapshot for a checkpoint: flushes the stream and writes summary.json (status
/// r.status, listing the part files so far), solver_stats.json and scene.resolved.json.
/// Returns the stream's marks.
std::vector<double> write_snapshot(const std::string& dir, RunRecord& r, const json& resolved);

/// The series of a finished run folder (series.csv), read back with the writer's own format.
/// Throws NumericalError naming the file when it is missing or malformed.
Series read_series(const std::string& dir);

/// The record of a finished run folder, the inverse of write_run without the radius field:
/// the summary's tier, model, status, events, derived values and statistics, and the series
/// with its rows kept (the events placed among them as the run produced them). Throws
/// NumericalError naming the file when summary.json or series.csv is missing or malformed.
RunRecord read_run(const std::string& dir);

}  // namespace swim::record
