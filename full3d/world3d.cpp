#include "full3d/world3d.hpp"

#include "full3d/fft.hpp"

namespace swim::full3d {

IbOptions ib_options(const Params3d& p) {
  IbOptions o;
  o.scheme = p.scheme;
  o.max_cfl = p.max_cfl;
  o.dt_key = "full3d.dt";
  o.threads = p.threads;
  o.axisymmetric_wall = p.axisymmetric_wall;
  o.wall_stabilization = p.wall_stabilization;
  o.stabilization_factor = p.stabilization_factor;
  o.stokes.memory_limit_gib = p.memory_limit_gib;
  o.stokes.fft.threads = p.threads;
  o.stokes.threads = p.threads;
  if (p.container == "cylinder") {
    o.stokes.cylinder.enabled = true;
    o.stokes.cylinder.radius = p.container_radius;
  }
  o.stokes.advection.enabled = p.navier_stokes;
  if (p.threads > 1) fftw_threads_init_once();
  return o;
}

void check_fluid_memory(const Params3d& p) {
  (void)factor_slots(MacGrid(p.nx, p.ny, p.nz, p.h, p.grid_boundary()), ib_options(p).stokes);
}

World3d::World3d(const Params3d& params)
    : p(params), mesh(make_mesh(params)), e_ref(uniform_contraction_energy(mesh, params.membrane, params.protocol.R_f)),
      options(ib_options(params)) {}

MacGrid World3d::grid() const { return MacGrid(p.nx, p.ny, p.nz, p.h, p.grid_boundary()); }

Protocol3d World3d::protocol() const { return Protocol3d(effective_protocol(p, mesh), mesh, e_ref); }

std::unique_ptr<IbSolver> World3d::solver(const IbOptions& o, const Eigen::VectorXd& mass) const {
  const Eigen::VectorXd m = mass.size() ? mass : Eigen::VectorXd(Eigen::VectorXd::Zero(mesh.nodes()));
  return std::make_unique<IbSolver>(grid(), p.fluid, mesh, p.membrane, m, o);
}

}  // namespace swim::full3d
