// The steady flows the 1D tier's end junction is fitted to (docs/outer-flow-1d.md §2c): on the
// axisymmetric tier (fitted method), a straight or partly contracted tube in the periodic
// container, (1) towed rigidly: its drag and the lumen flux relative to it; (2) the swimming
// velocity that a radial velocity of each wall ring alone gives, ring by ring (U is linear in the
// wall's velocity at a given shape, so these responses are the whole steady kernel). A tool, not
// part of the product: tools/fit_end_junction.py reads what it writes.
//
//   swim_junction_kernels [--cells 16] CASE ... > kernels.txt
//   CASE = L/R0,Rc/R0[,zf[,rf[,rt]]]: tube length and container radius in R0 = 0.125 um; zf < 0
//          (the default) a uniform tube of radius rt R0 (default 1), else the tube contracted to
//          rf R0 (default 0.55) over [0, zf L] with a front L/8 wide (a half sine) that rises to
//          rt R0 beyond it.
//
// Output per case: a header line "# L/R0 .. Rc/R0 .. Rt/R0 .. cells .. nodes .. drag .. mu ..
// zf .. rf ..", a line "# towed lumen flux per U .. m^2", then per ring "k z/R0 dz/R0 U" (U in m/s
// for dR/dt = 1 um/s at ring k alone; dz the ring's share of the wall).
//
//   swim_junction_kernels --expansion [--cells 16] L/R0,Rc/R0,R/R0 ... > expansion.txt
//
// The uniform expansion: a straight tube of radius R whose every ring moves outwards at the same
// rate w (fore-aft symmetric: it does not swim). One line per case, "# expansion L/R0 .. Rc/R0 ..
// R/R0 .. cells .. mu .. Z .. N s/m", Z = the viscous dissipation / w^2, the wall's resistance to
// that motion.
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "axi/prescribed_axi.hpp"
#include "axi/scene_axi.hpp"
#include "axi/wall_axi.hpp"
#include "common/scene.hpp"

