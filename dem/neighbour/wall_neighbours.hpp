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
#include <cstddef>
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

  // The wall springs (Simulation's wall history: one vector per WallSet history column)
  // follow these lists: a listed wall's column holds one spring per entry of its list (the
  // spring of particle list.i[k] at k), the column of a wall listing every particle one per
  // particle. So only the few particles near a fixed plane or cylinder hold a spring for it;
  // an unlisted particle cannot touch it before the next rebuild, and has none.
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
  // The list that history column c follows (after build()).
  const List& list_of_column(std::size_t c) const { return lists[column_wall_[c]]; }
  // How many springs column c holds, with `particles` particles.
  std::size_t column_size(std::size_t c, std::size_t particles) const {
    const List& l = list_of_column(c);
    return l.all ? particles : l.i.size();
  }
  // The particle of spring k of column c.
  std::size_t particle_of(std::size_t c, std::size_t k) const {
    const List& l = list_of_column(c);
    return l.all ? k : static_cast<std::size_t>(l.i[k]);
  }
  // The spring of particle i in column c, or npos when i is not on the column's list.
  std::size_t entry_of(std::size_t c, std::size_t i) const;

 private:
  std::vector<int> column_wall_;  // history column -> wall
};

}  // namespace grainflow
