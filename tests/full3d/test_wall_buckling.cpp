// The wall model (docs/full3d.md, "The wall model"): a bending rigidity that does not depend
// on the mesh, the ring-buckling estimate, the mode a uniform load grows on meshes of different
// symmetry, and the seed imperfection.
//
// The buckled modes are measured on the discrete wall by an overdamped relaxation of the
// membrane alone (c A_i dX_i/dt = F_i, no fluid): from the symmetric equilibrium under a
// uniform load, a small perturbation grows in the unstable modes at their linear rates, and
// the ring's Fourier spectrum of the radial displacement says which one.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "common/errors.hpp"
#include "common/scene.hpp"
#include "full3d/buckling_estimate.hpp"
#include "full3d/ib_solver.hpp"
#include "full3d/membrane.hpp"
#include "full3d/run3d_measure.hpp"
#include "full3d/run3d_output.hpp"
#include "full3d/scene3d.hpp"

using namespace swim;
using namespace swim::full3d;

namespace {
constexpr double kR0 = 0.125e-6;

// The test's own measure of the wall's bending rigidity on a mesh: the hinge energy of axially
// uniform inextensional lobes (radial w cos(m phi), tangential -(w/m) sin(m phi), set here
// on each node's polar coordinates) against the continuum (D / 2) int dkappa^2 dA,
// dkappa = (m^2 - 1) w cos(m phi) / R0^2 (m = 4 here: not the m = 2 lobes the scene's
// mapping uses).
double measured_rigidity(const CylinderMesh& mesh, double kb, BendingForm form, int lobes) {
  const double R0 = mesh.radius, w = 1e-4 * R0;
  auto lobed = [&](double amp) {
    Eigen::Matrix3Xd X = mesh.X0;
    for (int i = 0; i < mesh.nodes(); ++i) {
      const double dy = X(1, i) - mesh.axis_start[1], dz = X(2, i) - mesh.axis_start[2];
      const double phi = std::atan2(dz, dy) - amp / (lobes * R0) * std::sin(lobes * std::atan2(dz, dy));
      const double r = std::hypot(dy, dz) + amp * std::cos(lobes * std::atan2(dz, dy));
      X(1, i) = mesh.axis_start[1] + r * std::cos(phi);
      X(2, i) = mesh.axis_start[2] + r * std::sin(phi);
    }
    return bending_energy(mesh, X, kb, form);
  };
  const double e2 = 0.5 * (lobed(w) + lobed(-w)) - bending_energy(mesh, mesh.X0, kb, form);
  const double dk = (lobes * lobes - 1) * w / (R0 * R0);
  return 2.0 * e2 / (0.5 * 2.0 * M_PI * R0 * mesh.length * dk * dk);
}

Params3d paper_scene(int cells, const std::vector<std::string>& sets) {
  scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json");
  sc["full3d"]["grid"]["cells_across"] = cells;
  for (const auto& s : sets) scene::apply_override(sc, s);
  scene::json resolved;
  return read_scene3d(sc, resolved);
}

// The key the scene reader names when it refuses paper_scene(cells, sets), "accepted" when it does not.
std::string refused_scene_key(int cells, const std::vector<std::string>& sets) {
  try {
    paper_scene(cells, sets);
  } catch (const InputError& err) {
    return err.key();
  }
  return "accepted";
}

// Amplitudes |c_m| (m = 0 .. n_theta/2) of the radial displacement r_i - R_ref of one ring,
// c_m = (2 / n) sum_i (r_i - R_ref) exp(-i m phi_i), phi_i the node's reference angle.
std::vector<double> ring_spectrum(const CylinderMesh& mesh, const Eigen::Matrix3Xd& X, int ring) {
  const Eigen::VectorXd r = node_radii(mesh, X);
  double mean = 0.0;
  for (int i = 0; i < mesh.n_theta; ++i) mean += r[mesh.node(ring, i)] / mesh.n_theta;
  std::vector<double> out(std::size_t(mesh.n_theta / 2 + 1), 0.0);
  for (int m = 0; m <= mesh.n_theta / 2; ++m) {
    std::complex<double> c = 0.0;
    for (int i = 0; i < mesh.n_theta; ++i) {
      const int k = mesh.node(ring, i);
      const double phi = 2.0 * M_PI * (i + 0.5 * (ring % 2)) / mesh.n_theta;
      c += (r[k] - mean) * std::polar(1.0, -m * phi);
    }
    out[std::size_t(m)] = 2.0 / mesh.n_theta * std::abs(c);
  }
  return out;
}

int dominant_lobes(const std::vector<double>& spectrum) {
  return int(std::max_element(spectrum.begin() + 2, spectrum.end()) - spectrum.begin());
}

// Overdamped relaxation of the membrane under the uniform load P (potential P sum A_i r_i):
// X += dt / (c A_i) (F_el - P A_i e_r), c = 1 kg/(m^2 s), for the time T. The step is 0.9 / lambda_max of
// the relaxation operator (power iteration on differences of the exact forces), inside the
// explicit bound 2 / lambda_max.
struct Relaxation {
  const CylinderMesh& mesh;
  MembraneParams p;
  double pressure;
  Eigen::Matrix3Xd force(const Eigen::Matrix3Xd& X) const {
    Eigen::Matrix3Xd F = elastic_forces(mesh, X, p);
    const Eigen::Matrix3Xd e = radial_directions(mesh, X);
    for (int i = 0; i < mesh.nodes(); ++i) F.col(i) -= pressure * mesh.node_area[i] * e.col(i);
    return F;
  }
  Eigen::Matrix3Xd rate(const Eigen::Matrix3Xd& X) const {
    Eigen::Matrix3Xd V = force(X);
    for (int i = 0; i < mesh.nodes(); ++i) V.col(i) /= mesh.node_area[i];
    return V;
  }
  double largest_rate(const Eigen::Matrix3Xd& X) const {
    std::mt19937 rng(5);
    std::normal_distribution<double> N(0.0, 1.0);
    Eigen::Matrix3Xd v(3, X.cols());
    for (Eigen::Index i = 0; i < v.size(); ++i) v.data()[i] = N(rng);
    const double s = 1e-6 * mesh.rest_length.minCoeff();
    double lambda = 0.0;
    for (int it = 0; it < 60; ++it) {
      v /= v.norm();
      const Eigen::Matrix3Xd w = (rate(X - s * v) - rate(X + s * v)) / (2.0 * s);
      lambda = w.norm();
      v = w;
    }
    return lambda;
  }
  Eigen::Matrix3Xd run(Eigen::Matrix3Xd X, double T) const {
    const double dt = 0.9 / (1.2 * largest_rate(X));
    const long steps = long(std::ceil(T / dt));
    for (long n = 0; n < steps; ++n) X += (T / steps) * rate(X);
    return X;
  }
};

// A short tube on n_theta nodes per ring with the rigidity D (the scene's mapping of k_b on this mesh).
CylinderMesh tube(int n_theta) { return make_cylinder(kR0, 2.0 * kR0, n_theta, Eigen::Vector3d::Zero()); }
MembraneParams wall_with_rigidity(const CylinderMesh& mesh, double D) {
  MembraneParams p;
  p.kb = D / bending_rigidity_per_kb(mesh, p.bending);
  return p;
}
constexpr double kD = 4.0e-24;  // J; Y R^2 / D = 250: the load 12 D / R^3 contracts the tube by 2 %
}  // namespace

