#include "full3d/run3d_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/output.hpp"
#include "common/si_format.hpp"
#include "full3d/buckling_estimate.hpp"

namespace swim::full3d {

using scene::json;

namespace {
// The linear estimate of the contracted wall's buckling (buckling_estimate.hpp) for the scene:
// per stage of the contraction, the fastest-growing lobe number in the fluid and its rate.
scene::json buckling_estimate(const Params3d& p) {
  const double Y = 2.0 * p.membrane.ks / std::sqrt(3.0);  // (reported with the estimate)
  const double N = p.protocol.q * p.R0;                   // hoop compression holding R_f
  const auto stages = scene_contraction_buckling(p);
  scene::json j = {{"model", "Donnell shell, segment of the loaded length between round parts (the whole tube: free "
                             "ends), at R_f, Stokes drag 4 mu k"},
                   {"hoop_compression_N_per_m", N},
                   {"stretching_modulus_N_per_m", Y},
                   {"mode", stages.back().mode},
                   {"growth_rate_per_s", stages.back().growth_rate}};
  scene::json st = scene::json::array();
  for (const auto& s : stages)
    st.push_back({{"loaded_length_m", s.loaded_length},
                  {"mode", s.mode},
                  {"growth_rate_per_s", s.growth_rate},
                  {"critical_mode", s.critical_mode},
                  {"critical_compression_N_per_m", s.critical_compression}});
  j["stages"] = st;
  return j;
}

std::string frame_name(const char* kind, const char* ext, std::size_t index) {
  char name[64];
  std::snprintf(name, sizeof name, "vtk/%s_%06d.%s", kind, int(index), ext);
  return name;
}

/// The frame kinds (index 0: membrane, 1: fluid): collection, interval key, name.
struct FrameKind {
  const char* pvd;
  const char* key;
  const char* what;
};
constexpr FrameKind kFrameKinds[2] = {{"membrane.pvd", "full3d.output.vtk_interval", "membrane frames"},
                                      {"fluid.pvd", "full3d.output.fluid_interval", "fluid frames"}};

/// A file's size; 0 when it is not there.
std::uintmax_t size_of(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t n = std::filesystem::file_size(path, ec);
  return ec ? 0 : n;
}
}  // namespace

json wrinkle_by_cycle_json(const CycleWrinkles& w) {
  json a = json::array();
  for (const CycleWrinkles::Cycle& c : w.cycles())
    a.push_back({{"cycle", c.cycle},
                 {"max_wrinkle_m", c.max_wrinkle_m},
                 {"max_wrinkle_mode", c.max_wrinkle_mode},
                 {"modes_over_half_cell", c.modes}});
  return a;
}

std::string wrinkle_note(const json& s) {
  if (!s.contains("max_wrinkle_over_h") || !s.contains("max_wrinkle_m") || s["max_wrinkle_over_h"].get<double>() <= 0.5)
    return "";
  const double w = s["max_wrinkle_m"].get<double>(), wh = s["max_wrinkle_over_h"].get<double>();
  // a value of summary.json's "derived", 0 when absent
  const auto derived = [&](const char* key) {
    return s.contains("derived") && s["derived"].contains(key) ? s["derived"][key].get<double>() : 0.0;
  };
  const int seed = int(derived("seed_mode")), secondary = int(derived("secondary_seed_mode"));
  const double eps = derived("seed_amplitude");
  std::vector<int> modes;
  if (s.contains("wrinkle_modes_over_half_cell")) modes = s["wrinkle_modes_over_half_cell"].get<std::vector<int>>();
  if (modes.empty() && s.contains("max_wrinkle_mode") && s["max_wrinkle_mode"].get<int>() > 0)
    modes.push_back(s["max_wrinkle_mode"].get<int>());
  char buf[1024];
  std::string note;
  const std::string lobes = modes.empty() ? std::string("lobes") : "m = " + std::to_string(modes.front()) + " lobes";
  if (seed > 0) {
    std::snprintf(buf, sizeof buf,
                  "swim: note: the tube wall buckled into %s (up to %s RMS, %.2g cells); the seed "
                  "(full3d.membrane.seed_mode = %d, seed_amplitude = %.3g R0) ",
                  lobes.c_str(), si(w, "m").c_str(), wh, seed, eps);
    note = buf;
    note += !modes.empty() && modes.front() != seed
                ? "did not choose them: the wall grew another lobe number than the seed's, so the displacement "
                  "depends on full3d.grid.cells_across (docs/full3d.md \"Ring buckling and the seed imperfection\")"
                : "chose them on this grid (docs/full3d.md \"Ring buckling and the seed imperfection\")";
  } else {
    std::snprintf(buf, sizeof buf,
                  "swim: note: the tube wall wrinkled into %s (up to %s RMS, %.2g cells): without a seed the "
                  "lobes follow the grid, so the displacement depends on full3d.grid.cells_across; a seed "
                  "(full3d.membrane.seed_mode, seed_amplitude) chooses them, a wall stiff enough in bending "
                  "(full3d.membrane.bending_rigidity) keeps it round (docs/full3d.md \"Wall wrinkling\")",
                  lobes.c_str(), si(w, "m").c_str(), wh);
    note = buf;
  }
  if (modes.size() >= 2) {
    // the cycle where a lobe number first exceeded half a cell (0: not recorded)
    const auto first_cycle = [&](int m) {
      if (s.contains("wrinkle_by_cycle"))
        for (const auto& c : s["wrinkle_by_cycle"]) {
          const auto cm = c["modes_over_half_cell"].get<std::vector<int>>();
          if (std::find(cm.begin(), cm.end(), m) != cm.end()) return c["cycle"].get<int>();
        }
      return 0;
    };
    const int first_buckled = first_cycle(modes.front());
    std::string change;
    int first_change = 0;
    for (std::size_t k = 1; k < modes.size(); ++k)
      if (const int cyc = first_cycle(modes[k]); cyc > 0) {
        if (first_change == 0) first_change = cyc;
        change += (change.empty() ? "" : ", then ") + std::string("to m = ") + std::to_string(modes[k]) + " in cycle " +
                  std::to_string(cyc);
      }
    std::snprintf(buf, sizeof buf, "\nswim: note: the wall's lobes changed from m = %d %s (summary.json wrinkle_by_cycle): ",
                  modes.front(), change.empty() ? "to another lobe number" : change.c_str());
    note += buf;
    if (secondary > 0 && modes[1] == secondary)
      note += "the secondary seed (full3d.membrane.secondary_seed_mode = " + std::to_string(secondary) +
              ") chose the new lobes; ";
    note += first_change > first_buckled
                ? "the cycles from there on follow another buckled shape and do not repeat the earlier ones; compare "
                  "designs by the cycles before the change"
                : secondary > 0 && modes[1] == secondary
                      ? "the wall took that branch within its first buckled cycle"
                      : "the wall took another branch within its first buckled cycle, which the grid and the step "
                        "can tip; compare designs, and grids of one design, only on the same branch (a secondary "
                        "seed and full3d.membrane.ring_nodes_multiple = 4 choose it: docs/full3d.md)";
  }
  return note;
}

RunOutput::RunOutput(const RunSetup& run, const json& resolved, std::string dir, bool vtk, bool fluid,
                     record::RunRecord& rec)
    : run_(run), resolved_(resolved), dir_(std::move(dir)), vtk_(vtk), fluid_(fluid), pvd_(dir_ + "/membrane.pvd"),
      fluid_pvd_(dir_ + "/fluid.pvd"), rec_(rec) {}

RunOutput::~RunOutput() { rec_.attach(nullptr); }

void RunOutput::start(std::uintmax_t max_bytes) {
  stream_ = std::make_unique<record::RunStream>(dir_, rec_.series.columns());
  stream_->limit(max_bytes);
  rec_.attach(stream_.get());
}

void RunOutput::count_frame(int kind, const std::string& frame, double t) {
  const FrameKind& k = kFrameKinds[kind];
  const std::uintmax_t bytes = size_of(dir_ + "/" + frame);
  const std::uintmax_t pvd = size_of(dir_ + "/" + k.pvd);
  // the collection is rewritten with every frame: count what it grew by
  const std::uintmax_t grown = pvd > pvd_bytes_[kind] ? pvd - pvd_bytes_[kind] : 0;
  pvd_bytes_[kind] = pvd;
  frame_bytes_[kind] += bytes;
  stream_->add_external(bytes + grown, t, k.key, k.what);
}

void RunOutput::write_membrane_frame(const Stepper& stepper) {
  std::filesystem::create_directories(dir_ + "/vtk");
  const std::string name = frame_name("membrane", "vtp", pvd_.frames().size());
  const IbState& s = stepper.state();
  const Protocol3d& protocol = stepper.protocol();
  const CylinderMesh& mesh = run_.mesh;
  const int nn = mesh.nodes();
  std::vector<double> xyz(s.X.data(), s.X.data() + 3 * nn);
  vtk::PointArray vel{"velocity_m_per_s", 3, std::vector<double>(s.V.data(), s.V.data() + 3 * nn)};
  const Eigen::Matrix3Xd Fe = protocol.force(s.X);
  vtk::PointArray act{"actuation_force_N", 3, std::vector<double>(Fe.data(), Fe.data() + 3 * nn)};
  const Eigen::VectorXd r = node_radii(mesh, s.X);
  vtk::PointArray rad{"radius_m", 1, std::vector<double>(r.data(), r.data() + nn)};
  vtk::PointArray seg{"segment", 1, std::vector<double>(nn), true};
  for (int i = 0; i < nn; ++i) seg.values[i] = protocol.segment_of(i);
  vtk::write_polydata(dir_ + "/" + name, xyz, mesh.triangles, {vel, act, rad, seg}, s.t);
  pvd_.add(s.t, name);
  pvd_.write();
  count_frame(0, name, s.t);
}

void RunOutput::write_fluid_frame(const Stepper& stepper) {
  std::filesystem::create_directories(dir_ + "/vtk");
  const std::string name = frame_name("fluid", "vti", fluid_pvd_.frames().size());
  const IbState& s = stepper.state();
  const MacGrid& g = *stepper.grid();
  const int nx = g.nx(), ny = g.ny(), nz = g.nz();
  const auto du = g.dims(0), dv = g.dims(1), dw = g.dims(2);
  vtk::PointArray vel{"velocity_m_per_s", 3, std::vector<double>(3 * std::size_t(nx) * ny * nz)};
  std::size_t q = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {  // cell-centre averages of the face values
        const int ip = (i + 1) % nx;
        const int jp = g.periodic(1) ? (j + 1) % ny : j + 1;
        const int kp = g.periodic(2) ? (k + 1) % nz : k + 1;
        vel.values[q++] = 0.5 * (s.u.c[0][MacGrid::index(du, i, j, k)] + s.u.c[0][MacGrid::index(du, ip, j, k)]);
        vel.values[q++] = 0.5 * (s.u.c[1][MacGrid::index(dv, i, j, k)] + s.u.c[1][MacGrid::index(dv, i, jp, k)]);
        vel.values[q++] = 0.5 * (s.u.c[2][MacGrid::index(dw, i, j, k)] + s.u.c[2][MacGrid::index(dw, i, j, kp)]);
      }
  vtk::PointArray pr{"pressure_Pa", 1, stepper.pressure().v};
  std::vector<vtk::PointArray> arrays = {vel, pr};
  if (run_.p.container == "cylinder") {
    // the fluid domain of the fictitious-domain cylinder: 1 where the cell centre lies inside
    // r <= Rc, 0 in the fictitious region around it (ParaView: Threshold on inside_container)
    vtk::PointArray inside{"inside_container", 1, std::vector<double>(std::size_t(nx) * ny * nz), true};
    const double h = g.h(), yc = 0.5 * g.length(1), zc = 0.5 * g.length(2), rc = run_.p.container_radius;
    std::size_t c = 0;
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j) {
        const bool in = std::hypot((j + 0.5) * h - yc, (k + 0.5) * h - zc) <= rc;
        for (int i = 0; i < nx; ++i) inside.values[c++] = in ? 1.0 : 0.0;
      }
    arrays.push_back(std::move(inside));
  }
  vtk::write_image_data(dir_ + "/" + name, {nx, ny, nz}, g.h(), arrays, s.t);
  fluid_pvd_.add(s.t, name);
  fluid_pvd_.write();
  count_frame(1, name, s.t);
}

