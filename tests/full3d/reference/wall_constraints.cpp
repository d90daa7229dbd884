// The reference cylinder walls GhostLinear and SurfacePoints (reference_stokes.hpp); the
// staircase rows are the product's (container.hpp).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "common/errors.hpp"
#include "tests/full3d/reference/reference_stokes.hpp"

namespace swim::full3d::reference {

VelocityConstraints wall_constraints(const MacGrid& g, double radius, const WallOptions& wall) {
  CylinderOptions cyl;
  cyl.enabled = true;
  cyl.radius = radius;
  if (wall.wall == CylinderWall::Staircase) return VelocityConstraints(g, cyl);
  const bool surface = wall.wall == CylinderWall::SurfacePoints;
  if (surface && !(wall.surface_spacing > 0.0))
    throw InputError("reference.surface_spacing", std::to_string(wall.surface_spacing), "a positive spacing in cells");
  if (!(wall.mask_gap >= 0.0))
    throw InputError("reference.mask_gap", std::to_string(wall.mask_gap), "a gap >= 0 in cells");
  VelocityConstraints::check_geometry(g, radius);
  const double h = g.h();
  const double cy = 0.5 * g.length(1), cz = 0.5 * g.length(2);
  std::array<std::size_t, 4> offset{};
  for (int c = 0; c < 3; ++c) offset[c + 1] = offset[c] + g.size(c);

  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> t;
  int row = 0;
  // Mask rows: faces beyond the gap (ghost rows for GhostLinear).
  const double gap = surface ? wall.mask_gap * h : 0.0;
  auto radius_of = [&](const std::array<double, 3>& x) { return std::hypot(x[1] - cy, x[2] - cz); };
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          if (g.on_wall(c, 1, j) || g.on_wall(c, 2, k)) continue;
          if (!cylinder_outside(g, radius, c, j, k, gap)) continue;
          const auto x = g.position(c, i, j, k);
          const double r = radius_of(x);
          const std::size_t gi = offset[c] + MacGrid::index(d, i, j, k);
          if (wall.wall == CylinderWall::GhostLinear) {
            // fluid neighbour along y or z most aligned with the radial direction
            const double ny_ = (x[1] - cy) / r, nz_ = (x[2] - cz) / r;
            int best_dir = -1, best_idx = 0;
            double best_align = 0.0;
            for (int dir = 1; dir <= 2; ++dir)
              for (int s = -1; s <= 1; s += 2) {
                const int idx[3] = {i, j, k};
                const int tt = idx[dir] + s;
                if (tt < 0 || tt >= d[dir] || g.on_wall(c, dir, tt)) continue;
                int nb[3] = {i, j, k};
                nb[dir] = tt;
                if (radius_of(g.position(c, nb[0], nb[1], nb[2])) >= radius) continue;
                const double align = -s * (dir == 1 ? ny_ : nz_);  // neighbour lies inward
                if (align > best_align) {
                  best_align = align;
                  best_dir = dir;
                  best_idx = tt;
                }
              }
            if (best_dir > 0) {
              int nb[3] = {i, j, k};
              nb[best_dir] = best_idx;
              const auto xi = g.position(c, nb[0], nb[1], nb[2]);
              // crossing x_i + t (x - x_i) with r = Rc, t in (0, 1]
              const double ay = xi[1] - cy, az = xi[2] - cz, by = x[1] - xi[1], bz = x[2] - xi[2];
              const double A = by * by + bz * bz, B = 2 * (ay * by + az * bz), C = ay * ay + az * az - radius * radius;
              const double tc = std::clamp((-B + std::sqrt(std::max(0.0, B * B - 4 * A * C))) / (2 * A), 0.0, 1.0);
              t.emplace_back(row, offset[c] + MacGrid::index(d, nb[0], nb[1], nb[2]), 1.0 - tc);
              t.emplace_back(row++, gi, tc);
              continue;
            }
          }
          t.emplace_back(row++, gi, 1.0);
        }
  }
  const std::size_t n_mask = std::size_t(row);
  // Surface rows: bilinear interpolation in the (y,z) plane of every x-layer.
  if (surface) {
    const int m = std::max(8, int(std::ceil(2.0 * std::numbers::pi * radius / (wall.surface_spacing * h))));
    for (int c = 0; c < 3; ++c) {
      const auto d = g.dims(c);
      const double oy = MacGrid::offset(c, 1), oz = MacGrid::offset(c, 2);
      for (int q = 0; q < m; ++q) {
        const double th = 2.0 * std::numbers::pi * (q + 0.5) / m;
        const double fy = (cy + radius * std::cos(th)) / h - oy;
        const double fz = (cz + radius * std::sin(th)) / h - oz;
        const int j0 = int(std::floor(fy)), k0 = int(std::floor(fz));
        const double ty = fy - j0, tz = fz - k0;
        // (node index along a wall-bounded direction, weight) after the ghost fold / wall drop
        auto fold = [&](int dir, int idx, double w, int& out_idx, double& out_w) {
          const int n = d[dir];
          out_idx = idx;
          out_w = w;
          if (idx < 0) {  // ghost of a tangential component: u_ghost = -u_0
            out_idx = -idx - 1;
            out_w = -w;
          } else if (idx >= n) {
            out_idx = 2 * n - 1 - idx;
            out_w = -w;
          }
          if (g.on_wall(c, dir, out_idx)) out_w = 0.0;
        };
        for (int i = 0; i < d[0]; ++i) {
          std::vector<std::pair<std::size_t, double>> entries;
          for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) {
              int jj, kk;
              double wy, wz;
              fold(1, j0 + a, a ? ty : 1.0 - ty, jj, wy);
              fold(2, k0 + b, b ? tz : 1.0 - tz, kk, wz);
              const double w = wy * wz;
              if (w != 0.0) entries.emplace_back(offset[c] + MacGrid::index(d, i, jj, kk), w);
            }
          double norm2 = 0.0;
          for (const auto& e : entries) norm2 += e.second * e.second;
          if (norm2 < 1e-12) continue;
          for (const auto& e : entries) t.emplace_back(row, e.first, e.second);
          ++row;
        }
      }
    }
  }
  VelocityConstraints::Matrix E(row, static_cast<Eigen::Index>(offset[3]));
  E.setFromTriplets(t.begin(), t.end());
  E.makeCompressed();
  return VelocityConstraints(g, radius, std::move(E), n_mask);
}

}  // namespace swim::full3d::reference
