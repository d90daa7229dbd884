#include "full3d/membrane.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>

#include "common/errors.hpp"
#include "full3d/parallel.hpp"

namespace swim::full3d {

namespace {
constexpr double kPi = std::numbers::pi;
using V3 = Eigen::Vector3d;

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}
}  // namespace

CylinderMesh make_cylinder(double R0, double L, int n_theta, const Eigen::Vector3d& axis_start) {
  if (!(R0 > 0.0)) throw InputError("swimmer.R0", num(R0), "a positive radius in m");
  if (!(L > 0.0)) throw InputError("swimmer.L", num(L), "a positive length in m");
  if (n_theta < 3) throw InputError("swimmer.n_theta", std::to_string(n_theta), "an integer >= 3");
  CylinderMesh m;
  m.radius = R0;
  m.length = L;
  m.n_theta = n_theta;
  m.axis_start = axis_start;
  const double chord = 2.0 * R0 * std::sin(kPi / n_theta);
  const double half = 2.0 * R0 * std::sin(kPi / (2.0 * n_theta));
  const double dx_eq = std::sqrt(chord * chord - half * half);
  m.n_rings = std::max(2, int(std::lround(L / dx_eq)) + 1);
  m.ring_spacing = L / (m.n_rings - 1);
  const int nn = m.n_rings * n_theta;
  m.X0.resize(3, nn);
  for (int r = 0; r < m.n_rings; ++r)
    for (int i = 0; i < n_theta; ++i) {
      const double phi = 2.0 * kPi * (i + 0.5 * (r % 2)) / n_theta;
      m.X0.col(m.node(r, i)) = axis_start + V3(r * m.ring_spacing, R0 * std::cos(phi), R0 * std::sin(phi));
    }
  // triangles between ring r and r+1, oriented with outward normals
  for (int r = 0; r + 1 < m.n_rings; ++r)
    for (int i = 0; i < n_theta; ++i) {
      const int ip = (i + 1) % n_theta;
      std::array<int, 3> t1, t2;
      if (r % 2 == 0) {  // ring r+1 shifted by +half step: (r+1, i) lies between (r, i) and (r, i+1)
        t1 = {m.node(r, i), m.node(r, ip), m.node(r + 1, i)};
        t2 = {m.node(r + 1, i), m.node(r, ip), m.node(r + 1, ip)};
      } else {  // ring r shifted: (r, i) lies between (r+1, i) and (r+1, i+1)
        t1 = {m.node(r, i), m.node(r + 1, ip), m.node(r + 1, i)};
        t2 = {m.node(r, i), m.node(r, ip), m.node(r + 1, ip)};
      }
      for (auto t : {t1, t2}) {
        const V3 a = m.X0.col(t[0]), b = m.X0.col(t[1]), c = m.X0.col(t[2]);
        V3 centroid = (a + b + c) / 3.0 - axis_start;
        centroid.x() = 0.0;
        if ((b - a).cross(c - a).dot(centroid) < 0.0) std::swap(t[1], t[2]);
        m.triangles.push_back(t);
      }
    }
  // edges and hinges from directed triangle edges
  std::map<std::pair<int, int>, int> edge_id;              // undirected
  std::map<std::pair<int, int>, int> directed_opposite;    // (a,b) -> opposite vertex
  for (const auto& t : m.triangles)
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3], c = t[(e + 2) % 3];
      directed_opposite[{a, b}] = c;
      const auto key = std::minmax(a, b);
      if (!edge_id.count({key.first, key.second})) {
        edge_id[{key.first, key.second}] = int(m.edges.size());
        m.edges.push_back({key.first, key.second});
      }
    }
  for (const auto& [ab, c] : directed_opposite) {
    const auto [a, b] = ab;
    if (a > b) continue;  // visit each interior edge once
    const auto it = directed_opposite.find({b, a});
    if (it == directed_opposite.end()) continue;  // boundary edge: no bending hinge
    m.hinges.push_back({a, b, c, it->second});
    m.hinge_edge.push_back(edge_id.at({a, b}));
  }
  set_reference_geometry(m);
  return m;
}

