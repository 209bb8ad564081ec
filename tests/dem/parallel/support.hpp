#pragma once
// Helpers for the MPI tests: run one scene on a sub-communicator and gather the
// final particle states on rank 0 of that communicator, ordered by global id.
#include <mpi.h>

#include <algorithm>
#include <vector>

#include "dem/engine/simulation.hpp"

namespace grainflow::test {

struct State {
  GlobalId id;
  double x[3], v[3], w[3];
};

// Gathers every rank's records on rank 0 of `comm`, sorted by their `id` member
// (empty on the other ranks). T must be trivially copyable.
template <class T>
std::vector<T> gather_by_id(const std::vector<T>& mine, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int bytes = static_cast<int>(mine.size() * sizeof(T));
  std::vector<int> counts(size), displs(size);
  MPI_Gather(&bytes, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  int total = 0;
  for (int r = 0; r < size; ++r) {
    displs[r] = total;
    total += counts[r];
  }
  std::vector<T> all(rank == 0 ? total / sizeof(T) : 0);
  MPI_Gatherv(mine.data(), bytes, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE, 0,
              comm);
  std::sort(all.begin(), all.end(), [](const T& a, const T& b) { return a.id < b.id; });
  return all;
}

inline std::vector<State> gather_states(const Particles& p, MPI_Comm comm) {
  std::vector<State> mine(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    mine[i].id = p.id[i];
    for (int a = 0; a < 3; ++a) {
      mine[i].x[a] = p.x[i][a];
      mine[i].v[a] = p.v[i][a];
      mine[i].w[a] = p.omega[i][a];
    }
  }
  return gather_by_id(mine, comm);
}

// Largest difference between two gathered runs: positions relative to `length`,
// velocities relative to `speed`, spins relative to `speed / radius`.
inline double largest_difference(const std::vector<State>& a, const std::vector<State>& b,
                                 double length, double speed, double radius) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      worst = std::max(worst, std::abs(a[i].x[k] - b[i].x[k]) / length);
      worst = std::max(worst, std::abs(a[i].v[k] - b[i].v[k]) / speed);
      worst = std::max(worst, std::abs(a[i].w[k] - b[i].w[k]) * radius / speed);
    }
  return worst;
}

// Splits the world into a communicator of its first `n` ranks (others get MPI_COMM_NULL).
inline MPI_Comm first_ranks(int n) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm c;
  MPI_Comm_split(MPI_COMM_WORLD, rank < n ? 0 : MPI_UNDEFINED, rank, &c);
  return c;
}

}  // namespace grainflow::test
