// Strong scaling of the MPI DEM on one dense bed.
//
// The bed: N spheres (radius 1 mm) on a face-centred-cubic lattice compressed so that
// every sphere touches its 12 neighbours (74 % solids), on a floor under gravity in a
// box periodic along x and y: the densest case a DEM bed presents (~6 contacts per
// particle). The run
// times `--steps` steps after a warm-up and prints one line
//   ranks=R particles=N steps=S seconds=T particle_steps_per_second=P contacts=C
// (rank 0). benchmarks/strong_scaling/run.sh runs it on 1 and 2 ranks side by side.
#include <mpi.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "dem/engine/simulation.hpp"

using namespace grainflow;

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  long target = 100000, steps = 300;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string a = argv[k];
    if (a == "--particles") target = std::atol(argv[k + 1]);
    if (a == "--steps") steps = std::atol(argv[k + 1]);
  }
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);

  // FCC cell edge: nearest centres a/sqrt(2) = 1.998 r apart, so each sphere starts
  // touching its 12 neighbours with an overlap of 0.1 % of r: a dense bed (74 % solids).
  const double r = 1e-3, a = std::sqrt(8.0) * r * 0.999;
  const int nxy = 16;                   // cells along x and y
  const int nz = static_cast<int>(std::ceil(target / (4.0 * nxy * nxy)));
  Scene s;
  s.file = "<benchmark>";
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(nxy * a, nxy * a, nz * a * 1.3);
  s.domain.periodic = {true, true, false};
  s.gravity = Vec3(0, 0, -9.81);
  s.materials.push_back({"glass", 5e7, 0.25, 2500});
  MaterialPair pair;
  pair.restitution = 0.5;
  pair.friction = 0.5;
  s.pairs.push_back(pair);
  Wall floor;
  floor.name = "floor";
  s.walls.push_back(floor);
  s.contact.tangential = TangentialModel::history;
  s.time.end = 1;

  Simulation sim(s, false, MPI_COMM_WORLD);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  const Vec3 basis[4] = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 0.5), Vec3(0, 0.5, 0.5)};
  GlobalId id = 1;
  for (int k = 0; k < nz && id <= target; ++k)
    for (int j = 0; j < nxy; ++j)
      for (int i = 0; i < nxy; ++i)
        for (const Vec3& b : basis) {
          if (id > target) break;
          const Vec3 x = (Vec3(i, j, k) + b + Vec3(0.25, 0.25, 0.25)) * a + Vec3(0, 0, 0.3 * r) +
                         Vec3(u(rng), u(rng), u(rng)) * 1e-4 * r;
          sim.particles().add(id++, x, Vec3::Zero(), Vec3::Zero(), r, 0, 2500);
        }
  sim.set_dt(0.15 * rayleigh_time(s.materials[0], r));
  sim.initialise();
  for (int k = 0; k < 200; ++k) sim.step();  // warm-up: the bed starts to press together
  MPI_Barrier(MPI_COMM_WORLD);
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < steps; ++k) sim.step();
  MPI_Barrier(MPI_COMM_WORLD);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const GlobalState g = sim.global_state();
  if (rank == 0)
    std::printf("ranks=%d particles=%ld steps=%ld seconds=%.3f particle_steps_per_second=%.4g "
                "contacts=%ld imbalance=%.3f\n",
                size, g.particles, steps, seconds, g.particles * steps / seconds, g.contacts,
                sim.load_imbalance());
  else
    sim.load_imbalance();
  // Per rank: owned spheres, ghosts, pairs on the local neighbour list, and the pairs of an
  // owned sphere with a ghost closer than the list's reach (2 r + skin), which this rank
  // evaluates as well as the ghost's owner (inputs of benchmarks/scaling_model/model.py).
  const Particles& p = sim.particles();
  const Ghosts& gh = sim.ghosts();
  const double reach = 2 * r + 0.4 * r;  // the scene's default skin: 0.4 r_max
  std::map<std::array<long, 3>, std::vector<std::size_t>> bins;
  auto key = [reach](const Vec3& x) {
    return std::array<long, 3>{static_cast<long>(std::floor(x.x() / reach)),
                               static_cast<long>(std::floor(x.y() / reach)),
                               static_cast<long>(std::floor(x.z() / reach))};
  };
  for (std::size_t k = 0; k < p.size(); ++k) bins[key(p.x[k])].push_back(k);
  long cross = 0;
  for (std::size_t q = 0; q < gh.size(); ++q) {
    const Vec3 xg = gh.position(q);
    const auto c = key(xg);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = bins.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == bins.end()) continue;
          for (const std::size_t k : it->second) cross += (p.x[k] - xg).norm() < reach;
        }
  }
  const long mine[4] = {static_cast<long>(p.size()), static_cast<long>(gh.size()),
                        static_cast<long>(sim.neighbour_list().pairs()), cross};
  std::vector<long> all(4 * static_cast<std::size_t>(size));
  MPI_Gather(mine, 4, MPI_LONG, all.data(), 4, MPI_LONG, 0, MPI_COMM_WORLD);
  if (rank == 0)
    for (int q = 0; q < size; ++q)
      std::printf("rank=%d local=%ld ghosts=%ld list_pairs=%ld ghost_pairs=%ld\n", q, all[4 * q],
                  all[4 * q + 1], all[4 * q + 2], all[4 * q + 3]);
  MPI_Finalize();
  return 0;
}
