#pragma once
// The dense, frictional granular gas shared by the MPI tests: 2000 spheres at 34 %
// solids in a box periodic along x, walled along y and z, with gravity; stir() gives
// every particle a random velocity of 0.5 m/s (the same on every rank).
#include <cmath>
#include <random>

#include "dem/engine/simulation.hpp"
#include "tests/dem/support/test_scene.hpp"

namespace grainflow::test {

inline Scene gas_scene() {
  Scene s = one_material_scene(1e7, 0.3, 2500, 0.6, 0.4, 0.05);
  s.domain.lo = Vec3(0, 0, 0);
  s.domain.hi = Vec3(0.03, 0.015, 0.015);
  s.domain.periodic = {true, false, false};
  s.contact.tangential = TangentialModel::history;
  s.contact.rolling = RollingModel::epsd;
  s.walls = {plane(Vec3::Zero(), Vec3::UnitY()),
             plane(Vec3(0, 0.015, 0), -Vec3::UnitY()),
             plane(Vec3::Zero(), Vec3::UnitZ()),
             plane(Vec3(0, 0, 0.015), -Vec3::UnitZ())};
  s.gravity = Vec3(0, 0, -9.81);
  Insertion fill;
  fill.region.lo = s.domain.lo;
  fill.region.hi = s.domain.hi;
  fill.count = 2000;
  fill.radius.kind = SizeDistribution::Kind::uniform;
  fill.radius.min = 0.6e-3;
  fill.radius.max = 0.7e-3;
  fill.seed = 4;
  fill.source = "test";
  s.insertions.push_back(fill);
  return s;
}

inline void stir(Simulation& sim) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (auto& v : sim.particles().v) v = 0.5 / std::sqrt(3.0) * Vec3(u(rng), u(rng), u(rng));
}

}  // namespace grainflow::test
