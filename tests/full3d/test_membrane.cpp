// Spring-network membrane (eqs. 6-9): mesh, no-leak rule, analytic forces,
// reference equilibrium, invariances, uniform-pressure response.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "common/errors.hpp"
#include "full3d/membrane.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/run3d_measure.hpp"

using namespace swim::full3d;

namespace {
constexpr double kR0 = 0.125e-6, kL = 0.4e-6;

CylinderMesh small_mesh() { return make_cylinder(kR0, kL, 10, Eigen::Vector3d(0.1e-6, 0.25e-6, 0.25e-6)); }

Eigen::Matrix3Xd perturbed(const CylinderMesh& m, double rel, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N(0.0, rel * m.rest_length.mean());
  Eigen::Matrix3Xd X = m.X0;
  for (Eigen::Index i = 0; i < X.size(); ++i) X.data()[i] += N(rng);
  return X;
}

// max_i |F_i + dE/dX_i (central FD)| / max_i |F_i|
template <class E>
double fd_error(const Eigen::Matrix3Xd& X, const Eigen::Matrix3Xd& F, E energy, double eps) {
  Eigen::Matrix3Xd Y = X;
  double err = 0.0;
  for (Eigen::Index i = 0; i < X.size(); ++i) {
    const double x0 = Y.data()[i];
    Y.data()[i] = x0 + eps;
    const double ep = energy(Y);
    Y.data()[i] = x0 - eps;
    const double em = energy(Y);
    Y.data()[i] = x0;
    err = std::max(err, std::abs(F.data()[i] + (ep - em) / (2 * eps)));
  }
  return err / F.cwiseAbs().maxCoeff();
}
}  // namespace

TEST(MembraneMesh, NearEquilateralCylinder) {
  const CylinderMesh m = small_mesh();
  EXPECT_EQ(m.nodes(), m.n_theta * m.n_rings);
  EXPECT_EQ(int(m.triangles.size()), 2 * m.n_theta * (m.n_rings - 1));
  // Euler characteristic of an open tube: V - E + F = 0
  EXPECT_EQ(m.nodes() - int(m.edges.size()) + int(m.triangles.size()), 0);
  // every interior edge has a hinge; boundary edges are the two end rings
  EXPECT_EQ(m.hinges.size() + 2 * std::size_t(m.n_theta), m.edges.size());
  EXPECT_NEAR(m.ring_spacing * (m.n_rings - 1), kL, 1e-18);
  const double ratio = m.rest_length.maxCoeff() / m.rest_length.minCoeff();
  EXPECT_LT(ratio, 1.15) << "triangles should be near-equilateral";
  // all nodes on the cylinder, total area close to 2 pi R0 L (inscribed polygon)
  for (int i = 0; i < m.nodes(); ++i) {
    Eigen::Vector3d r = m.X0.col(i) - m.axis_start;
    r.x() = 0;
    EXPECT_NEAR(r.norm(), kR0, 1e-18);
  }
  const double area = m.node_area.sum() / (2 * M_PI * kR0 * kL);
  EXPECT_GT(area, 0.97);  // inscribed: slightly below the smooth cylinder's area
  EXPECT_LT(area, 1.0);
  // outward orientation
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d n = (m.X0.col(t[1]) - m.X0.col(t[0])).cross(m.X0.col(t[2]) - m.X0.col(t[0]));
    Eigen::Vector3d c = (m.X0.col(t[0]) + m.X0.col(t[1]) + m.X0.col(t[2])) / 3 - m.axis_start;
    c.x() = 0;
    EXPECT_GT(n.dot(c), 0.0);
  }
  // reference folds: convex (theta0 > 0) across the slanted edges, concave
  // (theta0 < 0) across the ring chords, whose neighbouring apexes stick out
  for (std::size_t k = 0; k < m.hinges.size(); ++k) {
    const auto& h = m.hinges[k];
    const bool ring_edge = m.ring_of(h[0]) == m.ring_of(h[1]);
    EXPECT_GT(ring_edge ? -m.rest_angle[k] : m.rest_angle[k], 0.1);
  }
}

