// CarriedSprings: the springs a neighbour rebuild carries by global ids. Checked against a
// plain map of the same records (the reference): every pair is found from either partner's
// side and every wall spring by particle and column, absent ones are not, the kinds the law
// does not keep read as zero, and dropping records keeps the others in order.
#include "dem/neighbour/carried_springs.hpp"

#include <gtest/gtest.h>

#include <map>
#include <random>

namespace grainflow {
namespace {

Vec3 value(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1e-5, 1e-5);
  return Vec3(u(rng), u(rng), u(rng));
}

TEST(CarriedSprings, FindsEveryPairFromEitherSide) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<GlobalId> id(1, 400);
  CarriedSprings c(true, true);
  std::map<std::pair<GlobalId, GlobalId>, ContactHistory> reference;
  while (reference.size() < 2000) {
    const GlobalId a = id(rng), b = id(rng);
    if (a == b || reference.count({std::min(a, b), std::max(a, b)})) continue;
    const ContactHistory h{value(rng), value(rng)};
    reference[{std::min(a, b), std::max(a, b)}] = h;
    c.add_pair(a, b, h.tangential, h.rolling);  // either orientation
  }
  c.index();
  ASSERT_EQ(c.pairs(), reference.size());
  for (const auto& [key, h] : reference) {
    for (const auto& [a, b] : {key, std::pair{key.second, key.first}}) {
      const std::size_t r = c.find_pair(a, b);
      ASSERT_NE(r, CarriedSprings::npos) << a << "-" << b;
      EXPECT_EQ(c.pair_key(r).lo, key.first);
      EXPECT_EQ(c.pair_key(r).hi, key.second);
      EXPECT_EQ(c.pair(r).tangential, h.tangential);  // exact: stored, not computed
      EXPECT_EQ(c.pair(r).rolling, h.rolling);
    }
  }
  int absent = 0;
  for (GlobalId a = 1; a <= 400; ++a)
    for (GlobalId b = a + 1; b <= 400; b += 7)
      if (!reference.count({a, b})) {
        EXPECT_EQ(c.find_pair(a, b), CarriedSprings::npos);
        EXPECT_EQ(c.find_pair(b, a), CarriedSprings::npos);
        ++absent;
      }
  EXPECT_GT(absent, 1000);
}

TEST(CarriedSprings, StoresOnlyTheKindsKept) {
  CarriedSprings t(true, false), r(false, true);
  t.add_pair(3, 2, Vec3(1, 2, 3), Vec3(4, 5, 6));
  r.add_pair(3, 2, Vec3(1, 2, 3), Vec3(4, 5, 6));
  t.index();
  r.index();
  EXPECT_EQ(t.pair(t.find_pair(2, 3)).tangential, Vec3(1, 2, 3));
  EXPECT_EQ(t.pair(t.find_pair(2, 3)).rolling, Vec3::Zero());
  EXPECT_EQ(r.pair(r.find_pair(2, 3)).tangential, Vec3::Zero());
  EXPECT_EQ(r.pair(r.find_pair(2, 3)).rolling, Vec3(4, 5, 6));
}

TEST(CarriedSprings, FindsWallSpringsByParticleAndColumn) {
  std::mt19937_64 rng(9);
  CarriedSprings c(true, false);
  std::map<std::pair<GlobalId, int>, ContactHistory> reference;
  std::uniform_int_distribution<GlobalId> id(10, 300);
  std::uniform_int_distribution<int> column(0, 7);
  while (reference.size() < 500) {
    const GlobalId p = id(rng);
    const int col = column(rng);
    if (reference.count({p, col})) continue;
    const ContactHistory h{value(rng), value(rng)};
    reference[{p, col}] = h;
    c.add_wall(p, col, h);
  }
  c.index();
  int found = 0;
  for (GlobalId p = 0; p <= 310; ++p)
    for (int col = 0; col <= 8; ++col) {
      const std::size_t r = c.find_wall(p, col);
      const auto it = reference.find({p, col});
      if (it == reference.end()) {
        EXPECT_EQ(r, CarriedSprings::npos) << p << " " << col;
        continue;
      }
      ASSERT_NE(r, CarriedSprings::npos) << p << " " << col;
      EXPECT_EQ(c.wall_key(r).particle, p);
      EXPECT_EQ(c.wall_key(r).column, col);
      EXPECT_EQ(c.wall(r).tangential, it->second.tangential);
      EXPECT_EQ(c.wall(r).rolling, it->second.rolling);
      ++found;
    }
  EXPECT_EQ(found, 500);
}

// Both owners' copies of a pair can meet on one rank (a partner migrated): either is found.
TEST(CarriedSprings, ACopyOfTheSamePairIsFound) {
  CarriedSprings c(true, false);
  c.add_pair(7, 3, Vec3(1, 2, 3), Vec3::Zero());
  c.add_pair(1, 2, Vec3(4, 5, 6), Vec3::Zero());
  c.add_pair(3, 7, Vec3(1, 2, 3), Vec3::Zero());
  c.index();
  const std::size_t r = c.find_pair(7, 3);
  ASSERT_TRUE(r == 0 || r == 2);
  EXPECT_EQ(c.pair(r).tangential, Vec3(1, 2, 3));
  EXPECT_EQ(c.find_pair(7, 2), CarriedSprings::npos);
  // A record added after index() clears the table: index() again finds it.
  c.add_pair(8, 9, Vec3(7, 8, 9), Vec3::Zero());
  EXPECT_EQ(c.find_pair(8, 9), CarriedSprings::npos);
  c.index();
  EXPECT_EQ(c.find_pair(9, 8), 3u);
}

TEST(CarriedSprings, DroppingKeepsTheOthersInOrder) {
  CarriedSprings c(true, false);
  for (GlobalId k = 1; k <= 10; ++k) {
    c.add_pair(k, k + 100, Vec3(k, 0, 0), Vec3::Zero());
    c.add_wall(k, 0, {Vec3(0, k, 0), Vec3::Zero()});
  }
  std::vector<char> drop(10, 0);
  drop[0] = drop[4] = drop[9] = 1;
  c.drop_pairs(drop);
  c.drop_walls(drop);
  ASSERT_EQ(c.pairs(), 7u);
  ASSERT_EQ(c.walls(), 7u);
  const std::vector<GlobalId> kept = {2, 3, 4, 6, 7, 8, 9};
  for (std::size_t r = 0; r < kept.size(); ++r) {
    EXPECT_EQ(c.pair_key(r).lo, kept[r]);
    EXPECT_EQ(c.pair(r).tangential.x(), static_cast<double>(kept[r]));
    EXPECT_EQ(c.wall_key(r).particle, kept[r]);
    EXPECT_EQ(c.wall(r).tangential.y(), static_cast<double>(kept[r]));
  }
  c.index();
  EXPECT_EQ(c.find_pair(105, 5), CarriedSprings::npos);
  EXPECT_NE(c.find_pair(106, 6), CarriedSprings::npos);
  c.clear();
  EXPECT_EQ(c.pairs(), 0u);
  EXPECT_EQ(c.walls(), 0u);
}

}  // namespace
}  // namespace grainflow
