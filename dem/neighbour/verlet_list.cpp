#include "dem/neighbour/verlet_list.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace grainflow {

Box::Box(const Domain& d)
    : lo(d.lo), hi(d.hi), length(d.hi - d.lo), periodic(d.periodic), any_periodic(false) {
  for (int a = 0; a < 3; ++a) {
    inv_length_periodic[a] = periodic[a] ? 1.0 / length[a] : 0.0;
    any_periodic = any_periodic || periodic[a];
  }
}

BinGrid::BinGrid(const Box& box, double bin_edge) : box_(box), min_edge_(bin_edge) {
  resize_for(0);
  for (int a = 0; a < 3; ++a) {
    if (box.periodic[a] && box.length[a] < 2 * bin_edge)
      throw std::invalid_argument(
          "periodic axis " + std::string(1, "xyz"[a]) + " is " + std::to_string(box.length[a]) +
          " m long, shorter than twice the interaction range (2 r_max + skin = " +
          std::to_string(bin_edge) + " m); enlarge the domain along it or reduce the skin");
  }
}

void BinGrid::resize_for(std::size_t particles) {
  // Bins no smaller than the interaction range, and no more bins than ~2 per
  // particle: a large, sparsely filled domain must not cost memory per empty bin.
  const double limit = std::max(1000.0, 2.0 * static_cast<double>(particles));
  double n[3];
  for (int a = 0; a < 3; ++a) n[a] = std::max(1.0, std::floor(box_.length[a] / min_edge_));
  const double total = n[0] * n[1] * n[2];
  if (total > limit) {
    const double f = std::cbrt(total / limit);
    for (int a = 0; a < 3; ++a) n[a] = std::max(1.0, std::floor(n[a] / f));
  }
  for (int a = 0; a < 3; ++a) {
    n_[a] = static_cast<int>(n[a]);
    inv_edge_[a] = n_[a] / box_.length[a];
  }
}

int BinGrid::bin_of(const Vec3& x) const {
  int c[3];
  for (int a = 0; a < 3; ++a) {
    int k = static_cast<int>(std::floor((x[a] - box_.lo[a]) * inv_edge_[a]));
    c[a] = std::clamp(k, 0, n_[a] - 1);  // particles leaving are removed by the caller
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
  return perm;
}

namespace {
// Bin indices to visit along one axis around bin c, each once.
int axis_stencil(int c, int n, bool periodic, int out[3]) {
  if (n < 3) {
    for (int k = 0; k < n; ++k) out[k] = k;
    return n;
  }
  int m = 0;
  for (int d = -1; d <= 1; ++d) {
    int k = c + d;
    if (k < 0 || k >= n) {
      if (!periodic) continue;
      k = (k + n) % n;
    }
    out[m++] = k;
  }
  return m;
}
}  // namespace

void BinGrid::build(const Particles& p, double skin, NeighbourList& out) const {
  const std::size_t n = p.size();
  out.offsets.assign(n + 1, 0);
  out.j.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const int b = bin_of(p.x[i]);
    const int cx = b % n_[0], cy = (b / n_[0]) % n_[1], cz = b / (n_[0] * n_[1]);
    int sx[3], sy[3], sz[3];
    const int mx = axis_stencil(cx, n_[0], box_.periodic[0], sx);
    const int my = axis_stencil(cy, n_[1], box_.periodic[1], sy);
    const int mz = axis_stencil(cz, n_[2], box_.periodic[2], sz);
    for (int iz = 0; iz < mz; ++iz)
      for (int iy = 0; iy < my; ++iy)
        for (int ix = 0; ix < mx; ++ix) {
          const int nb = (sz[iz] * n_[1] + sy[iy]) * n_[0] + sx[ix];
          for (int j = bin_start_[nb]; j < bin_start_[nb + 1]; ++j) {
            if (static_cast<std::size_t>(j) <= i) continue;
            const double cut = p.radius[i] + p.radius[j] + skin;
            if (box_.min_image(p.x[i] - p.x[j]).squaredNorm() < cut * cut) out.j.push_back(j);
          }
        }
    out.offsets[i + 1] = static_cast<int>(out.j.size());
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
