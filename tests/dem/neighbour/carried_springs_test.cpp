// CarriedSprings: the springs a neighbour rebuild carries by global ids. Checked against a
// plain map of the same records (the reference): every pair is found from either partner's
// side, absent pairs are not, the kinds the law does not keep read as zero, ranges by lower id
// and by particle hold exactly that id's records, and dropping records keeps the others.
#include "dem/neighbour/carried_springs.hpp"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

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
  // The records of each lower id, as a range of the index, are exactly the reference's.
  for (GlobalId lo = 0; lo <= 401; ++lo) {
    std::set<GlobalId> expected, got;
    for (const auto& [key, h] : reference)
      if (key.first == lo) expected.insert(key.second);
    const auto [first, last] = c.pairs_from(lo);
    for (std::size_t pos = first; pos < last; ++pos) {
      EXPECT_EQ(c.pair_key(c.pair_at(pos)).lo, lo);
      got.insert(c.pair_key(c.pair_at(pos)).hi);
    }
    EXPECT_EQ(got, expected) << "lower id " << lo;
    EXPECT_EQ(last - first, expected.size());
  }
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

TEST(CarriedSprings, WallSpringsByParticleInColumnOrder) {
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
  for (GlobalId p = 0; p <= 310; ++p) {
    std::vector<int> expected, got;
    for (const auto& [key, h] : reference)
      if (key.first == p) expected.push_back(key.second);  // ascending: map order
    const auto [first, last] = c.walls_of(p);
    for (std::size_t pos = first; pos < last; ++pos) {
      const std::size_t r = c.wall_at(pos);
      EXPECT_EQ(c.wall_key(r).particle, p);
      got.push_back(c.wall_key(r).column);
      EXPECT_EQ(c.wall(r).tangential, reference.at({p, c.wall_key(r).column}).tangential);
      EXPECT_EQ(c.wall(r).rolling, reference.at({p, c.wall_key(r).column}).rolling);
    }
    EXPECT_EQ(got, expected) << "particle " << p;
  }
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
