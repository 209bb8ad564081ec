#include "dem/neighbour/carried_springs.hpp"

#include <algorithm>
#include <numeric>

namespace grainflow {
namespace {

bool operator<(const CarriedSprings::PairKey& a, const CarriedSprings::PairKey& b) {
  return a.lo < b.lo || (a.lo == b.lo && a.hi < b.hi);
}
bool operator<(const CarriedSprings::WallKey& a, const CarriedSprings::WallKey& b) {
  return a.particle < b.particle || (a.particle == b.particle && a.column < b.column);
}

template <class T>
void keep_unflagged(std::vector<T>& a, const std::vector<char>& drop) {
  if (a.empty()) return;
  std::size_t w = 0;
  for (std::size_t r = 0; r < a.size(); ++r)
    if (!drop[r]) a[w++] = a[r];
  a.resize(w);
}

template <class Key>
void sort_index(const std::vector<Key>& keys, std::vector<std::uint32_t>& order) {
  order.resize(keys.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&keys](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
}

template <class T>
void release(std::vector<T>& a) {
  std::vector<T>().swap(a);
}

}  // namespace

void CarriedSprings::reserve(std::size_t pairs, std::size_t walls) {
  pair_key_.reserve(pairs);
  if (tangential_) tangential_values_.reserve(pairs);
  if (rolling_) rolling_values_.reserve(pairs);
  wall_key_.reserve(walls);
  wall_values_.reserve(walls);
}

void CarriedSprings::add_pair(GlobalId a, GlobalId b, const Vec3& tangential, const Vec3& rolling) {
  pair_key_.push_back(a < b ? PairKey{a, b} : PairKey{b, a});
  if (tangential_) tangential_values_.push_back(tangential);
  if (rolling_) rolling_values_.push_back(rolling);
  pair_order_.clear();
}

void CarriedSprings::add_wall(GlobalId particle, int column, const ContactHistory& h) {
  wall_key_.push_back({particle, column});
  wall_values_.push_back(h);
  wall_order_.clear();
}

void CarriedSprings::drop_pairs(const std::vector<char>& drop) {
  keep_unflagged(pair_key_, drop);
  keep_unflagged(tangential_values_, drop);
  keep_unflagged(rolling_values_, drop);
  pair_order_.clear();
}

void CarriedSprings::drop_walls(const std::vector<char>& drop) {
  keep_unflagged(wall_key_, drop);
  keep_unflagged(wall_values_, drop);
  wall_order_.clear();
}

void CarriedSprings::index() {
  sort_index(pair_key_, pair_order_);
  sort_index(wall_key_, wall_order_);
}

std::pair<std::size_t, std::size_t> CarriedSprings::pairs_from(GlobalId lo) const {
  const auto first = std::partition_point(pair_order_.begin(), pair_order_.end(),
                                          [&](std::uint32_t r) { return pair_key_[r].lo < lo; });
  const auto last = std::partition_point(first, pair_order_.end(),
                                         [&](std::uint32_t r) { return pair_key_[r].lo == lo; });
  return {static_cast<std::size_t>(first - pair_order_.begin()),
          static_cast<std::size_t>(last - pair_order_.begin())};
}

std::size_t CarriedSprings::find_pair(GlobalId a, GlobalId b) const {
  const PairKey key = a < b ? PairKey{a, b} : PairKey{b, a};
  const auto it = std::partition_point(pair_order_.begin(), pair_order_.end(),
                                       [&](std::uint32_t r) { return pair_key_[r] < key; });
  if (it == pair_order_.end() || pair_key_[*it].lo != key.lo || pair_key_[*it].hi != key.hi)
    return npos;
  return *it;
}

std::pair<std::size_t, std::size_t> CarriedSprings::walls_of(GlobalId particle) const {
  const auto first =
      std::partition_point(wall_order_.begin(), wall_order_.end(),
                           [&](std::uint32_t r) { return wall_key_[r].particle < particle; });
  const auto last = std::partition_point(
      first, wall_order_.end(), [&](std::uint32_t r) { return wall_key_[r].particle == particle; });
  return {static_cast<std::size_t>(first - wall_order_.begin()),
          static_cast<std::size_t>(last - wall_order_.begin())};
}

void CarriedSprings::clear() {
  release(pair_key_);
  release(tangential_values_);
  release(rolling_values_);
  release(wall_key_);
  release(wall_values_);
  release(pair_order_);
  release(wall_order_);
}

}  // namespace grainflow
