#include "dem/neighbour/carried_springs.hpp"

namespace grainflow {
namespace {

bool operator==(const CarriedSprings::PairKey& a, const CarriedSprings::PairKey& b) {
  return a.lo == b.lo && a.hi == b.hi;
}
bool operator==(const CarriedSprings::WallKey& a, const CarriedSprings::WallKey& b) {
  return a.particle == b.particle && a.column == b.column;
}

// A 64-bit mix of the key (the finaliser of splitmix64): consecutive ids spread evenly.
std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
std::uint64_t hash(const CarriedSprings::PairKey& k) {
  return mix(static_cast<std::uint64_t>(k.lo) * 0x9e3779b97f4a7c15ULL +
             static_cast<std::uint64_t>(k.hi));
}
std::uint64_t hash(const CarriedSprings::WallKey& k) {
  return mix(static_cast<std::uint64_t>(k.particle) * 0x9e3779b97f4a7c15ULL +
             static_cast<std::uint64_t>(k.column));
}
// The first slot of a key's probe sequence in a table of n slots (n < 2^32).
std::size_t home(std::uint64_t h, std::size_t n) { return ((h >> 32) * n) >> 32; }

template <class Key>
void build_table(const std::vector<Key>& keys, std::vector<std::uint32_t>& slots) {
  slots.assign(keys.empty() ? 0 : keys.size() + keys.size() / 2 + 1, 0);
  for (std::size_t r = 0; r < keys.size(); ++r) {
    std::size_t s = home(hash(keys[r]), slots.size());
    while (slots[s] != 0)
      if (++s == slots.size()) s = 0;
    slots[s] = static_cast<std::uint32_t>(r + 1);
  }
}

template <class Key>
std::size_t look_up(const std::vector<Key>& keys, const std::vector<std::uint32_t>& slots,
                    const Key& key) {
  if (slots.empty()) return CarriedSprings::npos;
  for (std::size_t s = home(hash(key), slots.size());;) {
    const std::uint32_t r = slots[s];
    if (r == 0) return CarriedSprings::npos;
    if (keys[r - 1] == key) return r - 1;
    if (++s == slots.size()) s = 0;
  }
}

template <class T>
void keep_unflagged(std::vector<T>& a, const std::vector<char>& drop) {
  if (a.empty()) return;
  std::size_t w = 0;
  for (std::size_t r = 0; r < a.size(); ++r)
    if (!drop[r]) a[w++] = a[r];
  a.resize(w);
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
  if (!pair_slots_.empty()) release(pair_slots_);
}

void CarriedSprings::add_wall(GlobalId particle, int column, const ContactHistory& h) {
  wall_key_.push_back({particle, column});
  wall_values_.push_back(h);
  if (!wall_slots_.empty()) release(wall_slots_);
}

void CarriedSprings::drop_pairs(const std::vector<char>& drop) {
  keep_unflagged(pair_key_, drop);
  keep_unflagged(tangential_values_, drop);
  keep_unflagged(rolling_values_, drop);
  release(pair_slots_);
}

void CarriedSprings::drop_walls(const std::vector<char>& drop) {
  keep_unflagged(wall_key_, drop);
  keep_unflagged(wall_values_, drop);
  release(wall_slots_);
}

void CarriedSprings::index() {
  build_table(pair_key_, pair_slots_);
  build_table(wall_key_, wall_slots_);
}

std::size_t CarriedSprings::find_pair(GlobalId a, GlobalId b) const {
  return look_up(pair_key_, pair_slots_, a < b ? PairKey{a, b} : PairKey{b, a});
}

std::size_t CarriedSprings::find_wall(GlobalId particle, int column) const {
  return look_up(wall_key_, wall_slots_, WallKey{particle, column});
}

void CarriedSprings::clear() {
  release(pair_key_);
  release(tangential_values_);
  release(rolling_values_);
  release(wall_key_);
  release(wall_values_);
  release(pair_slots_);
  release(wall_slots_);
}

}  // namespace grainflow