void RunOutput::fill(const std::string& status, double wall, const Stepper& stepper, const Measurements& measured) {
  const Params3d& p = run_.p;
  const CylinderMesh& mesh = run_.mesh;
  const Protocol3d& protocol = stepper.protocol();
  const long n = stepper.steps();
  rec_.status = status;
  rec_.wall_time_s = wall;
  rec_.derived = {{"C1_Pa_per_m", p.c1_estimate()},
                  {"mass_per_area_kg_per_m2", p.mass_per_area},
                  {"mass_per_length_kg_per_m", p.mass_per_area * 2.0 * M_PI * p.R0},
                  {"aspect_ratio_R0_over_L", p.R0 / p.L},
                  {"contracted_ratio", p.protocol.R_f / p.R0},
                  {"actuation_pressure_Pa", p.protocol.q},
                  {"force_per_node_N", p.protocol.q * 2.0 * M_PI * p.R0 * p.L / mesh.nodes()},
                  {"reference_energy_J", run_.e_ref},
                  {"recovery_end_energy_J", protocol.end_threshold()},
                  {"cell_size_m", p.h},
                  {"grid", {p.nx, p.ny, p.nz}},
                  {"nodes", mesh.nodes()},
                  {"n_theta", mesh.n_theta},
                  {"rings", mesh.n_rings},
                  {"ring_spacing_m", mesh.ring_spacing},
                  {"max_edge_m", max_edge_length(mesh, mesh.X0)},
                  {"bending_constant_N", p.membrane.kb},
                  {"bending_rigidity_J", p.bending_rigidity},
                  {"bending_rigidity_from", p.bending_source},
                  {"bending_model", p.bending_model == Params3d::BendingModel::FixedKb ? "fixed_kb" : "rigidity"},
                  {"seed_mode", p.seed_mode},
                  {"seed_amplitude", p.seed_amplitude},
                  {"secondary_seed_mode", p.secondary_seed_mode},
                  {"secondary_seed_amplitude", p.secondary_seed_amplitude},
                  {"segment_boundaries_m", protocol.boundaries()}};
  if (!p.dry && p.protocol.q > 0.0 && !p.axisymmetric_wall) rec_.derived["buckling_estimate"] = buckling_estimate(p);
  // the largest edge at the output steps; the no-leak guard needs < 0.5 h
  const double emax = rec_.series.count() ? rec_.series.max("max_edge_m") : 0.0;
  // the wall's largest departure from axisymmetry at the output steps (docs/full3d.md, "Wall wrinkling")
  const double wmax = rec_.series.count() ? rec_.series.max("wrinkle_m") : 0.0;
  rec_.extras = {{"max_edge_over_h", emax / p.h},
                 {"max_wrinkle_m", wmax},
                 {"max_wrinkle_over_h", wmax / p.h},
                 {"max_wrinkle_mode", measured.max_wrinkle_mode()},
                 {"wrinkle_by_cycle", wrinkle_by_cycle_json(measured.cycle_wrinkles())},
                 {"wrinkle_modes_over_half_cell", measured.cycle_wrinkles().modes()},
                 {"steps", n},
                 {"steps_per_cycle", stepper.steps_per_cycle()}};
  record::check_plausible(rec_, {p.fluid.rho, p.fluid.mu});
  rec_.events.switches = protocol.state().switches;
  rec_.events.segment_reached_s = protocol.state().segment_reached;
  const double t = stepper.state().t;
  rec_.stats = {{"steps", n},
                {"steps_per_cycle", stepper.steps_per_cycle()},
                {"time_step", stepper.time_step_summary()},
                {"dt_s", run_.adaptive ? (n > 0 ? t / double(n) : 0.0) : p.dt},
                {"mode", p.dry ? "dry" : "fluid"},
                {"stokes_iterations_total", measured.stokes_iterations()},
                {"stokes_setup", stepper.stokes_setup_summary()},
                {"max_cfl", measured.max_cfl()},
                {"protocol_switches", protocol.state().switches},
                {"wall_time_s", wall},
                {"steps_per_s", wall > 0 ? n / wall : 0.0},
                {"wall_time_split_s", measured.split().to_json()},
                {"output_every_steps", run_.out_every},
                {"checkpoint_every_steps", run_.ckpt_every}};
}

