// Stream insertion on 2 ranks: every rank agrees on what was inserted, each particle
// is added once (by the rank owning its position), and the totals equal a 1-rank run's
// (same candidates, same verdicts).
#include <gtest/gtest.h>
#include <mpi.h>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

TEST(StreamInsertionMpi, TwoRanksInsertWhatOneRankInserts) {
  Scene s = test::one_material_scene(5e6, 0.3, 2500, 0.3);
  s.domain.lo = Vec3(-0.03, -0.03, -0.1);
  s.domain.hi = Vec3(0.03, 0.03, 0.05);
  s.gravity = Vec3(0, 0, -9.81);
  s.time.step = 2e-5;
  s.walls.push_back(test::plane(Vec3(0, 0, -0.02), Vec3::UnitZ()));  // a floor: the pile touches ranks' boundary
  Insertion ins;
  ins.kind = Insertion::Kind::stream;
  ins.face.kind = InsertionFace::Kind::rectangle;
  ins.face.centre = Vec3(0, 0, 0.0);
  ins.face.normal = Vec3::UnitZ();
  ins.face.u = Vec3::UnitX();
  ins.face.length_u = 0.05;
  ins.face.length_v = 0.05;
  ins.mass_rate = 0.05;
  ins.radius.kind = SizeDistribution::Kind::uniform;
  ins.radius.min = 0.0008;
  ins.radius.max = 0.0012;
  ins.seed = 5;
  ins.source = "<test>";
  s.insertions.push_back(ins);

  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm self;
  MPI_Comm_split(MPI_COMM_WORLD, rank, 0, &self);
  Simulation one(s, true, self);
  one.advance_to(0.05);
  MPI_Comm_free(&self);

  Simulation two(s, true, MPI_COMM_WORLD, {2, 1, 1});
  two.advance_to(0.05);
  long local = static_cast<long>(two.particles().size()), global = 0;
  MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(two.streams().count_inserted(0), one.streams().count_inserted(0));
  EXPECT_DOUBLE_EQ(two.streams().mass_inserted(0), one.streams().mass_inserted(0));
  EXPECT_EQ(global, one.streams().count_inserted(0));
  EXPECT_GT(global, 100);
}

}  // namespace
}  // namespace grainflow