// ---- the wall's rigidity by mesh ----

// With the default wall model (bending_model "rigidity") the bending rigidity measured on the
// discrete wall (m = 4 lobes, the test's own measure) equals the scene's D on the meshes of 24,
// 32, 40 and 48 cells across (126, 168, 210 and 252 nodes per ring) within 6 %; the paper's
// literal fixed k_b gives the same meshes rigidities that differ by more than that (it halves
// with the edge length), so it fails the same assertion.
TEST(WallRigidity, MeasuredRigidityIsTheScenesOnEveryMeshAndAFixedKbIsNot) {
  constexpr double kTol = 0.06;
  std::vector<double> fixed;
  for (int cells : {24, 32, 40, 48}) {
    const Params3d p = paper_scene(cells, {});
    const CylinderMesh mesh = make_mesh(p);
    const double D = measured_rigidity(mesh, p.membrane.kb, p.membrane.bending, 4);
    std::printf("%d cells, n_theta %d, edge %.3g m: rigidity wall D = %.4g J (scene %.4g J, %+.2f %%)", cells,
                mesh.n_theta, mesh.rest_length.mean(), D, p.bending_rigidity, 100.0 * (D / p.bending_rigidity - 1.0));
    EXPECT_NEAR(D / p.bending_rigidity, 1.0, kTol) << cells << " cells";
    const Params3d q = paper_scene(cells, {"full3d.membrane.bending_model=\"fixed_kb\""});
    EXPECT_DOUBLE_EQ(q.membrane.kb, 1e-15);
    fixed.push_back(measured_rigidity(make_mesh(q), q.membrane.kb, q.membrane.bending, 4));
    std::printf("; fixed k_b: D = %.4g J; D / (k_b a) for m = 2, 3, 4, 8: %.4f %.4f %.4f %.4f\n", fixed.back(),
                bending_rigidity_per_kb(mesh, p.membrane.bending, 2) / mesh.rest_length.mean(),
                bending_rigidity_per_kb(mesh, p.membrane.bending, 3) / mesh.rest_length.mean(),
                bending_rigidity_per_kb(mesh, p.membrane.bending, 4) / mesh.rest_length.mean(),
                bending_rigidity_per_kb(mesh, p.membrane.bending, 8) / mesh.rest_length.mean());
  }
  // the fixed k_b's rigidity against the same assertion: a constant D would be within kTol of
  // every mesh's value; the spread is far larger
  const double lo = *std::min_element(fixed.begin(), fixed.end()), hi = *std::max_element(fixed.begin(), fixed.end());
  EXPECT_GT(hi / lo - 1.0, 4.0 * kTol);
  EXPECT_NEAR(hi / lo, 2.0, 0.2);  // 24 vs 48 cells: half the edge length, half the rigidity
}

// The default maps the paper's k_b = 1e-15 N at the reference edge 4.6875 nm, the default grid's:
// at 32 cells (the default) the rigidity wall is the literal one, k_b = 1e-15 N exactly.
TEST(WallRigidity, TheDefaultGridKeepsThePapersKb) {
  const Params3d p = paper_scene(32, {});
  EXPECT_EQ(p.bending_model, Params3d::BendingModel::Rigidity);
  EXPECT_NEAR(p.membrane.kb, 1e-15, 1e-9 * 1e-15);
  EXPECT_NEAR(p.reference_edge, 4.6875e-9, 1e-20);
  const Params3d q = paper_scene(32, {"full3d.membrane.bending_model=\"fixed_kb\""});
  EXPECT_NEAR(q.bending_rigidity, p.bending_rigidity, 1e-9 * p.bending_rigidity);
  // a stated D is the same wall as the k_b it maps from
  char d[64];
  std::snprintf(d, sizeof d, "full3d.membrane.bending_rigidity=\"%.17g J\"", p.bending_rigidity);
  const Params3d r = paper_scene(48, {d});
  EXPECT_NEAR(r.membrane.kb, paper_scene(48, {}).membrane.kb, 1e-5 * r.membrane.kb);
}

// The stretching modulus is the network's 2D Young's modulus Y = 2 k_s / sqrt(3).
TEST(WallRigidity, StretchingModulusIsTheNetworksYoungsModulus) {
  const Params3d p = paper_scene(24, {"wall={\"stretching_modulus\": \"6.350852961e-8 N/m\"}"});
  EXPECT_NEAR(p.membrane.ks, 5.5e-8, 1e-9 * 5.5e-8);
}

