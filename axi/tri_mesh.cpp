#include "axi/tri_mesh.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_no_edge_refinement_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <queue>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "common/errors.hpp"
#include "common/si_format.hpp"

namespace swim::axi {

namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Delaunay_mesh_vertex_base_2<Kernel>;
using Fb = CGAL::Delaunay_mesh_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;

/// The size field of the triangulation: the longest edge a triangle may have at axial position
/// x, `size` over the tube's axial extent [x0, x1] and growing beyond its ends with the axial
/// distance d as size min(gap_size, 1 + 5 d / Rc) (TriMeshParams::gap_size; the structured
/// mesh's gap columns grow at the same rate, 1 + 5 ds / Rc per column of width ds).
struct SizeField {
  double size = 0, gap = 1, Rc = 1, x0 = 0, x1 = 0;
  double operator()(double x) const {
    if (gap <= 1.0) return size;
    const double d = std::max({0.0, x0 - x, x - x1});
    return size * std::min(gap, 1.0 + 5.0 * d / Rc);
  }
};

/// CGAL's size and shape criteria with the size bound of SizeField at the triangle's centroid
/// (with a uniform field the same decisions as Delaunay_mesh_size_criteria_2, operation for
/// operation).
class GradedCriteria : public CGAL::Delaunay_mesh_size_criteria_2<Cdt> {
 public:
  using Base = CGAL::Delaunay_mesh_size_criteria_2<Cdt>;
  explicit GradedCriteria(double aspect_bound = 0.125, const SizeField& f = {}) : Base(aspect_bound, f.size), field_(f) {}

  class Is_bad : public Base::Is_bad {
   public:
    Is_bad(double aspect_bound, const SizeField& f, const Geom_traits& gt)
        : Base::Is_bad(aspect_bound, f.size, gt), field_(f) {}
    using Base::Is_bad::operator();
    CGAL::Mesh_2::Face_badness operator()(const Cdt::Face_handle& fh, Quality& q) const {
      const Cdt::Point& pa = fh->vertex(0)->point();
      const Cdt::Point& pb = fh->vertex(1)->point();
      const Cdt::Point& pc = fh->vertex(2)->point();
      const auto sq = this->traits.compute_squared_distance_2_object();
      const double a = CGAL::to_double(sq(pb, pc)), b = CGAL::to_double(sq(pc, pa)), c = CGAL::to_double(sq(pa, pb));
      double max_sq, second_sq;
      if (a < b) {
        if (b < c)
          max_sq = c, second_sq = b;
        else
          max_sq = b, second_sq = a < c ? c : a;
      } else {
        if (a < c)
          max_sq = c, second_sq = a;
        else
          max_sq = a, second_sq = b < c ? c : b;
      }
      const double s = field_((CGAL::to_double(pa.x()) + CGAL::to_double(pb.x()) + CGAL::to_double(pc.x())) / 3.0);
      q.second = max_sq / (s * s);
      if (q.size() > 1) {
        q.first = 1;
        return CGAL::Mesh_2::IMPERATIVELY_BAD;
      }
      const double area = 2 * CGAL::to_double(this->traits.compute_area_2_object()(pa, pb, pc));
      q.first = (area * area) / (max_sq * second_sq);
      return q.sine() < this->B ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
    }

   private:
    SizeField field_;
  };
  Is_bad is_bad_object() const { return Is_bad(this->bound(), field_, this->traits); }

 private:
  SizeField field_;
};
using Mesher = CGAL::Delaunay_mesher_no_edge_refinement_2<Cdt, GradedCriteria>;

/// Points x_0 = a < x_1 < ... < x_N = a + L (N >= min_segments) whose spacing follows the field
/// f: equal steps of the integral of 1 / f. With a uniform field, a + L i / N.
std::vector<double> graded_points(double a, double L, const SizeField& f, int min_segments) {
  const double b = a + L;
  if (f.gap <= 1.0) {
    const int N = std::max(min_segments, int(std::ceil(L / f.size - 1e-9)));
    std::vector<double> x(N + 1);
    for (int i = 0; i <= N; ++i) x[i] = i == 0 ? a : (i == N ? b : a + L * i / N);
    return x;
  }
  constexpr int kSamples = 4096;
  std::vector<double> cum(kSamples + 1, 0.0);
  const double dx = (b - a) / kSamples;
  for (int k = 0; k < kSamples; ++k) cum[k + 1] = cum[k] + dx / f(a + (k + 0.5) * dx);
  const int N = std::max(min_segments, int(std::ceil(cum[kSamples] - 1e-9)));
  std::vector<double> x(N + 1);
  x[0] = a;
  x[N] = b;
  int k = 0;
  for (int i = 1; i < N; ++i) {
    const double target = cum[kSamples] * i / N;
    while (cum[k + 1] < target) ++k;
    x[i] = a + dx * (k + (target - cum[k]) / (cum[k + 1] - cum[k]));
  }
  return x;
}
using Point = Cdt::Point;
using Sparse = Eigen::SparseMatrix<double>;
using Ldlt = Eigen::SimplicialLDLT<Sparse>;

std::int64_t edge_key(int a, int b) { return (std::int64_t(std::min(a, b)) << 32) | std::uint32_t(std::max(a, b)); }
}  // namespace

