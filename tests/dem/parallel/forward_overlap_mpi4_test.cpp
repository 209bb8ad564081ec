// The split forward exchange (Exchange::forward_begin / forward_end, dem/parallel/exchange.hpp)
// on 4 ranks: every ghost holds exactly its owner's fields of this round, through faces, edges
// and corners (ghosts received along x forwarded along y) and across a periodic side, when
// the ranks reach forward_end at different times, for several rounds in a row (the sends of
// one round complete only at the next), once more after the ghosts are rebuilt, and when the
// Exchange goes between the two halves. The reference is closed form: the fields are a
// function of the particle's id and the round.
#include <gtest/gtest.h>
#include <mpi.h>

#include <chrono>
#include <thread>

#include "dem/parallel/decomposition.hpp"
#include "dem/parallel/exchange.hpp"
#include "tests/dem/parallel/support.hpp"

namespace grainflow {
namespace {

constexpr int kSide = 10;  // lattice points per axis in the unit cube

Vec3 lattice_point(GlobalId id) {
  const int i = static_cast<int>(id % kSide), j = static_cast<int>(id / kSide % kSide),
            k = static_cast<int>(id / (kSide * kSide));
  return Vec3((i + 0.5) / kSide, (j + 0.5) / kSide, (k + 0.5) / kSide);
}
// The fields of particle `id` in `round`: a small move that keeps it in its box.
Vec3 position(GlobalId id, int round) {
  return lattice_point(id) + Vec3(1e-3 * round, -2e-3 * round, 0.5e-3 * round);
}
Vec3 velocity(GlobalId id, int round) { return Vec3(double(id), double(round), -1.0); }
Vec3 spin(GlobalId id, int round) { return Vec3(-double(id), 0.25, double(round)); }

TEST(ForwardOverlap, GhostsHoldTheirOwnersFieldsOfThisRound) {
  MPI_Comm comm = test::first_ranks(4);
  if (comm == MPI_COMM_NULL) return;
  Domain domain;
  domain.periodic = {true, false, false};
  Decomposition d(comm, domain, {2, 2, 1});
  Exchange exchange(d);
  Particles p;
  for (GlobalId id = 0; id < kSide * kSide * kSide; ++id)
    if (d.owns(lattice_point(id)))
      p.add_raw(id, position(id, 0), velocity(id, 0), spin(id, 0), 0.01, 1.0, 1.0, 0);
  Ghosts g;
  const double cutoff = 0.15;  // a layer and a half of the lattice
  exchange.borders(p, cutoff, g);
  long ghosts = static_cast<long>(g.id.size()), total = 0;
  MPI_Allreduce(&ghosts, &total, 1, MPI_LONG, MPI_SUM, comm);
  // Each rank's box is 0.5 x 0.5 x 1: faces, the corner column, and the periodic x sides.
  EXPECT_GT(total, 4 * 100);

  for (int round = 1; round <= 4; ++round) {
    if (round == 3) exchange.borders(p, cutoff, g);  // a rebuild between two rounds
    for (std::size_t i = 0; i < p.size(); ++i) {
      p.x[i] = position(p.id[i], round);
      p.v[i] = velocity(p.id[i], round);
      p.omega[i] = spin(p.id[i], round);
    }
    exchange.forward_begin(p, g);
    // The ranks arrive at forward_end apart: rank 0 late, rank 3 later still.
    if (d.rank() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (d.rank() == 3) std::this_thread::sleep_for(std::chrono::milliseconds(40));
    exchange.forward_end(p, g);
    int wrong = 0;
    for (std::size_t k = 0; k < g.id.size(); ++k) {
      const GlobalId id = g.id[k];
      wrong += g.x[k] != position(id, round) || g.v[k] != velocity(id, round) ||
               g.omega[k] != spin(id, round);
      // Where the ghost sits: within the cut-off of this rank's box (images across the
      // periodic side one period away).
      const Vec3 at = g.position(k);
      for (int a = 0; a < 3; ++a)
        wrong += at[a] < d.lo()[a] - cutoff - 0.01 || at[a] > d.hi()[a] + cutoff + 0.01;
    }
    EXPECT_EQ(wrong, 0) << "rank " << d.rank() << ", round " << round;
  }
  // Left half done (as by an error between the halves): ~Exchange completes it, without
  // hanging or writing into freed buffers.
  exchange.forward_begin(p, g);
  MPI_Comm_free(&comm);
}

}  // namespace
}  // namespace grainflow