// A wall given both ways is refused before anything is written, naming both keys.
TEST(WallRigidity, AWallGivenBothWaysIsRefusedNamingBothKeys) {
  auto refused = [](const std::vector<std::string>& sets, const std::string& a, const std::string& b) {
    try {
      paper_scene(24, sets);
      ADD_FAILURE() << "accepted: " << sets.front();
    } catch (const InputError& err) {
      const std::string m = err.what();
      EXPECT_NE(m.find(a), std::string::npos) << m;
      EXPECT_NE(m.find(b), std::string::npos) << m;
    }
  };
  refused({"full3d.membrane.bending_rigidity=\"2e-24 J\"", "full3d.membrane.bending_model=\"fixed_kb\""},
          "full3d.membrane.bending_rigidity", "full3d.membrane.bending_model");
  refused({"full3d.membrane.bending_rigidity=\"2e-24 J\"", "full3d.membrane.bending_constant=\"1e-15 N\""},
          "full3d.membrane.bending_rigidity", "full3d.membrane.bending_constant");
  refused({"full3d.membrane.bending_rigidity=\"2e-24 J\"", "full3d.membrane.reference_edge=\"5 nm\""},
          "full3d.membrane.reference_edge", "full3d.membrane.bending_rigidity");
  refused({"full3d.membrane.bending_model=\"fixed_kb\"", "full3d.membrane.reference_edge=\"5 nm\""},
          "full3d.membrane.reference_edge", "full3d.membrane.bending_model");
  refused({"wall.stretching_modulus=\"6e-8 N/m\""}, "wall.stretching_modulus", "spring_constant");
}

// ---- the ring-buckling estimate ----

// The free ring's loads (Timoshenko & Gere, Theory of Elastic Stability, 1961, sec. 7.4):
// 3 D / R^3 (hydrostatic) and 4.5 D / R^3 (centrally directed) for m = 2; both tend to
// m^2 D / R^3 for many lobes. The growth rate changes sign at p_m; the fastest mode moves from
// m = 2 to m = 3 as the load passes the rates' crossing (centrally directed: 4.5 D/R^3 < P,
// m = 3 faster from P = (m2 rate = m3 rate) ~ 8.9 D/R^3).
TEST(RingBuckling, LoadsAndGrowthRatesOfTheFreeRing) {
  const double D = 2e-24, R = 0.1e-6, b = D / (R * R * R);
  EXPECT_NEAR(ring_buckling_pressure(2, D, R, RingLoad::Hydrostatic), 3.0 * b, 1e-12 * b);
  EXPECT_NEAR(ring_buckling_pressure(2, D, R, RingLoad::CentrallyDirected), 4.5 * b, 1e-12 * b);
  EXPECT_NEAR(ring_buckling_pressure(3, D, R, RingLoad::CentrallyDirected), 64.0 / 7.0 * b, 1e-12 * b);
  EXPECT_NEAR(ring_buckling_pressure(40, D, R, RingLoad::CentrallyDirected) / (1600.0 * b), 1.0, 1e-3);
  EXPECT_NEAR(ring_buckling_pressure(40, D, R, RingLoad::Hydrostatic) / (1600.0 * b), 1.0, 1e-3);
  EXPECT_TRUE(std::isinf(ring_buckling_pressure(1, D, R, RingLoad::Hydrostatic)));
  for (auto load : {RingLoad::Hydrostatic, RingLoad::CentrallyDirected})
    for (int m = 2; m <= 8; ++m) {
      const double pm = ring_buckling_pressure(m, D, R, load);
      EXPECT_LT(ring_mode_growth_rate(m, 0.99 * pm, D, R, 1.0, load), 0.0);
      EXPECT_GT(ring_mode_growth_rate(m, 1.01 * pm, D, R, 1.0, load), 0.0);
    }
  EXPECT_EQ(fastest_ring_mode(4.4 * b, D, R, RingLoad::CentrallyDirected), 0);
  EXPECT_EQ(fastest_ring_mode(7.0 * b, D, R, RingLoad::CentrallyDirected), 2);
  EXPECT_EQ(fastest_ring_mode(12.0 * b, D, R, RingLoad::CentrallyDirected), 3);
  EXPECT_EQ(fastest_ring_mode(3.5 * b, D, R, RingLoad::Hydrostatic), 2);
}

// ---- the mode a uniform load grows ----

// A uniform load on the free tube grows the mode the estimate predicts at that load, on meshes
// of 20 (four-fold, no three-fold), 23 (prime) and 24 (four- and three-fold) nodes per ring: m = 2 at
// 7 D/R^3 (only m = 2 unstable) and m = 3 at 12 D/R^3 (m = 2 and 3 unstable, m = 3 fastest).
// The perturbation is random (all modes alike); it grows 10^4 times at the predicted rate.
TEST(RingBuckling, UniformLoadGrowsThePredictedModeOnEveryMesh) {
  for (int n : {20, 23, 24}) {
    const CylinderMesh mesh = tube(n);
    const MembraneParams p = wall_with_rigidity(mesh, kD);
    for (double load : {7.0, 12.0}) {
      // the load is load D / R^3 at the loaded radius R (two passes of the static relaxation)
      double R = kR0, P = 0.0;
      PressureResponse eq;
      for (int pass = 0; pass < 3; ++pass) {
        P = load * kD / std::pow(R, 3);
        eq = relax_under_pressure(mesh, p, P);
        R = eq.mid_radius;
      }
      const int predicted = fastest_ring_mode(P, kD, R, RingLoad::CentrallyDirected);
      ASSERT_EQ(predicted, load < 10 ? 2 : 3);
      const double rate = ring_mode_growth_rate(predicted, P, kD, R, 1.0, RingLoad::CentrallyDirected);
      std::mt19937 rng(17 + n);
      std::normal_distribution<double> N(0.0, 1e-9 * kR0);
      Eigen::Matrix3Xd X = eq.X;
      for (Eigen::Index i = 0; i < X.size(); ++i) X.data()[i] += N(rng);
      const Relaxation relax{mesh, p, P};
      const Eigen::Matrix3Xd Y = relax.run(X, std::log(1e4) / rate);
      const int ring = mesh.n_rings / 2;
      const std::vector<double> s = ring_spectrum(mesh, Y, ring);
      std::printf("n_theta %d, P = %.0f D/R0^3: predicted m = %d; grown amplitudes m = 2, 3, 4: %.3g %.3g %.3g R0\n", n,
                  load, predicted, s[2] / kR0, s[3] / kR0, s[4] / kR0);
      EXPECT_EQ(dominant_lobes(s), predicted) << "n_theta " << n << ", load " << load;
      EXPECT_GT(s[std::size_t(predicted)], 1e-7 * kR0);  // grown from ~1e-9 R0
    }
  }
}

