#include "full3d/container.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "common/errors.hpp"

namespace swim::full3d {

namespace {
using Triplet = Eigen::Triplet<double>;

std::string num(double v) { return std::to_string(v); }
}  // namespace

bool cylinder_outside(const MacGrid& g, double radius, int c, int j, int k, double gap) {
  const auto x = g.position(c, 0, j, k);
  return std::hypot(x[1] - 0.5 * g.length(1), x[2] - 0.5 * g.length(2)) > radius + gap;
}

VelocityConstraints::VelocityConstraints(const MacGrid& g, const CylinderOptions& opt) : grid_(g), rc_(opt.radius) {
  if (g.kind() != ContainerKind::SquareDuct)
    throw InputError("container", to_string(g.kind()), "the circular cylinder is built inside a square_duct grid");
  const double h = g.h();
  const double cy = 0.5 * g.length(1), cz = 0.5 * g.length(2);
  if (!(opt.radius > 0.0) || 2.0 * opt.radius > std::min(g.length(1), g.length(2)) * (1.0 + 1e-12))
    throw InputError("container.radius", num(opt.radius),
                     "a positive radius Rc with 2 Rc <= the duct side (" + num(std::min(g.length(1), g.length(2))) +
                         " m)");
  const bool surface = opt.wall == CylinderWall::SurfacePoints;
  if (surface && !(opt.surface_spacing > 0.0))
    throw InputError("container.surface_spacing", num(opt.surface_spacing), "a positive spacing in cells");
  if (!(opt.mask_gap >= 0.0)) throw InputError("container.mask_gap", num(opt.mask_gap), "a gap >= 0 in cells");

  offset_[0] = 0;
  for (int c = 0; c < 3; ++c) offset_[c + 1] = offset_[c] + g.size(c);
  const std::size_t total = offset_[3];

  std::vector<Triplet> t;
  int row = 0;
  // Mask rows: faces beyond the gap (ghost rows for GhostLinear).
  const double gap = surface ? opt.mask_gap * h : 0.0;
  auto radius_of = [&](const std::array<double, 3>& x) { return std::hypot(x[1] - cy, x[2] - cz); };
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          if (g.on_wall(c, 1, j) || g.on_wall(c, 2, k)) continue;
          if (!cylinder_outside(g, opt.radius, c, j, k, gap)) continue;
          const auto x = g.position(c, i, j, k);
          const double r = std::hypot(x[1] - cy, x[2] - cz);
          const std::size_t gi = offset_[c] + MacGrid::index(d, i, j, k);
          if (opt.wall == CylinderWall::GhostLinear) {
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
                if (radius_of(g.position(c, nb[0], nb[1], nb[2])) >= opt.radius) continue;
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
              const double A = by * by + bz * bz, B = 2 * (ay * by + az * bz), C = ay * ay + az * az - opt.radius * opt.radius;
              const double tc = std::clamp((-B + std::sqrt(std::max(0.0, B * B - 4 * A * C))) / (2 * A), 0.0, 1.0);
              t.emplace_back(row, offset_[c] + MacGrid::index(d, nb[0], nb[1], nb[2]), 1.0 - tc);
              t.emplace_back(row++, gi, tc);
              continue;
            }
          }
          t.emplace_back(row++, gi, 1.0);
        }
  }
  n_mask_ = std::size_t(row);
  // Surface rows: bilinear interpolation in the (y,z) plane of every x-layer.
  if (surface) {
    const int m = std::max(8, int(std::ceil(2.0 * std::numbers::pi * opt.radius / (opt.surface_spacing * h))));
    for (int c = 0; c < 3; ++c) {
      const auto d = g.dims(c);
      const double oy = MacGrid::offset(c, 1), oz = MacGrid::offset(c, 2);
      for (int q = 0; q < m; ++q) {
        const double th = 2.0 * std::numbers::pi * (q + 0.5) / m;
        const double fy = (cy + opt.radius * std::cos(th)) / h - oy;
        const double fz = (cz + opt.radius * std::sin(th)) / h - oz;
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
              if (w != 0.0) entries.emplace_back(offset_[c] + MacGrid::index(d, i, jj, kk), w);
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
  E_.resize(row, static_cast<Eigen::Index>(total));
  E_.setFromTriplets(t.begin(), t.end());
  E_.makeCompressed();

  // E E^T and E (-L) E^T, with -L restricted to the support of E (the only
  // entries these products need).
  std::vector<char> in_support(total, 0);
  for (int r = 0; r < E_.outerSize(); ++r)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(E_, r); it; ++it) in_support[it.col()] = 1;
  std::vector<Triplet> lt;
  const double ih2 = 1.0 / (h * h);
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i) {
          const std::size_t gi = offset_[c] + MacGrid::index(d, i, j, k);
          if (!in_support[gi]) continue;
          const int idx[3] = {i, j, k};
          double diag = 6.0;
          for (int dir = 0; dir < 3; ++dir)
            for (int s = -1; s <= 1; s += 2) {
              int nb[3] = {i, j, k};
              const int tt = idx[dir] + s;
              if (g.periodic(dir)) {
                nb[dir] = (tt + d[dir]) % d[dir];
              } else if (tt < 0 || tt >= d[dir]) {
                diag += 1.0;  // ghost value -u
                continue;
              } else {
                nb[dir] = tt;
                if (g.on_wall(c, dir, tt)) continue;  // held at zero
              }
              const std::size_t gj = offset_[c] + MacGrid::index(d, nb[0], nb[1], nb[2]);
              if (in_support[gj]) lt.emplace_back(gi, gj, -ih2);
            }
          lt.emplace_back(gi, gi, diag * ih2);
        }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> negL(static_cast<Eigen::Index>(total), static_cast<Eigen::Index>(total));
  negL.setFromTriplets(lt.begin(), lt.end());
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Et = E_.transpose();
  EEt_ = E_ * Et;
  ELEt_ = E_ * (negL * Et);
}

void VelocityConstraints::gather(const VectorField& u, std::vector<double>& out) const {
  out.assign(rows(), 0.0);
  for (int r = 0; r < E_.outerSize(); ++r) {
    double s = 0.0;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(E_, r); it; ++it) {
      const std::size_t gi = std::size_t(it.col());
      const int c = gi >= offset_[2] ? 2 : (gi >= offset_[1] ? 1 : 0);
      s += it.value() * u.c[c][gi - offset_[c]];
    }
    out[r] = s;
  }
}

void VelocityConstraints::scatter_add(const std::vector<double>& lam, double scale, VectorField& f) const {
  for (int r = 0; r < E_.outerSize(); ++r) {
    const double a = scale * lam[r];
    if (a == 0.0) continue;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(E_, r); it; ++it) {
      const std::size_t gi = std::size_t(it.col());
      const int c = gi >= offset_[2] ? 2 : (gi >= offset_[1] ? 1 : 0);
      f.c[c][gi - offset_[c]] += a * it.value();
    }
  }
}

void VelocityConstraints::apply_local_helmholtz(const std::vector<double>& r, std::vector<double>& z, double alpha,
                                                double mu) const {
  const Eigen::Map<const Eigen::VectorXd> rv(r.data(), Eigen::Index(r.size()));
  z.resize(r.size());
  Eigen::Map<Eigen::VectorXd> zv(z.data(), Eigen::Index(z.size()));
  zv = mu * (ELEt_ * rv);
  if (alpha != 0.0) zv += alpha * (EEt_ * rv);
}

bool VelocityConstraints::outside(int c, int /*i*/, int j, int k) const {
  return cylinder_outside(grid_, rc_, c, j, k);
}

}  // namespace swim::full3d
