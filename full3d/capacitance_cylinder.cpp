// The staircase cylinder of the capacitance Stokes solver (capacitance_stokes.hpp,
// "Staircase cylinder"): the face layout and the ring, the null space of the ring
// capacitance and its lift, the capacitance matrices and their factors, the sparse
// axial-mean problem, and the mode solve.
#include <algorithm>
#include <cmath>

#include "common/dot.hpp"
#include "full3d/capacitance_impl.hpp"

namespace swim::full3d {

namespace {

// Staircase-cylinder layout of the cross-section. Face status per component c (0..2) at
// (j, k) of the dims(c)[1] x dims(c)[2] cross-section: kWall (duct wall face, zero in both
// the free-slip and the no-slip problem), kFree, kRing (outside r = Rc and in the stencil of
// a free face's momentum row -- lateral neighbour of the same component, the MAC Laplacian
// being componentwise and x-neighbours sharing (j, k) -- or of the continuity row of a fluid
// cell), kOuter (outside, in no fluid equation).
enum : char { kWall = 0, kFree = 1, kRing = 2, kOuter = 3 };
struct CylinderLayout {
  std::array<std::array<int, 3>, 3> d{};
  std::array<std::vector<char>, 3> st;
  std::vector<char> fluid;  // per cell k ny + j: has a free face (carries a pressure)
  int ring = 0;
  bool wall_nodes_masked = true;  // every wall-adjacent tangential node is outside
  char at(int c, int j, int k) const {
    if (j < 0 || k < 0 || j >= d[c][1] || k >= d[c][2]) return kWall;
    return st[c][std::size_t(k) * d[c][1] + j];
  }
};
CylinderLayout cylinder_layout(const MacGrid& g, double radius) {
  CylinderLayout L;
  const int ny = g.ny(), nz = g.nz();
  for (int c = 0; c < 3; ++c) {
    L.d[c] = g.dims(c);
    L.st[c].assign(std::size_t(L.d[c][1]) * L.d[c][2], kWall);
    for (int k = 0; k < L.d[c][2]; ++k)
      for (int j = 0; j < L.d[c][1]; ++j)
        if (!g.on_wall(c, 1, j) && !g.on_wall(c, 2, k))
          L.st[c][std::size_t(k) * L.d[c][1] + j] = cylinder_outside(g, radius, c, j, k) ? kOuter : kFree;
  }
  L.fluid.assign(std::size_t(ny) * nz, 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      L.fluid[std::size_t(k) * ny + j] = L.at(0, j, k) == kFree || L.at(1, j, k) == kFree ||
                                         L.at(1, j + 1, k) == kFree || L.at(2, j, k) == kFree ||
                                         L.at(2, j, k + 1) == kFree;
  auto fluid = [&](int j, int k) { return j >= 0 && k >= 0 && j < ny && k < nz && L.fluid[std::size_t(k) * ny + j]; };
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < L.d[c][2]; ++k)
      for (int j = 0; j < L.d[c][1]; ++j) {
        char& s = L.st[c][std::size_t(k) * L.d[c][1] + j];
        if (s != kOuter) continue;
        bool r = L.at(c, j - 1, k) == kFree || L.at(c, j + 1, k) == kFree || L.at(c, j, k - 1) == kFree ||
                 L.at(c, j, k + 1) == kFree;
        if (c == 0) r = r || fluid(j, k);
        if (c == 1) r = r || fluid(j - 1, k) || fluid(j, k);
        if (c == 2) r = r || fluid(j, k - 1) || fluid(j, k);
        if (r) {
          s = kRing;
          ++L.ring;
        }
      }
  // wall-adjacent tangential nodes: u on j = 0, ny-1 or k = 0, nz-1; v on k = 0, nz-1; w on j = 0, ny-1
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      const bool edge_y = j == 0 || j == ny - 1, edge_z = k == 0 || k == nz - 1;
      if ((edge_y || edge_z) && L.at(0, j, k) == kFree) L.wall_nodes_masked = false;
    }
  for (int k : {0, nz - 1})
    for (int j = 1; j < ny; ++j)
      if (L.at(1, j, k) == kFree) L.wall_nodes_masked = false;
  for (int j : {0, ny - 1})
    for (int k = 1; k < nz; ++k)
      if (L.at(2, j, k) == kFree) L.wall_nodes_masked = false;
  return L;
}

bool cylinder_radius_valid(const MacGrid& g, double radius) {
  return g.boundary() == GridBoundary::SquareDuct && radius > 0.0 &&
         2.0 * radius <= std::min(g.length(1), g.length(2)) * (1.0 + 1e-12);
}

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

}  // namespace

