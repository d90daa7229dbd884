// The no-slip duct of the capacitance Stokes solver (capacitance_stokes.hpp, "Woodbury"):
// the wall-adjacent tangential nodes and their symmetry basis, the partial transforms on the
// wall lines, the capacitance matrices C(kx) = Dg^{-1} + U^T S_fs(kx)^{-1} U and their factors,
// the exact axial mean of the x component, and the mode solve.
#include <algorithm>
#include <cmath>

#include "full3d/capacitance_impl.hpp"

namespace swim::full3d {

void CapacitanceStokes::Impl::setup_wall_nodes() {
  // wall nodes
  bv = 2 * nz + 2 * (ny - 2);
  bw = bv + 2 * (ny - 1);
  m = bw + 2 * (nz - 1);
  const double h = grid.h();
  dg_inv.assign(std::size_t(m), h * h / (2.0 * mu));
  for (int js = 0; js < 2; ++js) {  // corners of u touch two walls
    dg_inv[std::size_t(js) * nz] = h * h / (4.0 * mu);
    dg_inv[std::size_t(js) * nz + nz - 1] = h * h / (4.0 * mu);
  }

  build_symmetry();
}

// Wall node number of (component c, j, k) (the numbering above), and its image under Ry
// (dir 1) or Rz (dir 2) with the sign of the reflected component.
int CapacitanceStokes::Impl::node_of(int c, int j, int k) const {
  if (c == 0) {
    if (j == 0) return k;
    if (j == ny - 1) return nz + k;
    return 2 * nz + (k == 0 ? 0 : ny - 2) + j - 1;
  }
  if (c == 1) return bv + (k == 0 ? 0 : ny - 1) + j - 1;
  return bw + (j == 0 ? 0 : nz - 1) + k - 1;
}

void CapacitanceStokes::Impl::node_position(int a, int& c, int& j, int& k) const {
  if (a < 2 * nz) {
    c = 0, j = a < nz ? 0 : ny - 1, k = a % nz;
  } else if (a < bv) {
    const int r = a - 2 * nz;
    c = 0, k = r < ny - 2 ? 0 : nz - 1, j = r % (ny - 2) + 1;
  } else if (a < bw) {
    const int r = a - bv;
    c = 1, k = r < ny - 1 ? 0 : nz - 1, j = r % (ny - 1) + 1;
  } else {
    const int r = a - bw;
    c = 2, j = r < nz - 1 ? 0 : ny - 1, k = r % (nz - 1) + 1;
  }
}

void CapacitanceStokes::Impl::reflect(int& c, int& j, int& k, double& sign, int dir) const {
  if (dir == 1) {
    j = c == 1 ? ny - j : ny - 1 - j;
    if (c == 1) sign = -sign;
  } else {
    k = c == 2 ? nz - k : nz - 1 - k;
    if (c == 2) sign = -sign;
  }
}

void CapacitanceStokes::Impl::build_symmetry() {
  build_symmetry_with([&](int a, int g, int& node, double& sg) {
    int c, j, k;
    node_position(a, c, j, k);
    sg = 1.0;
    if (g & 1) reflect(c, j, k, sg, 1);
    if (g & 2) reflect(c, j, k, sg, 2);
    node = node_of(c, j, k);
  });
}

// out = U^T T^{-1} F (unnormalised inverse): the values at the wall nodes of the field
// with yz coefficients F, evaluated line by line (contraction across the line, then the
// dense 1D inverse along it): O(n^2) instead of a full 2D inverse transform.
void CapacitanceStokes::Impl::wall_values(const double* F, double* out, Scratch& s) const {
  const double* Fu = F + off[0];
  const double* Fv = F + off[1];
  const double* Fw = F + off[2];
  double* t = s.a0.data();
  // u on the rows j = 0, ny-1
  for (int js = 0; js < 2; ++js) {
    const double* cy = dy.ci.data() + std::size_t(js ? ny - 1 : 0) * ny;
    for (int mz = 0; mz < nz; ++mz) {
      const double* f = Fu + std::size_t(mz) * ny;
      double acc = 0.0;
      for (int my = 0; my < ny; ++my) acc += cy[my] * f[my];
      t[mz] = acc;
    }
    for (int k = 0; k < nz; ++k) {
      const double* cz = dz.ci.data() + std::size_t(k) * nz;
      double acc = 0.0;
      for (int mz = 0; mz < nz; ++mz) acc += cz[mz] * t[mz];
      out[js * nz + k] = acc;
    }
  }
  // u on the columns k = 0, nz-1 (j = 1..ny-2) and v on the same columns (j = 1..ny-1)
  for (int ks = 0; ks < 2; ++ks) {
    const double* cz = dz.ci.data() + std::size_t(ks ? nz - 1 : 0) * nz;
    std::fill(t, t + ny, 0.0);
    double* tv = s.a1.data();
    std::fill(tv, tv + ny, 0.0);
    for (int mz = 0; mz < nz; ++mz) {
      const double c = cz[mz];
      const double* fu = Fu + std::size_t(mz) * ny;
      const double* fv = Fv + std::size_t(mz) * (ny + 1);
      for (int my = 0; my < ny; ++my) t[my] += c * fu[my];
      for (int my = 1; my < ny; ++my) tv[my] += c * fv[my];
    }
    for (int j = 1; j < ny - 1; ++j) {
      const double* cy = dy.ci.data() + std::size_t(j) * ny;
      double acc = 0.0;
      for (int my = 0; my < ny; ++my) acc += cy[my] * t[my];
      out[2 * nz + ks * (ny - 2) + j - 1] = acc;
    }
    for (int j = 1; j < ny; ++j) {
      const double* sy = dy.sn.data() + std::size_t(j) * ny;
      double acc = 0.0;
      for (int my = 1; my < ny; ++my) acc += sy[my] * tv[my];
      out[bv + ks * (ny - 1) + j - 1] = acc;
    }
  }
  // w on the rows j = 0, ny-1 (interior z faces k = 1..nz-1)
  for (int js = 0; js < 2; ++js) {
    const double* cy = dy.ci.data() + std::size_t(js ? ny - 1 : 0) * ny;
    for (int mz = 1; mz < nz; ++mz) {
      const double* f = Fw + std::size_t(mz) * ny;
      double acc = 0.0;
      for (int my = 0; my < ny; ++my) acc += cy[my] * f[my];
      t[mz] = acc;
    }
    for (int k = 1; k < nz; ++k) {
      const double* sz = dz.sn.data() + std::size_t(k) * nz;
      double acc = 0.0;
      for (int mz = 1; mz < nz; ++mz) acc += sz[mz] * t[mz];
      out[bw + js * (nz - 1) + k - 1] = acc;
    }
  }
}

// R = T U z (unnormalised forward yz transform of the field equal to z on the wall nodes
// and zero elsewhere): per line a dense 1D transform along it, then the rank-one spread
// across it (the line's cross-direction basis values). Writes every coefficient of u, v, w.
void CapacitanceStokes::Impl::wall_transform(const double* z, double* R, Scratch& s) const {
  double* Ru = R + off[0];
  double* Rv = R + off[1];
  double* Rw = R + off[2];
  const int jl = ny - 1, kl = nz - 1;
  double *a0 = s.a0.data(), *a1 = s.a1.data(), *b0 = s.b0.data(), *b1 = s.b1.data();
  // u: rows j = 0 / ny-1 transformed along z (a), columns k = 0 / nz-1 along y (b)
  for (int mz = 0; mz < nz; ++mz) {
    const double* cz = dz.cf.data() + std::size_t(mz) * nz;
    double s0 = 0.0, s1 = 0.0;
    for (int k = 0; k < nz; ++k) {
      s0 += cz[k] * z[k];
      s1 += cz[k] * z[nz + k];
    }
    a0[mz] = s0;
    a1[mz] = s1;
  }
  for (int my = 0; my < ny; ++my) {
    const double* cy = dy.cf.data() + std::size_t(my) * ny;
    double s0 = 0.0, s1 = 0.0;
    for (int j = 1; j < ny - 1; ++j) {
      s0 += cy[j] * z[2 * nz + j - 1];
      s1 += cy[j] * z[2 * nz + (ny - 2) + j - 1];
    }
    b0[my] = s0;
    b1[my] = s1;
  }
  for (int mz = 0; mz < nz; ++mz) {
    const double cz0 = dz.cf[std::size_t(mz) * nz], cz1 = dz.cf[std::size_t(mz) * nz + kl];
    double* r = Ru + std::size_t(mz) * ny;
    for (int my = 0; my < ny; ++my) {
      const double cy0 = dy.cf[std::size_t(my) * ny], cy1 = dy.cf[std::size_t(my) * ny + jl];
      r[my] = cy0 * a0[mz] + cy1 * a1[mz] + cz0 * b0[my] + cz1 * b1[my];
    }
  }
  // v: columns k = 0 / nz-1, sine transform along y
  for (int my = 1; my < ny; ++my) {
    const double* sy = dy.sn.data() + std::size_t(my) * ny;
    double s0 = 0.0, s1 = 0.0;
    for (int j = 1; j < ny; ++j) {
      s0 += sy[j] * z[bv + j - 1];
      s1 += sy[j] * z[bv + (ny - 1) + j - 1];
    }
    b0[my] = s0;
    b1[my] = s1;
  }
  for (int mz = 0; mz < nz; ++mz) {
    const double cz0 = dz.cf[std::size_t(mz) * nz], cz1 = dz.cf[std::size_t(mz) * nz + kl];
    double* r = Rv + std::size_t(mz) * (ny + 1);
    for (int my = 1; my < ny; ++my) r[my] = cz0 * b0[my] + cz1 * b1[my];
  }
  // w: rows j = 0 / ny-1, sine transform along z
  for (int mz = 1; mz < nz; ++mz) {
    const double* sz = dz.sn.data() + std::size_t(mz) * nz;
    double s0 = 0.0, s1 = 0.0;
    for (int k = 1; k < nz; ++k) {
      s0 += sz[k] * z[bw + k - 1];
      s1 += sz[k] * z[bw + (nz - 1) + k - 1];
    }
    a0[mz] = s0;
    a1[mz] = s1;
  }
  for (int mz = 1; mz < nz; ++mz) {
    double* r = Rw + std::size_t(mz) * ny;
    for (int my = 0; my < ny; ++my) {
      const double cy0 = dy.cf[std::size_t(my) * ny], cy1 = dy.cf[std::size_t(my) * ny + jl];
      r[my] = cy0 * a0[mz] + cy1 * a1[mz];
    }
  }
}

// Capacitance matrix of mode kx: C = Dg^{-1} + U^T S_fs(kx)^{-1} U, one unit solve per column.
Eigen::MatrixXd CapacitanceStokes::Impl::capacitance(int kx, double gx, Scratch& s) const {
  const double syz = 1.0 / (4.0 * ny * nz);
  Eigen::MatrixXd C(m, m);
  std::fill(s.e.begin(), s.e.end(), 0.0);
  for (int a = 0; a < m; ++a) {
    s.e[a] = 1.0;
    wall_transform(s.e.data(), s.r.data(), s);
    apply_M(s.r.data(), s.y.data(), gx, s, syz, false);
    wall_values(s.y.data(), C.col(a).data(), s);
    C(a, a) += dg_inv[a];
    s.e[a] = 0.0;
  }
  if (kx == 0) {
    // the x component of the axial mean is solved separately (solve_mean_x); its nodes are
    // decoupled from v, w here (g_x = 0: exact zeros), so their block is replaced by I
    const int nu = bv;
    C.topLeftCorner(nu, nu).setIdentity();
  }
  // S_fs^{-1} is symmetric: remove the round-off asymmetry before Cholesky
  return 0.5 * (C + C.transpose());
}

// Exact no-slip solve of the axial mean of the x component (plane 0, u part, real space,
// x-unnormalised) in place: u = (alpha - mu L_ns)^{-1} b, scaled by 1/nx like the planes.
void CapacitanceStokes::Impl::solve_mean_x(double* f, double alpha) {
  std::copy_n(f, std::size_t(ny) * nz, u0.data());
  u0_fwd.execute();
  const double scale = 1.0 / (4.0 * ny * nz * nx);
  for (std::size_t i = 0; i < u0_lam.size(); ++i) u0[i] *= scale / (alpha + mu * u0_lam[i]);
  u0_inv.execute();
  std::copy_n(u0.data(), std::size_t(ny) * nz, f);
}

// The Woodbury correction of mode kx on its np planes F, which hold the free-slip solution
// Y = M T b: wall values U^T y, z = C^{-1} U^T y, X = Y - M T (U z), normalised.
void CapacitanceStokes::Impl::correct_walls(int kx, double* const F[2], int np, double gx, const Factors& fac,
                                            Scratch& s) const {
  const double syz = 1.0 / (4.0 * ny * nz), inv_n = syz / nx;
  for (int q = 0; q < np; ++q) wall_values(F[q], s.w.col(q).data(), s);
  // (syz: the normalisation of the inverse transform)
  for (int q = 0; q < np; ++q)
    for (int i = 0; i < m; ++i) s.w(i, q) *= syz;
  // to the symmetry-adapted basis (s.e: 2 columns of m), the four block solves, and back
  block_solve(fac.chol[kx], np, s);
  for (int q = 0; q < np; ++q) {
    wall_transform(s.w.col(q).data(), s.r.data(), s);
    apply_M(s.r.data(), F[q], gx, s, inv_n, true);
  }
}

}  // namespace swim::full3d