struct TriMesh::Topology {
  TriMeshParams p;
  Eigen::Matrix3Xd X_ref;
  int n = 0;                         ///< rings
  int V = 0, E = 0, T = 0;
  std::vector<double> x0, r0;        ///< reference vertex positions
  std::vector<NodeKind> vkind;       ///< per vertex
  std::vector<int> tri;              ///< T x 3 vertices (counter-clockwise)
  std::vector<char> wrap;            ///< T x 3: the corner is the cut's image at x + P
  std::vector<int> tedge;            ///< T x 3 edges (0,1), (1,2), (2,0)
  std::vector<std::array<int, 2>> edges;
  std::vector<NodeKind> ekind;
  std::vector<int> wall_v, wall_e;   ///< ring k's vertex, segment (k, k+1)'s edge
  std::vector<int> wall_of;          ///< per vertex: its ring, or -1
  std::array<std::vector<int>, 2> rim_vertices, rim_edges;  ///< path from the axis to each rim
  // harmonic extension: the free vertices' factorisations and the couplings to the rings
  std::vector<int> free_x, free_r;   ///< vertex -> unknown (-1: fixed)
  Sparse lap;                        ///< the stiffened Laplacian, V x V
  Ldlt solve_x, solve_r;
};

namespace {

/// The stiffened P1 Laplacian of the reference triangulation (merged vertices).
Sparse stiffened_laplacian(const std::vector<double>& x, const std::vector<double>& r, const std::vector<int>& tri,
                           const std::vector<char>& wrap, double P, int V) {
  const int T = int(tri.size() / 3);
  std::vector<double> area(T);
  double amin = std::numeric_limits<double>::infinity();
  auto corner = [&](int t, int i, double& cx, double& cr) {
    const int v = tri[3 * t + i];
    cx = x[v] + (wrap[3 * t + i] ? P : 0.0);
    cr = r[v];
  };
  for (int t = 0; t < T; ++t) {
    double ax, ar, bx, br, cx, cr;
    corner(t, 0, ax, ar);
    corner(t, 1, bx, br);
    corner(t, 2, cx, cr);
    area[t] = 0.5 * ((bx - ax) * (cr - ar) - (cx - ax) * (br - ar));
    amin = std::min(amin, area[t]);
  }
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(std::size_t(T) * 9);
  for (int t = 0; t < T; ++t) {
    double px[3], pr[3];
    for (int i = 0; i < 3; ++i) corner(t, i, px[i], pr[i]);
    const double w = amin / area[t];  // small elements stiffer
    // gradients of the hat functions: (r_j - r_k, x_k - x_j) / (2A) for (i, j, k) cyclic
    double gx[3], gr[3];
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      gx[i] = (pr[j] - pr[k]) / (2 * area[t]);
      gr[i] = (px[k] - px[j]) / (2 * area[t]);
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        trip.emplace_back(tri[3 * t + i], tri[3 * t + j], w * area[t] * (gx[i] * gx[j] + gr[i] * gr[j]));
  }
  Sparse L(V, V);
  L.setFromTriplets(trip.begin(), trip.end());
  return L;
}

/// The block of L on the free vertices (index map `free`, -1 fixed), factored.
void factor_free(const Sparse& L, const std::vector<int>& free, Ldlt& solver) {
  int nf = 0;
  for (int f : free) nf = std::max(nf, f + 1);
  std::vector<Eigen::Triplet<double>> trip;
  for (int c = 0; c < L.outerSize(); ++c)
    for (Sparse::InnerIterator it(L, c); it; ++it) {
      const int i = free[std::size_t(it.row())], j = free[std::size_t(it.col())];
      if (i >= 0 && j >= 0) trip.emplace_back(i, j, it.value());
    }
  Sparse A(nf, nf);
  A.setFromTriplets(trip.begin(), trip.end());
  solver.compute(A);
  if (solver.info() != Eigen::Success)
    throw NumericalError("the triangular mesh's motion operator is singular", "change axi.grid");
}

}  // namespace

