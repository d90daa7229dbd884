// The communication of one 3D step over MPI as docs/scaling.md models it, measured: the 7
// all-to-all transposes of an nx x ny x nz field of doubles held in x-slabs (3 forward, 4
// inverse), and the latency of an all-to-all of one double per rank pair.
//
//   mpirun -n P build/bin/swim_mpi_transpose_bench [NX NY NZ [STEPS]]   (default 128 32 32 50)
//
// Prints per step: the bytes each rank sends, the time of the 7 transposes, the bandwidth it
// implies, and the small all-to-all's time (the latency term).
#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int p = 1, r = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  const long nx = argc > 1 ? std::atol(argv[1]) : 128, ny = argc > 2 ? std::atol(argv[2]) : 32,
             nz = argc > 3 ? std::atol(argv[3]) : 32, steps = argc > 4 ? std::atol(argv[4]) : 50;
  const long n = nx * ny * nz, per_pair = n / (long(p) * p);
  std::vector<double> a(static_cast<std::size_t>(per_pair * p), 1.0), b(a.size());
  double one[1024] = {}, got[1024];
  MPI_Alltoall(a.data(), int(per_pair), MPI_DOUBLE, b.data(), int(per_pair), MPI_DOUBLE, MPI_COMM_WORLD);  // warm-up
  MPI_Barrier(MPI_COMM_WORLD);
  double t0 = MPI_Wtime();
  for (long s = 0; s < steps; ++s)
    for (int k = 0; k < 7; ++k)
      MPI_Alltoall(a.data(), int(per_pair), MPI_DOUBLE, b.data(), int(per_pair), MPI_DOUBLE, MPI_COMM_WORLD);
  const double big = (MPI_Wtime() - t0) / double(steps);
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = MPI_Wtime();
  for (long s = 0; s < 100 * steps; ++s) MPI_Alltoall(one, 1, MPI_DOUBLE, got, 1, MPI_DOUBLE, MPI_COMM_WORLD);
  const double small = (MPI_Wtime() - t0) / double(100 * steps);
  double worst[2] = {big, small}, all[2];
  MPI_Reduce(worst, all, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  if (r == 0) {
    const double bytes = 7.0 * 8.0 * double(per_pair) * (p - 1);
    std::printf("%d ranks, %ldx%ldx%ld: 7 transposes per step %.3f ms, %.2f MB sent per rank, %.2f GB/s per rank; "
                "small all-to-all %.2f us\n",
                p, nx, ny, nz, 1e3 * all[0], bytes / 1e6, bytes / all[0] / 1e9, 1e6 * all[1]);
  }
  MPI_Finalize();
  return 0;
}
