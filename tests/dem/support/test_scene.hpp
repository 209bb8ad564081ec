#pragma once
// Builds small scenes in code for physics tests (no YAML involved).
#include "dem/scene/scene.hpp"

namespace grainflow::test {

inline Scene one_material_scene(double youngs, double poisson, double density, double restitution,
                                double friction = 0.0, double rolling_friction = 0.0,
                                double cohesion = 0.0) {
  Scene s;
  s.file = "<test>";
  s.domain.lo = Vec3(-1, -1, -1);
  s.domain.hi = Vec3(1, 1, 1);
  s.materials.push_back({"m", youngs, poisson, density});
  MaterialPair pair;
  pair.a = pair.b = 0;
  pair.restitution = restitution;
  pair.friction = friction;
  pair.rolling_friction = rolling_friction;
  pair.cohesion_energy_density = cohesion;
  s.pairs.push_back(pair);
  s.time.step = 1e-6;
  s.time.end = 1;
  s.contact.normal = NormalModel::hertz;
  s.contact.tangential = TangentialModel::none;
  return s;
}

inline Wall plane(const Vec3& point, const Vec3& normal) {
  Wall w;
  w.kind = Wall::Kind::plane;
  w.name = "plane";
  w.material = 0;
  w.plane.point = point;
  w.plane.normal = normal.normalized();
  return w;
}

}  // namespace grainflow::test