TEST(MembraneMesh, NoLeakResolutionChoice) {
  const double h = 0.5e-6 / 32;
  const CylinderMesh m = make_cylinder_for_grid(kR0, kL, h, Eigen::Vector3d::Zero());
  EXPECT_LT(max_edge_length(m, m.X0), 0.5 * h);
  EXPECT_NO_THROW(check_no_leak(m, m.X0, h));
  // the next coarser mesh would violate the safety margin
  const CylinderMesh c = make_cylinder(kR0, kL, m.n_theta - 1, Eigen::Vector3d::Zero());
  EXPECT_GE(max_edge_length(c, c.X0), 0.9 * 0.5 * h);
  std::printf("h = %.4g m: n_theta = %d, n_rings = %d, nodes = %d, max edge = %.4g m (h/2 = %.4g m)\n", h,
              m.n_theta, m.n_rings, m.nodes(), max_edge_length(m, m.X0), 0.5 * h);
  Eigen::Matrix3Xd X = m.X0;
  X.row(0) *= 1.6;  // stretch axially: edges beyond h/2
  EXPECT_THROW(check_no_leak(m, X, h, 1e-6), swim::NumericalError);
  EXPECT_THROW(make_cylinder(kR0, kL, 2, Eigen::Vector3d::Zero()), swim::InputError);
}

TEST(MembraneForces, DihedralGradientMatchesFiniteDifferences) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix<double, 3, 4> P;
    P << 0, 1, 0.5, 0.5, 0, 0, 1, -1, 0, 0, 0.3, 0.2;
    for (int i = 0; i < 12; ++i) P.data()[i] += 0.2 * U(rng);
    Eigen::Matrix<double, 3, 4> g;
    dihedral_angle(P.col(0), P.col(1), P.col(2), P.col(3), &g);
    const double eps = 1e-6;
    for (int i = 0; i < 12; ++i) {
      Eigen::Matrix<double, 3, 4> Q = P;
      Q.data()[i] += eps;
      const double tp = dihedral_angle(Q.col(0), Q.col(1), Q.col(2), Q.col(3));
      Q.data()[i] -= 2 * eps;
      const double tm = dihedral_angle(Q.col(0), Q.col(1), Q.col(2), Q.col(3));
      EXPECT_NEAR(g.data()[i], (tp - tm) / (2 * eps), 1e-8);
    }
  }
}

TEST(MembraneForces, ForcesAreMinusEnergyGradient) {
  const CylinderMesh m = small_mesh();
  const Eigen::Matrix3Xd X = perturbed(m, 0.05, 1);
  const double eps = 1e-6 * m.rest_length.mean();
  const double ks = 5.5e-8, kb = 1e-15;
  {
    Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, X.cols());
    add_stretching_forces(m, X, ks, F);
    const double e = fd_error(X, F, [&](const Eigen::Matrix3Xd& Y) { return stretching_energy(m, Y, ks); }, eps);
    std::printf("stretching: relative FD gradient error %.2e\n", e);
    EXPECT_LT(e, 1e-6);
  }
  for (auto form : {BendingForm::ReferenceAngle, BendingForm::Printed}) {
    Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, X.cols());
    add_bending_forces(m, X, kb, form, F);
    const double e = fd_error(X, F, [&](const Eigen::Matrix3Xd& Y) { return bending_energy(m, Y, kb, form); }, eps);
    std::printf("bending (%s): relative FD gradient error %.2e\n",
                form == BendingForm::Printed ? "printed" : "reference angle", e);
    EXPECT_LT(e, 1e-6);
  }
}

TEST(MembraneForces, ReferenceMeshIsEquilibriumOnlyWithReferenceAngles) {
  const CylinderMesh m = small_mesh();
  MembraneParams p;
  const Eigen::Matrix3Xd Fref = elastic_forces(m, m.X0, p);
  p.bending = BendingForm::Printed;
  const Eigen::Matrix3Xd Fprint = elastic_forces(m, m.X0, p);
  // scale of a bending force: kb * theta0 / 2 (dE/dtheta ~ kb L theta/2, dtheta/dX ~ 1/L)
  const double scale = p.kb * m.rest_angle.maxCoeff() / 2;
  const double fr = Fref.colwise().norm().maxCoeff(), fp = Fprint.colwise().norm().maxCoeff();
  std::printf("max |F| at the reference mesh: reference-angle form %.2e N, printed form %.2e N\n", fr, fp);
  EXPECT_LT(fr, 1e-12 * scale);
  EXPECT_GT(fp, 0.1 * scale);
  // the reference mesh stores zero energy, up to the round-off of tan((theta - theta0)/2) ~ 1e-16:
  // against the printed form's energy of the same mesh, < 1e-24 of it
  MembraneParams printed;
  printed.bending = BendingForm::Printed;
  const double e_print = elastic_energy(m, m.X0, printed);
  EXPECT_GT(e_print, 0.0);
  EXPECT_LT(elastic_energy(m, m.X0, MembraneParams{}), 1e-24 * e_print);
}