void CapacitanceStokes::Impl::setup_cylinder(double radius) {
  if (!cylinder_radius_valid(grid, radius))
    throw InputError("container.radius", std::to_string(radius), "a positive radius Rc with 2 Rc <= the duct side");
  const CylinderLayout L = cylinder_layout(grid, radius);
  if (!L.wall_nodes_masked)
    throw InputError("container.radius", std::to_string(radius),
                     "the capacitance cylinder solver needs every wall-adjacent tangential face outside the "
                     "cylinder (radius <= duct half-width - h/2); use a smaller radius");
  cyl = true;
  const double h = grid.h();
  row_masked.assign(std::size_t(off[3]), 0);
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < L.d[c][2]; ++k)
      for (int j = 0; j < L.d[c][1]; ++j) {
        const char st = L.at(c, j, k);
        const int row = off[c] + k * L.d[c][1] + j;
        row_masked[row] = st != kFree;
        if (st == kRing) {
          ring.push_back(row);
          ring_c.push_back(char(c));
        }
      }
  m = int(ring.size());
  cell_fluid = L.fluid;
  // groups of cells connected through free or outer y/z faces
  std::vector<int> parent(std::size_t(ny) * nz);
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = int(i);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      const int cell = k * ny + j;
      const char sv = L.at(1, j, k), sw = L.at(2, j, k);
      if (j > 0 && (sv == kFree || sv == kOuter)) parent[find_root(parent, cell)] = find_root(parent, cell - 1);
      if (k > 0 && (sw == kFree || sw == kOuter)) parent[find_root(parent, cell)] = find_root(parent, cell - ny);
    }
  std::vector<int> root(parent.size());
  std::vector<char> has_x(parent.size(), 0);  // group has a free or outer x face
  for (std::size_t i = 0; i < parent.size(); ++i) {
    root[i] = find_root(parent, int(i));
    const char su = L.st[0][i];
    if (su == kFree || su == kOuter) has_x[root[i]] = 1;
  }
  std::vector<NullVec> grp(parent.size());
  for (int a = 0; a < m; ++a) {
    const int c = ring_c[a], r = ring[a] - off[c];
    const int j = r % L.d[c][1], k = r / L.d[c][1];
    if (c == 0) {
      grp[root[std::size_t(k) * ny + j]].ux.push_back(a);
    } else {
      // y face j between cells j-1 and j: (q_j - q_{j-1})/h (likewise z)
      const int c1 = k * ny + j, c0 = c == 1 ? c1 - 1 : c1 - ny;
      if (root[c1] != root[c0]) {
        grp[root[c1]].yz.emplace_back(a, 1.0 / h);
        grp[root[c0]].yz.emplace_back(a, -1.0 / h);
      }
    }
  }
  for (std::size_t i = 0; i < grp.size(); ++i) {
    if (root[i] != int(i)) continue;
    if (!grp[i].yz.empty()) null0.push_back(NullVec{grp[i].yz, {}});
    if (!has_x[i] && (!grp[i].yz.empty() || !grp[i].ux.empty())) null1.push_back(grp[i]);
  }
  u0_id.assign(std::size_t(ny) * nz, -1);
  for (std::size_t i = 0; i < u0_id.size(); ++i)
    if (L.st[0][i] == kFree) u0_id[i] = u0_n++;

  // Reflection symmetry. When the face statuses are invariant under Ry and Rz (the centred
  // staircase; the mask is computed in floating point, so it is checked, not assumed), the
  // ring maps onto itself, C(kx) and the lift N N^T commute with both reflections (the
  // groups map onto groups), and the capacitance splits into the four character blocks
  // (as for the duct's wall nodes); C is then assembled from one column per orbit. Otherwise
  // one block of order m.
  auto refl = [&](int c, int& j, int& k, double& sg, int g) {
    if (g & 1) {
      j = c == 1 ? ny - j : ny - 1 - j;
      if (c == 1) sg = -sg;
    }
    if (g & 2) {
      k = c == 2 ? nz - k : nz - 1 - k;
      if (c == 2) sg = -sg;
    }
  };
  sym_ok = true;
  for (int c = 0; c < 3 && sym_ok; ++c)
    for (int k = 0; k < L.d[c][2] && sym_ok; ++k)
      for (int j = 0; j < L.d[c][1] && sym_ok; ++j)
        for (int g = 1; g < 4; ++g) {
          int jj = j, kk = k;
          double sg = 1.0;
          refl(c, jj, kk, sg, g);
          if (L.at(c, jj, kk) != L.at(c, j, k)) sym_ok = false;
        }
  std::vector<int> ring_of_row(std::size_t(off[3]), -1);
  for (int a = 0; a < m; ++a) ring_of_row[ring[a]] = a;
  for (int g = 0; g < 4; ++g) {
    ring_img[g].assign(std::size_t(m), 0);
    ring_sgn[g].assign(std::size_t(m), 1.0);
  }
  if (sym_ok) {
    for (int a = 0; a < m; ++a) {
      const int c = ring_c[a], r = ring[a] - off[c];
      const int d1 = L.d[c][1];
      for (int g = 0; g < 4; ++g) {
        int j = r % d1, k = r / d1;
        double sg = 1.0;
        refl(c, j, k, sg, g);
        ring_img[g][a] = ring_of_row[std::size_t(off[c] + k * d1 + j)];
        ring_sgn[g][a] = sg;
      }
    }
    build_symmetry_with([&](int a, int g, int& node, double& sg) {
      node = ring_img[g][a];
      sg = ring_sgn[g][a];
    });
    std::vector<char> done(std::size_t(m), 0);
    for (int a = 0; a < m; ++a)
      if (!done[a]) {
        orbit_rep.push_back(a);
        for (int g = 0; g < 4; ++g) done[ring_img[g][a]] = 1;
      }
  } else {
    sym.assign(std::size_t(m), SymVec{});
    for (int a = 0; a < m; ++a) {
      sym[a].n = 1;
      sym[a].node[0] = a;
      sym[a].w[0] = 1.0;
      ring_img[0][a] = a;
      orbit_rep.push_back(a);
    }
    cls_off = {0, m, m, m, m};
    factor_doubles = PackedCholesky::packed_size(m);
  }
}

