// A scene's 3D world: what the scene's parameters make of the tier, built in one place for
// every user (the run, swim bench, the calibration's wet confirmation, the hydraulic
// measurement):
//   - the reference mesh of the wall (make_mesh: the no-leak rule with the scene's spacing),
//   - the MAC grid (nx x ny x nz cells of size h in the container's kind),
//   - the coupled step's options (scheme, CFL bound, threads, the container's wall, advection),
//   - the coupled solver on that grid and mesh,
//   - the actuation protocol (recovery-end energy filled in, scaled by the energy of the tube
//     uniformly at R_f).
#pragma once

#include <memory>

#include <Eigen/Core>

#include "full3d/grid.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/membrane.hpp"
#include "full3d/protocol3d.hpp"
#include "full3d/scene3d.hpp"

namespace swim::full3d {

/// The coupled-step options a scene asks for: scheme, CFL bound, threads, container
/// (cylinder wall kind), Navier-Stokes advection.
IbOptions ib_options(const Params3d& p);
/// The scene's fluid grid against full3d.memory_limit_gib, before anything is built or written:
/// swim::InputError naming full3d.grid.cells_across and full3d.memory_limit_gib when the Stokes
/// factors of two time steps do not fit (factor_slots).
void check_fluid_memory(const Params3d& p);

struct World3d {
  /// `p` must outlive the world.
  explicit World3d(const Params3d& p);

  const Params3d& p;
  CylinderMesh mesh;  ///< the reference mesh
  double e_ref;       ///< energy of the tube uniformly at R_f, J (the protocol's energy scale)
  IbOptions options;  ///< ib_options(p)

  /// The fluid grid: nx x ny x nz cells of size h in the container's kind.
  MacGrid grid() const;
  /// The actuation protocol of the scene (effective_protocol) on the mesh.
  Protocol3d protocol() const;
  /// The coupled solver on grid() and the mesh with options `o` (this world's `options`,
  /// adjusted by the caller) and node masses `mass` (empty: a massless wall).
  std::unique_ptr<IbSolver> solver(const IbOptions& o, const Eigen::VectorXd& mass = {}) const;
  /// The same with this world's options.
  std::unique_ptr<IbSolver> solver() const { return solver(options); }
};

}  // namespace swim::full3d
