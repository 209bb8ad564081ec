#pragma once
// The travel guard for walls (docs/stability.md, "Moving walls: travel per step"): the rule
// of the particles' travel guard (time.max_step_travel), applied at start-up to each moving
// wall. A wall surface that moves more than the smallest particle's radius in one step can
// pass through a particle without the two ever overlapping at the end of a step.
//
// A wall's sweep speed is the largest speed at which its surface moves across space (the
// part of its motion along its own surface moves no surface and cannot pass a particle):
//   plane:    |n . V| + |w| rho_max  (rotation about an axis along n: 0)
//   cylinder: |V - (V . c) c| + |w| rho_max  (rotation about its own axis: 0)
//   mesh:     |V| + |w| rho_max
// with rho_max the farthest distance from the rotation axis of the wall's extent: a mesh's
// vertices (a rigid motion keeps it), a plane's or cylinder's part inside the domain (the
// domain's corners, plus |V| t_end for the axis' own travel). A cylinder's surface speed
// (cylinder.angular_velocity) and a mesh's conveyor speed are along the surface: not counted.
#include <limits>
#include <string>
#include <vector>

#include "dem/contact/pair_coefficients.hpp"
#include "dem/scene/scene.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

struct WallTravel {
  std::string name;
  std::size_t index = 0;  // into Scene::walls
  double speed = 0;       // sweep speed [m/s]
  double travel = 0;      // speed x dt [m]
};

struct WallTravelReport {
  std::vector<WallTravel> walls;   // every moving wall
  std::vector<std::string> notes;  // one line per moving wall, for grain check and the run
  std::string error;               // empty unless a wall moves too far per step
  double fitting_step = 0;         // the proposed step when `error` is set [s]
  double impact_step = 0;          // Hertz: the step that resolves the impact [s], or 0
};

// The sweep speed of wall k of `scene` (walls.walls()[k] is the same wall, loaded).
double wall_sweep_speed(const Scene& scene, const WallSet& walls, std::size_t k);

// Checks every moving wall's travel per step dt against time.max_step_travel x r_min, the
// smallest radius of a particle present or to be inserted (r_min = 0: no particles, nothing
// to pass through). A proposed step keeps both the wall and a particle it strikes within
// the limit: such a particle leaves at up to twice the wall's speed (an elastic rebound from
// a wall of unbounded mass), so the proposal is limit r_min / (2 v), rounded down to three
// significant digits.
// With Hertz contacts, the message also gives the step that resolves the impact of that
// particle (material `material`, unit at rest) on the wall at the wall's speed: 1/20 of the
// Hertz contact time (R* = r_min, m* = its mass), as the particles' travel guard does.
// `startup_step`: the largest step the start-up time-step check (check_time_step) accepts
// when it refuses dt, else infinity: the proposal is never above it, so that rerunning with it
// passes both checks.
WallTravelReport check_wall_travel(const Scene& scene, const WallSet& walls, double dt,
                                   double r_min, int material, const PairTable& table,
                                   double startup_step = std::numeric_limits<double>::infinity());

}  // namespace grainflow