TriMesh::TriMesh(const TriMeshParams& p, const Eigen::Matrix3Xd& X_ref) {
  if (!(std::isfinite(p.Rc) && p.Rc > 0 && std::isfinite(p.period) && p.period > 0 && std::isfinite(p.size) &&
        p.size > 0 && p.angle_bound > 0 && std::isfinite(p.gap_size) && p.gap_size >= 1.0))
    throw std::invalid_argument("TriMesh: Rc, period, size and angle_bound must be positive and finite, gap_size >= 1");
  const int n = int(X_ref.cols());
  if (n < 3) throw std::invalid_argument("TriMesh: at least 3 rings");
  // The shape is the wall's, taken from a run: a shape the strip cannot hold is a numerical
  // failure of that run (it keeps its partial results), not a programming error.
  const std::string remedy = "lower the load (protocol.pressure) or widen the container (container.radius)";
  if (!X_ref.topRows(2).allFinite()) throw NumericalError("a wall ring is not finite where the mesh is made", remedy);
  double xmin = X_ref(0, 0), xmax = X_ref(0, 0);
  for (int k = 0; k < n; ++k) {
    if (!(X_ref(1, k) > 0 && X_ref(1, k) < p.Rc))
      throw NumericalError("wall ring " + std::to_string(k) + " at r = " + significant(X_ref(1, k), 4) +
                               " m lies outside (0, Rc) where the mesh is made",
                           remedy);
    xmin = std::min(xmin, X_ref(0, k));
    xmax = std::max(xmax, X_ref(0, k));
  }
  if (!(xmax - xmin < p.period))
    throw NumericalError("the wall spans " + significant(xmax - xmin, 4) + " m, not less than the period", remedy);
  auto t = std::make_shared<Topology>();
  t->p = p;
  t->X_ref = X_ref;
  t->n = n;
  const double P = p.period, Rc = p.Rc;
  const double xL = 0.5 * (xmin + xmax - P), xR = xL + P;  // the cuts, in the middle of the gap

  // ---- the constrained triangulation
  Cdt cdt;
  const SizeField field{p.size, p.gap_size, Rc, xmin, xmax};
  // the cuts (in the gap's middle) divided at the field's size there, the axis and the container
  // wall along the field
  const std::vector<double> cut_r = graded_points(0.0, Rc, SizeField{field(xL), 1.0, Rc, 0, 0}, 2);
  const int m = int(cut_r.size()) - 1;
  for (int j = 0; j < m; ++j) {
    cdt.insert_constraint(Point(xL, cut_r[j]), Point(xL, cut_r[j + 1]));
    cdt.insert_constraint(Point(xR, cut_r[j]), Point(xR, cut_r[j + 1]));
  }
  const std::vector<double> line_x = graded_points(xL, P, field, 4);
  for (std::size_t i = 0; i + 1 < line_x.size(); ++i) {
    cdt.insert_constraint(Point(line_x[i], 0.0), Point(line_x[i + 1], 0.0));
    cdt.insert_constraint(Point(line_x[i], Rc), Point(line_x[i + 1], Rc));
  }
  for (int k = 0; k + 1 < n; ++k)
    cdt.insert_constraint(Point(X_ref(0, k), X_ref(1, k)), Point(X_ref(0, k + 1), X_ref(1, k + 1)));
  {
    Mesher mesher(cdt);
    mesher.set_criteria(GradedCriteria(p.angle_bound, field));
    mesher.refine_mesh();
  }

  // ---- vertices: the right cut's merged into the left's
  std::map<std::pair<double, double>, int> ring_at;
  for (int k = 0; k < n; ++k) ring_at[{X_ref(0, k), X_ref(1, k)}] = k;
  std::map<Cdt::Vertex_handle, int> id;
  std::map<double, int> left_at;             // radius -> vertex on the left cut
  std::vector<std::pair<Cdt::Vertex_handle, double>> right;
  t->wall_v.assign(n, -1);
  for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
    const double x = v->point().x(), r = v->point().y();
    if (x == xR) {
      right.emplace_back(v, r);
      continue;
    }
    const int i = int(t->x0.size());
    id[v] = i;
    t->x0.push_back(x);
    t->r0.push_back(r);
    t->vkind.push_back(r == 0.0 ? NodeKind::axis : (r == Rc ? NodeKind::container : NodeKind::interior));
    if (x == xL) left_at[r] = i;
    if (auto it = ring_at.find({x, r}); it != ring_at.end()) t->wall_v[it->second] = i;
  }
  if (right.size() != left_at.size())
    throw NumericalError("the triangular mesh's two cuts do not match (" + std::to_string(left_at.size()) + " and " +
                             std::to_string(right.size()) + " vertices)",
                         "change axi.grid");
  std::map<Cdt::Vertex_handle, int> right_id;
  for (const auto& [v, r] : right) {
    auto it = left_at.find(r);
    if (it == left_at.end())
      throw NumericalError("the triangular mesh's cuts do not match at r = " + significant(r, 6) + " m", "change axi.grid");
    right_id[v] = it->second;
  }
  for (int k = 0; k < n; ++k)
    if (t->wall_v[k] < 0)
      throw NumericalError("ring " + std::to_string(k) + " is not a vertex of the triangular mesh",
                           "check the wall's shape (segments crossing)");
  t->V = int(t->x0.size());
  t->wall_of.assign(t->V, -1);
  for (int k = 0; k < n; ++k) t->wall_of[t->wall_v[k]] = k;

  // ---- triangles and edges
  std::unordered_map<std::int64_t, int> edge_id;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    int v[3];
    char w[3];
    for (int i = 0; i < 3; ++i) {
      const auto vh = f->vertex(i);
      if (auto it = id.find(vh); it != id.end()) {
        v[i] = it->second;
        w[i] = 0;
      } else {
        v[i] = right_id.at(vh);
        w[i] = 1;
      }
      t->tri.push_back(v[i]);
      t->wrap.push_back(w[i]);
    }
    for (int i = 0; i < 3; ++i) {
      const int a = v[i], b = v[(i + 1) % 3];
      const auto [it, added] = edge_id.try_emplace(edge_key(a, b), int(t->edges.size()));
      if (added) t->edges.push_back({a, b});
      t->tedge.push_back(it->second);
    }
  }
  t->T = int(t->tri.size() / 3);
  t->E = int(t->edges.size());
  for (const auto& e : t->edges) {
    const NodeKind a = t->vkind[e[0]], b = t->vkind[e[1]];
    t->ekind.push_back(a == b && a != NodeKind::interior ? a : NodeKind::interior);
  }
  t->wall_e.assign(n - 1, -1);
  for (int k = 0; k + 1 < n; ++k) {
    auto it = edge_id.find(edge_key(t->wall_v[k], t->wall_v[k + 1]));
    if (it == edge_id.end())
      throw NumericalError("the wall segment of rings " + std::to_string(k) + " and " + std::to_string(k + 1) +
                               " is not an edge of the triangular mesh",
                           "check the wall's shape (segments crossing)");
    t->wall_e[k] = it->second;
  }

  // ---- paths from the axis to the rims (shortest along edges, avoiding the other rings and the cuts)
  {
    std::vector<std::vector<std::pair<int, int>>> adj(t->V);  // (neighbour, edge)
    for (int e = 0; e < t->E; ++e) {
      adj[t->edges[e][0]].emplace_back(t->edges[e][1], e);
      adj[t->edges[e][1]].emplace_back(t->edges[e][0], e);
    }
    std::vector<char> on_cut(t->V, 0);
    for (const auto& [r, i] : left_at) on_cut[i] = 1;
    for (int end = 0; end < 2; ++end) {
      const int start = t->wall_v[end == 0 ? 0 : n - 1];
      std::vector<double> dist(t->V, std::numeric_limits<double>::infinity());
      std::vector<int> from(t->V, -1), via(t->V, -1);
      using Item = std::pair<double, int>;
      std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
      dist[start] = 0;
      q.push({0.0, start});
      int goal = -1;
      while (!q.empty()) {
        const auto [d, v] = q.top();
        q.pop();
        if (d > dist[v]) continue;
        if (t->vkind[v] == NodeKind::axis) {
          goal = v;
          break;
        }
        for (const auto& [u, e] : adj[v]) {
          if (on_cut[u] || (t->wall_of[u] >= 0 && u != start)) continue;
          const double nd = d + std::hypot(t->x0[u] - t->x0[v], t->r0[u] - t->r0[v]);
          if (nd < dist[u]) {
            dist[u] = nd;
            from[u] = v;
            via[u] = e;
            q.push({nd, u});
          }
        }
      }
      if (goal < 0) throw NumericalError("no path of the triangular mesh joins a rim to the axis", "change axi.grid");
      for (int v = goal; v >= 0; v = from[v]) {
        t->rim_vertices[end].push_back(v);
        if (from[v] >= 0) t->rim_edges[end].push_back(via[v]);
      }
    }
  }

  // ---- the motion's operators
  t->lap = stiffened_laplacian(t->x0, t->r0, t->tri, t->wrap, P, t->V);
  t->free_x.assign(t->V, -1);
  t->free_r.assign(t->V, -1);
  int fx = 0, fr = 0;
  for (int v = 0; v < t->V; ++v) {
    if (t->wall_of[v] >= 0) continue;
    t->free_x[v] = fx++;
    if (t->vkind[v] == NodeKind::interior) t->free_r[v] = fr++;
  }
  factor_free(t->lap, t->free_x, t->solve_x);
  factor_free(t->lap, t->free_r, t->solve_r);
  t_ = std::move(t);
  fit(X_ref);
}