TEST(MembraneForces, TotalForceAndTorqueVanish) {
  const CylinderMesh m = small_mesh();
  const Eigen::Matrix3Xd X = perturbed(m, 0.1, 2);
  for (auto form : {BendingForm::ReferenceAngle, BendingForm::Printed}) {
    const MembraneParams p{5.5e-8, 1e-15, form};
    const Eigen::Matrix3Xd F = elastic_forces(m, X, p);
    const double fsum = F.cwiseAbs().sum();
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < X.cols(); ++i) torque += X.col(i).cross(F.col(i));
    EXPECT_LT(F.rowwise().sum().norm(), 1e-13 * fsum);
    EXPECT_LT(torque.norm(), 1e-13 * fsum * X.cwiseAbs().maxCoeff());
  }
}

TEST(MembranePressure, UniformContractionAndEffectiveC1) {
  const CylinderMesh m = make_cylinder(kR0, kL, 16, Eigen::Vector3d::Zero());
  const MembraneParams p;
  double c1[2];
  const double P[2] = {2e-3, 4e-3};  // Pa
  for (int s = 0; s < 2; ++s) {
    const PressureResponse r = relax_under_pressure(m, p, P[s]);
    c1[s] = r.c1;
    const Eigen::VectorXd nr = node_radii(m, r.X);
    // azimuthal uniformity: all nodes of a ring share its radius
    for (int i = 0; i < m.nodes(); ++i)
      EXPECT_NEAR(nr[i], r.ring_radius[m.ring_of(i)], 1e-6 * (kR0 - r.mid_radius));
    // axial uniformity of the contraction over the interior rings
    double lo = 1e300, hi = -1e300;
    for (int k = 2; k < m.n_rings - 2; ++k) {
      lo = std::min(lo, kR0 - r.ring_radius[k]);
      hi = std::max(hi, kR0 - r.ring_radius[k]);
    }
    std::printf("P = %.3g Pa: n_theta=%d rings=%d it=%d, R0-R mid %.4e m, interior spread %.2f%%, "
                "end ring %.4e m, C1 = %.4e Pa/m\n",
                P[s], m.n_theta, m.n_rings, r.iterations, kR0 - r.mid_radius, 100 * (hi - lo) / hi,
                kR0 - r.ring_radius[0], r.c1);
    EXPECT_GT(kR0 - r.mid_radius, 0.0);
    EXPECT_LT((hi - lo) / hi, 0.05);
  }
  EXPECT_NEAR(c1[1] / c1[0], 1.0, 0.02);  // linear regime
}

