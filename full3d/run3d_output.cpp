#include "full3d/run3d_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/output.hpp"

namespace swim::full3d {

using scene::json;

namespace {
std::string frame_name(const char* kind, const char* ext, std::size_t index) {
  char name[64];
  std::snprintf(name, sizeof name, "vtk/%s_%06d.%s", kind, int(index), ext);
  return name;
}
}  // namespace

RunOutput::RunOutput(const RunSetup& run, const json& resolved, std::string dir, bool vtk, bool fluid)
    : run_(run), resolved_(resolved), dir_(std::move(dir)), vtk_(vtk), fluid_(fluid), pvd_(dir_ + "/membrane.pvd"),
      fluid_pvd_(dir_ + "/fluid.pvd") {}

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
  vtk::PointArray seg{"segment", 1, std::vector<double>(nn)};
  for (int i = 0; i < nn; ++i) seg.values[i] = protocol.segment_of(i);
  vtk::write_polydata(dir_ + "/" + name, xyz, mesh.triangles, {vel, act, rad, seg});
  pvd_.add(s.t, name);
  pvd_.write();
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
  vtk::write_image_data(dir_ + "/" + name, {nx, ny, nz}, g.h(), {vel, pr});
  fluid_pvd_.add(s.t, name);
  fluid_pvd_.write();
}

json RunOutput::write_results(const std::string& status, double wall, const Stepper& stepper,
                              const Measurements& measured) const {
  const Params3d& p = run_.p;
  const CylinderMesh& mesh = run_.mesh;
  const Protocol3d& protocol = stepper.protocol();
  const auto& st = protocol.state();
  const auto& series = measured.series();
  const long n = stepper.steps();
  json s = json::object();
  s["tier"] = "3d";
  s["scene"] = resolved_;
  s["status"] = status;
  const auto& last = series.back();
  const double t_end = last[0];
  s["t_end_s"] = t_end;
  s["displacement_m"] = last[1];
  s["cycles_completed"] = st.cycles_completed;
  std::vector<double> ct;
  for (size_t k = 0; k < st.cycle_end.size() && k < st.cycle_start.size(); ++k)
    ct.push_back(st.cycle_end[k] - st.cycle_start[k]);
  s["cycle_times_s"] = ct;
  s["cycle_start_times_s"] = st.cycle_start;
  s["cycle_end_times_s"] = st.cycle_end;
  const double vmean = t_end > 0 ? last[1] / t_end : 0.0;
  s["mean_velocity_m_per_s"] = vmean;
  s["body_lengths_per_s"] = vmean / p.L;
  s["final_velocity_m_per_s"] = last[2];
  double vmax = -1e300, rmin = 1e300, emax = 0, xmax = 0;
  for (const auto& row : series) {
    vmax = std::max(vmax, row[2]);
    xmax = std::max(xmax, row[1]);
    rmin = std::min(rmin, row[4]);
    emax = std::max(emax, row[20]);
  }
  s["max_edge_over_h"] = emax / p.h;  // at the output steps; the no-leak guard needs < 0.5
  s["max_velocity_m_per_s"] = vmax;
  s["max_displacement_m"] = xmax;  // largest centre displacement at the output steps
  s["pumped_volume_m3"] = measured.pumped_volume();
  s["min_radius_m"] = rmin;
  s["protocol_switches"] = st.switches;
  s["segment_reached_s"] = st.segment_reached;
  s["steps"] = n;
  s["steps_per_cycle"] = stepper.steps_per_cycle();
  s["derived"] = {{"C1_estimate_Pa_per_m", p.c1_estimate()},
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
                  {"segment_boundaries_m", protocol.boundaries()}};
  s["wall_time_s"] = wall;
  {
    output::CsvWriter csv(dir_ + "/series.csv", kSeriesColumns);
    for (const auto& row : series) csv.row(row);
  }
  {
    output::CsvWriter csv(dir_ + "/radius.csv", {"t_s", "z_m", "radius_m"});
    const int nr = mesh.n_rings;
    const auto& times = measured.radius_times();
    const auto& radius = measured.radius();
    for (size_t k = 0; k < times.size(); ++k)
      for (int r = 0; r < nr; ++r) csv.row({times[k], r * mesh.ring_spacing, radius[k * nr + r]});
  }
  const double t = stepper.state().t;
  json stats = {{"steps", n},
                {"steps_per_cycle", stepper.steps_per_cycle()},
                {"time_step", stepper.time_step_summary()},
                {"dt_s", run_.adaptive ? (n > 0 ? t / double(n) : 0.0) : p.dt},
                {"mode", p.dry ? "dry" : "fluid"},
                {"stokes_iterations_total", measured.stokes_iterations()},
                {"max_cfl", measured.max_cfl()},
                {"protocol_switches", st.switches},
                {"wall_time_s", wall},
                {"steps_per_s", wall > 0 ? n / wall : 0.0},
                {"output_every_steps", run_.out_every},
                {"checkpoint_every_steps", run_.ckpt_every}};
  output::write_json(dir_ + "/solver_stats.json", stats);
  output::write_json(dir_ + "/scene.resolved.json", resolved_);
  output::write_json(dir_ + "/summary.json", s);
  return s;
}

void RunOutput::save(CheckpointWriter& w) const {
  std::vector<double> ft;
  for (const auto& f : pvd_.frames()) ft.push_back(f.first);
  w.put("vtk_frames", ft);
  ft.clear();
  for (const auto& f : fluid_pvd_.frames()) ft.push_back(f.first);
  w.put("fluid_frames", ft);
}

void RunOutput::load(const CheckpointReader& r) {
  for (double t : r.get_vector("vtk_frames")) pvd_.add(t, frame_name("membrane", "vtp", pvd_.frames().size()));
  for (double t : r.get_vector("fluid_frames")) fluid_pvd_.add(t, frame_name("fluid", "vti", fluid_pvd_.frames().size()));
  if (vtk_) pvd_.write();
  if (fluid_) fluid_pvd_.write();
}

}  // namespace swim::full3d