int TriMesh::membrane_nodes() const { return t_->n; }
int TriMesh::nodes() const { return t_->V + t_->E + t_->T; }
int TriMesh::elements() const { return t_->T; }
int TriMesh::vertices() const { return t_->V; }
const TriMeshParams& TriMesh::params() const { return t_->p; }
const Eigen::Matrix3Xd& TriMesh::reference() const { return t_->X_ref; }
double TriMesh::length_scale() const { return t_->p.size; }

double TriMesh::bound_angle() const { return std::asin(std::sqrt(t_->p.angle_bound)); }

double TriMesh::remesh_threshold(double angle) const {
  return angle * std::min(1.0, min_angle_ / bound_angle());
}

int TriMesh::element_slot(int e, int a) const {
  if (a < 3) return t_->tri[3 * e + a];
  if (a < 6) return t_->V + t_->tedge[3 * e + (a - 3)];
  if (a == 6) return t_->V + t_->E + e;
  return -1;
}

NodeKind TriMesh::node_kind(int node) const {
  if (node < t_->V) return t_->vkind[node];
  if (node < t_->V + t_->E) return t_->ekind[node - t_->V];
  return NodeKind::interior;
}

int TriMesh::wall_node(int k) const { return t_->wall_v.at(std::size_t(k)); }
int TriMesh::wall_midside_node(int k) const { return t_->V + t_->wall_e.at(std::size_t(k)); }
Eigen::Vector2d TriMesh::wall_point(int k) const {
  const int v = t_->wall_v.at(std::size_t(k));
  return {x_[v], r_[v]};
}

