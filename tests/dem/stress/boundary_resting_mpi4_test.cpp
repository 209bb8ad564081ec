// Particles resting exactly on processor boundaries and on periodic sides (issue 8).
//
// A 16 x 16 mm floor, periodic along x and y, cut 2 x 2 over 4 ranks at x = y = 8 mm
// (exact in binary). Three layers of spheres (r = 1 mm) on a lattice of pitch 2 mm:
// the first and third layers put centres exactly on the cut planes x = 8 mm, y = 8 mm,
// on the corner (8, 8) mm of all four ranks, and on the periodic sides x = 0, y = 0;
// one row sits at x = 16 mm (= hi, the same plane as x = 0 seen from the other side).
// The middle layer nests in the hollows. Gravity, friction and rolling resistance
// then let the pile settle for a while.
//
// Invariants:
// - each particle is owned exactly once: the global count is 136 right after
//   initialise() and at the end, and the gathered ids are 1..136 without repeats;
// - no NaN / Inf;
// - forces are symmetric across rank and periodic boundaries: the 4-rank run matches
//   the 1-rank run to round-off. The only expected difference is the order in which
//   a sphere's contact forces are summed (docs/parallel.md), i.e. a few ulps per step.
//   Tolerances: positions 1e-14 of L (measured 2.6e-17 m = 1.6e-15 L); velocities and
//   surface speeds w r 1e-12 m/s absolute (measured 6.6e-14 m/s and 1.0e-13 m/s after
//   5000 steps, not growing with the horizon: 2.1e-14 and 1.3e-14 after 15000). An
//   asymmetric force — a contact seen once or twice — differs by its whole size,
//   ~1e-4 N here, i.e. ~1e-5 m/s within a step.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/dem/parallel/support.hpp"
#include "tests/dem/stress/stress_support.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

constexpr double kL = 0.016, kR = 1e-3, kRho = 2500;

Scene floor_scene() {
  Scene s = test::one_material_scene(1e7, 0.3, kRho, 0.5, 0.5, 0.05);
  s.domain.lo = Vec3::Zero();
  s.domain.hi = Vec3(kL, kL, 0.01);
  s.domain.periodic = {true, true, false};
  s.contact.tangential = TangentialModel::history;
  s.contact.rolling = RollingModel::epsd;
  s.gravity = Vec3(0, 0, -9.81);
  s.walls = {test::plane(Vec3::Zero(), Vec3::UnitZ())};
  return s;
}

void add_pile(Simulation& sim) {
  GlobalId id = 1;
  const double pitch = 2 * kR, z1 = kR - 1e-6;  // resting on the floor
  const double z2 = z1 + std::sqrt(2.0) * kR, z3 = z1 + 2 * std::sqrt(2.0) * kR;  // nested
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      // Row j = 2 starts at x = 16 mm instead of 0: on the hi periodic side.
      const double x = (j == 2 && i == 0) ? kL : i * pitch;
      sim.particles().add(id++, Vec3(x, j * pitch, z1), Vec3::Zero(), Vec3::Zero(), kR, 0, kRho);
    }
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i)
      sim.particles().add(id++, Vec3((i + 0.5) * pitch, (j + 0.5) * pitch, z2), Vec3::Zero(),
                          Vec3::Zero(), kR, 0, kRho);
  // A third layer of 8, only on the planes, including the corner of all four ranks
  // (8, 8) mm and the corner of the periodic sides (0, 0); lattice indices below.
  const int on_planes[8][2] = {{0, 0}, {4, 0}, {0, 4}, {4, 4}, {4, 2}, {2, 4}, {6, 4}, {4, 6}};
  for (const auto& ij : on_planes)
    sim.particles().add(id++, Vec3(ij[0] * pitch, ij[1] * pitch, z3), Vec3(0.01, -0.01, 0),
                        Vec3::Zero(), kR, 0, kRho);
}

struct Outcome {
  std::vector<test::State> states;
  long count_at_start = 0, count_at_end = 0;
  bool finite = true;
};

Outcome run(int ranks, std::array<int, 3> grid, long steps) {
  Outcome o;
  MPI_Comm comm = test::first_ranks(ranks);
  if (comm == MPI_COMM_NULL) return o;
  Simulation sim(floor_scene(), false, comm, grid);
  add_pile(sim);
  sim.set_dt(2e-6);  // 0.05 t_R for r = 1 mm, Y = 10 MPa
  sim.initialise();
  o.count_at_start = sim.global_state().particles;
  for (long k = 0; k < steps; ++k) {
    sim.step();
    if (k % 100 == 0) o.finite = o.finite && test::all_finite(sim.particles(), comm);
  }
  o.count_at_end = sim.global_state().particles;
  o.states = test::gather_states(sim.particles(), comm);
  MPI_Comm_free(&comm);
  return o;
}

TEST(BoundaryResting, OwnedOnceAndSameAsOneRank) {
  const long steps = 5000 * test::stress_scale();
  const Outcome four = run(4, {2, 2, 1}, steps);
  const Outcome one = run(1, {1, 1, 1}, steps);
  if (test::world_rank() != 0) return;
  EXPECT_TRUE(four.finite);
  EXPECT_TRUE(one.finite);
  EXPECT_EQ(four.count_at_start, 136);
  EXPECT_EQ(four.count_at_end, 136);
  EXPECT_EQ(one.count_at_start, 136);
  ASSERT_EQ(four.states.size(), 136u);
  ASSERT_EQ(one.states.size(), 136u);
  for (std::size_t k = 0; k < four.states.size(); ++k)
    ASSERT_EQ(four.states[k].id, static_cast<GlobalId>(k + 1)) << "owned twice or lost";
  double dx = 0, dv = 0, dw = 0;
  for (std::size_t k = 0; k < one.states.size(); ++k)
    for (int a = 0; a < 3; ++a) {
      dx = std::max(dx, std::abs(one.states[k].x[a] - four.states[k].x[a]));
      dv = std::max(dv, std::abs(one.states[k].v[a] - four.states[k].v[a]));
      dw = std::max(dw, std::abs(one.states[k].w[a] - four.states[k].w[a]));
    }
  double moved = 0;
  for (const auto& s : one.states) moved = std::max(moved, std::abs(s.v[2]));
  std::printf(
      "%ld steps, 136 spheres on cut planes and periodic sides: 4 ranks vs 1 differ by "
      "%.3e m (%.2e L), %.3e m/s, %.3e m/s (w r); largest |v_z| %.3e m/s\n",
      steps, dx, dx / kL, dv, dw * kR, moved);
  EXPECT_LT(dx, 1e-14 * kL);
  EXPECT_LT(dv, 1e-12);
  EXPECT_LT(dw * kR, 1e-12);
}

}  // namespace
}  // namespace grainflow
