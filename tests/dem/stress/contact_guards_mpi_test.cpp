// The contact guards on two ranks (issue 8; docs/stability.md): the steps-per-contact
// guard and the overlap guard share one reduction (Simulation::check_contacts), and the
// rank that holds the worst contact writes the message. Here the contact that trips them
// is a pair across the processor plane, or a wall contact on one rank only.
//
// Scene (the too_large_step_test material: r = 1 mm, Y = 10 MPa, e = 0.5; dt = 1e-4 s =
// 1.2 t_R): sphere 1 rests on the floor at x = 5.8 mm, left of the cut x = 6 mm of a
// 2 x 1 x 1 grid; sphere 2 falls onto it at 3 m/s from x = 6.3 mm, right of the cut.
// Sphere 3 falls at 3 m/s onto the floor far away on the right (x = 10 mm), a wall
// contact that only rank 1 sees.
//
// Reference: the same scene on one rank (MPI_COMM_SELF, run on every rank). Every rank
// of the 2-rank run must stop with ParallelError at the same step and with the same
// message, word for word, as the 1-rank run: with the guard on, "particles 1 and 2
// approach at ..." (or the wall contact of sphere 3, whichever has fewer steps per
// contact); with it off, the overlap guard's message.
#include <gtest/gtest.h>

#include <string>

#include "tests/dem/stress/stress_support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kR = 1e-3, kRho = 2500, kV = 3.0;

std::string stop_message(bool guard, MPI_Comm comm, std::array<int, 3> grid) {
  Scene s = test::one_material_scene(1e7, 0.3, kRho, 0.5, 0.5);
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(0.012, 0.012, 0.03);
  s.contact.tangential = TangentialModel::history;
  s.gravity = Vec3(0, 0, -9.81);
  s.walls = {test::plane(Vec3::Zero(), Vec3::UnitZ())};
  s.time.min_steps_per_contact = guard ? 5 : 0;
  Simulation sim(s, false, comm, grid);
  sim.particles().add(1, Vec3(0.0058, 0.006, kR - 1e-6), Vec3::Zero(), Vec3::Zero(), kR, 0, kRho);
  sim.particles().add(2, Vec3(0.0063, 0.006, 3.4 * kR), Vec3(0, 0, -kV), Vec3::Zero(), kR, 0, kRho);
  sim.particles().add(3, Vec3(0.010, 0.006, 1.4 * kR), Vec3(0, 0, -kV), Vec3::Zero(), kR, 0, kRho);
  sim.set_dt(1e-4);
  try {
    sim.initialise();
    for (int k = 0; k < 100; ++k) sim.step();
  } catch (const ParallelError& e) {
    return e.what();
  }
  return "";
}

TEST(ContactGuards, TwoRanksStopWithTheOneRankMessage) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  ASSERT_EQ(size, 2) << "run with mpirun -np 2";
  for (const bool guard : {true, false}) {
    const std::string serial = stop_message(guard, MPI_COMM_SELF, {1, 1, 1});
    const std::string parallel = stop_message(guard, MPI_COMM_WORLD, {2, 1, 1});
    ASSERT_FALSE(serial.empty()) << "guard " << guard << ": the 1-rank run should stop";
    EXPECT_EQ(parallel, serial) << "rank " << test::world_rank();
    EXPECT_NE(serial.find(guard ? "key time.min_steps_per_contact" : "key time.max_overlap"),
              std::string::npos)
        << serial;
    if (test::world_rank() == 0)
      std::printf("guard %s: %s\n", guard ? "on" : "off", serial.c_str());
  }
}

// The travel guard (time.max_step_travel, 1 r) mid-run, on the rank that owns the particle
// only: sphere 1, right of the cut, falls freely at 9.995 m/s under g = 9.81 m/s^2 with
// dt = 1e-4 s. The drift of step k moves it with v = 9.995 + g dt (k - 1/2) (velocity
// Verlet's half kick), which first exceeds r / dt = 10 m/s at k = 6 (closed form:
// k - 1/2 > 0.005 / (g dt) = 5.097; 1.0004 radii, printed to 4 digits). Both ranks must
// stop at step 6 with the 1-rank message.
std::string travel_stop(MPI_Comm comm, std::array<int, 3> grid) {
  Scene s = test::one_material_scene(1e7, 0.3, kRho, 0.5, 0.5);
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(0.012, 0.012, 0.03);
  s.gravity = Vec3(0, 0, -9.81);
  s.walls = {test::plane(Vec3::Zero(), Vec3::UnitZ())};
  Simulation sim(s, false, comm, grid);
  sim.particles().add(1, Vec3(0.010, 0.006, 0.025), Vec3(0, 0, -9.995), Vec3::Zero(), kR, 0,
                      kRho);
  sim.set_dt(1e-4);
  try {
    sim.initialise();
    for (int k = 0; k < 15; ++k) sim.step();
  } catch (const ParallelError& e) {
    return e.what();
  }
  return "";
}

TEST(ContactGuards, TravelGuardStopsBothRanksWithTheOneRankMessage) {
  const std::string serial = travel_stop(MPI_COMM_SELF, {1, 1, 1});
  const std::string parallel = travel_stop(MPI_COMM_WORLD, {2, 1, 1});
  ASSERT_FALSE(serial.empty()) << "the 1-rank run should stop";
  EXPECT_EQ(parallel, serial) << "rank " << test::world_rank();
  EXPECT_NE(serial.find("(step 6): particle 1 moves 1 of its radii"), std::string::npos) << serial;
  EXPECT_NE(serial.find("key time.max_step_travel"), std::string::npos) << serial;
  if (test::world_rank() == 0) std::printf("travel guard: %s\n", serial.c_str());
}

}  // namespace
}  // namespace grainflow