json RunOutput::write_results(const std::string& status, double wall, const Stepper& stepper,
                              const Measurements& measured) {
  fill(status, wall, stepper, measured);
  return record::write_run(dir_, rec_, resolved_);
}

std::vector<double> RunOutput::write_snapshot(const std::string& status, double wall, const Stepper& stepper,
                                              const Measurements& measured) {
  fill(status, wall, stepper, measured);
  return record::write_snapshot(dir_, rec_, resolved_);
}

void RunOutput::write_snapshot_summary() { output::write_json(dir_ + "/summary.json", record::summary(rec_, resolved_)); }

void RunOutput::save(CheckpointWriter& w, const std::vector<double>& marks) const {
  w.put(kOutputMarks, marks);
  std::vector<double> ft;
  for (const auto& f : pvd_.frames()) ft.push_back(f.first);
  w.put("vtk_frames", ft);
  ft.clear();
  for (const auto& f : fluid_pvd_.frames()) ft.push_back(f.first);
  w.put("fluid_frames", ft);
  w.put(kFrameBytes, std::vector<double>{double(frame_bytes_[0]), double(frame_bytes_[1])});
}

void RunOutput::load(const CheckpointReader& r, std::uintmax_t max_bytes) {
  // the frames written before the checkpoint (RunCheckpoint::open checked they are there) are
  // files of this run: the final summary.json lists them with the frames written after it
  for (double t : r.get_vector("vtk_frames")) {
    pvd_.add(t, frame_name("membrane", "vtp", pvd_.frames().size()));
    output::adopt(dir_ + "/" + pvd_.frames().back().second);
  }
  for (double t : r.get_vector("fluid_frames")) {
    fluid_pvd_.add(t, frame_name("fluid", "vti", fluid_pvd_.frames().size()));
    output::adopt(dir_ + "/" + fluid_pvd_.frames().back().second);
  }
  if (vtk_) pvd_.write();
  if (fluid_) fluid_pvd_.write();
  stream_ = std::make_unique<record::RunStream>(dir_, r.get_vector(kOutputMarks));
  // the frames written up to the checkpoint and the collections as they are now count again
  // (before the limit is set: the checkpoint was within it)
  const std::vector<double> fb = r.get_vector(kFrameBytes);
  for (int kind = 0; kind < 2; ++kind) {
    const FrameKind& k = kFrameKinds[kind];
    frame_bytes_[kind] = static_cast<std::uintmax_t>(fb.at(kind));
    pvd_bytes_[kind] = size_of(dir_ + "/" + k.pvd);
    if (frame_bytes_[kind] + pvd_bytes_[kind] > 0)
      stream_->add_external(frame_bytes_[kind] + pvd_bytes_[kind], r.get_double("t"), k.key, k.what);
  }
  stream_->limit(max_bytes);
  rec_.attach(stream_.get());
}

}  // namespace swim::full3d
