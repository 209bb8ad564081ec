#include "dem/neighbour/wall_neighbours.hpp"

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
  for (std::size_t w = 0; w < walls.walls().size(); ++w) {
    const WallSet::Entry& wall = walls.walls()[w];
    List& list = lists[w];
    list.i.clear();
    list.all = wall.kind == Wall::Kind::mesh || wall.pose.moving();
    if (list.all) continue;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (wall_gap(wall, p.x[i], p.radius[i]) < skin) list.i.push_back(static_cast<int>(i));
  }
}

void WallNeighbours::end_unlisted_springs(const WallSet& walls,
                                          std::vector<std::vector<ContactHistory>>& history) const {
  for (std::size_t w = 0; w < lists.size(); ++w) {
    const List& list = lists[w];
    if (list.all) continue;
    std::vector<ContactHistory>& column = history[walls.walls()[w].column];
    std::size_t next = 0;  // position in the ascending list
    for (std::size_t i = 0; i < column.size(); ++i) {
      if (next < list.i.size() && static_cast<std::size_t>(list.i[next]) == i)
        ++next;
      else
        column[i] = ContactHistory{};
    }
  }
}

}  // namespace grainflow