// ---- the seed ----

// A seed of mode m and amplitude eps R0 in the stress-free shape grows mode m under a load
// above its buckling load: m = 2 and m = 3 at 12 D/R^3 on 20 nodes per ring (where m = 3
// would grow faster from noise), each from eps = 1e-8 to more than 100 eps. With a zero seed the
// symmetric mesh stays round to round-off under the same load for the same time.
TEST(WallSeed, SeedGrowsItsModeAndNoSeedStaysRound) {
  double R = kR0, P = 0.0;
  {
    const CylinderMesh mesh = tube(20);
    for (int pass = 0; pass < 3; ++pass) {
      P = 12.0 * kD / std::pow(R, 3);
      R = relax_under_pressure(mesh, wall_with_rigidity(mesh, kD), P).mid_radius;
    }
  }
  const double T = std::log(1e4) / ring_mode_growth_rate(3, P, kD, R, 1.0, RingLoad::CentrallyDirected);
  const int ring = 5;
  for (int m : {2, 3}) {
    CylinderMesh mesh = tube(20);
    const MembraneParams p = wall_with_rigidity(mesh, kD);
    seed_ring_mode(mesh, m, 1e-8);
    EXPECT_NEAR(ring_spectrum(mesh, mesh.X0, ring)[std::size_t(m)], 1e-8 * kR0, 1e-3 * 1e-8 * kR0);
    const Relaxation relax{mesh, p, P};
    const Eigen::Matrix3Xd Y = relax.run(mesh.X0, T);
    const std::vector<double> s = ring_spectrum(mesh, Y, ring);
    std::printf("seed m = %d, eps = 1e-8: grown amplitudes m = 2, 3, 4: %.3g %.3g %.3g R0\n", m, s[2] / kR0,
                s[3] / kR0, s[4] / kR0);
    EXPECT_EQ(dominant_lobes(s), m);
    EXPECT_GT(s[std::size_t(m)], 100 * 1e-8 * kR0);
  }
  const CylinderMesh mesh = tube(20);
  const MembraneParams p = wall_with_rigidity(mesh, kD);
  const Relaxation relax{mesh, p, P};
  const Eigen::Matrix3Xd Y = relax.run(mesh.X0, T);
  const double wrinkle = wall_wrinkle(mesh, node_radii(mesh, Y), ring_radii(mesh, Y));
  std::printf("no seed: wall wrinkle %.3g R0 after the same time\n", wrinkle / kR0);
  EXPECT_LT(wrinkle, 1e-11 * kR0);
}

// The scene keys: the seed is in the run's stress-free mesh with the stated mode and amplitude;
// bad seeds are refused naming the key.
TEST(WallSeed, SceneKeysSeedTheRunsMesh) {
  const Params3d p = paper_scene(24, {"full3d.membrane.seed_mode=4", "full3d.membrane.seed_amplitude=0.01"});
  const CylinderMesh mesh = make_mesh(p);
  const std::vector<double> s = ring_spectrum(mesh, mesh.X0, mesh.n_rings / 2);
  EXPECT_NEAR(s[4], 0.01 * kR0, 1e-6 * kR0);
  EXPECT_EQ(dominant_lobes(s), 4);
  // the seeded wall has the unseeded wall's rigidity
  EXPECT_NEAR(p.bending_rigidity, paper_scene(24, {}).bending_rigidity, 1e-12 * p.bending_rigidity);
  EXPECT_NEAR(p.membrane.kb, paper_scene(24, {}).membrane.kb, 1e-12 * p.membrane.kb);
  auto refused_key = [](const std::vector<std::string>& sets) { return refused_scene_key(24, sets); };
  EXPECT_EQ(refused_key({"full3d.membrane.seed_mode=1", "full3d.membrane.seed_amplitude=0.01"}),
            "full3d.membrane.seed_mode");
  EXPECT_EQ(refused_key({"full3d.membrane.seed_amplitude=0.01"}), "full3d.membrane.seed_amplitude");
  EXPECT_EQ(refused_key({"full3d.membrane.seed_amplitude=0.2", "full3d.membrane.seed_mode=2"}),
            "full3d.membrane.seed_amplitude");
  EXPECT_EQ(refused_key({"full3d.membrane.seed_mode=64", "full3d.membrane.seed_amplitude=0.01", "full3d.grid.cells_across=12"}),
            "full3d.membrane.seed_mode");
}

