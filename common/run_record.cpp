#include "common/run_record.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/run_figures.hpp"

namespace swim::record {

namespace {

using Put = std::function<void(const std::string&, const std::vector<double>&)>;
using Get = std::function<std::vector<double>(const std::string&)>;

double size_of(std::size_t n) { return static_cast<double>(n); }
std::size_t count_of(const std::vector<double>& v) { return v.empty() ? 0 : static_cast<std::size_t>(v[0]); }

/// Linear interpolation of the centre displacement (column 1) between two rows at time t.
double x_between(std::span<const double> a, std::span<const double> b, double t) {
  if (a.empty()) return b[1];
  const double dt = b[0] - a[0];
  if (!(dt > 0)) return b[1];
  const double w = std::clamp((t - a[0]) / dt, 0.0, 1.0);
  return a[1] + w * (b[1] - a[1]);
}

}  // namespace

const std::vector<std::string>& common_series_columns() {
  static const std::vector<std::string> c = {
      "t_s",           "x_center_m",          "velocity_m_per_s", "energy_J",       "min_radius_m",
      "max_radius_m",  "flux_rear_m3_per_s",  "flux_front_m3_per_s", "volume_rear_m3", "volume_front_m3",
      "tube_volume_m3", "phase"};
  return c;
}

// ---- Series ------------------------------------------------------------------------------

Series::Series(std::vector<std::string> columns) : columns_(std::move(columns)) {
  const auto& common = common_series_columns();
  if (columns_.size() < common.size() || !std::equal(common.begin(), common.end(), columns_.begin()))
    throw std::logic_error("a series must start with the common columns");
}

std::size_t Series::index(std::string_view name) const {
  for (std::size_t i = 0; i < columns_.size(); ++i)
    if (columns_[i] == name) return i;
  throw std::logic_error("the series has no column " + std::string(name));
}

bool Series::has(std::string_view name) const {
  return std::find(columns_.begin(), columns_.end(), name) != columns_.end();
}

void Series::append(std::span<const double> row) {
  if (row.size() != width()) throw std::logic_error("series row width mismatch");
  for (std::size_t i = 0; i < row.size(); ++i)
    if (!std::isfinite(row[i]))
      throw NumericalError("non-finite value in the series column '" + columns_[i] + "'",
                           "tighten the solver tolerances or reduce the time step", row[0]);
  if (count_ == 0) {
    first_.assign(row.begin(), row.end());
    min_ = first_;
    max_ = first_;
  } else {
    for (std::size_t i = 0; i < row.size(); ++i) {
      min_[i] = std::min(min_[i], row[i]);
      max_[i] = std::max(max_[i], row[i]);
    }
  }
  prev_.swap(last_);
  last_.assign(row.begin(), row.end());
  if (keep_) data_.insert(data_.end(), row.begin(), row.end());
  ++count_;
}

std::vector<double> Series::column(std::string_view name) const {
  const std::size_t c = index(name);
  std::vector<double> v(rows());
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = data_[k * width() + c];
  return v;
}

void Series::save(const Put& put) const {
  put("series_count", {size_of(count_)});
  put("series_min", min_);
  put("series_max", max_);
  put("series_first", first_);
  put("series_last", last_);
  put("series_previous", prev_);
  put("series_rows", data_);
}

void Series::load(const Get& get) {
  count_ = count_of(get("series_count"));
  min_ = get("series_min");
  max_ = get("series_max");
  first_ = get("series_first");
  last_ = get("series_last");
  prev_ = get("series_previous");
  data_ = keep_ ? get("series_rows") : std::vector<double>{};
  const std::size_t w = width();
  const auto bad = [&](const std::vector<double>& v, bool may_be_empty) {
    return !(v.size() == w || (may_be_empty && v.empty()));
  };
  if (bad(min_, count_ == 0) || bad(max_, count_ == 0) || bad(first_, count_ == 0) || bad(last_, count_ == 0) ||
      bad(prev_, count_ < 2) || data_.size() % std::max<std::size_t>(w, 1) != 0)
    throw InputError("--resume", "checkpoint.bin", "the series records have the wrong width for this scene");
}

// ---- RadiusField -------------------------------------------------------------------------

void RadiusField::append(double t, std::span<const double> radius) {
  if (radius.size() != z_.size()) throw std::logic_error("radius snapshot width mismatch");
  for (std::size_t i = 0; i < radius.size(); ++i)
    if (!std::isfinite(radius[i]))
      throw NumericalError("non-finite radius at z = " + std::to_string(z_[i]) + " m",
                           "tighten the solver tolerances or reduce the time step", t);
  if (keep_) {
    times_.push_back(t);
    values_.insert(values_.end(), radius.begin(), radius.end());
  }
  ++count_;
}

void RadiusField::save(const Put& put) const {
  put("radius_count", {size_of(count_)});
  put("radius_times", times_);
  put("radius", values_);
}

void RadiusField::load(const Get& get) {
  count_ = count_of(get("radius_count"));
  times_ = keep_ ? get("radius_times") : std::vector<double>{};
  values_ = keep_ ? get("radius") : std::vector<double>{};
  if (values_.size() != times_.size() * z_.size())
    throw InputError("--resume", "checkpoint.bin", "the radius records have the wrong size for this scene");
}

// ---- RunRecord ---------------------------------------------------------------------------

RunRecord::RunRecord(std::string tier_, std::string model_, double length, std::vector<std::string> series_columns,
                     std::vector<double> z_m)
    : tier(std::move(tier_)), model(std::move(model_)), length_m(length), series(std::move(series_columns)),
      radius(std::move(z_m)) {}

void RunRecord::keep(bool k) {
  series.keep(k);
  radius.keep(k);
}

void RunRecord::resolve_pending(std::span<const double> prev, std::span<const double> row) {
  // events up to this row's time get their displacement, interpolated from the row before
  while (pending_start_ < events.cycle_start_s.size() && events.cycle_start_s[pending_start_] <= row[0])
    events.x_at_cycle_start_m.push_back(x_between(prev, row, events.cycle_start_s[pending_start_++]));
  while (pending_end_ < events.cycle_end_s.size() && events.cycle_end_s[pending_end_] <= row[0])
    events.x_at_cycle_end_m.push_back(x_between(prev, row, events.cycle_end_s[pending_end_++]));
}

void RunRecord::add_row(std::span<const double> row) {
  series.append(row);
  resolve_pending(series.previous(), series.last());
  if (stream_) stream_->row(row);
}

void RunRecord::add_radius(double t, std::span<const double> r) {
  radius.append(t, r);
  if (stream_) stream_->radius(t, radius.z(), r);
}

void RunRecord::cycle_started(double t) {
  events.cycle_start_s.push_back(t);
  if (series.count() > 0 && t <= series.last()[0]) resolve_pending(series.previous(), series.last());
}

void RunRecord::cycle_ended(double t) {
  events.cycle_end_s.push_back(t);
  if (series.count() > 0 && t <= series.last()[0]) resolve_pending(series.previous(), series.last());
}

double RunRecord::t_end() const { return series.count() ? series.last()[0] : 0.0; }
double RunRecord::displacement() const { return series.count() ? series.last()[1] : 0.0; }

void RunRecord::save(const Put& put) const {
  series.save(put);
  radius.save(put);
  put("events_cycle_start", events.cycle_start_s);
  put("events_cycle_end", events.cycle_end_s);
  put("events_x_at_cycle_start", events.x_at_cycle_start_m);
  put("events_x_at_cycle_end", events.x_at_cycle_end_m);
  put("events_segment_reached", events.segment_reached_s);
  put("events_switches", {double(events.switches)});
}

void RunRecord::load(const Get& get) {
  series.load(get);
  radius.load(get);
  events.cycle_start_s = get("events_cycle_start");
  events.cycle_end_s = get("events_cycle_end");
  events.x_at_cycle_start_m = get("events_x_at_cycle_start");
  events.x_at_cycle_end_m = get("events_x_at_cycle_end");
  events.segment_reached_s = get("events_segment_reached");
  const auto sw = get("events_switches");
  events.switches = sw.empty() ? 0 : static_cast<long>(sw[0]);
  if (events.x_at_cycle_start_m.size() > events.cycle_start_s.size() ||
      events.x_at_cycle_end_m.size() > events.cycle_end_s.size())
    throw InputError("--resume", "checkpoint.bin", "the event records are inconsistent");
  pending_start_ = events.x_at_cycle_start_m.size();
  pending_end_ = events.x_at_cycle_end_m.size();
}

void replay(RunRecord& r, std::size_t rows, const std::function<double(std::size_t)>& time,
            const std::function<void(std::size_t)>& add_row, const std::vector<double>& starts,
            const std::vector<double>& ends) {
  std::size_t a = 0, b = 0;
  for (std::size_t k = 0; k < rows; ++k) {
    const double t = time(k);
    while (a < starts.size() && starts[a] <= t) r.cycle_started(starts[a++]);
    while (b < ends.size() && ends[b] <= t) r.cycle_ended(ends[b++]);
    add_row(k);
  }
  while (a < starts.size()) r.cycle_started(starts[a++]);
  while (b < ends.size()) r.cycle_ended(ends[b++]);
}

// ---- summary -------------------------------------------------------------------------------

CycleFigures cycle_figures(const RunRecord& r) {
  CycleFigures c;
  const Events& e = r.events;
  // the displacement at an event after the last row is that of the last row
  auto x_at = [&](const std::vector<double>& xs, std::size_t k) { return k < xs.size() ? xs[k] : r.displacement(); };
  const std::size_t n = std::min(e.cycle_start_s.size(), e.cycle_end_s.size());
  c.cycles_completed = static_cast<int>(e.cycle_end_s.size());
  for (std::size_t k = 0; k < n; ++k) {
    c.cycle_times_s.push_back(e.cycle_end_s[k] - e.cycle_start_s[k]);
    c.cycle_displacements_m.push_back(x_at(e.x_at_cycle_end_m, k) - x_at(e.x_at_cycle_start_m, k));
  }
  // the centre's position at time t from the kept rows (linear between the rows around t); read
  // only where there are phases to measure (a summary written at each checkpoint need not copy
  // the columns otherwise)
  const bool rows = n > 0 && !e.segment_reached_s.empty() && r.series.rows() >= 2 && r.series.has("t_s") &&
                    r.series.has("x_center_m");
  const std::vector<double> ts = rows ? r.series.column("t_s") : std::vector<double>();
  const std::vector<double> xs = rows ? r.series.column("x_center_m") : std::vector<double>();
  auto x_of = [&](double t) {
    const auto it = std::lower_bound(ts.begin(), ts.end(), t);
    if (it == ts.begin()) return xs.front();
    if (it == ts.end()) return xs.back();
    const std::size_t j = static_cast<std::size_t>(it - ts.begin());
    const double w = (t - ts[j - 1]) / (ts[j] - ts[j - 1]);
    return xs[j - 1] + w * (xs[j] - xs[j - 1]);
  };
  for (std::size_t k = 0; k < n; ++k) {
    std::vector<double> b = {e.cycle_start_s[k]};
    for (double t : e.segment_reached_s)
      if (t > e.cycle_start_s[k] && t < e.cycle_end_s[k]) b.push_back(t);
    std::sort(b.begin() + 1, b.end());
    b.push_back(e.cycle_end_s[k]);
    if (k == 0) {
      c.phase_times_s.assign(b.size() - 1, 0.0);
      if (rows) c.phase_displacements_m.assign(b.size() - 1, 0.0);
    }
    if (b.size() - 1 != c.phase_times_s.size()) {
      c.phase_times_s.clear();
      c.phase_displacements_m.clear();
      break;
    }
    for (std::size_t i = 0; i + 1 < b.size(); ++i) c.phase_times_s[i] += (b[i + 1] - b[i]) / double(n);
    for (std::size_t i = 0; i + 1 < b.size() && rows; ++i)
      c.phase_displacements_m[i] += (x_of(b[i + 1]) - x_of(b[i])) / double(n);
  }
  if (n > 0) {
    double T = 0, d = 0;
    for (double v : c.cycle_times_s) T += v;
    for (double v : c.cycle_displacements_m) d += v;
    c.has_cycle = true;
    c.cycle_time_s = T / double(n);
    c.displacement_per_cycle_m = d / double(n);
    c.mean_velocity_per_cycle_m_per_s = d / T;
  } else if (r.transit_is_cycle && r.series.count() > 0) {
    c.has_cycle = true;
    c.cycle_time_s = r.t_end();
    c.displacement_per_cycle_m = r.displacement() - r.series.first()[1];
    c.mean_velocity_per_cycle_m_per_s = r.t_end() > 0 ? c.displacement_per_cycle_m / r.t_end() : 0.0;
  } else {
    c.absent_because = r.status.rfind("failed", 0) == 0 ? "the run stopped before completing a cycle"
                                                         : "no cycle completed within the run's duration";
  }
  return c;
}

void check_plausible(RunRecord& r, const FluidProperties& fluid) {
  r.implausible.clear();
  const CycleFigures c = cycle_figures(r);
  if (c.has_cycle && std::abs(c.displacement_per_cycle_m) > r.length_m)
    r.implausible.push_back("displacement per cycle exceeds the wave's travel (the swimmer length)");
  if (fluid.density_kg_per_m3 > 0 && fluid.viscosity_Pa_s > 0 && r.series.count() > 0) {
    const double u = std::max(std::abs(r.series.max("velocity_m_per_s")), std::abs(r.series.min("velocity_m_per_s")));
    const double re = fluid.density_kg_per_m3 * u * r.length_m / fluid.viscosity_Pa_s;
    if (re > kMaxReynolds) {
      char b[320];
      std::snprintf(b, sizeof b,
                    "Reynolds number rho max|U| L / mu = %.3g above %g: the tiers solve creeping (Stokes) flow, whose "
                    "error grows as Re (check fluid.viscosity and fluid.density)",
                    re, kMaxReynolds);
      r.implausible.push_back(b);
    }
  }
}

RunFigures run_figures(const RunRecord& r) {
  RunFigures f;
  f.cycles = cycle_figures(r);
  const Series& s = r.series;
  f.t_end_s = r.t_end();
  f.displacement_m = r.displacement();
  f.mean_velocity_m_per_s = f.t_end_s > 0 ? f.displacement_m / f.t_end_s : 0.0;
  f.body_lengths_per_s = f.t_end_s > 0 && r.length_m > 0 ? f.displacement_m / f.t_end_s / r.length_m : 0.0;
  if (s.count() == 0) return f;
  f.max_displacement_m = s.max("x_center_m");
  f.final_velocity_m_per_s = s.last()[s.index("velocity_m_per_s")];
  f.max_velocity_m_per_s = s.max("velocity_m_per_s");
  f.min_radius_m = s.min("min_radius_m");
  f.pumped_volume_m3 = -s.last()[s.index("volume_rear_m3")];
  return f;
}

json summary(const RunRecord& r, const json& resolved) {
  const RunFigures f = run_figures(r);
  const CycleFigures& c = f.cycles;
  const Series& s = r.series;
  json j = json::object();
  j["tier"] = r.tier;
  j["model"] = r.model;
  j["scene"] = resolved;
  j["status"] = r.status;
  j["t_end_s"] = f.t_end_s;
  j["displacement_m"] = f.displacement_m;
  j["max_displacement_m"] = f.max_displacement_m;
  j["mean_velocity_m_per_s"] = f.mean_velocity_m_per_s;
  j["body_lengths_per_s"] = f.body_lengths_per_s;
  j["final_velocity_m_per_s"] = f.final_velocity_m_per_s;
  j["max_velocity_m_per_s"] = f.max_velocity_m_per_s;
  j["min_radius_m"] = f.min_radius_m;
  j["cycles_completed"] = c.cycles_completed;
  j["cycle_start_times_s"] = r.events.cycle_start_s;
  j["cycle_end_times_s"] = r.events.cycle_end_s;
  j["cycle_times_s"] = c.cycle_times_s;
  j["cycle_displacements_m"] = c.cycle_displacements_m;
  if (c.has_cycle) {
    j["cycle_time_s"] = c.cycle_time_s;
    j["displacement_per_cycle_m"] = c.displacement_per_cycle_m;
    j["mean_velocity_per_cycle_m_per_s"] = c.mean_velocity_per_cycle_m_per_s;
    j["body_lengths_per_cycle_per_s"] = r.length_m > 0 ? c.mean_velocity_per_cycle_m_per_s / r.length_m : 0.0;
    j["per_cycle_absent_because"] = nullptr;
  } else {
    j["cycle_time_s"] = nullptr;
    j["displacement_per_cycle_m"] = nullptr;
    j["mean_velocity_per_cycle_m_per_s"] = nullptr;
    j["body_lengths_per_cycle_per_s"] = nullptr;
    j["per_cycle_absent_because"] = c.absent_because;
  }
  j["pumped_volume_m3"] = f.pumped_volume_m3;
  j["protocol_switches"] = r.events.switches;
  j["segment_reached_s"] = r.events.segment_reached_s;
  j["plausible"] = r.implausible.empty();
  j["implausible_because"] = r.implausible;
  j["swimmer_length_m"] = r.length_m;
  j["derived"] = r.derived;
  for (const auto& [k, v] : r.extras.items()) j[k] = v;
  j["series_rows"] = s.count();
  j["radius_snapshots"] = r.radius.count();
  j["wall_time_s"] = r.wall_time_s;
  return j;
}

// ---- RunStream ---------------------------------------------------------------------------

namespace {
void write_header(std::ostream& o, const std::vector<std::string>& columns) {
  for (std::size_t i = 0; i < columns.size(); ++i) o << (i ? "," : "") << columns[i];
  o << "\n";
}
void write_number(std::ostream& o, double v, bool first) {
  char b[40];
  if (!first) o << ',';
  o << output::csv_number(v, b);
}
const std::vector<std::string> kRadiusColumns = {"t_s", "z_m", "radius_m"};
}  // namespace

RunStream::RunStream(const std::string& dir, const std::vector<std::string>& columns)
    : series_(std::make_unique<output::PartFile>(dir + "/series.csv")),
      radius_(std::make_unique<output::PartFile>(dir + "/radius.csv")) {
  write_header(series_->stream(), columns);
  write_header(radius_->stream(), kRadiusColumns);
}

namespace {
// A checksum (64 bits) does not fit a double: it is stored as two 32-bit halves.
output::PartFile::Mark unpack(const std::vector<double>& marks, std::size_t k) {
  if (marks.size() != 6) throw InputError("--resume", "checkpoint.bin", "the output marks are missing");
  output::PartFile::Mark m;
  m.bytes = static_cast<std::uintmax_t>(marks[3 * k]);
  m.checksum = (static_cast<std::uint64_t>(marks[3 * k + 1]) << 32) | static_cast<std::uint64_t>(marks[3 * k + 2]);
  return m;
}
void pack(std::vector<double>& out, output::PartFile::Mark m) {
  out.push_back(static_cast<double>(m.bytes));
  out.push_back(static_cast<double>(m.checksum >> 32));
  out.push_back(static_cast<double>(m.checksum & 0xffffffffull));
}
}  // namespace

RunStream::RunStream(const std::string& dir, const std::vector<double>& marks)
    : series_(std::make_unique<output::PartFile>(dir + "/series.csv", unpack(marks, 0))),
      radius_(std::make_unique<output::PartFile>(dir + "/radius.csv", unpack(marks, 1))) {}

RunStream::~RunStream() = default;

void RunStream::row(std::span<const double> values) {
  auto& o = series_->stream();
  for (std::size_t i = 0; i < values.size(); ++i) write_number(o, values[i], i == 0);
  o << '\n';
  if (!o) series_->sync();  // a failed write (disk full) ends the run now: OutputError naming the file
  check_limit(values[0]);
}

std::uintmax_t RunStream::bytes() const {
  std::uintmax_t b = series_->bytes() + radius_->bytes();
  for (const External& e : external_) b += e.bytes;
  return b;
}

void RunStream::add_external(std::uintmax_t bytes, double t, const std::string& key, const std::string& what) {
  auto it = std::find_if(external_.begin(), external_.end(), [&](const External& e) { return e.key == key; });
  if (it == external_.end()) it = external_.insert(external_.end(), External{key, what, 0});
  it->bytes += bytes;
  check_limit(t);
}

std::uintmax_t RunStream::external(const std::string& key) const {
  for (const External& e : external_)
    if (e.key == key) return e.bytes;
  return 0;
}

void RunStream::check_limit(double t) {
  if (limit_ == 0 || passed_ || bytes() <= limit_) return;
  passed_ = true;
  // what was written, and the interval of the largest part: the key to raise
  const std::uintmax_t csv = series_->bytes() + radius_->bytes();
  std::string parts = "series.csv and radius.csv " + std::to_string(csv) + " bytes";
  std::string key = "time.output_interval";
  std::uintmax_t most = csv;
  for (const External& e : external_) {
    parts += ", " + e.what + " " + std::to_string(e.bytes) + " bytes";
    if (e.bytes > most) most = e.bytes, key = e.key;
  }
  throw NumericalError("the run's output reached output.max_bytes = " + std::to_string(limit_) +
                           " bytes before the run ended (" + parts + ")",
                       "raise " + key + " or output.max_bytes", t);
}

void RunStream::radius(double t, std::span<const double> z, std::span<const double> r) {
  auto& o = radius_->stream();
  for (std::size_t i = 0; i < r.size(); ++i) {
    write_number(o, t, true);
    write_number(o, z[i], false);
    write_number(o, r[i], false);
    o << '\n';
  }
  if (!o) radius_->sync();
  check_limit(t);
}

std::vector<double> RunStream::mark() {
  std::vector<double> m;
  pack(m, series_->sync());
  pack(m, radius_->sync());
  return m;
}

void RunStream::commit() {
  series_->commit();
  radius_->commit();
}

bool RunStream::matches(const std::string& dir, const std::vector<double>& marks) {
  if (marks.size() != 6) return false;
  return output::PartFile::matches(dir + "/series.csv", unpack(marks, 0)) &&
         output::PartFile::matches(dir + "/radius.csv", unpack(marks, 1));
}

// ---- the run folder -------------------------------------------------------------------------

namespace {
void write_side_files(const std::string& dir, const RunRecord& r, const json& resolved) {
  output::write_json(dir + "/solver_stats.json", r.stats);
  output::write_json(dir + "/scene.resolved.json", resolved);
}
}  // namespace

json write_run(const std::string& dir, RunRecord& r, const json& resolved) {
  if (r.stream()) {
    r.stream()->commit();
  } else {
    RunStream s(dir, r.series.columns());
    const Series& se = r.series;
    if (se.rows() != se.count() || r.radius.times().size() != r.radius.count())
      throw std::logic_error("write_run: a record that kept no rows needs its stream");
    for (std::size_t k = 0; k < se.rows(); ++k) s.row(se.row(k));
    const std::size_t nz = r.radius.z().size();
    for (std::size_t k = 0; k < r.radius.times().size(); ++k)
      s.radius(r.radius.times()[k], r.radius.z(), {r.radius.values().data() + k * nz, nz});
    s.commit();
  }
  write_side_files(dir, r, resolved);
  json j = summary(r, resolved);
  output::write_json(dir + "/summary.json", j);
  return j;
}

std::vector<double> write_snapshot(const std::string& dir, RunRecord& r, const json& resolved) {
  if (!r.stream()) throw std::logic_error("write_snapshot: no stream attached");
  std::vector<double> marks = r.stream()->mark();
  write_side_files(dir, r, resolved);
  output::write_json(dir + "/summary.json", summary(r, resolved));
  return marks;
}

// ---- reading a finished folder back ------------------------------------------------------------

Series read_series(const std::string& dir) {
  const std::string path = dir + "/series.csv";
  std::ifstream in(path);
  if (!in) throw NumericalError("the run folder has no series.csv (" + path + ")", "run the scene again");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> cols;
  {
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) cols.push_back(c);
  }
  Series s;
  try {
    s = Series(cols);
  } catch (const std::logic_error&) {
    throw NumericalError(path + " does not start with the common series columns", "run the scene again");
  }
  std::vector<double> v(cols.size());
  long line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    std::size_t n = 0;
    const char* p = line.c_str();
    while (*p && n < v.size()) {
      char* end = nullptr;
      v[n++] = std::strtod(p, &end);
      if (end == p) break;
      p = end;
      if (*p == ',') ++p;
    }
    if (n != v.size() || *p)
      throw NumericalError(path + " line " + std::to_string(line_no) + " is malformed", "run the scene again");
    s.append(v);
  }
  return s;
}

