// CoupledFluid (dem/fluid/coupled_fluid.hpp): the samples a fluid solver sets by particle id
// reach the right particles whatever the particles' order at each DEM sub-step. Reference:
// each particle's sample carries its own id (void fraction id / 100, velocity (id, 0, 0)),
// so a sample served to the wrong particle shows.
#include "dem/fluid/coupled_fluid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dem/core/particles.hpp"

namespace grainflow {
namespace {

CoupledSample sampleOf(GlobalId id, double scale = 1) {
  CoupledSample s;
  s.void_fraction = scale * static_cast<double>(id) / 100;
  s.velocity = Vec3(static_cast<double>(id), 0, 0);
  return s;
}

Particles fourParticles() {
  Particles p;
  for (GlobalId id : {3, 7, 11, 20})
    p.add(id, Vec3(0.01 * static_cast<double>(id), 0, 0), Vec3::Zero(), Vec3::Zero(), 1e-3, 0,
          2500);
  return p;
}

// Samples for the particles' current order, `scale` telling one set from another.
void setFor(CoupledFluid& fluid, const Particles& p, double scale) {
  std::vector<CoupledSample> samples;
  for (GlobalId id : p.id) samples.push_back(sampleOf(id, scale));
  fluid.set(p.id, samples);
}

void expectServed(CoupledFluid& fluid, const Particles& p, double scale) {
  const CoupledFluid::View v = fluid.at_particles(p);
  ASSERT_EQ(v.size, p.size());
  EXPECT_EQ(v.vorticity, nullptr);  // the sets of these tests carry none
  for (std::size_t i = 0; i < p.size(); ++i) {
    const FluidSample s = fluid.sample(v, i);
    EXPECT_EQ(s.void_fraction, sampleOf(p.id[i], scale).void_fraction) << "particle " << p.id[i];
    EXPECT_EQ(s.velocity[0], static_cast<double>(p.id[i])) << "particle " << p.id[i];
  }
}

TEST(CoupledFluid, ServesTheSamplesWhileTheOrderHolds) {
  Particles p = fourParticles();
  CoupledFluid fluid;
  setFor(fluid, p, 1);
  expectServed(fluid, p, 1);
  expectServed(fluid, p, 1);  // every sub-step
  EXPECT_EQ(fluid.late_samples(), 0);
}

TEST(CoupledFluid, FollowsAReorder) {
  Particles p = fourParticles();
  CoupledFluid fluid;
  setFor(fluid, p, 1);
  p.permute({2, 0, 3, 1});
  expectServed(fluid, p, 1);
  p.permute({3, 2, 1, 0});
  expectServed(fluid, p, 1);
  EXPECT_EQ(fluid.late_samples(), 0);
}

// After a re-map, a new set must be served, not the re-mapped copy of the old one: also when
// the new set comes in the old order and the particles are still in the re-mapped order.
TEST(CoupledFluid, ANewSetReplacesARemappedOne) {
  Particles p = fourParticles();
  const Particles original = p;
  CoupledFluid fluid;
  setFor(fluid, p, 1);
  p.permute({1, 3, 0, 2});
  expectServed(fluid, p, 1);  // re-mapped
  setFor(fluid, p, 2);        // new samples, in the particles' (re-mapped) order
  expectServed(fluid, p, 2);
  setFor(fluid, original, 3);  // new samples in the original order
  expectServed(fluid, p, 3);
  EXPECT_EQ(fluid.late_samples(), 0);
}

TEST(CoupledFluid, SamplesALateArrivalOnce) {
  Particles p = fourParticles();
  CoupledFluid fluid;
  setFor(fluid, p, 1);
  int calls = 0;
  fluid.set_sampler([&calls](const Vec3& x) {
    ++calls;
    const CoupledSample c = sampleOf(static_cast<GlobalId>(std::lround(x[0] / 0.01)));
    FluidSample f;
    f.velocity = c.velocity;
    f.void_fraction = c.void_fraction;
    return f;
  });
  p.add(42, Vec3(0.42, 0, 0), Vec3::Zero(), Vec3::Zero(), 1e-3, 0, 2500);  // migrated in
  expectServed(fluid, p, 1);
  expectServed(fluid, p, 1);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(fluid.late_samples(), 1);
}

// The run's density and viscosity reach every sample; the vorticity, when a set carries it,
// follows its particle through a reorder and comes with a late arrival.
TEST(CoupledFluid, ConstantsAndVorticityReachTheirParticles) {
  Particles p = fourParticles();
  CoupledFluid fluid;
  fluid.set_constants(1.2, 1.8e-5);
  std::vector<CoupledSample> samples;
  std::vector<Vec3> vorticity;
  for (GlobalId id : p.id) {
    samples.push_back(sampleOf(id));
    vorticity.push_back(Vec3(0, 0, -static_cast<double>(id)));
  }
  fluid.set(p.id, samples, vorticity);
  fluid.set_sampler([](const Vec3& x) {
    FluidSample f;
    f.vorticity = Vec3(0, 0, -std::round(x[0] / 0.01));
    return f;
  });
  p.permute({3, 1, 0, 2});
  p.add(42, Vec3(0.42, 0, 0), Vec3::Zero(), Vec3::Zero(), 1e-3, 0, 2500);
  const CoupledFluid::View v = fluid.at_particles(p);
  ASSERT_NE(v.vorticity, nullptr);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const FluidSample s = fluid.sample(v, i);
    EXPECT_EQ(s.density, 1.2);
    EXPECT_EQ(s.viscosity, 1.8e-5);
    EXPECT_EQ(s.vorticity, Vec3(0, 0, -static_cast<double>(p.id[i]))) << "particle " << p.id[i];
    EXPECT_EQ(s.material_derivative, Vec3::Zero());
  }
  EXPECT_EQ(fluid.late_samples(), 1);
  EXPECT_THROW(fluid.set(p.id, std::vector<CoupledSample>(p.size()), std::vector<Vec3>(2)),
               std::invalid_argument);
}

// sampling cellPoint: each particle's cell velocity U_fp follows it through a reorder; a late
// arrival's is its sample (it is sampled in the cell holding it); a set without them serves
// none.
TEST(CoupledFluid, CellVelocityFollowsItsParticle) {
  Particles p = fourParticles();
  CoupledFluid fluid;
  std::vector<CoupledSample> samples;
  std::vector<Vec3> cells;
  for (GlobalId id : p.id) {
    samples.push_back(sampleOf(id));
    cells.push_back(Vec3(0, static_cast<double>(id), 1));
  }
  fluid.set(p.id, samples, {}, {}, {}, cells);
  fluid.set_sampler([](const Vec3& x) {
    FluidSample f;
    f.velocity = Vec3(std::round(x[0] / 0.01), 0, 0);
    return f;
  });
  p.permute({2, 3, 1, 0});
  p.add(42, Vec3(0.42, 0, 0), Vec3::Zero(), Vec3::Zero(), 1e-3, 0, 2500);
  const CoupledFluid::View v = fluid.at_particles(p);
  ASSERT_NE(v.cell_velocity, nullptr);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 expected =
        p.id[i] == 42 ? Vec3(42, 0, 0) : Vec3(0, static_cast<double>(p.id[i]), 1);
    EXPECT_EQ(v.cell_velocity[i], expected) << "particle " << p.id[i];
  }
  EXPECT_THROW(fluid.set(p.id, std::vector<CoupledSample>(p.size()), {}, {}, {},
                         std::vector<Vec3>(2)),
               std::invalid_argument);
  setFor(fluid, p, 1);
  EXPECT_EQ(fluid.at_particles(p).cell_velocity, nullptr);
}

}  // namespace
}  // namespace grainflow