// Donnell's segment estimate (buckling_estimate.hpp). Without an axial variation (the free
// tube) its buckling compression is the ring's m^2 D / R^2 and the growth rate changes sign
// there; a long segment's lowest buckling pressure over m is the classical short-cylinder
// result p = 0.855 E t^(5/2) / ((1 - nu^2)^(3/4) ell R^(3/2)) (Windenburg and Trilling 1934;
// Batdorf 1947), with Y = E t and D = E t^3 / (12 (1 - nu^2)) of the network's nu = 1/3. The
// integer lobe number puts the discrete minimum at most 2 % above the continuous one.
TEST(SegmentBuckling, FreeTubeIsTheRingAndLongSegmentsBuckleAtTheClassicalPressure) {
  const double R = kR0, D = kD, Y = 6.35e-8, inf = std::numeric_limits<double>::infinity();
  for (int m : {2, 5, 8}) {
    const double Nm = segment_buckling_compression(m, D, Y, R, inf);
    EXPECT_NEAR(Nm, m * m * D / (R * R), 1e-12 * Nm) << m;
    for (WallDrag drag : {WallDrag::Dry, WallDrag::Stokes}) {
      EXPECT_LT(segment_mode_growth_rate(m, 0.99 * Nm, D, Y, R, inf, drag, 1e-3), 0.0);
      EXPECT_GT(segment_mode_growth_rate(m, 1.01 * Nm, D, Y, R, inf, drag, 1e-3), 0.0);
    }
  }
  EXPECT_TRUE(std::isinf(segment_buckling_compression(1, D, Y, R, inf)));
  // a thin shell, R / t = 1000
  const double nu = 1.0 / 3.0, E = 1.0, Rs = 1.0, t = 1e-3, Ys = E * t, Ds = E * t * t * t / (12 * (1 - nu * nu));
  for (double ell : {5.0, 10.0}) {
    double pmin = inf;
    for (int m = 2; m <= 64; ++m) pmin = std::min(pmin, segment_buckling_compression(m, Ds, Ys, Rs, ell) / Rs);
    const double classical = 0.855 * E * std::pow(t, 2.5) / (std::pow(1 - nu * nu, 0.75) * ell * std::pow(Rs, 1.5));
    EXPECT_GE(pmin / classical, 1.0) << ell;
    EXPECT_LE(pmin / classical, 1.02) << ell;
  }
  // a shorter segment is stiffer, and buckles in more lobes
  const double N_short = segment_buckling_compression(4, D, Y, 0.55 * R, 50e-9),
               N_long = segment_buckling_compression(4, D, Y, 0.55 * R, 200e-9);
  EXPECT_GT(N_short, N_long);
}

// The estimate for the paper's L = 0.2 µm tube at R_f = 0.55 R0 under 0.32 Pa (the numbers of
// docs/full3d.md, "Ring buckling and the seed imperfection", computed there independently):
// the first 20 nm segment holds (its critical compression is 2.5 times the load's 4e-8 N/m),
// and from the second stage on the fastest-growing mode in the fluid is m = 8, at 530–640 /s.
// A dry wall (constant drag) favours more lobes (m = 9–10): the fluid's drag grows with k.
TEST(SegmentBuckling, ThePapersShortTubeGrowsEightLobesInTheFluid) {
  const double R0 = 0.125e-6, D = 1.009e-24, Y = 2.0 * 5.5e-8 / std::sqrt(3.0), N = 0.32 * R0, mu = 1.2e-3;
  const auto stages = contraction_buckling(0.2e-6, 4, 1.0 / 3.0, 0.55 * R0, N, D, Y, mu);
  ASSERT_EQ(stages.size(), 4u);
  EXPECT_NEAR(stages[0].loaded_length, 20e-9, 1e-15);
  EXPECT_NEAR(stages[1].loaded_length, 80e-9, 1e-15);
  EXPECT_TRUE(std::isinf(stages[3].ell));
  EXPECT_EQ(stages[0].mode, 0);
  EXPECT_NEAR(stages[0].critical_compression / N, 2.49, 0.02);
  for (int j = 1; j < 4; ++j) {
    EXPECT_EQ(stages[std::size_t(j)].mode, 8) << j;
    EXPECT_GT(stages[std::size_t(j)].growth_rate, 500.0) << j;
    EXPECT_LT(stages[std::size_t(j)].growth_rate, 650.0) << j;
  }
  EXPECT_GE(fastest_segment_mode(N, D, Y, 0.55 * R0, 140e-9, WallDrag::Dry, 1.0), 9);
}

// The runs' lobe measure (wall_wrinkle_shape): the seeded lobe number of a lobed wall, the larger
// of two superposed lobe numbers, and 0 on a round wall.
TEST(WallSeed, TheWrinkleModeIsTheLobeNumberOfTheMostWrinkledRing) {
  for (int m : {3, 7, 12}) {
    CylinderMesh mesh = tube(40);
    seed_ring_mode(mesh, m, 0.01);
    const Eigen::VectorXd rn = node_radii(mesh, mesh.X0);
    EXPECT_EQ(wall_wrinkle_shape(mesh, mesh.X0, rn, ring_radii(mesh, rn)).mode, m);
  }
  CylinderMesh mesh = tube(40);
  seed_ring_mode(mesh, 5, 0.01);
  const Eigen::Matrix3Xd X = inextensional_lobes(mesh, mesh.X0, 9, 0.004 * kR0);
  const Eigen::VectorXd rn = node_radii(mesh, X);
  EXPECT_EQ(wall_wrinkle_shape(mesh, X, rn, ring_radii(mesh, rn)).mode, 5);
  const CylinderMesh round = tube(40);
  const Eigen::VectorXd r0 = node_radii(round, round.X0);
  EXPECT_EQ(wall_wrinkle_shape(round, round.X0, r0, ring_radii(round, r0)).mode, 0);
}