RunRecord read_run(const std::string& dir) {
  const std::string path = dir + "/summary.json";
  std::ifstream in(path);
  if (!in) throw NumericalError("the run folder has no summary.json (" + path + ")", "run the scene again");
  const json j = json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw NumericalError(path + " is not valid JSON", "run the scene again");
  const auto doubles = [&](const char* key) {
    std::vector<double> v;
    if (j.contains(key) && j[key].is_array())
      for (const auto& x : j[key])
        if (x.is_number()) v.push_back(x.get<double>());
    return v;
  };
  const Series rows = read_series(dir);
  RunRecord r(j.value("tier", std::string()), j.value("model", std::string()), j.value("swimmer_length_m", 0.0),
              rows.columns(), {});
  r.status = j.value("status", std::string("unknown"));
  if (j.contains("derived")) r.derived = j["derived"];
  r.wall_time_s = j.value("wall_time_s", 0.0);
  r.events.segment_reached_s = doubles("segment_reached_s");
  r.events.switches = j.value("protocol_switches", 0L);
  replay(
      r, rows.rows(), [&](std::size_t k) { return rows.row(k)[0]; }, [&](std::size_t k) { r.add_row(rows.row(k)); },
      doubles("cycle_start_times_s"), doubles("cycle_end_times_s"));
  return r;
}

}  // namespace swim::record