void set_reference_geometry(CylinderMesh& m) {
  m.rest_length.resize(Eigen::Index(m.edges.size()));
  for (std::size_t e = 0; e < m.edges.size(); ++e)
    m.rest_length[Eigen::Index(e)] = (m.X0.col(m.edges[e][1]) - m.X0.col(m.edges[e][0])).norm();
  m.rest_angle.resize(Eigen::Index(m.hinges.size()));
  for (std::size_t k = 0; k < m.hinges.size(); ++k) {
    const auto& h = m.hinges[k];
    m.rest_angle[Eigen::Index(k)] =
        dihedral_angle(m.X0.col(h[0]), m.X0.col(h[1]), m.X0.col(h[2]), m.X0.col(h[3]));
  }
  m.rest_cos = m.rest_angle.array().cos();
  m.rest_sin = m.rest_angle.array().sin();
  m.node_area = Eigen::VectorXd::Zero(m.nodes());
  for (const auto& t : m.triangles) {
    const double area =
        0.5 * (m.X0.col(t[1]) - m.X0.col(t[0])).cross(m.X0.col(t[2]) - m.X0.col(t[0])).norm();
    for (int v : t) m.node_area[v] += area / 3.0;
  }
}

void seed_ring_mode(CylinderMesh& mesh, int m, double eps) { seed_ring_modes(mesh, {{m, eps}}); }

void seed_ring_modes(CylinderMesh& mesh, const std::vector<std::pair<int, double>>& modes) {
  std::vector<std::pair<int, double>> used;
  double total = 0.0;
  for (const auto& [m, eps] : modes) {
    if (!(m == 0 || m >= 2)) throw InputError("full3d.membrane.seed_mode", std::to_string(m), "0 (no seed) or >= 2");
    if (!(eps >= 0.0 && eps < 0.5))
      throw InputError("full3d.membrane.seed_amplitude", num(eps), "a fraction of R0 in [0, 0.5)");
    if (m == 0 || eps == 0.0) continue;
    if (!(2 * m < mesh.n_theta))
      throw InputError("full3d.membrane.seed_mode", std::to_string(m),
                       "fewer than half the nodes per ring (" + std::to_string(mesh.n_theta) +
                           " on this mesh), so that the ring resolves the lobes");
    used.emplace_back(m, eps);
    total += eps;
  }
  if (used.empty()) return;
  if (!(total < 0.5))
    throw InputError("full3d.membrane.seed_amplitude", num(total), "seed amplitudes adding up to less than 0.5 R0");
  for (int i = 0; i < mesh.nodes(); ++i) {
    const double dy = mesh.X0(1, i) - mesh.axis_start[1], dz = mesh.X0(2, i) - mesh.axis_start[2];
    const double phi = std::atan2(dz, dy);
    double f = 1.0 + used[0].second * std::cos(used[0].first * phi);
    for (std::size_t k = 1; k < used.size(); ++k) f += used[k].second * std::cos(used[k].first * phi);
    mesh.X0(1, i) = mesh.axis_start[1] + f * dy;
    mesh.X0(2, i) = mesh.axis_start[2] + f * dz;
  }
  set_reference_geometry(mesh);
}

double ring_buckling_pressure(int m, double D, double R, RingLoad load) {
  if (m < 2) return std::numeric_limits<double>::infinity();  // m = 1 is a rigid shift of the ring
  const double m2 = double(m) * m;
  const double b = D / (R * R * R);
  return load == RingLoad::Hydrostatic ? (m2 - 1.0) * b : (m2 - 1.0) * (m2 - 1.0) / (m2 - 2.0) * b;
}

double ring_mode_growth_rate(int m, double P, double D, double R, double drag, RingLoad load) {
  if (m < 2) return -std::numeric_limits<double>::infinity();
  const double m2 = double(m) * m;
  // modal stiffness per unit length K_m (energy pi a^2 K_m / 2 of the lobe w = a cos(m theta),
  // v = -(a / m) sin(m theta)) and modal drag c R (1 + 1/m^2) (dissipation pi c R (1 + 1/m^2) adot^2 / 2)
  const double K = load == RingLoad::Hydrostatic
                       ? (m2 - 1.0) * ((m2 - 1.0) * D / (R * R * R) - P)
                       : (m2 - 1.0) * (m2 - 1.0) * D / (R * R * R) - P * ((m2 - 1.0) * (m2 - 1.0) - 1.0) / m2;
  return -K / (drag * R * (1.0 + 1.0 / m2));
}