void TriMesh::corners(int e, double x[4], double r[4]) const {
  const double P = t_->p.period;
  for (int i = 0; i < 3; ++i) {
    const int v = t_->tri[3 * e + i];
    x[i] = x_[v] + (t_->wrap[3 * e + i] ? P : 0.0);
    r[i] = r_[v];
  }
}

Eigen::Vector2d TriMesh::slot_position(int e, int a) const {
  double x[4], r[4];
  corners(e, x, r);
  if (a < 3) return {x[a], r[a]};
  if (a < 6) {
    const int i = a - 3, j = (i + 1) % 3;
    return {0.5 * (x[i] + x[j]), 0.5 * (r[i] + r[j])};
  }
  return {(x[0] + x[1] + x[2]) / 3.0, (r[0] + r[1] + r[2]) / 3.0};
}

bool TriMesh::place(const Eigen::Matrix3Xd& X, std::vector<double>& x, std::vector<double>& r, double* min_angle,
                    std::string* cause) const {
  const Topology& t = *t_;
  if (X.cols() != t.n) throw std::invalid_argument("TriMesh::fit: X must have " + std::to_string(t.n) + " columns");
  for (int k = 0; k < t.n; ++k)
    if (!std::isfinite(X(0, k)) || !(X(1, k) > 0.0 && X(1, k) < t.p.Rc)) {
      if (cause) *cause = "ring " + std::to_string(k) + " at radius " + significant(X(1, k), 4) + " m, outside (0, Rc)";
      return false;
    }
  // harmonic extension of the rings' displacement: L_ff d_f = -L_fw d_w per component
  Eigen::VectorXd bx = Eigen::VectorXd::Zero(t.solve_x.rows()), br = Eigen::VectorXd::Zero(t.solve_r.rows());
  for (int c = 0; c < t.lap.outerSize(); ++c) {
    const int k = t.wall_of[c];
    if (k < 0) continue;
    const double dx = X(0, k) - t.X_ref(0, k), dr = X(1, k) - t.X_ref(1, k);
    for (Sparse::InnerIterator it(t.lap, c); it; ++it) {
      const int row = int(it.row());
      if (t.free_x[row] >= 0) bx[t.free_x[row]] -= it.value() * dx;
      if (t.free_r[row] >= 0) br[t.free_r[row]] -= it.value() * dr;
    }
  }
  const Eigen::VectorXd ux = t.solve_x.solve(bx), ur = t.solve_r.solve(br);
  x.resize(t.V);
  r.resize(t.V);
  for (int v = 0; v < t.V; ++v) {
    const int k = t.wall_of[v];
    if (k >= 0) {
      x[v] = X(0, k);
      r[v] = X(1, k);
      continue;
    }
    x[v] = t.x0[v] + ux[t.free_x[v]];
    r[v] = t.r0[v] + (t.free_r[v] >= 0 ? ur[t.free_r[v]] : 0.0);
  }
  double worst = std::numeric_limits<double>::infinity();
  const double P = t.p.period;
  for (int e = 0; e < t.T; ++e) {
    double px[3], pr[3];
    for (int i = 0; i < 3; ++i) {
      const int v = t.tri[3 * e + i];
      px[i] = x[v] + (t.wrap[3 * e + i] ? P : 0.0);
      pr[i] = r[v];
    }
    const double det = (px[1] - px[0]) * (pr[2] - pr[0]) - (px[2] - px[0]) * (pr[1] - pr[0]);
    if (!(det > 0.0)) {
      if (cause) {
        int near = 0;
        double best = std::numeric_limits<double>::infinity();
        for (int k = 0; k < t.n; ++k) {
          const double d = std::hypot(X(0, k) - px[0], X(1, k) - pr[0]);
          if (d < best) best = d, near = k;
        }
        *cause = "triangle " + std::to_string(e) + " of the moved mesh has a non-positive Jacobian, near membrane vertex " +
                 std::to_string(near);
      }
      return false;
    }
    if (min_angle) {
      for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3, k = (i + 2) % 3;
        const double ux1 = px[j] - px[i], ur1 = pr[j] - pr[i], ux2 = px[k] - px[i], ur2 = pr[k] - pr[i];
        const double cross = ux1 * ur2 - ux2 * ur1, dot = ux1 * ux2 + ur1 * ur2;
        worst = std::min(worst, std::atan2(cross, dot));
      }
    }
  }
  if (min_angle) *min_angle = worst;
  return true;
}

