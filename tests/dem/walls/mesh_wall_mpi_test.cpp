// A frictional bed falling into a mesh box, pushed sideways across the rank boundary,
// ends where the 1-rank run ends: mesh contacts and their history slots (which
// migrate with the particles) do not depend on the decomposition. Compared per
// particle id to 1e-12 m at 0.04 s, after the first wall impacts (measured: 0). Later
// the runs drift apart by round-off amplified by the packing's chaos -- a plane-walled
// box does the same (5e-3 m apart at 0.15 s), so that is not the mesh's doing.
#include <gtest/gtest.h>
#include <mpi.h>

#include <map>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"
#include "tests/dem/walls/mesh_support.hpp"

namespace grainflow {
namespace {

std::map<GlobalId, Vec3> gather(const Particles& p, MPI_Comm comm) {
  std::vector<double> mine;
  for (std::size_t i = 0; i < p.size(); ++i)
    mine.insert(mine.end(), {static_cast<double>(p.id[i]), p.x[i][0], p.x[i][1], p.x[i][2]});
  int n = static_cast<int>(mine.size()), size = 1;
  MPI_Comm_size(comm, &size);
  std::vector<int> counts(size), offsets(size, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < size; ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(offsets[size - 1] + counts[size - 1]);
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE,
                 comm);
  std::map<GlobalId, Vec3> out;
  for (std::size_t k = 0; k < all.size(); k += 4)
    out[static_cast<GlobalId>(all[k])] = Vec3(all[k + 1], all[k + 2], all[k + 3]);
  return out;
}

TEST(MeshWallMpi, SettlingBedIsIndependentOfRankCount) {
  Scene s = test::one_material_scene(5e6, 0.3, 2500, 0.3, 0.5);
  s.contact.tangential = TangentialModel::history;
  s.domain.lo = Vec3(-0.001, -0.001, -0.001);
  s.domain.hi = Vec3(0.017, 0.013, 0.041);
  s.gravity = Vec3(-2, 0, -9.81);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  // One file per rank: no rank reads a file another is writing.
  const std::string file = test::write_mesh(test::box(Vec3::Zero(), Vec3(0.016, 0.012, 0.04)), "mpi_box_" +
                                                                            std::to_string(rank) + ".stl");
  s.walls.push_back(test::mesh_wall(file));
  Insertion ins;
  ins.kind = Insertion::Kind::fill;
  ins.region.lo = Vec3(0, 0, 0.005);
  ins.region.hi = Vec3(0.016, 0.012, 0.035);
  ins.count = 250;
  ins.radius.kind = SizeDistribution::Kind::uniform;
  ins.radius.min = 0.0008;
  ins.radius.max = 0.0010;
  ins.seed = 2;
  ins.source = "<test>";
  s.insertions.push_back(ins);
  s.time.step = 2e-5;

  MPI_Comm self;
  MPI_Comm_split(MPI_COMM_WORLD, rank, 0, &self);
  Simulation one(s, true, self);
  one.advance_to(0.04);
  const auto a = gather(one.particles(), self);
  MPI_Comm_free(&self);

  Simulation two(s, true, MPI_COMM_WORLD, {2, 1, 1});
  two.advance_to(0.04);
  const auto b = gather(two.particles(), MPI_COMM_WORLD);
  ASSERT_EQ(a.size(), b.size());
  double worst = 0;
  for (const auto& [id, x] : a) worst = std::max(worst, (b.at(id) - x).norm());
  if (rank == 0) std::printf("[ measured ] 1 vs 2 ranks, mesh box: max position difference %.3e m\n", worst);
  EXPECT_LT(worst, 1e-12);
}

}  // namespace
}  // namespace grainflow