int fastest_ring_mode(double P, double D, double R, RingLoad load, int m_max) {
  int best = 0;
  double rate = 0.0;
  for (int m = 2; m <= m_max; ++m) {
    const double s = ring_mode_growth_rate(m, P, D, R, 1.0, load);
    if (s > rate) rate = s, best = m;
  }
  return best;
}

int n_theta_for_spacing(double R0, double spacing) {
  if (!(spacing > 0.0)) throw InputError("swimmer.node_spacing", num(spacing), "a positive length in m");
  int n = 3;
  while (2.0 * R0 * std::sin(kPi / n) > spacing) ++n;
  return n;
}

CylinderMesh make_cylinder_with_spacing(double R0, double L, double spacing, const Eigen::Vector3d& axis_start) {
  return make_cylinder(R0, L, n_theta_for_spacing(R0, spacing), axis_start);
}

CylinderMesh make_cylinder_for_grid(double R0, double L, double h, const Eigen::Vector3d& axis_start,
                                    double safety, int ring_multiple) {
  if (!(h > 0.0)) throw InputError("grid.h", num(h), "a positive cell size in m");
  if (ring_multiple < 1)
    throw InputError("full3d.membrane.ring_nodes_multiple", std::to_string(ring_multiple), "an integer >= 1");
  const double limit = safety * 0.5 * h;
  const int n0 = n_theta_for_spacing(R0, limit);
  for (int n = (n0 + ring_multiple - 1) / ring_multiple * ring_multiple;; n += ring_multiple) {
    CylinderMesh m = make_cylinder(R0, L, n, axis_start);
    if (max_edge_length(m, m.X0) < limit) return m;
  }
}

double max_edge_length(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X) {
  double mx = 0.0;
  for (const auto& e : mesh.edges) mx = std::max(mx, (X.col(e[1]) - X.col(e[0])).norm());
  return mx;
}

void check_no_leak(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double h, double t_s) {
  const double mx = max_edge_length(mesh, X);
  if (!(mx < 0.5 * h))
    throw NumericalError("membrane edge of " + num(mx) + " m exceeds h/2 = " + num(0.5 * h) +
                             " m (fluid leaks through the immersed boundary)",
                         "refine the membrane (smaller swimmer.node_spacing) or reduce the deformation", t_s);
}

double dihedral_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& d, Eigen::Matrix<double, 3, 4>* grad) {
  const V3 e = b - a;
  const V3 n1 = e.cross(c - a);  // normal of (a, b, c)
  const V3 n2 = (d - a).cross(e);  // normal of (b, a, d)
  const double le = e.norm();
  const double theta = std::atan2(n1.cross(n2).dot(e) / le, n1.dot(n2));
  if (grad) {
    const double n1sq = n1.squaredNorm(), n2sq = n2.squaredNorm();
    const V3 gc = -le / n1sq * n1;
    const V3 gd = -le / n2sq * n2;
    const double ac = (c - a).dot(e) / (le * le), ad = (d - a).dot(e) / (le * le);
    grad->col(0) = -(1.0 - ac) * gc - (1.0 - ad) * gd;
    grad->col(1) = -ac * gc - ad * gd;
    grad->col(2) = gc;
    grad->col(3) = gd;
  }
  return theta;
}

namespace {
double stretching_energy_range(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, std::size_t e0, std::size_t e1) {
  double s = 0.0;
  for (std::size_t e = e0; e < e1; ++e) {
    const double dl = (X.col(mesh.edges[e][1]) - X.col(mesh.edges[e][0])).norm() - mesh.rest_length[Eigen::Index(e)];
    s += dl * dl;
  }
  return s;
}

/// Sum of a per-range quantity over [0, n) split into the static blocks of parallel_blocks,
/// the block sums added in block order (reproducible for a given thread count).
template <class F>
double blocked_sum(std::size_t n, int threads, F&& range_sum) {
  const int T = block_count(long(n), threads);
  std::vector<double> part(std::size_t(T), 0.0);
  parallel_blocks(long(n), T, [&](long b, long e, int t) { part[std::size_t(t)] = range_sum(std::size_t(b), std::size_t(e)); });
  double s = 0.0;
  for (double v : part) s += v;
  return s;
}
}  // namespace