void TriMesh::fit(const Eigen::Matrix3Xd& X) {
  std::string cause;
  std::vector<double> x, r;
  double ang = 0.0;
  if (!place(X, x, r, &ang, &cause))
    throw NumericalError(cause, "the triangular mesh is made again on a nearer shape; a folding wall needs a finer axi.grid");
  x_.swap(x);
  r_.swap(r);
  min_angle_ = ang;
  buckets_ = false;
}

bool TriMesh::follows(const Eigen::Matrix3Xd& X, std::string* cause) const {
  std::vector<double> x, r;
  return place(X, x, r, nullptr, cause);
}

void TriMesh::rim_path(int end, std::vector<RimPathEdge>& path) const {
  if (end != 0 && end != 1) throw std::invalid_argument("TriMesh::rim_path: end must be 0 or 1");
  const auto& vs = t_->rim_vertices[end];
  const auto& es = t_->rim_edges[end];
  path.resize(es.size());
  // vs runs from the axis (vs[0]) to the rim; edge es[i] joins vs[i] and vs[i + 1]
  for (std::size_t i = 0; i < es.size(); ++i) {
    RimPathEdge& s = path[i];
    const int a = vs[i], b = vs[i + 1];
    s.node[0] = a;
    s.node[1] = t_->V + es[i];
    s.node[2] = b;
    s.x0 = x_[a];
    s.r0 = r_[a];
    s.x1 = x_[b];
    s.r1 = r_[b];
  }
}

