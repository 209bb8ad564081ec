// Wall neighbour lists (dem/neighbour/wall_neighbours.hpp): a sphere left off a fixed
// plane's or cylinder's list must not touch that wall after any displacement up to skin/2
// (the rebuild criterion), so the wall sweep may skip it. Reference: the wall contact test
// itself (touch_plane / touch_cylinder, dem/walls/wall_contact.hpp) on every sphere after
// random displacements, against the list built before them.
#include "dem/neighbour/wall_neighbours.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "dem/walls/wall_contact.hpp"
#include "tests/dem/support/test_scene.hpp"
#include "tests/dem/walls/mesh_support.hpp"

namespace grainflow {
namespace {

Wall cylinder(const Vec3& axis_point, const Vec3& axis, double radius, bool inside) {
  Wall w;
  w.kind = Wall::Kind::cylinder;
  w.name = inside ? "drum" : "rod";
  w.cylinder.axis_point = axis_point;
  w.cylinder.axis = axis.normalized();
  w.cylinder.radius = radius;
  w.cylinder.inside = inside;
  return w;
}

// A floor, a tilted plane, a drum around the spheres and a rod through them.
Scene walled_scene() {
  Scene s = test::one_material_scene(1e7, 0.3, 2500, 0.5);
  s.walls.push_back(test::plane(Vec3(0, 0, -0.5), Vec3::UnitZ()));
  s.walls.push_back(test::plane(Vec3(0.3, 0, 0), Vec3(-1, 0.5, 0.2)));
  s.walls.push_back(cylinder(Vec3::Zero(), Vec3(0, 0.1, 1), 0.6, true));
  s.walls.push_back(cylinder(Vec3(-0.2, 0.1, 0), Vec3(1, 0, 0.3), 0.05, false));
  return s;
}

// Spheres inside the walled region (clear of every plane and cylinder), like a packing in a
// container.
Particles random_spheres(const WallSet& walls, int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.7, 0.7), ur(0.01, 0.03);
  Particles p;
  while (static_cast<int>(p.size()) < n) {
    const Vec3 x(u(rng), u(rng), u(rng));
    const double r = ur(rng);
    if (std::all_of(walls.walls().begin(), walls.walls().end(), [&](const WallSet::Entry& w) {
          return w.kind == Wall::Kind::mesh || wall_gap(w, x, r) >= 0;
        }))
      p.add(static_cast<GlobalId>(p.size()) + 1, x, Vec3::Zero(), Vec3::Zero(), r, 0, 2500);
  }
  return p;
}

bool touches(const WallSet::Entry& w, const Vec3& x, double r) {
  WallTouch t;
  return w.kind == Wall::Kind::plane ? touch_plane(w.plane, x, r, t)
                                     : touch_cylinder(w.cylinder, x, r, t);
}

TEST(WallNeighbours, NoContactIsMissedBeforeTheNextRebuild) {
  const WallSet walls(walled_scene());
  const double skin = 0.02;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Particles p = random_spheres(walls, 4000, seed);
    WallNeighbours lists;
    lists.build(p, walls, skin);
    ASSERT_EQ(lists.lists.size(), walls.walls().size());
    std::mt19937_64 rng(100 + seed);
    std::normal_distribution<double> g;
    std::uniform_real_distribution<double> length(0, 0.5 * skin);
    long touching = 0;
    for (int trial = 0; trial < 20; ++trial)
      for (std::size_t w = 0; w < walls.walls().size(); ++w) {
        const WallNeighbours::List& list = lists.lists[w];
        ASSERT_FALSE(list.all);
        EXPECT_TRUE(std::is_sorted(list.i.begin(), list.i.end()));
        // A list is the spheres within the skin of the wall, a small part of all of them.
        EXPECT_LT(list.i.size(), p.size() / 4);
        for (std::size_t i = 0; i < p.size(); ++i) {
          const Vec3 dir(g(rng), g(rng), g(rng));
          const Vec3 x = p.x[i] + length(rng) * dir.normalized();
          if (!touches(walls.walls()[w], x, p.radius[i])) continue;
          ++touching;
          EXPECT_TRUE(std::binary_search(list.i.begin(), list.i.end(), static_cast<int>(i)))
              << "sphere " << i << " touches wall " << w << " but is not listed";
        }
      }
    EXPECT_GT(touching, 100);  // the check is not empty
  }
}

TEST(WallNeighbours, MovingWallsAndMeshesListEveryParticle) {
  Scene s = walled_scene();
  s.walls[1].motion.velocity = Vec3(0, 0, 0.1);
  const WallSet walls(s);
  WallNeighbours lists;
  lists.build(random_spheres(walls, 100, 1), walls, 0.02);
  EXPECT_FALSE(lists.lists[0].all);
  EXPECT_TRUE(lists.lists[1].all);
  EXPECT_TRUE(lists.lists[1].i.empty());
}

// The wall springs follow the lists (Simulation's wall history): a listed wall's column has
// one spring per list entry, a moving wall's or a mesh's columns one per particle. Reference:
// the lists themselves and WallSet's column numbering (a mesh takes 2 kMeshSlots columns).
TEST(WallNeighbours, SpringColumnsFollowTheLists) {
  Scene s = walled_scene();
  s.walls[2].motion.angular_velocity = 1;  // the drum turns: every particle
  s.walls.insert(s.walls.begin() + 1, test::mesh_wall(test::write_mesh(
                                          test::box(Vec3::Constant(-0.9), Vec3::Constant(0.9)),
                                          "wall_neighbours_box.stl")));
  const WallSet walls(s);
  ASSERT_EQ(walls.history_columns(), 4 + 2 * WallSet::kMeshSlots);
  const Particles p = random_spheres(walls, 2000, 3);
  WallNeighbours lists;
  lists.build(p, walls, 0.02);
  std::size_t column = 0;
  for (std::size_t w = 0; w < walls.walls().size(); ++w) {
    const WallNeighbours::List& list = lists.lists[w];
    const bool every = w == 1 || w == 3;  // the mesh and the turning drum
    EXPECT_EQ(list.all, every) << "wall " << w;
    EXPECT_EQ(walls.walls()[w].column, static_cast<int>(column));
    for (std::size_t c = column; c < column + WallSet::columns_of(walls.walls()[w]); ++c) {
      EXPECT_EQ(&lists.list_of_column(c), &list) << "column " << c;
      ASSERT_EQ(lists.column_size(c, p.size()), every ? p.size() : list.i.size());
      if (!every) {
        EXPECT_GT(list.i.size(), 10u) << "wall " << w << " lists nothing to check";
      }
      for (std::size_t k = 0; k < lists.column_size(c, p.size()); ++k) {
        const std::size_t i = lists.particle_of(c, k);
        EXPECT_EQ(i, every ? k : static_cast<std::size_t>(list.i[k]));
        EXPECT_EQ(lists.entry_of(c, i), k);
      }
      for (std::size_t i = 0; i < p.size(); ++i)
        if (!every && !std::binary_search(list.i.begin(), list.i.end(), static_cast<int>(i))) {
          EXPECT_EQ(lists.entry_of(c, i), WallNeighbours::npos) << "sphere " << i;
        }
    }
    column += WallSet::columns_of(walls.walls()[w]);
  }
  EXPECT_EQ(column, walls.history_columns());
}

}  // namespace
}  // namespace grainflow