// seed_mode = "auto": the lobe number is the one the contraction's buckling estimate grows fastest
// in the fluid, for the scene's own D and load, on any grid: 8 for the paper's short tube on 24,
// 32 and 48 cells across (40, 56 and 84 nodes per ring, whose own symmetry would pick 4 or 8),
// with the default amplitude 0.01 R0 in the mesh; a wall four times stiffer in bending grows fewer
// lobes, and one 400 times stiffer is stable (no seed); a wall held axisymmetric gets none. The
// resolved scene keeps "auto" (it re-reads to the same run), the summary reports the number;
// another string is refused naming the key.
TEST(WallSeed, AutoSeedIsTheBucklingEstimatesFastestModeOnEveryGrid) {
  for (int cells : {24, 32, 48}) {
    const Params3d p = paper_scene(cells, {"full3d.membrane.seed_mode=auto"});
    EXPECT_TRUE(p.seed_auto);
    EXPECT_EQ(p.seed_mode, 8) << cells;
    EXPECT_EQ(p.seed_amplitude, 0.01);
    const CylinderMesh mesh = make_mesh(p);
    const std::vector<double> s = ring_spectrum(mesh, mesh.X0, mesh.n_rings / 2);
    EXPECT_EQ(dominant_lobes(s), 8) << cells;
  }
  const Params3d p = paper_scene(32, {"full3d.membrane.seed_mode=auto"});
  const double Y = 2.0 * p.membrane.ks / std::sqrt(3.0);
  const auto stages = contraction_buckling(p.L, p.protocol.segments, p.protocol.first_ratio, p.protocol.R_f,
                                           p.protocol.q * p.R0, p.bending_rigidity, Y, p.fluid.mu);
  int fastest = 0;
  double rate = 0;
  for (const auto& st : stages)
    if (st.growth_rate > rate) rate = st.growth_rate, fastest = st.mode;
  EXPECT_EQ(p.seed_mode, fastest);
  const double D = p.bending_rigidity;
  auto with_D = [&](double factor) {
    char rigidity[80];
    std::snprintf(rigidity, sizeof rigidity, "full3d.membrane.bending_rigidity=%.10g J", factor * D);
    return paper_scene(32, {"full3d.membrane.seed_mode=auto", "full3d.membrane.bending_constant=null",
                            "full3d.membrane.reference_edge=null", rigidity});
  };
  const Params3d stiff = with_D(4.0), stable = with_D(400.0);
  EXPECT_GE(stiff.seed_mode, 2);
  EXPECT_LT(stiff.seed_mode, 8);
  EXPECT_EQ(stable.seed_mode, 0);
  EXPECT_EQ(stable.seed_amplitude, 0.0);
  const Params3d round = paper_scene(32, {"full3d.membrane.seed_mode=auto", "full3d.membrane.axisymmetric=true"});
  EXPECT_EQ(round.seed_mode, 0);
  scene::json sc = scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_aspect_L0.2.json"), r1, r2;
  scene::apply_override(sc, "full3d.membrane.seed_mode=auto");
  const Params3d a = read_scene3d(sc, r1);
  EXPECT_EQ(r1["full3d"]["membrane"]["seed_mode"], "auto");
  const Params3d b = read_scene3d(r1, r2);
  EXPECT_EQ(r1, r2);
  EXPECT_EQ(a.seed_mode, b.seed_mode);
  scene::apply_override(sc, "full3d.membrane.seed_mode=automatic");
  try {
    read_scene3d(sc, r1);
    ADD_FAILURE() << "seed_mode = automatic was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "full3d.membrane.seed_mode");
  }
}

// The wall's lobes cycle by cycle (CycleWrinkles): each row goes to its cycle, the largest
// wrinkle of a cycle and its lobe number are kept, and a lobe number counts as shown only
// while the wrinkle exceeds the threshold (half a cell), in the order it first appeared. The
// rows of a seeded two-cycle run on 128 cells whose second recovery turned from 8 to 4 lobes
// (t, cycle, wrinkle, mode, with h = 3.9 nm) are the pattern.
TEST(WallSeed, TheLobesAreRecordedCycleByCycle) {
  const double h = 3.90625e-9;
  CycleWrinkles w(0.5 * h);
  w.add(1, 0.88e-9, 8);   // the seed, below half a cell
  w.add(1, 11.8e-9, 8);   // the first contraction buckles it
  w.add(1, 1.9e-9, 5);    // a small wrinkle of another shape: not shown
  w.add(2, 1.96e-9, 8);
  w.add(2, 11.8e-9, 4);   // the second recovery turns to m = 4
  w.add(2, 6.0e-9, 8);
  w.add(3, 1.9e-9, 4);
  ASSERT_EQ(w.cycles().size(), 3u);
  EXPECT_EQ(w.cycles()[0].cycle, 1);
  EXPECT_DOUBLE_EQ(w.cycles()[0].max_wrinkle_m, 11.8e-9);
  EXPECT_EQ(w.cycles()[0].max_wrinkle_mode, 8);
  EXPECT_EQ(w.cycles()[0].modes, std::vector<int>({8}));
  EXPECT_EQ(w.cycles()[1].modes, std::vector<int>({8, 4}));
  EXPECT_EQ(w.cycles()[1].max_wrinkle_mode, 4);
  EXPECT_TRUE(w.cycles()[2].modes.empty());
  EXPECT_EQ(w.modes(), std::vector<int>({8, 4}));
  // the checkpoint's flat form reads back to the same record
  CycleWrinkles r(0.5 * h);
  r.unflatten(w.flat());
  ASSERT_EQ(r.cycles().size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(r.cycles()[k].cycle, w.cycles()[k].cycle);
    EXPECT_EQ(r.cycles()[k].max_wrinkle_m, w.cycles()[k].max_wrinkle_m);
    EXPECT_EQ(r.cycles()[k].max_wrinkle_mode, w.cycles()[k].max_wrinkle_mode);
    EXPECT_EQ(r.cycles()[k].modes, w.cycles()[k].modes);
  }
  const scene::json j = wrinkle_by_cycle_json(w);
  ASSERT_EQ(j.size(), 3u);
  EXPECT_EQ(j[1]["modes_over_half_cell"].get<std::vector<int>>(), std::vector<int>({8, 4}));
}

