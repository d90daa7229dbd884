#include "full3d/container.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "common/errors.hpp"
#include "full3d/operators.hpp"

namespace swim::full3d {

namespace {
std::string num(double v) { return std::to_string(v); }
}  // namespace

bool cylinder_outside(const MacGrid& g, double radius, int c, int j, int k, double gap) {
  const auto x = g.position(c, 0, j, k);
  return std::hypot(x[1] - 0.5 * g.length(1), x[2] - 0.5 * g.length(2)) > radius + gap;
}

void VelocityConstraints::check_geometry(const MacGrid& g, double radius) {
  if (g.boundary() != GridBoundary::SquareDuct)
    throw InputError("container", to_string(g.boundary()), "the circular cylinder is built inside a square_duct grid");
  if (!(radius > 0.0) || 2.0 * radius > std::min(g.length(1), g.length(2)) * (1.0 + 1e-12))
    throw InputError("container.radius", num(radius),
                     "a positive radius Rc with 2 Rc <= the duct side (" + num(std::min(g.length(1), g.length(2))) +
                         " m)");
}

VelocityConstraints::VelocityConstraints(const MacGrid& g, double radius, Matrix E, std::size_t mask_rows)
    : grid_(g), rc_(radius), n_mask_(mask_rows), E_(std::move(E)) {
  check_geometry(g, radius);
  offset_[0] = 0;
  for (int c = 0; c < 3; ++c) offset_[c + 1] = offset_[c] + g.size(c);
  if (std::size_t(E_.cols()) != offset_[3] || mask_rows > rows())
    throw InputError("constraint rows", std::to_string(E_.rows()) + " x " + std::to_string(E_.cols()),
                     "one column per face (" + std::to_string(offset_[3]) + ") and mask_rows <= rows");
}

VelocityConstraints::VelocityConstraints(const MacGrid& g, const CylinderOptions& opt) : grid_(g), rc_(opt.radius) {
  check_geometry(g, opt.radius);
  offset_[0] = 0;
  for (int c = 0; c < 3; ++c) offset_[c + 1] = offset_[c] + g.size(c);
  std::vector<Eigen::Triplet<double>> t;
  int row = 0;
  for (int c = 0; c < 3; ++c) {
    const auto d = g.dims(c);
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j) {
        if (g.on_wall(c, 1, j) || g.on_wall(c, 2, k) || !cylinder_outside(g, opt.radius, c, j, k)) continue;
        for (int i = 0; i < d[0]; ++i) t.emplace_back(row++, offset_[c] + MacGrid::index(d, i, j, k), 1.0);
      }
  }
  n_mask_ = std::size_t(row);
  E_.resize(row, static_cast<Eigen::Index>(offset_[3]));
  E_.setFromTriplets(t.begin(), t.end());
  E_.makeCompressed();
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

bool VelocityConstraints::outside(int c, int /*i*/, int j, int k) const {
  return cylinder_outside(grid_, rc_, c, j, k);
}

void recover_multiplier(const VelocityConstraints& con, const VectorField& b, const VectorField& u,
                        const ScalarField& p, double alpha, double mu, std::vector<double>& lam) {
  const MacGrid& g = con.grid();
  VectorField r(g), gp(g);
  laplacian(g, u, r);
  gradient(g, p, gp);
  for (int c = 0; c < 3; ++c)
    for (std::size_t m = 0; m < r.c[c].size(); ++m)
      r.c[c][m] = b.c[c][m] - alpha * u.c[c][m] + mu * r.c[c][m] - gp.c[c][m];
  con.gather(r, lam);
}

}  // namespace swim::full3d