double stretching_energy(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double ks, int threads) {
  return 0.5 * ks * blocked_sum(mesh.edges.size(), threads, [&](std::size_t b, std::size_t e) {
           return stretching_energy_range(mesh, X, b, e);
         });
}

namespace {
// Spring forces (eq. 7 gradient) of edges [e0, e1) added to F.
// Returns the sum of (l - l0)^2 over the range (the energy without ks / 2).
double add_stretching_range(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double ks, std::size_t e0,
                            std::size_t e1, Eigen::Matrix3Xd& F) {
  double s = 0.0;
  for (std::size_t e = e0; e < e1; ++e) {
    const int a = mesh.edges[e][0], b = mesh.edges[e][1];
    const V3 v = X.col(b) - X.col(a);
    const double l = v.norm(), dl = l - mesh.rest_length[Eigen::Index(e)];
    const V3 fb = -ks * dl / l * v;  // -dE/dX_b
    F.col(b) += fb;
    F.col(a) -= fb;
    s += dl * dl;
  }
  return s;
}
}  // namespace

void add_stretching_forces(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double ks, Eigen::Matrix3Xd& F) {
  add_stretching_range(mesh, X, ks, 0, mesh.edges.size(), F);
}

Eigen::Matrix3Xd inextensional_lobes(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, int m, double amp) {
  Eigen::Matrix3Xd Y = X;
  for (int i = 0; i < mesh.nodes(); ++i) {
    const double dy = X(1, i) - mesh.axis_start[1], dz = X(2, i) - mesh.axis_start[2];
    const double r = std::hypot(dy, dz), phi = std::atan2(dz, dy);
    const double ur = amp * std::cos(m * phi), ut = -amp / m * std::sin(m * phi);
    Y(1, i) += (ur * dy - ut * dz) / r;
    Y(2, i) += (ur * dz + ut * dy) / r;
  }
  return Y;
}

double bending_rigidity_per_kb(const CylinderMesh& mesh, BendingForm form, int m) {
  const double R0 = mesh.radius, w = 1e-4 * R0;
  auto lobed = [&](double amp) { return bending_energy(mesh, inextensional_lobes(mesh, mesh.X0, m, amp), 1.0, form); };
  const double e2 = 0.5 * (lobed(w) + lobed(-w)) - bending_energy(mesh, mesh.X0, 1.0, form);
  const double length = mesh.ring_spacing * (mesh.n_rings - 1);
  const double dk = (double(m) * m - 1.0) * w / (R0 * R0);
  return 2.0 * e2 / (0.5 * 2.0 * M_PI * R0 * length * dk * dk);
}

namespace {
// Bending forces (eq. 8 gradient) of hinges [k0, k1) added to F.
//
// Same quantities as dihedral_angle (with its gradient), without the trigonometric calls:
// with the unnormalised normals n1 = e x (c - a), n2 = (d - a) x e of the two triangles,
//   rho cos(theta) = n1.n2 =: C,   rho sin(theta) = (n1 x n2).e / |e| =: S,   rho = sqrt(C^2 + S^2),
// and, with D = theta - theta0,
//   t = tan(D/2) = sin D / (1 + cos D) = (S cos0 - C sin0) / (rho + C cos0 + S sin0),
// which equals tan((atan2(S, C) - theta0)/2) exactly (the rest angle enters through
// cos0 = cos(theta0), sin0 = sin(theta0), precomputed in the mesh).
struct Hinge {
  V3 e, ca, da, n1, n2;  ///< edge b - a, c - a, d - a, normals of (a, b, c) and (b, a, d)
  double l2, l, t;       ///< |e|^2, |e|, tan((theta - theta0)/2)
};

/// The reference angle's cosine and sine per hinge (or none: BendingForm::Printed, theta0 = 0).
class RestAngles {
 public:
  RestAngles(const CylinderMesh& mesh, BendingForm form)
      : mesh_(mesh), ref_(form == BendingForm::ReferenceAngle),
        have_cs_(mesh.rest_cos.size() == mesh.rest_angle.size() && mesh.rest_sin.size() == mesh.rest_angle.size()) {}
  void get(std::size_t k, double& cos0, double& sin0) const {
    cos0 = 1.0, sin0 = 0.0;
    if (!ref_) return;
    const Eigen::Index i = Eigen::Index(k);
    cos0 = have_cs_ ? mesh_.rest_cos[i] : std::cos(mesh_.rest_angle[i]);
    sin0 = have_cs_ ? mesh_.rest_sin[i] : std::sin(mesh_.rest_angle[i]);
  }