// What `swim run` says after a 3D run whose wall wrinkled (wrinkle_note): nothing below half a
// cell; what chose the lobes (the seed, naming its keys, or the grid); a wall that grew another
// lobe number than the seed's; and lobes that changed during the run, naming the cycle.
TEST(WallSeed, TheRunsNoteNamesWhatChoseTheLobesAndAChange) {
  auto summary = [](double over_h, int seed, std::vector<int> modes, scene::json by_cycle) {
    scene::json s;
    s["max_wrinkle_m"] = over_h * 3.90625e-9;
    s["max_wrinkle_over_h"] = over_h;
    s["max_wrinkle_mode"] = modes.empty() ? 0 : modes.front();
    s["wrinkle_modes_over_half_cell"] = modes;
    s["wrinkle_by_cycle"] = by_cycle;
    s["derived"] = {{"seed_mode", seed}, {"seed_amplitude", seed > 0 ? 0.01 : 0.0}};
    return s;
  };
  const scene::json one = scene::json::array({{{"cycle", 1}, {"modes_over_half_cell", {8}}}});
  const scene::json two = scene::json::array(
      {{{"cycle", 1}, {"modes_over_half_cell", {8}}}, {{"cycle", 2}, {"modes_over_half_cell", {8, 4}}}});
  const auto has = [](const std::string& s, const char* what) { return s.find(what) != std::string::npos; };

  EXPECT_EQ(wrinkle_note(summary(0.4, 8, {}, scene::json::array())), "");
  EXPECT_EQ(wrinkle_note(scene::json::object()), "");

  const std::string seeded = wrinkle_note(summary(3.0, 8, {8}, one));
  EXPECT_TRUE(has(seeded, "buckled into m = 8 lobes")) << seeded;
  EXPECT_TRUE(has(seeded, "full3d.membrane.seed_mode = 8")) << seeded;
  EXPECT_TRUE(has(seeded, "chose them")) << seeded;
  EXPECT_FALSE(has(seeded, "did not choose")) << seeded;
  EXPECT_FALSE(has(seeded, "changed")) << seeded;

  const std::string other = wrinkle_note(summary(3.0, 8, {4}, scene::json::array({{{"cycle", 1}, {"modes_over_half_cell", {4}}}})));
  EXPECT_TRUE(has(other, "buckled into m = 4 lobes")) << other;
  EXPECT_TRUE(has(other, "did not choose them")) << other;

  const std::string changed = wrinkle_note(summary(3.0, 8, {8, 4}, two));
  EXPECT_TRUE(has(changed, "chose them")) << changed;
  EXPECT_TRUE(has(changed, "lobes changed from m = 8 to m = 4 in cycle 2")) << changed;
  EXPECT_TRUE(has(changed, "cycles before the change")) << changed;
  // a change within the first cycle (the L = 0.4 um tube's recovery turns from 8 to 4 lobes)
  const std::string within = wrinkle_note(
      summary(3.0, 8, {8, 4}, scene::json::array({{{"cycle", 1}, {"modes_over_half_cell", {8, 4}}}})));
  EXPECT_TRUE(has(within, "lobes changed from m = 8 to m = 4 in cycle 1")) << within;
  EXPECT_TRUE(has(within, "another branch within its first buckled cycle")) << within;
  EXPECT_FALSE(has(within, "cycles before the change")) << within;
  // ... and when the secondary seed chose the new lobes, the note says so
  scene::json chosen = summary(3.0, 8, {8, 4}, scene::json::array({{{"cycle", 1}, {"modes_over_half_cell", {8, 4}}}}));
  chosen["derived"]["secondary_seed_mode"] = 4;
  const std::string seeded2 = wrinkle_note(chosen);
  EXPECT_TRUE(has(seeded2, "secondary_seed_mode = 4) chose the new lobes")) << seeded2;
  EXPECT_FALSE(has(seeded2, "can tip")) << seeded2;

  const std::string grid = wrinkle_note(summary(1.2, 0, {4}, scene::json::array({{{"cycle", 1}, {"modes_over_half_cell", {4}}}})));
  EXPECT_TRUE(has(grid, "wrinkled into m = 4 lobes")) << grid;
  EXPECT_TRUE(has(grid, "without a seed the lobes follow the grid")) << grid;
  EXPECT_FALSE(has(grid, "changed")) << grid;
}

// ---- lobes that change: the secondary instability (docs/full3d.md) ----

