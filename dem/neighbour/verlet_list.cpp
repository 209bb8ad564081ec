#include "dem/neighbour/verlet_list.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace grainflow {

Box::Box(const Domain& d)
    : lo(d.lo), hi(d.hi), length(d.hi - d.lo), periodic(d.periodic), any_periodic(false) {
  for (int a = 0; a < 3; ++a) {
    inv_length_periodic[a] = periodic[a] ? 1.0 / length[a] : 0.0;
    any_periodic = any_periodic || periodic[a];
  }
}

namespace {

// Stable LSD radix sort of `order` (indices into `key`) by key[order[k]] - base, all of
// which are below 2^bits: a few passes over the particles, whatever the keys' range.
void radix_sort(std::vector<int>& order, const std::vector<std::uint64_t>& key, std::uint64_t base,
                int bits, std::vector<int>& tmp) {
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  tmp.resize(order.size());
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::array<int, kBuckets + 1> start{};
    for (int k : order) ++start[((key[k] - base) >> shift & (kBuckets - 1)) + 1];
    for (std::size_t b = 0; b < kBuckets; ++b) start[b + 1] += start[b];
    for (int k : order) tmp[start[(key[k] - base) >> shift & (kBuckets - 1)]++] = k;
    order.swap(tmp);
  }
}

// Sorts 0 .. key.size()-1 by key into `order`.
void sort_by_key(const std::vector<std::uint64_t>& key, std::vector<int>& order,
                 std::vector<int>& tmp) {
  order.resize(key.size());
  if (key.empty()) return;
  std::uint64_t lo = key[0], hi = key[0];
  for (std::size_t k = 0; k < key.size(); ++k) {
    order[k] = static_cast<int>(k);
    lo = std::min(lo, key[k]);
    hi = std::max(hi, key[k]);
  }
  radix_sort(order, key, lo, static_cast<int>(std::bit_width(hi - lo)), tmp);
}

}  // namespace

BinGrid::BinGrid(const Vec3& lo, const Vec3& hi, double bin_edge) : lo_(lo), hi_(hi) {
  // Bins no smaller than the interaction range. No bin is stored for empty space, so the
  // lattice may be as fine as that over any domain.
  constexpr double kMaxPerAxis = 1 << 20;
  const Vec3 length = hi_ - lo_;
  for (int a = 0; a < 3; ++a) {
    n_[a] = static_cast<int>(std::clamp(std::floor(length[a] / bin_edge), 1.0, kMaxPerAxis));
    inv_edge_[a] = n_[a] / length[a];
  }
  choose_axes();
}

void BinGrid::choose_axes() {
  // The key's slowest axis is z, the usual height of a bed, unless x or y has more than
  // twice its bins: then that axis (the one with more bins). Particles next to each other
  // along the slowest axis are one layer of the two others apart in memory, so the layer
  // should be small: in a wide, flat bed (10^6 spheres, 147 x 147 x 30 bins) the z-major
  // order put a particle 21 600 bins (about 5 MB of particle data) from its partners above
  // it, beyond the L2 cache; the x-major order, 4 400 bins. Another order sums each
  // particle's forces in another order (rounding), so it is taken only where the layer
  // shrinks at least twofold: nearly cubic lattices and columns keep the z-major order.
  int slow = 2;
  for (int a = 1; a >= 0; --a)
    if (n_[a] > 2 * n_[2] && n_[a] > n_[slow]) slow = a;
  int k = 0;
  for (int a = 0; a < 3; ++a)
    if (a != slow) axis_[k++] = a;
  axis_[2] = slow;
}

BinGrid BinGrid::anchored(const Vec3& lo, const Vec3& hi, double bin_edge) {
  constexpr double kMaxPerAxis = (1 << 20) - 2;
  BinGrid grid(lo, hi, bin_edge);
  const Vec3 length = hi - lo;
  for (int a = 0; a < 3; ++a) {
    const double bins = std::clamp(std::floor(length[a] / bin_edge), 1.0, kMaxPerAxis);
    const double edge = length[a] / bins;
    grid.lo_[a] = lo[a] - edge;
    grid.hi_[a] = hi[a] + edge;
    grid.n_[a] = static_cast<int>(bins) + 2;
    grid.inv_edge_[a] = bins / length[a];
  }
  grid.choose_axes();
  return grid;
}

std::uint64_t BinGrid::key_of(const Vec3& x) const {
  std::uint64_t c[3];
  for (int a = 0; a < 3; ++a) {
    const double k = std::floor((x[a] - lo_[a]) * inv_edge_[a]);
    c[a] = static_cast<std::uint64_t>(std::clamp(k, 0.0, n_[a] - 1.0));
  }
  const int f = axis_[0], m = axis_[1], s = axis_[2];
  return (c[s] * static_cast<std::uint64_t>(n_[m]) + c[m]) * static_cast<std::uint64_t>(n_[f]) +
         c[f];
}

