#include "dem/neighbour/wall_neighbours.hpp"

#include <algorithm>
#include <cmath>

namespace grainflow {

double wall_gap(const WallSet::Entry& wall, const Vec3& x, double r) {
  if (wall.kind == Wall::Kind::plane) return (x - wall.plane.point).dot(wall.plane.normal) - r;
  const CylinderWall& c = wall.cylinder;
  const Vec3 rel = x - c.axis_point;
  const double rho = (rel - rel.dot(c.axis) * c.axis).norm();
  return (c.inside ? c.radius - rho : rho - c.radius) - r;
}

void WallNeighbours::build(const Particles& p, const WallSet& walls, double skin) {
  lists.resize(walls.walls().size());
  column_wall_.assign(walls.history_columns(), 0);
  for (std::size_t w = 0; w < walls.walls().size(); ++w) {
    const WallSet::Entry& wall = walls.walls()[w];
    List& list = lists[w];
    list.i.clear();
    list.all = wall.kind == Wall::Kind::mesh || wall.pose.moving();
    for (std::size_t c = 0; c < WallSet::columns_of(wall); ++c)
      column_wall_[wall.column + c] = static_cast<int>(w);
    if (list.all) continue;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (wall_gap(wall, p.x[i], p.radius[i]) < skin) list.i.push_back(static_cast<int>(i));
  }
}

std::size_t WallNeighbours::entry_of(std::size_t c, std::size_t i) const {
  const List& l = list_of_column(c);
  if (l.all) return i;
  const auto it = std::lower_bound(l.i.begin(), l.i.end(), static_cast<int>(i));
  return it != l.i.end() && *it == static_cast<int>(i) ? static_cast<std::size_t>(it - l.i.begin())
                                                       : npos;
}

}  // namespace grainflow