// Sparse (alpha - mu L) of the axial mean x component on the free u faces of the cross-section
// (5-point, masked neighbours zero, duct-wall ghost -u), Cholesky-factorised.
std::unique_ptr<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>> CapacitanceStokes::Impl::factor_mean_x(
    double alpha) const {
  const double ih2 = 1.0 / (grid.h() * grid.h());
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      const int i = u0_id[std::size_t(k) * ny + j];
      if (i < 0) continue;
      double diag = alpha + 4.0 * mu * ih2;
      const int nb[4][2] = {{j - 1, k}, {j + 1, k}, {j, k - 1}, {j, k + 1}};
      for (const auto& q : nb) {
        if (q[0] < 0 || q[0] >= ny || q[1] < 0 || q[1] >= nz) {
          diag += mu * ih2;  // ghost u = -u_0 across the duct wall
          continue;
        }
        const int n = u0_id[std::size_t(q[1]) * ny + q[0]];
        if (n >= 0) t.emplace_back(i, n, -mu * ih2);
      }
      t.emplace_back(i, i, diag);
    }
  Eigen::SparseMatrix<double> A(u0_n, u0_n);
  A.setFromTriplets(t.begin(), t.end());
  auto llt = std::make_unique<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>>(A);
  if (llt->info() != Eigen::Success)
    throw NumericalError("axial-mean factorisation of the cylinder capacitance solver failed",
                         "change the grid (full3d.grid.cells_across)");
  return llt;
}

// ---- cylinder: capacitance, factorisation and mode solve --------------------------------
// Unnormalised forward yz transform of the unit field at ring node a, written into the
// coefficient slots of R (u, v, w parts; all other slots left untouched, zero): separable,
// the product of the 1D basis values across y and z.
void CapacitanceStokes::Impl::ring_unit_transform(int a, double* R) const {
  const int c = ring_c[a], r = ring[a] - off[c];
  const int d1 = c == 1 ? ny + 1 : ny;
  const int j = r % d1, k = r / d1;
  double* X = R + off[c];
  if (c == 0) {
    for (int mz = 0; mz < nz; ++mz) {
      const double cz = dz.cf[std::size_t(mz) * nz + k];
      for (int my = 0; my < ny; ++my) X[std::size_t(mz) * ny + my] = cz * dy.cf[std::size_t(my) * ny + j];
    }
  } else if (c == 1) {
    for (int mz = 0; mz < nz; ++mz) {
      const double cz = dz.cf[std::size_t(mz) * nz + k];
      for (int my = 1; my < ny; ++my) X[std::size_t(mz) * (ny + 1) + my] = cz * dy.sn[std::size_t(my) * ny + j];
    }
  } else {
    for (int mz = 1; mz < nz; ++mz) {
      const double sz = dz.sn[std::size_t(mz) * nz + k];
      for (int my = 0; my < ny; ++my) X[std::size_t(mz) * ny + my] = sz * dy.cf[std::size_t(my) * ny + j];
    }
  }
}