void TriMesh::build_buckets() const {
  const Topology& t = *t_;
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
  for (int e = 0; e < t.T; ++e) {
    double x[4], r[4];
    corners(e, x, r);
    for (int i = 0; i < 3; ++i) xmin = std::min(xmin, x[i]), xmax = std::max(xmax, x[i]);
  }
  bcell_ = t.p.size;
  bx0_ = xmin;
  br0_ = 0.0;
  bnx_ = std::max(1, int(std::ceil((xmax - xmin) / bcell_)));
  bnr_ = std::max(1, int(std::ceil(t.p.Rc / bcell_)));
  std::vector<std::vector<int>> cells(std::size_t(bnx_) * bnr_);
  for (int e = 0; e < t.T; ++e) {
    double x[4], r[4];
    corners(e, x, r);
    const double x_lo = std::min({x[0], x[1], x[2]}), x_hi = std::max({x[0], x[1], x[2]});
    const double r_lo = std::min({r[0], r[1], r[2]}), r_hi = std::max({r[0], r[1], r[2]});
    const int i0 = std::clamp(int((x_lo - bx0_) / bcell_), 0, bnx_ - 1), i1 = std::clamp(int((x_hi - bx0_) / bcell_), 0, bnx_ - 1);
    const int j0 = std::clamp(int(r_lo / bcell_), 0, bnr_ - 1), j1 = std::clamp(int(r_hi / bcell_), 0, bnr_ - 1);
    for (int i = i0; i <= i1; ++i)
      for (int j = j0; j <= j1; ++j) cells[std::size_t(i) * bnr_ + j].push_back(e);
  }
  bucket_start_.assign(cells.size() + 1, 0);
  bucket_tris_.clear();
  for (std::size_t c = 0; c < cells.size(); ++c) {
    bucket_tris_.insert(bucket_tris_.end(), cells[c].begin(), cells[c].end());
    bucket_start_[c + 1] = int(bucket_tris_.size());
  }
  buckets_ = true;
}

int TriMesh::locate(double& x, double r, double& xi, double& eta) const {
  const double Rc = t_->p.Rc, P = t_->p.period;
  if (!(r >= 0.0 && r <= Rc)) throw std::invalid_argument("TriMesh::locate: r outside [0, Rc]");
  if (!buckets_) build_buckets();
  int best = -1;
  double best_min = -std::numeric_limits<double>::infinity(), bx = x, bxi = 0, beta = 0;
  for (int shift = -1; shift <= 1; ++shift) {
    const double xs = x + shift * P;
    const int i = int(std::floor((xs - bx0_) / bcell_));
    if (i < 0 || i >= bnx_) continue;
    const int j = std::clamp(int(r / bcell_), 0, bnr_ - 1);
    const std::size_t c = std::size_t(i) * bnr_ + j;
    for (int q = bucket_start_[c]; q < bucket_start_[c + 1]; ++q) {
      const int e = bucket_tris_[q];
      double px[4], pr[4];
      corners(e, px, pr);
      const double det = (px[1] - px[0]) * (pr[2] - pr[0]) - (px[2] - px[0]) * (pr[1] - pr[0]);
      const double l1 = ((xs - px[0]) * (pr[2] - pr[0]) - (px[2] - px[0]) * (r - pr[0])) / det;
      const double l2 = ((px[1] - px[0]) * (r - pr[0]) - (xs - px[0]) * (pr[1] - pr[0])) / det;
      const double lmin = std::min({l1, l2, 1.0 - l1 - l2});
      if (lmin > best_min) best_min = lmin, best = e, bx = xs, bxi = l1, beta = l2;
    }
  }
  if (best < 0 || best_min < -1e-9)
    throw std::invalid_argument("TriMesh::locate: no triangle holds (" + significant(x, 6) + ", " + significant(r, 6) + ")");
  x = bx;
  xi = bxi;
  eta = beta;
  return best;
}

}  // namespace swim::axi
