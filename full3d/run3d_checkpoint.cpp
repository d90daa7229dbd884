#include "full3d/run3d_checkpoint.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/checksum.hpp"
#include "full3d/grid.hpp"
#include "full3d/run3d_measure.hpp"
#include "full3d/run3d_output.hpp"
#include "full3d/run3d_stepper.hpp"
#include "common/run_record.hpp"

namespace swim::full3d {

namespace {

constexpr const char* kWallTime = "wall_time_s";

/// The scene as it must match on resume: everything except the keys that only steer
/// output cadence and parallelism, and the cap of an auto-duration run (a run stopped by
/// the cap can be continued with a larger one). The same for both tiers that checkpoint
/// (3D and the axisymmetric tier's own keys).
std::string resume_key(const scene::json& resolved) {
  scene::json r = resolved;
  if (r.contains("full3d") && r["full3d"].is_object()) {
    r["full3d"].erase("checkpoint_interval");
    r["full3d"].erase("threads");
    r["full3d"].erase("time_limit");
  }
  if (r.contains("axi") && r["axi"].is_object()) {
    r["axi"].erase("checkpoint_interval");
    r["axi"].erase("threads");
    r["axi"].erase("time_limit");
  }
  return r.dump();
}

std::string count(std::int64_t v) { return std::to_string(v); }

/// An integer record within [lo, hi].
std::int64_t int_in(const CheckpointReader& r, const std::string& name, std::int64_t lo, std::int64_t hi,
                    const std::string& what) {
  const std::int64_t v = r.get_int(name);
  if (v < lo || v > hi)
    r.damaged("the checkpoint's " + what + " ('" + name + "') is " + count(v) + ", outside [" + count(lo) + ", " +
              count(hi) + "]");
  return v;
}

void expect_size(const CheckpointReader& r, const std::string& name, std::size_t n, const std::string& what) {
  const std::size_t m = r.size_of(name);
  if (m != n)
    r.damaged("the checkpoint's '" + name + "' has " + std::to_string(m) + " values, this scene's " + what + " needs " +
              std::to_string(n) + " (a different grid or mesh)");
}

void validate(const CheckpointReader& r, const RunSetup& run) {
  const Params3d& p = run.p;
  // time and step counts
  const double t = r.get_double("t");
  if (!std::isfinite(t)) r.damaged("the checkpoint's simulated time is " + short_number(t) + ", not a finite number");
  if (t < 0.0) r.damaged("the checkpoint's simulated time is negative (t = " + short_number(t) + " s)");
  const double t_end = run.t_end();
  if (t > t_end + run.dt_top())
    r.damaged("the checkpoint's simulated time t = " + short_number(t) + " s lies beyond the end of this run (" +
              short_number(t_end) + " s: time.duration, or full3d.time_limit when the duration is auto)");
  const std::int64_t big = std::int64_t(1) << 53;
  const std::int64_t n = int_in(r, "step", 0, big, "step count");
  if (!run.adaptive && std::llround(t / p.dt) != n)
    r.damaged("the checkpoint's step count " + count(n) + " does not match its time t = " + short_number(t) +
              " s with full3d.dt = " + short_number(p.dt) + " s");
  if (run.adaptive && t > double(n) * p.adaptive.dt_max * (1.0 + 1e-9))
    r.damaged("the checkpoint's time t = " + short_number(t) + " s is more than " + count(n) +
              " steps of full3d.adaptive.dt_max");
  int_in(r, "last_recorded", -1, n, "last output step");
  int_in(r, "phase", 0, 2, "protocol phase");
  int_in(r, "active", 0, p.protocol.segments - 1, "active segment");
  int_in(r, "cycles_completed", 0, n, "completed cycles");
  int_in(r, "switches", 0, big, "protocol switches");
  int_in(r, "after_event", 0, 1, "event flag");
  int_in(r, "lambda_step", -1, n + 1, "step of the last stability estimate");
  for (const char* name : {"estimates", "rejected", "stokes_iterations_total", "last_stokes_iterations"})
    int_in(r, name, 0, big, "counter");
  for (const char* bound : {"growth", "cfl", "accuracy", "stability", "event"})
    int_in(r, std::string("steps_by_bound.") + bound, 0, n, "step counter");
  // sizes
  const std::size_t nodes = std::size_t(run.mesh.nodes());
  for (const char* name : {"X", "V", "V_prev"}) expect_size(r, name, 3 * nodes, "membrane mesh");
  if (!p.dry) {
    const MacGrid grid = run.grid();
    const char* const u[3] = {"u0", "u1", "u2"};
    for (int c = 0; c < 3; ++c) expect_size(r, u[c], grid.size(c), "fluid grid");
    expect_size(r, "p", grid.cells(), "fluid grid");
  }
  // the record's running figures: one value per series column (none before the first row)
  const std::size_t width = kSeriesColumns.size();
  const std::int64_t rows = r.size_of("series_count") == 1 ? std::int64_t(r.get_vector("series_count")[0]) : -1;
  if (rows < 0 || rows > n + 1) r.damaged("the checkpoint's series row count is missing or out of range");
  for (const char* name : {"series_min", "series_max", "series_first", "series_last"})
    expect_size(r, name, rows > 0 ? width : 0, "series (one value per column)");
  expect_size(r, "series_previous", rows > 1 ? width : 0, "series (one value per column)");
  if (r.size_of("series_rows") % width != 0 || r.size_of("radius") != r.size_of("radius_times") * std::size_t(run.mesh.n_rings))
    r.damaged("the checkpoint's kept rows do not match this scene's series columns and rings");
  expect_size(r, kOutputMarks, 6, "output streams (size and checksum of series.csv.part and radius.csv.part)");
  expect_size(r, kFrameBytes, 2, "VTK frames (bytes of the membrane and fluid frames written)");
  for (double b : r.get_vector(kFrameBytes))
    if (b < 0.0 || b > 9.0e15) r.damaged("the checkpoint's VTK frame byte count is negative or out of range");
  // every number finite
  if (const std::string bad = r.first_non_finite(); !bad.empty())
    r.damaged("the checkpoint's record '" + bad + "' holds a NaN or infinite value");
  // node positions within the container: transversally within its radius (half-width),
  // axially within 1000 container periods of the start (the container is periodic along x)
  const std::vector<double> X = r.get_vector("X");
  const Eigen::Vector3d a = p.axis_start();
  const double rc = p.container_radius * (1.0 + 1e-9), reach = 1000.0 * p.period;
  for (std::size_t i = 0; i < nodes; ++i) {
    const double x = X[3 * i] - a[0], y = X[3 * i + 1] - a[1], z = X[3 * i + 2] - a[2];
    const bool inside = p.container == "cylinder" ? std::hypot(y, z) <= rc : std::abs(y) <= rc && std::abs(z) <= rc;
    if (!inside || std::abs(x) > reach)
      r.damaged("the checkpoint's node " + std::to_string(i) + " lies outside the container (at " + short_number(X[3 * i]) +
                ", " + short_number(X[3 * i + 1]) + ", " + short_number(X[3 * i + 2]) + " m)");
  }
  const double wall = r.get_double(kWallTime);
  if (wall < 0.0) r.damaged("the checkpoint's wall time is negative");
}

}  // namespace

std::uint64_t RunCheckpoint::scene_hash(const scene::json& resolved) { return fnv1a64(resume_key(resolved)); }

RunCheckpoint::RunCheckpoint(const RunSetup& run, const scene::json& resolved, const std::string& dir)
    : run_(run), hash_(scene_hash(resolved)), dir_(dir), path_(dir + "/checkpoint.bin") {}

void RunCheckpoint::save(const Stepper& stepper, const Measurements& measured, const RunOutput& output,
                         const std::vector<double>& output_marks, double wall) const {
  CheckpointWriter w(hash_);
  stepper.save(w);
  measured.save(w);
  output.save(w, output_marks);
  w.put(kWallTime, wall);
  w.save(path_);
}

CheckpointReader RunCheckpoint::open() const {
  CheckpointReader r(path_, hash_);
  validate(r, run_);
  if (!record::RunStream::matches(dir_, r.get_vector(kOutputMarks)))
    r.damaged("the partial results series.csv.part and radius.csv.part next to it are missing or do not match it "
              "(changed, or shorter than at the checkpoint)");
  // every VTK frame the checkpoint (and the collections) refer to is still there
  const std::pair<const char*, const char*> kinds[] = {{"vtk_frames", "vtk/membrane_%06d.vtp"}, {"fluid_frames", "vtk/fluid_%06d.vti"}};
  for (const auto& [record, pattern] : kinds) {
    const std::size_t n = r.get_vector(record).size();
    for (std::size_t k = 0; k < n; ++k) {
      char name[64];
      std::snprintf(name, sizeof name, pattern, int(k));
      std::error_code ec;
      if (!std::filesystem::is_regular_file(std::filesystem::path(dir_) / name, ec))
        r.damaged(std::string("the frame ") + name + " written before the checkpoint is missing");
    }
  }
  return r;
}

double RunCheckpoint::restore(Stepper& stepper, Measurements& measured, RunOutput& output,
                              std::uintmax_t max_bytes) const {
  const CheckpointReader r = open();
  stepper.load(r);
  measured.load(r);
  output.load(r, max_bytes);
  return r.get_double(kWallTime);
}

}  // namespace swim::full3d