// A pressure profile along the axis (relax_under_ring_pressures) that is the same on every ring
// is the uniform load: the same Newton path, so the same static state bit for bit. A profile of
// the wrong length is refused.
TEST(MembranePressure, AConstantRingProfileIsTheUniformLoad) {
  const CylinderMesh m = make_cylinder(kR0, kL, 16, Eigen::Vector3d::Zero());
  const MembraneParams p;
  const double P = 3e-3;  // Pa
  const PressureResponse u = relax_under_pressure(m, p, P);
  const PressureResponse v = relax_under_ring_pressures(m, p, Eigen::VectorXd::Constant(m.n_rings, P));
  EXPECT_GT(u.iterations, 0);
  EXPECT_EQ(v.iterations, u.iterations);
  EXPECT_EQ((v.X - u.X).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(v.c1, u.c1);
  EXPECT_EQ(v.max_residual_force, u.max_residual_force);
  EXPECT_THROW(relax_under_ring_pressures(m, p, Eigen::VectorXd::Constant(m.n_rings - 1, P)), swim::InputError);
  // a profile that varies, inward at the ends and outward in the middle: the rings follow it
  Eigen::VectorXd prof(m.n_rings);
  for (int k = 0; k < m.n_rings; ++k) prof[k] = P * std::cos(2.0 * M_PI * k / (m.n_rings - 1));
  const PressureResponse w = relax_under_ring_pressures(m, p, prof);
  EXPECT_GT(w.ring_radius[(m.n_rings - 1) / 2], kR0);
  EXPECT_LT(w.ring_radius[0], kR0);
  EXPECT_LT(w.ring_radius[m.n_rings - 1], kR0);
}

// The wall-wrinkle measure of a 3D run's series (run3d_measure.hpp): zero for any
// axisymmetric shape (here rings contracted to different radii), and the RMS amplitude
// a / sqrt(2) of an azimuthal lobe pattern r = r_k (1 + ...) + a cos(m theta) on the ring
// that carries it.
TEST(MembraneMeasure, WallWrinkleIsTheRmsOfTheAzimuthalLobes) {
  const CylinderMesh m = small_mesh();
  Eigen::Matrix3Xd X = m.X0;
  auto set_radius = [&](int node, double r) {
    Eigen::Vector3d d = X.col(node) - m.axis_start;
    const double x = d.x();
    d.x() = 0;
    d *= r / d.norm();
    d.x() = x;
    X.col(node) = m.axis_start + d;
  };
  for (int r = 0; r < m.n_rings; ++r)
    for (int i = 0; i < m.n_theta; ++i) set_radius(m.node(r, i), kR0 * (0.55 + 0.4 * r / (m.n_rings - 1)));
  EXPECT_LT(wall_wrinkle(m, node_radii(m, X), ring_radii(m, X)), 1e-12 * kR0);
  const int ring = m.n_rings / 2, lobes = 3;
  const double a = 0.1 * kR0, base = node_radii(m, X)[m.node(ring, 0)];
  for (int i = 0; i < m.n_theta; ++i) {
    const Eigen::Vector3d d = X.col(m.node(ring, i)) - m.axis_start;
    set_radius(m.node(ring, i), base + a * std::cos(lobes * std::atan2(d.z(), d.y())));
  }
  EXPECT_NEAR(wall_wrinkle(m, node_radii(m, X), ring_radii(m, X)), a / std::sqrt(2.0), 1e-3 * a);
}

// The bending rigidity that eq. (8) gives the tube wall against azimuthal lobes
// r = R0 + w cos(m theta): its energy (k_b / 2) sum L_l tan^2(theta_l / 2) against the
// continuum (D / 2) int dkappa^2 dA, dkappa = (m^2 - 1) w cos(m theta) / R0^2. Every hinge
// angle scales with the edge length a times the curvature and there are about 2 sqrt(3) / a^2
// edges per area, so D = c k_b a: halving the mesh spacing halves the wall's bending
// rigidity (docs/full3d.md, "Wall wrinkling").
TEST(MembraneForces, PaperBendingRigidityIsProportionalToTheEdgeLength) {
  double prev = 0.0;
  for (int n : {63, 126, 252}) {
    const CylinderMesh m = make_cylinder(kR0, kL, n, Eigen::Vector3d::Zero());
    const double a = m.rest_length.mean();
    for (int lobes : {4, 8}) {
      const double w = 1e-4 * kR0;
      Eigen::Matrix3Xd X = m.X0;
      for (int i = 0; i < m.nodes(); ++i) {
        const double th = std::atan2(X(2, i), X(1, i));
        X(1, i) *= 1.0 + w / kR0 * std::cos(lobes * th);
        X(2, i) *= 1.0 + w / kR0 * std::cos(lobes * th);
      }
      const double e = bending_energy(m, X, 1.0, BendingForm::ReferenceAngle);
      const double dk = (lobes * lobes - 1) * w / (kR0 * kR0);
      const double d_per_kb = 2.0 * e / (0.5 * 2.0 * M_PI * kR0 * kL * dk * dk);
      std::printf("n_theta %d, edge %.3g m, m = %d: D / k_b = %.4g m, D / (k_b a) = %.4f\n", n, a, lobes, d_per_kb,
                  d_per_kb / a);
      if (lobes == 4) {
        if (prev > 0) {
          EXPECT_NEAR(prev / d_per_kb, 2.0, 0.1);
        }
        prev = d_per_kb;
      }
    }
  }
}

// The axisymmetric wall (IbOptions::axisymmetric_wall): the projected node velocities are,
// ring by ring, one axial velocity plus one radial speed along each node's radial direction;
// an axisymmetric field is left as it is; the projection is idempotent; rings moved with it
// stay circles about the axis (wall wrinkle zero).
TEST(MembraneMeasure, AxisymmetricProjectionKeepsTheRingsCircles) {
  const CylinderMesh m = small_mesh();
  std::mt19937 rng(11);
  std::normal_distribution<double> N(0.0, 1e-6);
  Eigen::Matrix3Xd U(3, m.nodes());
  for (Eigen::Index i = 0; i < U.size(); ++i) U.data()[i] = N(rng);
  Eigen::Matrix3Xd P = U;
  project_axisymmetric(m, m.X0, P);
  for (int r = 0; r < m.n_rings; ++r) {
    const int k0 = m.node(r, 0);
    const Eigen::Vector3d d0 = m.X0.col(k0) - m.axis_start;
    const double ur0 = (P(1, k0) * d0.y() + P(2, k0) * d0.z()) / std::hypot(d0.y(), d0.z());
    double ux_mean = 0.0;
    for (int i = 0; i < m.n_theta; ++i) ux_mean += U(0, m.node(r, i)) / m.n_theta;
    for (int i = 0; i < m.n_theta; ++i) {
      const int k = m.node(r, i);
      const Eigen::Vector3d d = m.X0.col(k) - m.axis_start;
      const double rho = std::hypot(d.y(), d.z());
      EXPECT_NEAR(P(0, k), ux_mean, 1e-18);
      EXPECT_NEAR((P(1, k) * d.y() + P(2, k) * d.z()) / rho, ur0, 1e-18);   // one radial speed
      EXPECT_NEAR((-P(1, k) * d.z() + P(2, k) * d.y()) / rho, 0.0, 1e-18);  // no azimuthal motion
    }
  }
  Eigen::Matrix3Xd Q = P;
  project_axisymmetric(m, m.X0, Q);
  EXPECT_LT((Q - P).cwiseAbs().maxCoeff(), 1e-20);
  // one step of 5 % of R0 with the projected and with the raw velocities
  const Eigen::Matrix3Xd Xp = m.X0 + (0.05 * kR0 / P.cwiseAbs().maxCoeff()) * P;
  const Eigen::Matrix3Xd Xu = m.X0 + (0.05 * kR0 / U.cwiseAbs().maxCoeff()) * U;
  EXPECT_LT(wall_wrinkle(m, node_radii(m, Xp), ring_radii(m, Xp)), 1e-12 * kR0);
  EXPECT_GT(wall_wrinkle(m, node_radii(m, Xu), ring_radii(m, Xu)), 1e-3 * kR0);
}

TEST(MembraneForces, EnergyOfTheForcePassAndOfTheThreadsEqualsTheAngleDefinition) {
  // the energies of elastic_forces' pass equal stretching_energy / bending_energy with the same
  // threads to the last bits (the same per-element formula; compiled for FMA, the two inlined
  // copies may round differently in the last place), differ between thread counts only at
  // round-off, and the hinge term
  // (evaluated without trigonometry) equals kb/2 sum |e| tan^2((theta - theta0)/2) with theta
  // from dihedral_angle (atan2) to round-off
  const CylinderMesh m = small_mesh();
  const Eigen::Matrix3Xd X = perturbed(m, 0.05, 3);
  for (auto form : {BendingForm::ReferenceAngle, BendingForm::Printed}) {
    MembraneParams p;
    p.ks = 5.5e-8;
    p.kb = 1e-15;
    p.bending = form;
    double by_angle = 0.0;
    for (std::size_t k = 0; k < m.hinges.size(); ++k) {
      const auto& h = m.hinges[k];
      const double th = dihedral_angle(X.col(h[0]), X.col(h[1]), X.col(h[2]), X.col(h[3]));
      const double t = std::tan(0.5 * (th - (form == BendingForm::ReferenceAngle ? m.rest_angle[Eigen::Index(k)] : 0.0)));
      by_angle += (X.col(h[1]) - X.col(h[0])).norm() * t * t;
    }
    by_angle *= 0.5 * p.kb;
    for (int threads : {1, 2, 3}) {
      std::array<double, 2> e{};
      const Eigen::Matrix3Xd F = elastic_forces(m, X, p, threads, &e);
      EXPECT_DOUBLE_EQ(e[0], stretching_energy(m, X, p.ks, threads));  // within 4 ulps
      EXPECT_DOUBLE_EQ(e[1], bending_energy(m, X, p.kb, form, threads));
      EXPECT_EQ(F, elastic_forces(m, X, p, threads)) << "the energy does not change the forces";
      EXPECT_NEAR(e[0], stretching_energy(m, X, p.ks, 1), 1e-13 * e[0]);
      EXPECT_NEAR(e[1], by_angle, 1e-12 * by_angle);
      EXPECT_GT(e[0], 0.0);
      EXPECT_GT(e[1], 0.0);
    }
  }
}