 private:
  const CylinderMesh& mesh_;
  bool ref_, have_cs_;
};

Hinge hinge(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const RestAngles& rest, std::size_t k) {
  const auto& h = mesh.hinges[k];
  Hinge g;
  const V3 a = X.col(h[0]);
  g.e = X.col(h[1]) - a;
  g.ca = X.col(h[2]) - a;
  g.da = X.col(h[3]) - a;
  g.n1 = g.e.cross(g.ca);
  g.n2 = g.da.cross(g.e);
  g.l2 = g.e.squaredNorm();
  g.l = std::sqrt(g.l2);
  const double C = g.n1.dot(g.n2), S = g.n1.cross(g.n2).dot(g.e) / g.l;
  const double rho = std::sqrt(C * C + S * S);
  double cos0, sin0;
  rest.get(k, cos0, sin0);
  g.t = (S * cos0 - C * sin0) / (rho + C * cos0 + S * sin0);
  return g;
}

double bending_energy_range(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const RestAngles& rest,
                            std::size_t k0, std::size_t k1) {
  double s = 0.0;
  for (std::size_t k = k0; k < k1; ++k) {
    const Hinge g = hinge(mesh, X, rest, k);
    s += g.l * g.t * g.t;
  }
  return s;
}

// Returns the sum of |e| t^2 over the range (the energy without kb / 2).
double add_bending_range(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double kb, BendingForm form,
                         std::size_t k0, std::size_t k1, Eigen::Matrix3Xd& F) {
  const RestAngles rest(mesh, form);
  double energy = 0.0;
  for (std::size_t k = k0; k < k1; ++k) {
    const auto& h = mesh.hinges[k];
    const Hinge g = hinge(mesh, X, rest, k);
    const V3 &e = g.e, &ca = g.ca, &da = g.da, &n1 = g.n1, &n2 = g.n2;
    const double l2 = g.l2, l = g.l, t = g.t;
    // d theta / d(c, d) = -|e| n / |n|^2; d theta / d(a, b) from translation and rotation invariance
    const V3 gc = -l / n1.squaredNorm() * n1;
    const V3 gd = -l / n2.squaredNorm() * n2;
    const double ac = ca.dot(e) / l2, ad = da.dot(e) / l2;
    // dE = kb/2 t^2 dL + kb/2 L t (1 + t^2) dtheta
    const double cl = 0.5 * kb * t * t;
    const double ct = 0.5 * kb * l * t * (1.0 + t * t);
    const V3 dl_db = e / l;
    F.col(h[0]) -= ct * (-(1.0 - ac) * gc - (1.0 - ad) * gd) - cl * dl_db;
    F.col(h[1]) -= ct * (-ac * gc - ad * gd) + cl * dl_db;
    F.col(h[2]) -= ct * gc;
    F.col(h[3]) -= ct * gd;
    energy += l * t * t;
  }
  return energy;
}
}  // namespace

double bending_energy(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double kb, BendingForm form, int threads) {
  const RestAngles rest(mesh, form);
  return 0.5 * kb * blocked_sum(mesh.hinges.size(), threads, [&](std::size_t b, std::size_t e) {
           return bending_energy_range(mesh, X, rest, b, e);
         });
}

void add_bending_forces(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, double kb, BendingForm form,
                        Eigen::Matrix3Xd& F) {
  add_bending_range(mesh, X, kb, form, 0, mesh.hinges.size(), F);
}

double elastic_energy(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const MembraneParams& p, int threads) {
  return stretching_energy(mesh, X, p.ks, threads) + bending_energy(mesh, X, p.kb, p.bending, threads);
}

