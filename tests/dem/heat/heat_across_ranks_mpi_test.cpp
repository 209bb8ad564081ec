// Heat conduction across a rank cut (run on 2 ranks): a row of four spheres between a hot and
// a cold wall, cut between the second and the third by the processor grid [2, 1, 1], gives
// the same temperatures, bit for bit, as the same row on one rank. Reference: the one-rank
// run. Bit-identical because each pair's heat is computed from the same bits on both ranks
// of the cut (heat_transfer.hpp), each particle's contributions are added in the same order
// (a row: its lower partner, its upper partner, then the walls), and the mechanics of this
// row is bit-identical on 1 and 2 ranks (checked too).
#include <gtest/gtest.h>
#include <mpi.h>

#include <array>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "dem/engine/simulation.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

constexpr int kSpheres = 4;
constexpr double kRadius = 1e-3, kOverlap = 5e-7;

Scene row_scene() {
  const double length = kSpheres * 2 * kRadius - (kSpheres + 1) * kOverlap;
  const std::string yaml =
      "domain: {min: [0, -0.004, -0.004], max: [" + std::to_string(length) +
      ", 0.004, 0.004]}\n"
      "time: {step: 1e-6, end: 1}\n"
      "heat: {}\n"
      "materials:\n"
      "  - {name: glass, youngs_modulus: 1e7, poisson_ratio: 0.3, density: 2500,\n"
      "     heat_capacity: 0.05, conductivity: 1.2}\n"
      "  - {name: steel, youngs_modulus: 2e8, poisson_ratio: 0.3, density: 7800,\n"
      "     heat_capacity: 500, conductivity: 16}\n"
      "interaction_defaults: {restitution: 0.1, friction: 0.3}\n"
      "contact: {normal: hertz}\n"
      "walls:\n"
      "  - {type: plane, name: hot, point: [0, 0, 0], normal: [1, 0, 0], material: steel,\n"
      "     temperature: 400}\n"
      "  - {type: plane, name: cold, point: [" + std::to_string(length) +
      ", 0, 0], normal: [-1, 0, 0], material: steel, heat_flux: -2000}\n";
  return parse_scene(yaml, "row.yaml");
}

// Every rank's (id -> temperature, x) on every rank.
std::map<GlobalId, std::pair<double, double>> gather(const Simulation& sim, MPI_Comm comm) {
  const Particles& p = sim.particles();
  std::vector<double> mine;
  for (std::size_t i = 0; i < p.size(); ++i)
    mine.insert(mine.end(), {static_cast<double>(p.id[i]), p.temperature[i], p.x[i][0]});
  int size = 1;
  MPI_Comm_size(comm, &size);
  int count = static_cast<int>(mine.size());
  std::vector<int> counts(size), displs(size);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  int total = 0;
  for (int r = 0; r < size; ++r) {
    displs[r] = total;
    total += counts[r];
  }
  std::vector<double> all(total);
  MPI_Allgatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(),
                 MPI_DOUBLE, comm);
  std::map<GlobalId, std::pair<double, double>> out;
  for (int k = 0; k + 2 < total; k += 3)
    out[static_cast<GlobalId>(all[k])] = {all[k + 1], all[k + 2]};
  return out;
}

std::map<GlobalId, std::pair<double, double>> run(MPI_Comm comm, std::array<int, 3> grid,
                                                  long* pair_on_cut = nullptr) {
  const Scene s = row_scene();
  Simulation sim(s, false, comm, grid);
  for (int k = 0; k < kSpheres; ++k) {
    const double x = kRadius - kOverlap + k * (2 * kRadius - kOverlap);
    sim.particles().add(k + 1, Vec3(x, 0, 0), Vec3::Zero(), Vec3::Zero(), kRadius, 0, 2500);
    sim.particles().temperature.back() = 300 + 10 * k;
  }
  sim.next_id() = kSpheres + 1;
  sim.initialise();
  sim.advance_to(5e-3);
  if (pair_on_cut) *pair_on_cut = static_cast<long>(sim.neighbour_list().pairs());
  return gather(sim, comm);
}

TEST(HeatAcrossRanks, SameTemperaturesOnOneAndTwoRanks) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  ASSERT_EQ(size, 2);
  std::map<GlobalId, std::pair<double, double>> one;
  if (rank == 0) one = run(MPI_COMM_SELF, {1, 1, 1});
  long local_pairs = 0;
  const auto two = run(MPI_COMM_WORLD, {2, 1, 1}, &local_pairs);
  // Each rank holds two spheres and one local pair: the third pair crosses the cut.
  EXPECT_EQ(local_pairs, 1);
  if (rank != 0) return;
  ASSERT_EQ(one.size(), static_cast<std::size_t>(kSpheres));
  ASSERT_EQ(two.size(), static_cast<std::size_t>(kSpheres));
  for (const auto& [id, state] : one) {
    std::printf("sphere %ld: T = %.12f K (1 rank), %.12f K (2 ranks)\n", static_cast<long>(id),
                state.first, two.at(id).first);
    EXPECT_EQ(state.second, two.at(id).second) << "x of sphere " << id;
    EXPECT_EQ(state.first, two.at(id).first) << "T of sphere " << id;
  }
  // The temperatures moved: heat flowed along the row (hot wall at 400 K, cooled at the other).
  EXPECT_GT(one.at(1).first, 330);
}

}  // namespace
}  // namespace grainflow