void CapacitanceStokes::Impl::clear_ring_unit(int a, double* R) const {
  const int c = ring_c[a];
  const std::size_t n = c == 1 ? std::size_t(nz) * (ny + 1) : c == 2 ? std::size_t(nz + 1) * ny : std::size_t(nz) * ny;
  std::fill(R + off[c], R + off[c] + n, 0.0);
}

// Capacitance of mode kx for the cylinder: C = E_R S_fs(kx)^{-1} E_R^T + s N N^T (see the
// header): one unit solve per column (separable forward transform, spectral projection, three
// inverse 2D transforms, gather on the ring). kx = 0: the ring x faces are decoupled
// (g_x = 0, exact zeros) and solved separately; their block is replaced by I.
Eigen::MatrixXd CapacitanceStokes::Impl::capacitance_cyl(int kx, double gx, Scratch& s) const {
  const double syz = 1.0 / (4.0 * ny * nz);
  double* fb = s.fb.data();
  std::fill(s.r.begin(), s.r.end(), 0.0);
  Eigen::MatrixXd C(m, m);
  for (int a : orbit_rep) {
    ring_unit_transform(a, s.r.data());
    apply_M(s.r.data(), fb, gx, s, syz, false);
    clear_ring_unit(a, s.r.data());
    double* col = C.col(a).data();
    ring_values(fb, 1.0, col, s.tb.data());
    if (sym_ok)  // C(g b, g a) = sign_g(b) sign_g(a) C(b, a)
      for (int g = 1; g < 4; ++g) {
        const int ga = ring_img[g][a];
        if (ga == a) continue;
        double* cg = C.col(ga).data();
        const double sa = ring_sgn[g][a];
        for (int b = 0; b < m; ++b) cg[ring_img[g][b]] = ring_sgn[g][b] * sa * col[b];
      }
  }
  // s: the mean diagonal of the coupled part, the scale of the null-space lift (and of the
  // decoupled kx = 0 x block); with s far from the spectrum of C the Cholesky factor of the
  // lifted matrix would mix round-off of the lifted directions into the others
  double sc = 0.0;
  int ns = 0;
  for (int a = 0; a < m; ++a)
    if (kx != 0 || ring_c[a] != 0) {
      sc += C(a, a);
      ++ns;
    }
  sc = ns ? sc / ns : 1.0;
  if (kx == 0)
    for (int a = 0; a < m; ++a)
      if (ring_c[a] == 0) {
        C.row(a).setZero();
        C.col(a).setZero();
        C(a, a) = sc;
      }
  Eigen::MatrixXd Cs = 0.5 * (C + C.transpose());
  // lift the null space: + s n n^T per (normalised) null vector
  std::vector<std::pair<int, double>> v;
  for (const NullVec& nv : kx == 0 ? null0 : null1) {
    v = nv.yz;
    if (kx != 0)
      for (int a : nv.ux) v.emplace_back(a, gx);
    double n2 = 0.0;
    for (const auto& e : v) n2 += e.second * e.second;
    if (!(n2 > 0.0)) continue;
    for (const auto& e : v)
      for (const auto& f : v) Cs(e.first, f.first) += sc * e.second * f.second / n2;
  }
  return Cs;
}

// The ring correction of mode kx on its np planes F, which hold the free-slip solution
// Y = M T b: ring values y_R (3 inverse transforms of a copy), lam = C^{-1} y_R,
// X = Y - M T E_R^T lam (3 forward transforms).
void CapacitanceStokes::Impl::correct_ring(int kx, double* const F[2], int np, double gx, const Factors& fac,
                                           Scratch& s) const {
  double* fb = s.fb.data();
  const double syz = 1.0 / (4.0 * ny * nz), inv_n = syz / nx;
  for (int q = 0; q < np; ++q) {
    double* w = s.w.col(q).data();
    ring_values(F[q], syz, w, s.tb.data());
    if (kx == 0)
      for (int a = 0; a < m; ++a)
        if (ring_c[a] == 0) w[a] = 0.0;
  }
  block_solve(fac.chol[kx], np, s);
  for (int q = 0; q < np; ++q) {
    ring_forward(s.w.col(q).data(), fb, s.tb.data());
    apply_M(fb, F[q], gx, s, inv_n, true);
  }
}

