#include "dem/neighbour/verlet_list.hpp"

#include <algorithm>
#include <cmath>

namespace grainflow {

Box::Box(const Domain& d)
    : lo(d.lo), hi(d.hi), length(d.hi - d.lo), periodic(d.periodic), any_periodic(false) {
  for (int a = 0; a < 3; ++a) {
    inv_length_periodic[a] = periodic[a] ? 1.0 / length[a] : 0.0;
    any_periodic = any_periodic || periodic[a];
  }
}

BinGrid::BinGrid(const Vec3& lo, const Vec3& hi, double bin_edge)
    : lo_(lo), hi_(hi), min_edge_(bin_edge) {
  resize_for(0);
}

void BinGrid::resize_for(std::size_t particles) {
  // Bins no smaller than the interaction range, and no more bins than ~2 per
  // particle: a large, sparsely filled domain must not cost memory per empty bin.
  const double limit = std::max(1000.0, 2.0 * static_cast<double>(particles));
  const Vec3 length = hi_ - lo_;
  double n[3];
  for (int a = 0; a < 3; ++a) n[a] = std::max(1.0, std::floor(length[a] / min_edge_));
  const double total = n[0] * n[1] * n[2];
  if (total > limit) {
    const double f = std::cbrt(total / limit);
    for (int a = 0; a < 3; ++a) n[a] = std::max(1.0, std::floor(n[a] / f));
  }
  for (int a = 0; a < 3; ++a) {
    n_[a] = static_cast<int>(n[a]);
    inv_edge_[a] = n_[a] / length[a];
  }
}

int BinGrid::bin_of(const Vec3& x) const {
  int c[3];
  for (int a = 0; a < 3; ++a) {
    const int k = static_cast<int>(std::floor((x[a] - lo_[a]) * inv_edge_[a]));
    c[a] = std::clamp(k, 0, n_[a] - 1);
  }
  return (c[2] * n_[1] + c[1]) * n_[0] + c[0];
}

std::vector<std::size_t> BinGrid::sort_permutation(const Particles& p) {
  resize_for(p.size());
  const int nbins = n_[0] * n_[1] * n_[2];
  std::vector<int> bin(p.size());
  bin_start_.assign(nbins + 1, 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    bin[i] = bin_of(p.x[i]);
    ++bin_start_[bin[i] + 1];
  }
  for (int b = 0; b < nbins; ++b) bin_start_[b + 1] += bin_start_[b];
  std::vector<int> fill(bin_start_.begin(), bin_start_.end() - 1);
  std::vector<std::size_t> perm(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) perm[fill[bin[i]]++] = i;
  // Within a bin, order by global id: the order (and so the order in which each
  // particle's contact forces are summed) then depends on positions and ids only,
  // not on the order particles arrived in — a restart or another rank count
  // rebuilds the same lists.
  for (int b = 0; b < nbins; ++b)
    if (bin_start_[b + 1] - bin_start_[b] > 1)
      std::sort(perm.begin() + bin_start_[b], perm.begin() + bin_start_[b + 1],
                [&p](std::size_t a, std::size_t c) { return p.id[a] < p.id[c]; });
  return perm;
}

void BinGrid::build(const Particles& p, const Ghosts& g, double skin, NeighbourList& local,
                    NeighbourList& ghost) const {
  const std::size_t n = p.size();
  const int nbins = n_[0] * n_[1] * n_[2];
  // Ghosts by bin (CSR), in their exchange order within a bin.
  std::vector<int> gstart(nbins + 1, 0), gbin(g.size()), gsorted(g.size());
  for (std::size_t k = 0; k < g.size(); ++k) {
    gbin[k] = bin_of(g.position(k));
    ++gstart[gbin[k] + 1];
  }
  for (int b = 0; b < nbins; ++b) gstart[b + 1] += gstart[b];
  {
    std::vector<int> fill(gstart.begin(), gstart.end() - 1);
    for (std::size_t k = 0; k < g.size(); ++k) gsorted[fill[gbin[k]]++] = static_cast<int>(k);
  }
  local.offsets.assign(n + 1, 0);
  local.j.clear();
  ghost.offsets.assign(n + 1, 0);
  ghost.j.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const int b = bin_of(p.x[i]);
    const int c[3] = {b % n_[0], (b / n_[0]) % n_[1], b / (n_[0] * n_[1])};
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, c[a] - 1);
      hi[a] = std::min(n_[a] - 1, c[a] + 1);
    }
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const int nb = (z * n_[1] + y) * n_[0] + x;
          for (int j = std::max(bin_start_[nb], static_cast<int>(i) + 1); j < bin_start_[nb + 1];
               ++j) {
            const double cut = p.radius[i] + p.radius[j] + skin;
            if ((p.x[i] - p.x[j]).squaredNorm() < cut * cut) local.j.push_back(j);
          }
          for (int s = gstart[nb]; s < gstart[nb + 1]; ++s) {
            const int k = gsorted[s];
            const double cut = p.radius[i] + g.radius[k] + skin;
            if ((p.x[i] - g.position(k)).squaredNorm() < cut * cut) ghost.j.push_back(k);
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
