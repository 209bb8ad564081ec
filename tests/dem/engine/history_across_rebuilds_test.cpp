// Contact springs (tangential and EPSD rolling) survive neighbour-list rebuilds and
// spatial re-sorting. The skin is a numerical parameter: a run that rebuilds at almost
// every step (skin 1e-6 r) must follow the same trajectories as one that rarely rebuilds
// (skin 0.5 r). If a rebuild dropped or mismatched a spring, the sticking contacts of
// this frictional pile would jump at once by a fraction of their tangential force.
// Reference: skin independence of the dynamics. Tolerance 1e-8 relative to the
// particle speed scale: re-sorting changes the order of force summation, which changes
// the last bits, and a dense pile amplifies them over 4000 steps.
#include <gtest/gtest.h>

#include <random>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

Particles run_pile(double skin, long* rebuilds) {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.4, 0.5, 0.05);
  s.gravity = Vec3(0, 0, -9.81);
  s.contact.tangential = TangentialModel::history;
  s.contact.rolling = RollingModel::epsd;
  s.neighbour.skin = skin;
  s.walls.push_back(test::plane(Vec3::Zero(), Vec3::UnitZ()));
  Simulation sim(s, false);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  GlobalId id = 1;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k)
        sim.particles().add(id++, Vec3(i * 2.05e-3, j * 2.05e-3, 1.01e-3 + k * 2.05e-3) +
                                       2e-5 * Vec3(u(rng), u(rng), 0),
                            0.05 * Vec3(u(rng), u(rng), 0), Vec3::Zero(), 1e-3, 0, 2500);
  sim.set_dt(2e-6);
  sim.initialise();
  for (int k = 0; k < 4000; ++k) sim.step();
  *rebuilds = sim.counters().rebuilds;
  // Return in id order for comparison.
  Particles& p = sim.particles();
  std::vector<std::size_t> order(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) order[p.id[i] - 1] = i;
  p.permute(order);
  return p;
}

TEST(ContactHistory, SurvivesRebuildsAndResorting) {
  long few = 0, many = 0;
  const Particles a = run_pile(0.5e-3, &few);
  const Particles b = run_pile(1e-9, &many);
  ASSERT_GT(many, 2000) << "the small-skin run must rebuild at most steps";
  ASSERT_LT(few, 100);
  ASSERT_EQ(a.size(), b.size());
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, (a.v[i] - b.v[i]).norm() / 0.05);
    worst = std::max(worst, (a.omega[i] - b.omega[i]).norm() * 1e-3 / 0.05);
  }
  EXPECT_LT(worst, 1e-8);
}

}  // namespace
}  // namespace grainflow
