#include "dem/scene/scene.hpp"

#include <stdexcept>
#include <utility>

namespace grainflow {

namespace {

// Position of the unordered pair (a <= b) in the parser's canonical order:
// (0,0), (0,1), ..., (0,n-1), (1,1), (1,2), ... (upper triangle, row by row).
std::size_t canonical_pair_index(int a, int b, int n) {
  return static_cast<std::size_t>(a * n - a * (a - 1) / 2 + (b - a));
}

}  // namespace

int Scene::material_index(const std::string& name) const {
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return static_cast<int>(i);
  return -1;
}

std::vector<double> Scene::coarse_grain_table() const {
  std::vector<double> k;
  for (const Material& m : materials)
    if (m.coarse_grain != 1) {
      for (const Material& n : materials) k.push_back(n.coarse_grain);
      break;
    }
  return k;
}

std::vector<int> Scene::real_material_table() const {
  std::vector<int> real;
  if (coarse_grain_table().empty()) return real;
  for (std::size_t m = 0; m < materials.size(); ++m)
    real.push_back(materials[m].real_material < 0 ? static_cast<int>(m)
                                                  : materials[m].real_material);
  return real;
}

std::vector<std::string> Scene::material_names() const {
  std::vector<std::string> names;
  for (const Material& m : materials) names.push_back(m.name);
  return names;
}

const MaterialPair& Scene::pair(int a, int b) const {
  if (a > b) std::swap(a, b);
  const int n = static_cast<int>(materials.size());
  if (a >= 0 && b < n) {
    const std::size_t k = canonical_pair_index(a, b, n);
    if (k < pairs.size() && pairs[k].a == a && pairs[k].b == b) return pairs[k];
  }
  // A table built by hand (tests) may be in another order.
  for (const MaterialPair& p : pairs)
    if (p.a == a && p.b == b) return p;
  throw std::logic_error("Scene::pair: no entry for material pair (" + std::to_string(a) + ", " +
                         std::to_string(b) + "); the pair table must be complete");
}

}  // namespace grainflow