namespace {

using swim::scene::json;

constexpr double kR0 = 0.125e-6, kRate = 1e-6;

std::string um(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.12g um", v * 1e6);
  return b;
}

/// The steady flows' scene: a tube of length L in the periodic cylinder Rc (period about 5 L, a
/// whole number of cells), the fitted method at `cells` across; its resolved parameters.
swim::axi::ParamsAxi tube_scene(const char* name, double L, double Rc, int cells) {
  const double h = Rc / cells, P = std::round(5 * L / h) * h;
  const json sc = {{"name", name},
                   {"swimmer", {{"radius", um(kR0)}, {"length", um(L)}}},
                   {"container", {{"kind", "cylinder"}, {"radius", um(Rc)}, {"period", um(P)}}},
                   {"wave", {{"kind", "sine"}, {"contracted_ratio", 0.55}, {"speed", "10 um/s"}, {"wavelength", um(L)}}},
                   {"full3d", {{"membrane", {{"axisymmetric", true}}}}},
                   {"axi", {{"method", "fitted"}, {"grid", {{"cells_across", cells}}}}}};
  json resolved;
  return swim::axi::read_scene_axi(sc, resolved);
}

void measure(double l, double rc, double zf, double rf, double rt, int cells) {
  const double L = l * kR0, Rc = rc * kR0;
  const swim::axi::ParamsAxi p = tube_scene("junction_kernel", L, Rc, cells);
  swim::axi::AxiWall wall(swim::axi::AxiWallParams{p.base.R0, p.base.L, p.ks, p.D, p.wall_nodes, p.ring_s0});
  auto shape = [&](double z) {
    if (zf < 0) return rt * kR0;
    const double x = (z - zf * L) / (L / 8);
    if (x <= -0.5) return rf * kR0;
    if (x >= 0.5) return rt * kR0;
    return rf * kR0 + (rt - rf) * kR0 * 0.5 * (1 + std::sin(M_PI * x));
  };
  int ring = -1;  // the ring that moves; -1: none (the towed tube)
  swim::axi::RingKinematics kin = [&](double, const std::vector<double>& z, Eigen::VectorXd& R, Eigen::VectorXd& Rt) {
    R.resize(Eigen::Index(z.size()));
    for (std::size_t k = 0; k < z.size(); ++k) R[Eigen::Index(k)] = shape(z[k]);
    Rt = Eigen::VectorXd::Zero(Eigen::Index(z.size()));
    if (ring >= 0) Rt[ring] = kRate;
  };
  swim::axi::PrescribedSwimmer sw(swim::axi::fitted_mesh_params(p), p.base.fluid.mu, wall.reference_positions(), kin,
                                  p.x_start());
  const std::vector<double>& z = sw.z();
  const int n = int(z.size());
  const swim::axi::PrescribedState tow = sw.evaluate(0.0);
  std::printf("# towed lumen flux per U %.9e m^2\n", tow.towed_lumen_flux);
  std::printf("# L/R0 %.4f Rc/R0 %.4f Rt/R0 %.2f cells %d nodes %d drag %.9e mu %.6e zf %.4f rf %.4f\n", l, rc, rt,
              cells, n, tow.drag, p.base.fluid.mu, zf, rf);
  for (ring = 0; ring < n; ++ring) {
    const double dz = 0.5 * ((ring + 1 < n ? z[ring + 1] : z[ring]) - (ring > 0 ? z[ring - 1] : z[ring]));
    std::printf("%d %.9e %.9e %.9e\n", ring, z[ring] / kR0, dz / kR0, sw.evaluate(0.0).velocity);
  }
  std::fflush(stdout);
}

void expansion(double l, double rc, double r, int cells) {
  const double R = r * kR0;
  const swim::axi::ParamsAxi p = tube_scene("junction_expansion", l * kR0, rc * kR0, cells);
  swim::axi::AxiWall wall(swim::axi::AxiWallParams{p.base.R0, p.base.L, p.ks, p.D, p.wall_nodes, p.ring_s0});
  swim::axi::RingKinematics kin = [&](double, const std::vector<double>& z, Eigen::VectorXd& Rv, Eigen::VectorXd& Rt) {
    Rv = Eigen::VectorXd::Constant(Eigen::Index(z.size()), R);
    Rt = Eigen::VectorXd::Constant(Eigen::Index(z.size()), kRate);
  };
  swim::axi::PrescribedSwimmer sw(swim::axi::fitted_mesh_params(p), p.base.fluid.mu, wall.reference_positions(), kin,
                                  p.x_start());
  sw.evaluate(0.0);
  std::printf("# expansion L/R0 %.4f Rc/R0 %.4f R/R0 %.4f cells %d mu %.6e Z %.9e N s/m\n", l, rc, r, cells,
              p.base.fluid.mu, sw.stokes().dissipation() / (kRate * kRate));
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int cells = 16;
  bool expand = false;
  std::vector<std::string> cases;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--cells" && i + 1 < argc) cells = std::atoi(argv[++i]);
    else if (a == "--expansion") expand = true;
    else cases.push_back(a);
  }
  if (cases.empty() || cells < 4) {
    std::fprintf(stderr, "usage: swim_junction_kernels [--cells N >= 4] L/R0,Rc/R0[,zf[,rf[,rt]]] ...\n"
                         "       swim_junction_kernels --expansion [--cells N >= 4] L/R0,Rc/R0,R/R0 ...\n");
    return 2;
  }
  try {
    for (const std::string& c : cases) {
      if (expand) {
        double l = 0, rc = 0, r = 0;
        if (std::sscanf(c.c_str(), "%lf,%lf,%lf", &l, &rc, &r) != 3 || !(l > 0) || !(rc > 1) || !(r > 0 && r < rc)) {
          std::fprintf(stderr, "swim_junction_kernels: case \"%s\": expected L/R0 > 0, Rc/R0 > 1, 0 < R/R0 < Rc/R0\n",
                       c.c_str());
          return 2;
        }
        expansion(l, rc, r, cells);
        continue;
      }
      double l = 0, rc = 0, zf = -1, rf = 0.55, rt = 1.0;
      if (std::sscanf(c.c_str(), "%lf,%lf,%lf,%lf,%lf", &l, &rc, &zf, &rf, &rt) < 2 || !(l > 0) || !(rc > 1) ||
          !(rf > 0 && rf < 1) || zf >= 1 || !(rt > 0 && rt <= 1) || (zf >= 0 && !(rt > rf))) {
        std::fprintf(stderr,
                     "swim_junction_kernels: case \"%s\": expected L/R0 > 0, Rc/R0 > 1, zf < 1, 0 < rf < 1, rf < rt <= 1\n",
                     c.c_str());
        return 2;
      }
      measure(l, rc, zf, rf, rt, cells);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "swim_junction_kernels: %s\n", e.what());
    return 3;
  }
  return 0;
}
