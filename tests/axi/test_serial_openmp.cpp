// OpenMP regions inline on the calling thread (axi/serial_openmp.hpp): what the CHOLMOD
// factorisations of the fitted Stokes solver run under.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>

#include <atomic>
#include <cstring>
#include <random>
#include <thread>

#include "axi/serial_openmp.hpp"
#include "cholmod_test_support.hpp"

namespace {

using swim::axi::SerialOpenMp;
using Sparse = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

struct Region {
  std::atomic<int> bodies{0};
  int threads = 0, level = -1;
  bool on_caller = false;
};

// One region asking for two threads; records what its body saw.
void run_region(Region& r) {
  const std::thread::id caller = std::this_thread::get_id();
#pragma omp parallel num_threads(2)
  {
    ++r.bodies;
#pragma omp master
    {
      r.threads = omp_get_num_threads();
      r.level = omp_get_level();
      r.on_caller = std::this_thread::get_id() == caller;
    }
  }
}

// Expected: without a guard the region is libgomp's, a team of the two threads it asks for at
// nesting level 1; under a guard (also nested, and after an inner guard has gone) its body runs
// once, on the calling thread, outside any team (level 0, one thread), and each such region is
// counted; once the guards are gone the region is libgomp's again.
TEST(SerialOpenMp, RegionsRunInlineOnlyUnderTheGuard) {
  Region plain;
  run_region(plain);
  EXPECT_EQ(plain.bodies, 2);
  EXPECT_EQ(plain.threads, 2);
  EXPECT_EQ(plain.level, 1);
  const long before = SerialOpenMp::inline_regions();
  {
    const SerialOpenMp outer;
    {
      const SerialOpenMp inner;
      Region r;
      run_region(r);
      EXPECT_EQ(r.bodies, 1);
      EXPECT_EQ(r.threads, 1);
      EXPECT_EQ(r.level, 0);
      EXPECT_TRUE(r.on_caller);
    }
    Region r;
    run_region(r);
    EXPECT_EQ(r.bodies, 1);
    EXPECT_EQ(r.level, 0);
  }
  EXPECT_EQ(SerialOpenMp::inline_regions(), before + 2);
  Region after;
  run_region(after);
  EXPECT_EQ(after.bodies, 2);
  EXPECT_EQ(after.level, 1);
  EXPECT_EQ(SerialOpenMp::inline_regions(), before + 2);
}

// Expected: a guard on one thread leaves another thread's regions to libgomp.
TEST(SerialOpenMp, TheGuardIsPerThread) {
  const SerialOpenMp guard;
  Region other;
  std::thread t([&] { run_region(other); });
  t.join();
  EXPECT_EQ(other.bodies, 2);
  EXPECT_EQ(other.level, 1);
}

using OpenFactor = swim::axi::testing::OpenFactor<Eigen::Lower>;


// CHOLMOD's supernodal factorisation reaches the product's entry point for its regions (the
// dynamic linker binds libcholmod's GOMP_parallel to it). Expected: under the guard the
// factorisation runs at least one region per supernode inline, and its factor is the same to
// the bit as the one computed with CHOLMOD's own threads.
TEST(SerialOpenMp, CholmodsFactorisationRunsInlineAndGivesTheSameFactor) {
  std::mt19937 rng(11);
  const Sparse S = swim::axi::testing::spd_element_matrix(30, 15, rng);
  OpenFactor threaded;
  threaded.compute(S);
  ASSERT_EQ(threaded.info(), Eigen::Success);
  const cholmod_factor* Lt = threaded.factor();
  ASSERT_TRUE(Lt->is_super);

  OpenFactor inlined;
  const long before = SerialOpenMp::inline_regions();
  {
    const SerialOpenMp guard;
    inlined.compute(S);
  }
  ASSERT_EQ(inlined.info(), Eigen::Success);
  const cholmod_factor* Li = inlined.factor();
  EXPECT_GE(SerialOpenMp::inline_regions() - before, long(Li->nsuper)) << Li->nsuper << " supernodes";
  ASSERT_EQ(Li->xsize, Lt->xsize);
  EXPECT_EQ(std::memcmp(Li->x, Lt->x, sizeof(double) * Li->xsize), 0);
}

}  // namespace
