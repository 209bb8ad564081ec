#pragma once
// The particles near each wall: the wall counterpart of the Verlet list (verlet_list.hpp),
// built at the same neighbour rebuilds. A sphere whose surface is at least one skin away
// from a fixed plane or cylinder cannot touch it before the next rebuild, which comes as
// soon as any sphere has moved skin/2 (the gap to a plane or a cylinder changes by at most
// the distance moved). The wall sweep then visits the listed spheres only, in ascending
// index order as before, so forces and springs are the same bit for bit; without the lists
// every plane cost a pass over all particles every step.
//
// Moving walls (their distance changes without the particles moving) and meshes (their
// own search grid, triangle_mesh.hpp) are not listed: the sweep visits every particle.
#include <vector>

#include "dem/contact/contact_geometry.hpp"
#include "dem/core/particles.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

// Gap between the surface of a sphere (centre x, radius r) and a plane or cylinder wall at
// its current position; negative when they overlap. Not for meshes.
double wall_gap(const WallSet::Entry& wall, const Vec3& x, double r);

struct WallNeighbours {
  struct List {
    bool all = true;     // moving wall or mesh: every particle
    std::vector<int> i;  // else: local indices with wall_gap < skin, ascending
  };
  std::vector<List> lists;  // one per WallSet::walls() entry, in that order

  void build(const Particles& p, const WallSet& walls, double skin);

  // Ends the springs of particles off a wall's list: they do not touch the wall now (the
  // sweep would end them at this step's force evaluation) nor before the next rebuild.
  // history: Simulation's wall history columns (WallSet::history_columns()).
  void end_unlisted_springs(const WallSet& walls,
                            std::vector<std::vector<ContactHistory>>& history) const;
};

}  // namespace grainflow