// The 2D transforms are separable: the inverse across z runs over every y column (dense line
// transforms), the inverse along y only at the ring nodes (a contiguous dot product along the
// node's z row); the forward transform of a ring-supported field likewise, the sums along y
// first. About half the work of the three full 2D transforms each.
void CapacitanceStokes::Impl::ring_values(const double* F, double scale, double* w, double* tmp) const {
  for (int c = 0; c < 3; ++c) {
    const YzLayout& l = yz[c];
    l.iz->across(F + yz_at[c], l.row, tmp + yz_at[c], l.row, l.ly);
  }
  for (int a = 0; a < m; ++a) {
    const int c = ring_c[a], row = c == 1 ? ny + 1 : ny, r = ring[a] - off[c];
    const int j = r % row, k = r / row;
    const double* t = tmp + off[c] + std::size_t(k) * row;  // z row k: coefficients along y
    double v;
    if (c == 1)  // faces along y: RODFT00 on faces 1..ny-1
      v = dot4(t + 1, dy.sn.data() + std::size_t(j) * ny + 1, ny - 1);
    else  // cells along y: REDFT01
      v = dot4(t, dy.ci.data() + std::size_t(j) * ny, ny);
    w[a] = scale * v;
  }
}

void CapacitanceStokes::Impl::ring_forward(const double* z, double* fb, double* tmp) const {
  std::fill(tmp, tmp + off[3], 0.0);
  for (int a = 0; a < m; ++a) {
    const int c = ring_c[a], row = c == 1 ? ny + 1 : ny, r = ring[a] - off[c];
    const int j = r % row, k = r / row;
    double* t = tmp + off[c] + std::size_t(k) * row;  // z row k: coefficients along y
    const double za = z[a];
    if (c == 1) {  // faces along y: RODFT00 on faces 1..ny-1
      const double* b = dy.sn.data() + std::size_t(j) * ny;  // symmetric: sn[j ny + my] = sn[my ny + j]
      for (int my = 1; my < ny; ++my) t[my] += za * b[my];
    } else {  // cells along y: REDFT10
      const double* b = dy.cft.data() + std::size_t(j) * ny;
      for (int my = 0; my < ny; ++my) t[my] += za * b[my];
    }
  }
  zero_wall_slots(fb);  // the slots no transform writes
  for (int c = 0; c < 3; ++c) {
    const YzLayout& l = yz[c];
    l.fz->across(tmp + yz_at[c], l.row, fb + yz_at[c], l.row, l.ly);
  }
}

// Exact axial mean of u on the free faces (masked ones 0) into u (plane 0, real space),
// scaled by 1/nx like the planes; its right-hand side was kept in s.y.
void CapacitanceStokes::Impl::mean_x_ring(double* u, const Factors& fac, Scratch& s) const {
  for (std::size_t i = 0; i < u0_id.size(); ++i)
    if (u0_id[i] >= 0) s.u0b[u0_id[i]] = s.y[i];
  s.u0x = fac.u0llt->solve(s.u0b);
  for (std::size_t i = 0; i < u0_id.size(); ++i) u[i] = u0_id[i] >= 0 ? s.u0x[u0_id[i]] / nx : 0.0;
}

bool CapacitanceStokes::supports_cylinder(const MacGrid& g, const CylinderOptions& cylinder) {
  if (!cylinder_radius_valid(g, cylinder.radius)) return false;
  return cylinder_layout(g, cylinder.radius).wall_nodes_masked;
}

std::size_t CapacitanceStokes::estimate_bytes(const MacGrid& g, const CylinderOptions* cylinder) {
  if (!cylinder) return estimate_bytes(g);
  const std::size_t m = std::size_t(cylinder_layout(g, cylinder->radius).ring);
  // packed dense factors per mode, plus the sparse axial-mean factor (bounded by a band of n)
  const std::size_t cells = std::size_t(g.ny()) * g.nz();
  return std::size_t(g.nx() / 2 + 1) * (m * (m + 1) / 2) * sizeof(double) +
         cells * std::size_t(std::max(g.ny(), g.nz())) * (sizeof(double) + sizeof(int));
}

}  // namespace swim::full3d