// The secondary seed adds its lobes to the seed's, each at its amplitude, and the scene refuses
// a secondary seed that is not one: a lobe number of 1, a number without an amplitude or an
// amplitude without a number, and the seed's own lobe number (also the one "auto" resolves to).
TEST(WallSeed, TheSecondarySeedAddsItsLobesToTheSeeds) {
  const Params3d p = paper_scene(48, {"full3d.membrane.seed_mode=8", "full3d.membrane.seed_amplitude=0.01",
                                      "full3d.membrane.secondary_seed_mode=4",
                                      "full3d.membrane.secondary_seed_amplitude=0.001"});
  EXPECT_EQ(p.secondary_seed_mode, 4);
  const CylinderMesh mesh = make_mesh(p);
  const std::vector<double> s = ring_spectrum(mesh, mesh.X0, mesh.n_rings / 2);
  EXPECT_NEAR(s[8], 0.01 * kR0, 1e-6 * kR0);
  EXPECT_NEAR(s[4], 0.001 * kR0, 1e-6 * kR0);
  for (int m : {2, 3, 5, 6, 7}) EXPECT_LT(s[std::size_t(m)], 1e-9 * kR0) << m;
  // one pair gives the single seed's mesh bit for bit; the seeded wall keeps the round wall's D
  CylinderMesh a = make_round_mesh(p), b = make_round_mesh(p);
  seed_ring_mode(a, 8, 0.01);
  seed_ring_modes(b, {{8, 0.01}, {4, 0.0}});
  EXPECT_EQ((a.X0 - b.X0).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR(p.bending_rigidity, paper_scene(48, {}).bending_rigidity, 1e-12 * p.bending_rigidity);
  auto refused_key = [](const std::vector<std::string>& sets) { return refused_scene_key(48, sets); };
  EXPECT_EQ(refused_key({"full3d.membrane.secondary_seed_mode=1", "full3d.membrane.secondary_seed_amplitude=0.001"}),
            "full3d.membrane.secondary_seed_mode");
  EXPECT_EQ(refused_key({"full3d.membrane.secondary_seed_mode=4"}), "full3d.membrane.secondary_seed_mode");
  EXPECT_EQ(refused_key({"full3d.membrane.secondary_seed_amplitude=0.001"}), "full3d.membrane.secondary_seed_amplitude");
  EXPECT_EQ(refused_key({"full3d.membrane.seed_mode=8", "full3d.membrane.seed_amplitude=0.01",
                         "full3d.membrane.secondary_seed_mode=8", "full3d.membrane.secondary_seed_amplitude=0.001"}),
            "full3d.membrane.secondary_seed_mode");
  EXPECT_EQ(refused_key({"full3d.membrane.seed_mode=\"auto\"", "full3d.membrane.secondary_seed_mode=8",
                         "full3d.membrane.secondary_seed_amplitude=0.001"}),
            "full3d.membrane.secondary_seed_mode");
  EXPECT_EQ(refused_key({"full3d.membrane.secondary_seed_mode=4", "full3d.membrane.secondary_seed_amplitude=0.2"}),
            "full3d.membrane.secondary_seed_amplitude");
  EXPECT_EQ(refused_key({"full3d.membrane.ring_nodes_multiple=0"}), "full3d.membrane.ring_nodes_multiple");
}

// full3d.membrane.ring_nodes_multiple = 4: on every grid of the suite's series the node count
// per ring is the smallest multiple of 4 the spacing rule allows (at most 3 more than without
// the key), and the seeded wall (8 and 4 lobes) is mapped onto itself by the quarter turn about
// its axis, node onto node, as the Cartesian fluid grid is. Without the key the 96-cell grid
// has 503 nodes per ring, a prime, and no quarter turn maps it onto itself.
TEST(WallSeed, ARingNodeMultipleOfFourGivesEveryGridTheSquaresSymmetry) {
  const std::vector<std::string> seeds = {"full3d.membrane.seed_mode=8", "full3d.membrane.seed_amplitude=0.01",
                                          "full3d.membrane.secondary_seed_mode=4",
                                          "full3d.membrane.secondary_seed_amplitude=0.001"};
  auto quarter_turn_maps_nodes_onto_nodes = [](const CylinderMesh& mesh) {
    if (mesh.n_theta % 4 != 0) return false;
    const int q = mesh.n_theta / 4;
    double worst = 0.0;
    for (int r = 0; r < mesh.n_rings; ++r)
      for (int i = 0; i < mesh.n_theta; ++i) {
        const int k = mesh.node(r, i), l = mesh.node(r, (i + q) % mesh.n_theta);
        const double dy = mesh.X0(1, k) - mesh.axis_start[1], dz = mesh.X0(2, k) - mesh.axis_start[2];
        const Eigen::Vector3d turned(mesh.X0(0, k), mesh.axis_start[1] - dz, mesh.axis_start[2] + dy);
        worst = std::max(worst, (turned - mesh.X0.col(l)).norm());
      }
    return worst < 1e-12 * mesh.radius;
  };
  for (int cells : {48, 64, 80, 96, 128}) {
    std::vector<std::string> sets = seeds;
    const CylinderMesh free = make_mesh(paper_scene(cells, sets));
    sets.push_back("full3d.membrane.ring_nodes_multiple=4");
    const Params3d p = paper_scene(cells, sets);
    const CylinderMesh mesh = make_mesh(p);
    EXPECT_EQ(mesh.n_theta % 4, 0) << cells;
    EXPECT_GE(mesh.n_theta, free.n_theta) << cells;
    EXPECT_LE(mesh.n_theta, free.n_theta + 3) << cells;
    EXPECT_LT(max_edge_length(make_round_mesh(p), make_round_mesh(p).X0), 0.5 * p.spacing_factor * p.h) << cells;
    EXPECT_TRUE(quarter_turn_maps_nodes_onto_nodes(mesh)) << cells;
    if (cells == 96) {
      EXPECT_EQ(free.n_theta, 503);
      EXPECT_FALSE(quarter_turn_maps_nodes_onto_nodes(free));
    }
  }
}

// The coupled step keeps the square's symmetry: a seeded tube (8 and 4 lobes) on 4k nodes per
// ring, centred in a periodic box of 16^3 cells, compressed by 10 % and left to relax for 20
// steps, keeps its odd lobes (m = 3, 5, 7: the pairs a buckled m = 8 wall's secondary
// instability grows, with 4 + 4) at round-off; on 4k + 1 nodes per ring the fluid grid's
// four-fold pattern and the ring's own do not match, and the same steps put them at the
// discretisation's level, 10^4 times higher or more. Which pair a buckled wall grows therefore
// depends on whether its grid admits the odd ones (docs/full3d.md).
TEST(WallSeed, TheCoupledStepKeepsTheSquaresSymmetryOnFourfoldRings) {
  constexpr int kN = 16;
  constexpr double kBox = 0.5e-6, kL = 0.4e-6;
  const MacGrid grid{kN, kN, kN, kBox / kN, GridBoundary::PeriodicBox};
  const Eigen::Vector3d start(0.05e-6, 0.25e-6, 0.25e-6);
  const CylinderMesh fourfold = make_cylinder_for_grid(kR0, kL, kBox / kN, start, 0.9, 4);
  auto odd_over_even = [&](int n_theta) {
    CylinderMesh mesh = make_cylinder(kR0, kL, n_theta, start);
    seed_ring_modes(mesh, {{8, 0.01}, {4, 0.001}});
    IbSolver s(grid, FluidParams{1.0e3, 1.2e-3}, mesh, MembraneParams{}, Eigen::VectorXd::Zero(mesh.nodes()), IbOptions{});
    IbState st = s.initial_state();
    for (int i = 0; i < mesh.nodes(); ++i) st.X.col(i) = start + Eigen::Vector3d(st.X(0, i) - start[0], 0.9 * (st.X(1, i) - start[1]),
                                                                           0.9 * (st.X(2, i) - start[2]));
    for (int k = 0; k < 20; ++k) s.step(st, 2e-6);
    double odd = 0.0, even = 0.0;
    for (int r = 0; r < mesh.n_rings; ++r) {
      const std::vector<double> sp = ring_spectrum(mesh, st.X, r);
      odd = std::max({odd, sp[3], sp[5], sp[7]});
      even = std::max(even, sp[8]);
    }
    std::printf("%d nodes per ring: largest odd lobe %.3g of the m = 8 lobes\n", n_theta, odd / even);
    return odd / even;
  };
  ASSERT_EQ(fourfold.n_theta % 4, 0);
  const double sym = odd_over_even(fourfold.n_theta), broken = odd_over_even(fourfold.n_theta + 1);
  EXPECT_LT(sym, 1e-11);
  EXPECT_GT(broken, 1e4 * std::max(sym, 1e-16));
}