Eigen::Matrix3Xd elastic_forces(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, const MembraneParams& p,
                                int threads, std::array<double, 2>* energy) {
  const std::size_t ne = mesh.edges.size(), nh = mesh.hinges.size();
  const int T = block_count(long(std::max(ne, nh)), threads);
  Eigen::Matrix3Xd F(3, X.cols());
  std::vector<std::array<double, 2>> sums(std::size_t(T), {0.0, 0.0});
  // Thread t accumulates the springs of edge block t and the hinges of hinge block t
  // (static blocks) into its own buffer (thread 0: F itself); the buffers are then summed
  // in the fixed order 0, 1, .., T-1. T = 1 is the plain serial loop.
  std::vector<Eigen::Matrix3Xd> part(std::size_t(T - 1));
  parallel_blocks(T, T, [&](long tb, long, int) {
    const std::size_t t = std::size_t(tb);
    Eigen::Matrix3Xd& Ft = t == 0 ? F : part[t - 1];
    Ft.setZero(3, X.cols());
    sums[t][0] = add_stretching_range(mesh, X, p.ks, ne * t / T, ne * (t + 1) / T, Ft);
    sums[t][1] = add_bending_range(mesh, X, p.kb, p.bending, nh * t / T, nh * (t + 1) / T, Ft);
  });
  if (energy) {
    *energy = {0.0, 0.0};
    for (const auto& b : sums) (*energy)[0] += b[0], (*energy)[1] += b[1];
    (*energy)[0] *= 0.5 * p.ks;
    (*energy)[1] *= 0.5 * p.kb;
  }
  if (T > 1)
    parallel_blocks(long(X.cols()), T, [&](long b, long e, int) {
      for (const auto& Ft : part) F.middleCols(b, e - b) += Ft.middleCols(b, e - b);
    });
  return F;
}

Eigen::VectorXd node_masses(const CylinderMesh& mesh, double areal_density) {
  if (!(areal_density >= 0.0))
    throw InputError("swimmer.areal_density", num(areal_density), "a non-negative mass per area in kg/m^2");
  return areal_density * mesh.node_area;
}

Eigen::Matrix3Xd radial_directions(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X) {
  Eigen::Matrix3Xd R(3, X.cols());
  const double ay = mesh.axis_start[1], az = mesh.axis_start[2];
  for (Eigen::Index i = 0; i < X.cols(); ++i) {  // plain loop, as node_radii
    const double y = X(1, i) - ay, z = X(2, i) - az, r = std::sqrt(y * y + z * z);
    R(0, i) = 0.0;  // a node on the axis: no direction (0, as Eigen's normalized())
    R(1, i) = r > 0.0 ? y / r : 0.0;
    R(2, i) = r > 0.0 ? z / r : 0.0;
  }
  return R;
}

Eigen::VectorXd node_radii(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X) {
  Eigen::VectorXd r(X.cols());
  const double ay = mesh.axis_start[1], az = mesh.axis_start[2];
  for (Eigen::Index i = 0; i < X.cols(); ++i) {
    const double y = X(1, i) - ay, z = X(2, i) - az;
    r[i] = std::sqrt(y * y + z * z);  // (a plain loop: Eigen's 3-vector norm here is several times slower)
  }
  return r;
}

Eigen::VectorXd ring_radii(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X) {
  return ring_radii(mesh, node_radii(mesh, X));
}

Eigen::VectorXd ring_radii(const CylinderMesh& mesh, const Eigen::VectorXd& r) {
  Eigen::VectorXd rr = Eigen::VectorXd::Zero(mesh.n_rings);
  for (int i = 0; i < mesh.nodes(); ++i) rr[mesh.ring_of(i)] += r[i] / mesh.n_theta;
  return rr;
}

