// Every slot combination (2 normal x 2 tangential x 3 rolling x 2 cohesion = 24)
// compiles into its own force loop and obeys Newton's third law: in a cluster of
// colliding spheres with no walls and no gravity, total linear momentum and total
// angular momentum (orbital + spin) are conserved to round-off. Reference:
// conservation laws. Tolerance 1e-12 relative to the initial momentum scale: the
// sums accumulate ~1e4 contact evaluations of rounding error ~1e-16 each.
#include <gtest/gtest.h>

#include <random>
#include <tuple>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow {
namespace {

using Combo = std::tuple<NormalModel, TangentialModel, RollingModel, CohesionModel>;

class ContactCombination : public ::testing::TestWithParam<Combo> {};

TEST_P(ContactCombination, ConservesMomentumAndStaysFinite) {
  const auto [normal, tangential, rolling, cohesion] = GetParam();
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5, 0.4, 0.05, 2e4);
  s.contact.normal = normal;
  s.contact.tangential = tangential;
  s.contact.rolling = rolling;
  s.contact.cohesion = cohesion;
  s.contact.hooke_characteristic_velocity = 1.0;
  Simulation sim(s, false);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  GlobalId id = 1;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        const Vec3 x = Vec3(i, j, k) * 2.25e-3 + 2e-5 * Vec3(u(rng), u(rng), u(rng));
        sim.particles().add(id++, x, 1.0 * Vec3(u(rng), u(rng), u(rng)),
                            100 * Vec3(u(rng), u(rng), u(rng)), 1e-3 * (1 + 0.1 * u(rng)), 0,
                            2500);
      }
  sim.set_dt(1e-6);
  sim.initialise();
  auto momenta = [&] {
    const Particles& p = sim.particles();
    Vec3 lin = Vec3::Zero(), ang = Vec3::Zero();
    for (std::size_t i = 0; i < p.size(); ++i) {
      lin += p.mass[i] * p.v[i];
      ang += p.x[i].cross(p.mass[i] * p.v[i]) + p.inertia[i] * p.omega[i];
    }
    return std::pair{lin, ang};
  };
  const auto [l0, a0] = momenta();
  double l_scale = 0, a_scale = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) {
    l_scale += sim.particles().mass[i] * sim.particles().v[i].norm();
    a_scale += sim.particles().inertia[i] * sim.particles().omega[i].norm() +
               sim.particles().x[i].norm() * sim.particles().mass[i] * sim.particles().v[i].norm();
  }
  long touching = 0;
  for (int k = 0; k < 400; ++k) {
    sim.step();
    touching += sim.counters().contacts;
  }
  ASSERT_GT(touching, 1000) << "the cluster never collided; the test checks nothing";
  const auto [l1, a1] = momenta();
  EXPECT_LT((l1 - l0).norm() / l_scale, 1e-12);
  EXPECT_LT((a1 - a0).norm() / a_scale, 1e-12);
  for (std::size_t i = 0; i < sim.particles().size(); ++i)
    ASSERT_TRUE(sim.particles().x[i].allFinite() && sim.particles().v[i].allFinite() &&
                sim.particles().omega[i].allFinite());
  EXPECT_EQ(sim.particles().size(), 64u);
}

// A rank holding more than 50 000 particles runs the pair sweep that prefetches the
// partners and springs ahead (local_pair_sweep, kPrefetchAbove): the same conservation of
// linear and angular momentum, for the four-lane law and for the scalar one (EPSD rolling
// springs), in a cluster of 40^3 spheres with random velocities and spins.
TEST(ContactCombinationLarge, PrefetchingSweepConservesMomentum) {
  for (const RollingModel rolling : {RollingModel::none, RollingModel::epsd}) {
    Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5, 0.4, 0.05, 2e4);
    s.contact.normal = NormalModel::hertz;
    s.contact.tangential = TangentialModel::history;
    s.contact.rolling = rolling;
    Simulation sim(s, false);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    GlobalId id = 1;
    constexpr int kSide = 40;
    for (int i = 0; i < kSide; ++i)
      for (int j = 0; j < kSide; ++j)
        for (int k = 0; k < kSide; ++k)
          sim.particles().add(id++, Vec3(i, j, k) * 2.05e-3 + 2e-5 * Vec3(u(rng), u(rng), u(rng)),
                              0.5 * Vec3(u(rng), u(rng), u(rng)),
                              100 * Vec3(u(rng), u(rng), u(rng)), 1e-3 * (1 + 0.05 * u(rng)), 0,
                              2500);
    sim.set_dt(1e-6);
    sim.initialise();
    const Particles& p = sim.particles();
    auto momenta = [&] {
      Vec3 lin = Vec3::Zero(), ang = Vec3::Zero();
      double l_scale = 0, a_scale = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        lin += p.mass[i] * p.v[i];
        ang += p.x[i].cross(p.mass[i] * p.v[i]) + p.inertia[i] * p.omega[i];
        l_scale += p.mass[i] * p.v[i].norm();
        a_scale += p.inertia[i] * p.omega[i].norm() + p.x[i].norm() * p.mass[i] * p.v[i].norm();
      }
      return std::tuple{lin, ang, l_scale, a_scale};
    };
    const auto [l0, a0, l_scale, a_scale] = momenta();
    long touching = 0;
    for (int k = 0; k < 5; ++k) {
      sim.step();
      touching += sim.counters().contacts;
    }
    ASSERT_GT(touching, 5 * 20000) << "too few contacts to test anything";
    const auto [l1, a1, l_end, a_end] = momenta();
    EXPECT_LT((l1 - l0).norm() / l_scale, 1e-12);
    EXPECT_LT((a1 - a0).norm() / a_scale, 1e-12);
    ASSERT_EQ(p.size(), static_cast<std::size_t>(kSide * kSide * kSide));
    for (std::size_t i = 0; i < p.size(); ++i)
      ASSERT_TRUE(p.x[i].allFinite() && p.v[i].allFinite() && p.omega[i].allFinite());
  }
}

INSTANTIATE_TEST_SUITE_P(
    AllSlots, ContactCombination,
    ::testing::Combine(::testing::Values(NormalModel::hertz, NormalModel::hooke),
                       ::testing::Values(TangentialModel::none, TangentialModel::history),
                       ::testing::Values(RollingModel::none, RollingModel::cdt, RollingModel::epsd),
                       ::testing::Values(CohesionModel::none, CohesionModel::sjkr)));

}  // namespace
}  // namespace grainflow
