#include "coupling/footprint.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace grainflow::coupling {
namespace {

constexpr const char* kValidMethods = "centre, divided, smoothed";

// Integrals of a kernel over one cube-ball intersection, in fine-lattice units (see below).
struct Part {
  double mass = 0;              // sum of the kernel over the cube's sub-points inside the ball
  double first[3] = {0, 0, 0};  // sum of kernel * a (a: integer coordinate numerator)
  double second = 0;            // sum of kernel * |a|^2
};

// Footprint of a kernel on the ball of radius 1 (units: the ball radius), cut into n x n x n
// cubes spanning [-1, 1]^3, each sampled by m^3 midpoints. Fine index f in [0, N), N = n m,
// sits at x = (2 f + 1 - N) / N: an odd integer numerator, so mirror images are exact
// negations, squared distances are exact integers, and the inside test a^2 + b^2 + c^2 <= N^2
// is exact. Parts are integrated on the cubes with index >= n / 2 on every axis only and
// mirrored, so the footprint is exactly symmetric whatever the summation order.
// rms_placement: point on the ray through the part's centroid at its RMS distance (keeps the
// part's second moment); otherwise at the centroid. `scale` maps ball units to particle radii.
template <class Kernel>
std::vector<FootprintPoint> lattice_footprint(int n, int m, double scale, bool rms_placement,
                                              Kernel kernel) {
  const std::int64_t big_n = std::int64_t{n} * m, n2 = big_n * big_n;
  const int lo = n / 2, half = n - lo;
  const auto h = static_cast<std::size_t>(half);
  std::vector<Part> parts(h * h * h);
  auto part_at = [&](int i, int j, int k) -> Part& {
    const auto at = [lo](int cell) { return static_cast<std::size_t>(cell - lo); };
    return parts[(at(i) * h + at(j)) * h + at(k)];
  };
  auto numerator = [&](int cell, int sub) {
    return 2 * (std::int64_t{cell} * m + sub) + 1 - big_n;
  };

  for (int i = lo; i < n; ++i)
    for (int j = lo; j < n; ++j)
      for (int k = lo; k < n; ++k) {
        Part& p = part_at(i, j, k);
        for (int qi = 0; qi < m; ++qi) {
          const std::int64_t a = numerator(i, qi);
          for (int qj = 0; qj < m; ++qj) {
            const std::int64_t b = numerator(j, qj);
            for (int qk = 0; qk < m; ++qk) {
              const std::int64_t c = numerator(k, qk);
              const std::int64_t d2 = a * a + b * b + c * c;
              if (d2 > n2) continue;
              const double g = kernel(static_cast<double>(d2) / static_cast<double>(n2));
              p.mass += g;
              p.first[0] += g * static_cast<double>(a);
              p.first[1] += g * static_cast<double>(b);
              p.first[2] += g * static_cast<double>(c);
              p.second += g * static_cast<double>(d2);
            }
          }
        }
        // The middle cube of an odd lattice is its own mirror image: centroid 0 on that axis.
        const int idx[3] = {i, j, k};
        for (int ax = 0; ax < 3; ++ax)
          if (idx[ax] == n - 1 - idx[ax]) p.first[ax] = 0;
      }

  std::vector<FootprintPoint> out;
  double total = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const int idx[3] = {i, j, k};
        const Part& p =
            part_at(std::max(i, n - 1 - i), std::max(j, n - 1 - j), std::max(k, n - 1 - k));
        if (p.mass <= 0) continue;
        double pos[3], norm2 = 0;
        for (int ax = 0; ax < 3; ++ax) {
          pos[ax] = p.first[ax] / p.mass / static_cast<double>(big_n);
          norm2 += pos[ax] * pos[ax];
        }
        if (rms_placement && norm2 > 0) {
          const double rms = std::sqrt(p.second / p.mass) / static_cast<double>(big_n);
          const double stretch = rms / std::sqrt(norm2);
          for (double& x : pos) x *= stretch;
        }
        FootprintPoint fp{};
        for (int ax = 0; ax < 3; ++ax) fp.offset[ax] = (idx[ax] >= lo ? scale : -scale) * pos[ax];
        fp.weight = p.mass;
        total += p.mass;
        out.push_back(fp);
      }
  for (FootprintPoint& fp : out) fp.weight /= total;
  return out;
}

}  // namespace

VoidFractionMethod parse_void_fraction_method(const std::string& name) {
  if (name == "centre") return VoidFractionMethod::centre;
  if (name == "divided") return VoidFractionMethod::divided;
  if (name == "smoothed") return VoidFractionMethod::smoothed;
  throw std::invalid_argument("unknown void fraction method \"" + name +
                              "\"; valid methods: " + kValidMethods);
}

const char* void_fraction_method_name(VoidFractionMethod m) {
  switch (m) {
    case VoidFractionMethod::centre:
      return "centre";
    case VoidFractionMethod::divided:
      return "divided";
    case VoidFractionMethod::smoothed:
      return "smoothed";
  }
  return "unknown";
}

Footprint::Footprint(VoidFractionMethod method, int divided_resolution, double smoothing_factor)
    : method_(method), support_(1.0) {
  if (divided_resolution < 2 || divided_resolution > kMaxDividedResolution)
    throw std::invalid_argument("void fraction: divided_resolution " +
                                std::to_string(divided_resolution) + " is outside [2, " +
                                std::to_string(kMaxDividedResolution) +
                                "]; it counts the lattice cubes across the particle diameter");
  if (!(smoothing_factor >= 1.0 && smoothing_factor <= 2.0)) {
    // Every digit that reads back (to_string would show 2.0000001 as 2.000000, inside [1, 2]).
    char value[32];
    char* end = std::to_chars(value, value + sizeof value, smoothing_factor).ptr;
    throw std::invalid_argument("void fraction: smoothing_factor " +
                                std::string(value, static_cast<std::size_t>(end - value)) +
                                " is outside [1, 2]; it is the smoothed kernel's support "
                                "radius in particle radii");
  }
  switch (method) {
    case VoidFractionMethod::centre:
      unit_.push_back(FootprintPoint{{0, 0, 0}, 1});
      break;
    case VoidFractionMethod::divided:
      unit_ = lattice_footprint(divided_resolution, kSubSamples, 1.0, false,
                                [](double) { return 1.0; });
      break;
    case VoidFractionMethod::smoothed: {
      support_ = smoothing_factor;
      // sigma = R / 3 in units of R: exp(-s^2 / (2 sigma^2)) = exp(-4.5 s^2).
      unit_ = lattice_footprint(kSmoothedResolution, kSubSamples, smoothing_factor, true,
                                [](double s2) { return std::exp(-4.5 * s2); });
      break;
    }
  }
}

void Footprint::points(double radius, std::vector<FootprintPoint>& out) const {
  out.resize(unit_.size());
  for (std::size_t p = 0; p < unit_.size(); ++p) {
    for (int ax = 0; ax < 3; ++ax) out[p].offset[ax] = unit_[p].offset[ax] * radius;
    out[p].weight = unit_[p].weight;
  }
}

}  // namespace grainflow::coupling
