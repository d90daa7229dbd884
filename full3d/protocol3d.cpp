#include "full3d/protocol3d.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/errors.hpp"

namespace swim::full3d {

namespace {

/// C2 smooth step on [0, 1], clamped outside.
double smooth_step(double s) {
  if (s <= 0.0) return 0.0;
  if (s >= 1.0) return 1.0;
  return s * s * s * (10.0 + s * (-15.0 + 6.0 * s));
}

/// Levels lev[0..n] separated by increasing thresholds thr[0..n-1]; each jump is a smooth
/// step of width eps centred on its threshold.
double relay(double r, const double* thr, const double* lev, int n, double eps) {
  double v = lev[0];
  for (int j = 0; j < n; ++j) v += (lev[j + 1] - lev[j]) * smooth_step((r - thr[j]) / eps + 0.5);
  return v;
}

}  // namespace

Protocol3d::Protocol3d(const ProtocolParams& p, const CylinderMesh& mesh, double e_ref)
    : p_(p), mesh_(&mesh), e_ref_(e_ref) {
  const int n = p_.segments;
  const double L = mesh.length;
  const double other = L / (p_.first_ratio + n - 1);
  bounds_.resize(n + 1);
  for (int k = 0; k < n; ++k) bounds_[k] = k * other;
  bounds_[n] = L;
  seg_.assign(mesh.nodes(), 0);
  seg_count_.assign(n, 0);
  std::vector<int> ring_count(n, 0);
  // reference axial position of each ring along the tube (the axi tier's rings may be graded)
  std::vector<double> ring_s(mesh.n_rings);
  for (int r = 0; r < mesh.n_rings; ++r) ring_s[r] = mesh.X0(0, mesh.node(r, 0)) - mesh.axis_start.x();
  for (int r = 0; r < mesh.n_rings; ++r) {
    const double s = ring_s[r];
    int k = 0;
    while (k + 1 < n && s >= bounds_[k + 1] - 1e-12 * L) ++k;
    ++ring_count[k];
    for (int i = 0; i < mesh.n_theta; ++i) seg_[mesh.node(r, i)] = k;
    seg_count_[k] += mesh.n_theta;
  }
  for (int k = 0; k < n; ++k)
    if (ring_count[k] == 0)
      throw InputError("protocol.segments", std::to_string(n),
                       "segment " + std::to_string(k) + " of the 3D mesh holds no ring of nodes (ring spacing " +
                           std::to_string(mesh.ring_spacing) + " m); use fewer segments, a larger "
                           "protocol.first_segment_ratio or a finer full3d.grid");
  if (!(e_ref_ > 0.0)) throw InputError("wave.contracted_ratio", "", "the reference energy of the contracted tube must be > 0");
  if (p_.dual_cell_segments) {
    ring_share_.assign(mesh.n_rings, {});
    const int nr = mesh.n_rings;
    for (int r = 0; r < nr; ++r) {
      const double a = r > 0 ? 0.5 * (ring_s[r - 1] + ring_s[r]) : 0.0;
      const double b = r + 1 < nr ? 0.5 * (ring_s[r] + ring_s[r + 1]) : L;
      for (int k = 0; k < n; ++k) {
        const double o = std::min(b, bounds_[k + 1]) - std::max(a, bounds_[k]);
        if (o > 1e-12 * L) ring_share_[r].emplace_back(k, o / (b - a));
      }
    }
  }
}

void Protocol3d::start(double t, const Eigen::Matrix3Xd& X) {
  st_.phase = 0;
  st_.active = p_.segments - 1;
  st_.cycle_start.push_back(t);
  update(t, X, 0.0);  // cascades when the rightmost segment already sits at R_f
}

Eigen::VectorXd Protocol3d::segment_radii(const Eigen::Matrix3Xd& X) const {
  const Eigen::VectorXd r = node_radii(*mesh_, X);
  Eigen::VectorXd R = Eigen::VectorXd::Zero(p_.segments);
  if (p_.dual_cell_segments) {
    Eigen::VectorXd W = Eigen::VectorXd::Zero(p_.segments);
    for (int ring = 0; ring < mesh_->n_rings; ++ring)
      for (int i = 0; i < mesh_->n_theta; ++i) {
        const int node = mesh_->node(ring, i);
        for (const auto& [k, f] : ring_share_[ring]) {
          R[k] += f * mesh_->node_area[node] * r[node];
          W[k] += f * mesh_->node_area[node];
        }
      }
    return R.cwiseQuotient(W);
  }
  for (int i = 0; i < int(r.size()); ++i) R[seg_[i]] += r[i];
  for (int k = 0; k < p_.segments; ++k) R[k] /= seg_count_[k];
  return R;
}

Eigen::VectorXd Protocol3d::levels(const Eigen::Matrix3Xd& X) const {
  const int nn = mesh_->nodes();
  Eigen::VectorXd s = Eigen::VectorXd::Zero(nn);
  const double eps = kRampFraction * p_.delta;
  if (st_.phase == 0) {
    const Eigen::VectorXd R = segment_radii(X);
    const double thr[2] = {p_.R_f - p_.delta, p_.R_f + p_.delta};
    const double lev[3] = {-1.0, 0.0, 1.0};
    Eigen::VectorXd seg_level(p_.segments);
    for (int k = 0; k < p_.segments; ++k)
      seg_level[k] = k < st_.active ? 0.0 : k == st_.active ? 1.0 : relay(R[k], thr, lev, 2, eps);
    if (p_.dual_cell_segments) {
      for (int ring = 0; ring < mesh_->n_rings; ++ring) {
        double v = 0.0;
        for (const auto& [k, f] : ring_share_[ring]) v += f * seg_level[k];
        for (int i = 0; i < mesh_->n_theta; ++i) s[mesh_->node(ring, i)] = v;
      }
    } else {
      for (int i = 0; i < nn; ++i) s[i] = seg_level[seg_[i]];
    }
  } else if (st_.phase == 1) {
    const double R0 = mesh_->radius;
    const double thr[4] = {0.5 * R0, 0.8 * R0, R0 - p_.delta, R0 + p_.delta};
    const double lev[5] = {-1.0, -0.5, -0.1, 0.0, 0.1};
    if (p_.dual_cell_segments) {
      // the five-band law at every point of the wall, averaged over each ring's cell with the
      // radius interpolated linearly between the rings: the bands' thresholds cross the wall as
      // fronts narrower than a cell, which a per-ring evaluation would sample irregularly
      const Eigen::VectorXd rr = ring_radii(*mesh_, X);
      const int nr = mesh_->n_rings;
      constexpr int kSub = 16;  // samples per half-cell (midpoint rule)
      for (int ring = 0; ring < nr; ++ring) {
        double v = 0.0, len = 0.0;
        for (int side : {-1, 1}) {
          const int nb = ring + side;
          if (nb < 0 || nb >= nr) continue;
          const double half = 0.5 * std::abs(mesh_->X0(0, mesh_->node(nb, 0)) - mesh_->X0(0, mesh_->node(ring, 0)));
          double sum = 0.0;
          for (int j = 0; j < kSub; ++j) {
            const double w = 0.5 * (j + 0.5) / kSub;  // distance from the ring, in ring spacings
            sum += relay((1.0 - w) * rr[ring] + w * rr[nb], thr, lev, 4, eps);
          }
          v += half * sum / kSub;
          len += half;
        }
        for (int i = 0; i < mesh_->n_theta; ++i) s[mesh_->node(ring, i)] = v / len;
      }
    } else {
      const Eigen::VectorXd r = node_radii(*mesh_, X);
      for (int i = 0; i < nn; ++i) s[i] = relay(r[i], thr, lev, 4, eps);
    }
  }
  return s;
}

Eigen::Matrix3Xd Protocol3d::force(const Eigen::Matrix3Xd& X) const {
  const Eigen::VectorXd s = levels(X);
  Eigen::Matrix3Xd F = radial_directions(*mesh_, X);
  for (Eigen::Index i = 0; i < F.cols(); ++i) F.col(i) *= -p_.q * mesh_->node_area[i] * s[i];
  return F;
}

int Protocol3d::update(double t, const Eigen::Matrix3Xd& X, double wall_energy) {
  int switches = 0;
  if (st_.phase == 0) {
    const Eigen::VectorXd R = segment_radii(X);
    while (st_.phase == 0 && R[st_.active] <= p_.R_f) {
      st_.segment_reached.push_back(t);
      ++switches;
      if (--st_.active < 0) {
        st_.phase = 1;
        st_.active = 0;
      }
    }
  } else if (st_.phase == 1 && (p_.shape_end ? shape_recovered(X) : wall_energy < end_threshold())) {
    st_.cycle_end.push_back(t);
    ++st_.cycles_completed;
    ++switches;
    if (!p_.repeat_until_duration && st_.cycles_completed >= p_.cycles) {
      st_.phase = 2;
    } else {
      st_.switches += switches;
      start(t, X);
      return switches;
    }
  }
  st_.switches += switches;
  return switches;
}

bool Protocol3d::shape_recovered(const Eigen::Matrix3Xd& X) const {
  const CylinderMesh& m = *mesh_;
  const Eigen::VectorXd rr = ring_radii(m, X);
  if ((rr.array() - m.radius).abs().maxCoeff() > p_.delta) return false;
  // the mean axial translation: the plain node mean, or (dual cells) the mean over the tube's
  // surface, whose discrete value converges to the continuum one at second order
  const double shift = p_.dual_cell_segments
                           ? (X.row(0) - m.X0.row(0)).dot(m.node_area.transpose()) / m.node_area.sum()
                           : X.row(0).mean() - m.X0.row(0).mean();
  for (int r = 0; r < m.n_rings; ++r) {
    double dx = 0;
    for (int i = 0; i < m.n_theta; ++i) dx += X(0, m.node(r, i)) - m.X0(0, m.node(r, i));
    if (std::abs(dx / m.n_theta - shift) > p_.delta) return false;
  }
  return true;
}

double uniform_contraction_energy(const CylinderMesh& mesh, const MembraneParams& m, double R_f) {
  Eigen::Matrix3Xd X = mesh.X0;
  const double scale = R_f / mesh.radius;
  for (Eigen::Index i = 0; i < X.cols(); ++i) {
    X(1, i) = mesh.axis_start[1] + scale * (X(1, i) - mesh.axis_start[1]);
    X(2, i) = mesh.axis_start[2] + scale * (X(2, i) - mesh.axis_start[2]);
  }
  return elastic_energy(mesh, X, m);
}

}  // namespace swim::full3d