namespace {
// The ring-stack Newton solve of relax_under_pressure with the inward pressure ring_pressure[k]
// on the nodes of ring k; `pressure` is the load of the middle ring(s) for the effective C1 and
// `load_scale` the largest |P| for the default tolerance.
PressureResponse relax_ring_stack(const CylinderMesh& mesh, const MembraneParams& p,
                                  const Eigen::VectorXd& ring_pressure, double pressure, double load_scale,
                                  double tol_force, int max_iterations, const Eigen::Matrix3Xd* start) {
  // The mesh is invariant under rotation by 2 pi / n_theta about the axis and under the
  // mirror theta -> -theta, and so is the load; the equilibrium therefore has every ring a
  // circle of radius r_k at axial position x_k, each node at its reference angle. The
  // stationarity conditions restricted to that family are the generalised forces
  //   G_r,k = sum_{i in ring k} g_i . e_r,i,   G_x,k = sum_{i in ring k} g_i . e_x,
  // g = grad (E + P sum A_i r_i) = -F_el + P A_i e_r; by the symmetry, G = 0 makes the full
  // gradient vanish (checked on every node below). Newton on the 2 n_rings - 1 unknowns
  // (x_0 is held: axial translation is free and sum_k G_x,k = 0 identically), with the
  // banded Jacobian from central differences, 5 rings per colour (a hinge couples at most
  // 3 consecutive rings, so a ring's generalised force depends on rings k-2..k+2).
  const int nr = mesh.n_rings, nt = mesh.n_theta;
  const int nn = mesh.nodes();
  Eigen::VectorXd cph(nn), sph(nn);
  for (int i = 0; i < nn; ++i) {
    const V3 d = mesh.X0.col(i) - mesh.axis_start;
    const double r = std::hypot(d.y(), d.z());
    cph[i] = d.y() / r;
    sph[i] = d.z() / r;
  }
  auto positions = [&](const Eigen::VectorXd& rk, const Eigen::VectorXd& xk) {
    Eigen::Matrix3Xd X(3, nn);
    for (int i = 0; i < nn; ++i) {
      const int k = i / nt;
      X.col(i) = mesh.axis_start + V3(xk[k], rk[k] * cph[i], rk[k] * sph[i]);
    }
    return X;
  };
  // full gradient g (3 x N) of the loaded energy at X
  auto gradient = [&](const Eigen::Matrix3Xd& X) {
    Eigen::Matrix3Xd G = -elastic_forces(mesh, X, p);
    for (int i = 0; i < nn; ++i) {
      const double P = ring_pressure[i / nt];
      G(1, i) += P * mesh.node_area[i] * cph[i];
      G(2, i) += P * mesh.node_area[i] * sph[i];
    }
    return G;
  };
  auto generalised = [&](const Eigen::Matrix3Xd& G) {
    Eigen::VectorXd out = Eigen::VectorXd::Zero(2 * nr);
    for (int i = 0; i < nn; ++i) {
      const int k = i / nt;
      out[k] += G(1, i) * cph[i] + G(2, i) * sph[i];
      out[nr + k] += G(0, i);
    }
    return out;
  };
  auto max_node_force = [&](const Eigen::Matrix3Xd& G) { return G.colwise().norm().maxCoeff(); };
  if (tol_force <= 0.0) tol_force = 1e-7 * load_scale * mesh.node_area.maxCoeff() + 1e-30;

  Eigen::VectorXd rk = Eigen::VectorXd::Constant(nr, mesh.radius), xk(nr);
  for (int k = 0; k < nr; ++k) xk[k] = mesh.X0(0, mesh.node(k, 0)) - mesh.axis_start.x();
  if (start) {
    rk = ring_radii(mesh, *start);
    for (int k = 0; k < nr; ++k) xk[k] = (*start)(0, mesh.node(k, 0)) - mesh.axis_start.x();
  }
  Eigen::Matrix3Xd G = gradient(positions(rk, xk));
  Eigen::VectorXd res = generalised(G);
  const int nu = 2 * nr - 1;  // unknowns r_0..r_{nr-1}, x_1..x_{nr-1}; equations likewise
  auto reduced = [&](const Eigen::VectorXd& full) {
    Eigen::VectorXd v(nu);
    v.head(nr) = full.head(nr);
    v.tail(nr - 1) = full.tail(nr - 1);
    return v;
  };
  const double eps = 1e-6 * mesh.radius;
  int it = 0;
  for (; it < max_iterations && max_node_force(G) > tol_force; ++it) {
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(nu, nu);
    for (int comp = 0; comp < 2; ++comp)
      for (int colour = 0; colour < 5; ++colour) {
        Eigen::VectorXd rp = rk, xp = xk, rm = rk, xm = xk;
        bool any = false;
        for (int k = colour; k < nr; k += 5) {
          if (comp == 1 && k == 0) continue;
          any = true;
          (comp == 0 ? rp : xp)[k] += eps;
          (comp == 0 ? rm : xm)[k] -= eps;
        }
        if (!any) continue;
        const Eigen::VectorXd d =
            reduced((generalised(gradient(positions(rp, xp))) - generalised(gradient(positions(rm, xm)))) /
                    (2.0 * eps));
        for (int k = colour; k < nr; k += 5) {
          if (comp == 1 && k == 0) continue;
          const int col = comp == 0 ? k : nr + k - 1;
          for (int j = std::max(0, k - 2); j <= std::min(nr - 1, k + 2); ++j) {
            J(j, col) = d[j];
            if (j > 0) J(nr + j - 1, col) = d[nr + j - 1];
          }
        }
      }
    const Eigen::VectorXd step = J.partialPivLu().solve(-reduced(res));
    if (!step.allFinite()) break;
    // backtracking on the generalised residual
    double t = 1.0;
    bool accepted = false;
    for (int ls = 0; ls < 30; ++ls, t *= 0.5) {
      Eigen::VectorXd rn = rk + t * step.head(nr), xn = xk;
      xn.tail(nr - 1) += t * step.tail(nr - 1);
      if (!(rn.minCoeff() > 0.0)) continue;
      const Eigen::Matrix3Xd Gn = gradient(positions(rn, xn));
      const Eigen::VectorXd resn = generalised(Gn);
      if (resn.allFinite() && (resn.norm() < res.norm() || max_node_force(Gn) <= tol_force)) {
        rk = rn;
        xk = xn;
        G = Gn;
        res = resn;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
  }
  PressureResponse out;
  out.X = positions(rk, xk);
  out.iterations = it;
  out.max_residual_force = max_node_force(G);
  if (!(out.max_residual_force <= tol_force))
    throw NumericalError("membrane static relaxation stalled at residual force " + num(out.max_residual_force) +
                             " N (tolerance " + num(tol_force) + " N) after " + std::to_string(it) +
                             " Newton iterations",
                         "reduce the applied pressure (protocol.pressure sets the scale of the calibration loads)");
  out.ring_radius = ring_radii(mesh, out.X);
  const int r0 = (mesh.n_rings - 1) / 2, r1 = mesh.n_rings / 2;
  out.mid_radius = 0.5 * (out.ring_radius[r0] + out.ring_radius[r1]);
  out.c1 = pressure / (mesh.radius - out.mid_radius);
  return out;
}
}  // namespace

PressureResponse relax_under_pressure(const CylinderMesh& mesh, const MembraneParams& p, double pressure,
                                      double tol_force, int max_iterations, const Eigen::Matrix3Xd* start) {
  return relax_ring_stack(mesh, p, Eigen::VectorXd::Constant(mesh.n_rings, pressure), pressure, std::abs(pressure),
                          tol_force, max_iterations, start);
}

PressureResponse relax_under_ring_pressures(const CylinderMesh& mesh, const MembraneParams& p,
                                            const Eigen::VectorXd& ring_pressure, double tol_force,
                                            int max_iterations, const Eigen::Matrix3Xd* start) {
  if (ring_pressure.size() != mesh.n_rings)
    throw InputError("ring pressures", std::to_string(ring_pressure.size()) + " values",
                     "one inward pressure per ring of the mesh (" + std::to_string(mesh.n_rings) + ")");
  if (!ring_pressure.allFinite())
    throw InputError("ring pressures", "a non-finite value", "finite pressures in Pa");
  const int r0 = (mesh.n_rings - 1) / 2, r1 = mesh.n_rings / 2;
  return relax_ring_stack(mesh, p, ring_pressure, 0.5 * (ring_pressure[r0] + ring_pressure[r1]),
                          ring_pressure.cwiseAbs().maxCoeff(), tol_force, max_iterations, start);
}

}  // namespace swim::full3d
