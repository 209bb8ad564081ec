#pragma once
// Footprint of one spherical particle: the points over which its volume is spread when the
// void fraction is computed on a CFD mesh (unresolved CFD-DEM). The caller adds
// weight * V_particle to the cell holding centre + offset, for every point.
//
//   centre    one point at the centre, weight 1: the whole volume goes to the cell holding
//             the centre (CFDEMcoupling "centre").
//   divided   the sphere cut into parts by a cubic lattice of n x n x n little cubes spanning
//             [-r, r]^3; each part (cube and sphere intersection) is one point at its centroid, weighted by
//             its volume / V_sphere. Our construction of the CFDEMcoupling "divided" idea
//             (sphere split into parts, each part to the cell holding it); see coupling/README.md.
//   smoothed  a Gaussian of standard deviation sigma = R / 3, truncated at the support radius
//             R = smoothing_factor * r (the Gaussian filtering kernel of Capecelatro &
//             Desjardins 2013, J. Comput. Phys. 238:1-31; sigma = R / 3 is our choice, so the
//             truncation drops 2.9 % of the untruncated mass), on 6 x 6 x 6 cubes spanning
//             [-R, R]^3 (spacing = sigma); each cube-ball intersection is one point weighted by the
//             Gaussian integrated over it. The point sits on the ray through the part's
//             weighted centroid at the part's RMS distance from the centre, so each part keeps
//             its own second moment and the footprint has the kernel's variance exactly (a
//             point at the centroid would lose the within-cube variance, 8 % at this spacing).
//
// Per-part volumes and Gaussian integrals are midpoint sums over 16^3 sub-points per cube,
// done once in the constructor on an integer lattice, for one octant, then mirrored, so every
// footprint is exactly mirror-symmetric in x, y and z and its first moment is zero to
// round-off. Weights sum to 1 and do not depend on r; offsets scale with r.
// Accuracy (measured, tests/coupling/footprint_test.cpp; table in coupling/README.md):
// at the default divided_resolution 5 (117 points) the weight on one side of a plane at
// height h differs from the spherical-cap volume fraction by at most 0.15 (RMS 0.056 over
// h in (-r, r)); when the plane is a lattice plane it is exact up to the sub-sampling
// (< 5e-4).
//
// C++17, standard headers only: compiled into the OpenFOAM solver as well.
#include <cstddef>
#include <string>
#include <vector>

namespace grainflow::coupling {

enum class VoidFractionMethod { centre, divided, smoothed };

// Parses "centre" | "divided" | "smoothed"; throws std::invalid_argument naming the bad
// value and listing the valid names.
VoidFractionMethod parse_void_fraction_method(const std::string& name);
const char* void_fraction_method_name(VoidFractionMethod m);

struct FootprintPoint {
  double offset[3];  // from the particle centre [m]
  double weight;     // fraction of the particle volume; the weights of one footprint sum to 1
};

class Footprint {
 public:
  static constexpr int kDefaultDividedResolution = 5;  // 117 points
  static constexpr int kMaxDividedResolution = 32;     // 19 544 points: beyond any use
  static constexpr int kSmoothedResolution = 6;        // cubes across 2R: spacing = sigma
  static constexpr int kSubSamples = 16;               // sub-points per cube edge

  // divided_resolution: cubes across the diameter for `divided`, in [2, 32].
  // smoothing_factor: the smoothed kernel's support radius in particle radii, in [1, 2].
  // Both are checked whatever the method; throws std::invalid_argument when out of range.
  explicit Footprint(VoidFractionMethod method, int divided_resolution = kDefaultDividedResolution,
                     double smoothing_factor = 2.0);

  // The points for a particle of radius r. `out` is resized to size(); reusing one vector
  // across particles avoids any allocation per particle.
  void points(double radius, std::vector<FootprintPoint>& out) const;
  // The points for r = 1 (offsets in particle radii).
  const std::vector<FootprintPoint>& unit_points() const { return unit_; }
  std::size_t size() const { return unit_.size(); }  // points per particle
  // Radius of the ball holding every offset: r for centre and divided, smoothing_factor * r
  // for smoothed.
  double support_radius(double radius) const { return support_ * radius; }
  VoidFractionMethod method() const { return method_; }

 private:
  VoidFractionMethod method_;
  double support_;  // support radius in particle radii
  std::vector<FootprintPoint> unit_;
};

}  // namespace grainflow::coupling
