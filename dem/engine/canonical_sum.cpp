#include "dem/engine/canonical_sum.hpp"

#include <algorithm>
#include <tuple>

namespace grainflow {

void CanonicalSum::build(const Particles& p, const Ghosts& g, const NeighbourList& local,
                         const NeighbourList& ghost) {
  const std::size_t n = p.size();
  const int local_entries = static_cast<int>(local.pairs());
  const int entries = local_entries + static_cast<int>(ghost.pairs());
  ghost_base = local_entries;
  // The ring: the t-th touching contact of a sweep is read, at the latest, when the chunk
  // of its partner ends; until then fewer touching contacts than list entries of the chunks
  // from the owner's to the partner's follow it.
  const auto chunk_start = [&](int i) { return i / kChunk * kChunk; };
  const auto chunk_end = [&](int i) { return std::min<int>(n, (i / kChunk + 1) * kChunk); };
  const auto before = [&](int i) { return (n > 0 ? local.offsets[i] + ghost.offsets[i] : 0); };
  int window = 1;
  for (int k = 0; k < local_entries; ++k)
    window = std::max(window, before(chunk_end(local.j[k])) - before(chunk_start(local.owner[k])));
  for (int a = 0; a < static_cast<int>(n); a += kChunk)
    window = std::max(window, before(chunk_end(a)) - before(a));
  int ring = 1;
  while (ring < window) ring *= 2;
  mask = ring - 1;
  none = ring;
  slot.assign(entries, none);
  shares.assign(static_cast<std::size_t>(ring) + 1,
                Share{Vec3::Zero(), {Vec3::Zero(), Vec3::Zero()}});
  // Each local entry is referenced by both its particles, each ghost entry by its local one.
  offsets_.assign(n + 1, 0);
  for (int k = 0; k < local_entries; ++k) {
    ++offsets_[local.owner[k] + 1];
    ++offsets_[local.j[k] + 1];
  }
  for (std::size_t k = 0; k < ghost.pairs(); ++k) ++offsets_[ghost.owner[k] + 1];
  for (std::size_t i = 0; i < n; ++i) offsets_[i + 1] += offsets_[i];
  // The sort key of a reference: the partner's id and image shift (a partner could appear
  // twice only through two images, in a box shorter than twice the interaction range, which
  // Simulation refuses; the shift keeps even that order canonical).
  struct Keyed {
    GlobalId partner;
    double sx, sy, sz;
    int ref;
  };
  std::vector<Keyed> keyed(offsets_[n]);
  std::vector<int> fill(offsets_.begin(), offsets_.end() - 1);
  for (int k = 0; k < local_entries; ++k) {
    const int i = local.owner[k], j = local.j[k];
    const int side_i = p.id[i] < p.id[j] ? 0 : 1;
    keyed[fill[i]++] = {p.id[j], 0, 0, 0, 2 * k + side_i};
    keyed[fill[j]++] = {p.id[i], 0, 0, 0, 2 * k + (1 - side_i)};
  }
  for (std::size_t k = 0; k < ghost.pairs(); ++k) {
    const int i = ghost.owner[k], q = ghost.j[k];
    const Vec3& s = g.shift[q];
    const int e = local_entries + static_cast<int>(k);
    keyed[fill[i]++] = {g.id[q], s[0], s[1], s[2], 2 * e + (p.id[i] < g.id[q] ? 0 : 1)};
  }
  const auto by_key = [](const Keyed& a, const Keyed& b) {
    return std::tie(a.partner, a.sx, a.sy, a.sz) < std::tie(b.partner, b.sx, b.sy, b.sz);
  };
  refs_.resize(keyed.size());
  for (std::size_t i = 0; i < n; ++i) {
    std::sort(keyed.begin() + offsets_[i], keyed.begin() + offsets_[i + 1], by_key);
    for (int r = offsets_[i]; r < offsets_[i + 1]; ++r) refs_[r] = keyed[r].ref;
  }
}

void CanonicalSum::add_to(Particles& p, bool spin, int a, int b) const {
  const int* offsets = offsets_.data();
  const int* refs = refs_.data();
  const int* slots = slot.data();
  const Share* s = shares.data();
  Vec3* force = p.force.data();
  Vec3* torque = p.torque.data();
  // An entry that does not touch adds the zero share: x + 0 = x exactly (and a sum that
  // starts from a non-negative-zero value never becomes -0), so it changes no bit.
  const auto pass = [&]<bool Spin>() {
    for (int i = a; i < b; ++i) {
      Vec3 f = force[i], t = torque[i];
      for (int r = offsets[i]; r < offsets[i + 1]; ++r) {
        const int side = refs[r] & 1;
        const Share& c = s[slots[refs[r] >> 1]];
        f += static_cast<double>(1 - 2 * side) * c.force;  // -F exactly on side 1
        if constexpr (Spin) t += c.torque[side];
      }
      force[i] = f;
      if constexpr (Spin) torque[i] = t;
    }
  };
  spin ? pass.template operator()<true>() : pass.template operator()<false>();
}

}  // namespace grainflow