std::vector<std::size_t> BinGrid::sort_permutation(const Particles& p) {
  const std::size_t n = p.size();
  key_.resize(n);
  for (std::size_t i = 0; i < n; ++i) key_[i] = key_of(p.x[i]);
  sort_by_key(key_, order_, order_tmp_);
  // Within a bin, order by global id: the order (and so the order in which each
  // particle's contact forces are summed) then depends on positions and ids only,
  // not on the order particles arrived in — a restart or another rank count
  // rebuilds the same lists.
  for (std::size_t s = 0; s < n;) {
    std::size_t e = s + 1;
    while (e < n && key_[order_[e]] == key_[order_[s]]) ++e;
    if (e - s > 1)
      std::sort(order_.begin() + static_cast<std::ptrdiff_t>(s),
                order_.begin() + static_cast<std::ptrdiff_t>(e),
                [&p](int a, int c) { return p.id[a] < p.id[c]; });
    s = e;
  }
  return std::vector<std::size_t>(order_.begin(), order_.end());
}

void BinGrid::build(const Particles& p, const Ghosts& g, double skin, NeighbourList& local,
                    NeighbourList& ghost) {
  const std::size_t n = p.size(), ng = g.size();
  key_.resize(n);
  for (std::size_t i = 0; i < n; ++i) key_[i] = key_of(p.x[i]);  // sorted: see above
  // Ghosts by key, in their exchange order within a bin (the sort is stable).
  key_tmp_.resize(ng);
  for (std::size_t k = 0; k < ng; ++k) key_tmp_[k] = key_of(g.position(k));
  sort_by_key(key_tmp_, ghost_order_, order_tmp_);
  ghost_key_.resize(ng);
  for (std::size_t s = 0; s < ng; ++s) ghost_key_[s] = key_tmp_[ghost_order_[s]];

  local.offsets.assign(n + 1, 0);
  local.j.clear();
  ghost.offsets.assign(n + 1, 0);
  ghost.j.clear();
  // Along the key's axes (axis_: fastest first), named x, y, z below for the usual order.
  const std::uint64_t nx = n_[axis_[0]], ny = n_[axis_[1]], nz = n_[axis_[2]];
  // For each of the nine rows (dz, dy) of the 27 bins, the range of sorted locals and of
  // sorted ghosts in the row's three bins. The particles come in key order, so each
  // range's ends only move forward: all rows of all particles cost O(N + ghosts).
  std::array<std::size_t, 9> lb{}, le{}, gb{}, ge{};
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t k = key_[i];
    const std::uint64_t cx = k % nx, cy = k / nx % ny, cz = k / (nx * ny);
    const std::uint64_t x0 = cx > 0 ? cx - 1 : 0, x1 = std::min(cx + 1, nx - 1);
    // Rows (z, y) = (cz + dz - 1, cy + dy - 1) in the lattice, z then y ascending.
    for (std::uint64_t dz = 0; dz < 3; ++dz) {
      if (cz + dz < 1 || cz + dz - 1 >= nz) continue;
      for (std::uint64_t dy = 0; dy < 3; ++dy) {
        if (cy + dy < 1 || cy + dy - 1 >= ny) continue;
        const std::uint64_t row = ((cz + dz - 1) * ny + cy + dy - 1) * nx;
        const std::uint64_t first = row + x0, last = row + x1;
        const std::size_t r = 3 * dz + dy;
        std::size_t& b = lb[r];
        std::size_t& e = le[r];
        while (b < n && key_[b] < first) ++b;
        e = std::max(e, b);
        while (e < n && key_[e] <= last) ++e;
        for (std::size_t j = std::max(b, i + 1); j < e; ++j) {
          const double cut = p.radius[i] + p.radius[j] + skin;
          if ((p.x[i] - p.x[j]).squaredNorm() < cut * cut) local.j.push_back(static_cast<int>(j));
        }
        std::size_t& c = gb[r];
        std::size_t& f = ge[r];
        while (c < ng && ghost_key_[c] < first) ++c;
        f = std::max(f, c);
        while (f < ng && ghost_key_[f] <= last) ++f;
        for (std::size_t s = c; s < f; ++s) {
          const int q = ghost_order_[s];
          const double cut = p.radius[i] + g.radius[q] + skin;
          if ((p.x[i] - g.position(q)).squaredNorm() < cut * cut) ghost.j.push_back(q);
        }
      }
    }
    local.offsets[i + 1] = static_cast<int>(local.j.size());
    ghost.offsets[i + 1] = static_cast<int>(ghost.j.size());
  }
  for (NeighbourList* list : {&local, &ghost}) {
    list->owner.resize(list->j.size());
    list->owner.shrink_to_fit();
    for (std::size_t i = 0; i < n; ++i)
      for (int k = list->offsets[i]; k < list->offsets[i + 1]; ++k)
        list->owner[k] = static_cast<int>(i);
  }
}

std::size_t BinGrid::memory_bytes() const {
  return (key_.capacity() + key_tmp_.capacity() + ghost_key_.capacity()) * sizeof(std::uint64_t) +
         (order_.capacity() + order_tmp_.capacity() + ghost_order_.capacity()) * sizeof(int);
}

std::vector<std::pair<GlobalId, GlobalId>> brute_force_pairs(const Particles& p, const Box& box,
                                                              double skin) {
  std::vector<std::pair<GlobalId, GlobalId>> pairs;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double cut = p.radius[i] + p.radius[j] + skin;
      if (box.min_image(p.x[i] - p.x[j]).squaredNorm() < cut * cut)
        pairs.emplace_back(std::min(p.id[i], p.id[j]), std::max(p.id[i], p.id[j]));
    }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace grainflow
