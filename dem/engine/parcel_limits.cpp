#include "dem/engine/parcel_limits.hpp"

#include <algorithm>
#include <sstream>

#include "dem/core/number_format.hpp"
#include "dem/insert/insertion.hpp"
#include "dem/walls/mesh_openings.hpp"

namespace grainflow {

std::vector<ParcelClass> parcel_classes(const Scene& scene, const Particles& p, MPI_Comm comm) {
  const std::vector<double> k = scene.coarse_grain_table();
  if (k.empty()) return {};
  const std::size_t n = scene.materials.size();
  // Per material: parcels, real particles, mass; largest parcel radius.
  std::vector<double> sum(3 * n, 0.0), largest(n, 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto m = static_cast<std::size_t>(p.material[i]);
    sum[3 * m] += 1;
    sum[3 * m + 1] += k[m] * k[m] * k[m];
    sum[3 * m + 2] += p.mass[i];
    largest[m] = std::max(largest[m], p.radius[i]);
  }
  MPI_Allreduce(MPI_IN_PLACE, sum.data(), static_cast<int>(sum.size()), MPI_DOUBLE, MPI_SUM, comm);
  MPI_Allreduce(MPI_IN_PLACE, largest.data(), static_cast<int>(n), MPI_DOUBLE, MPI_MAX, comm);
  // A stream's parcels count before the first is inserted: the limits hold for what comes.
  std::vector<bool> streamed(n, false);
  for (const Insertion& in : scene.insertions) {
    const auto m = static_cast<std::size_t>(in.material);
    if (in.kind != Insertion::Kind::stream || m >= n) continue;
    streamed[m] = true;
    largest[m] = std::max(largest[m], max_radius(in.radius));
  }
  std::vector<ParcelClass> out;
  for (std::size_t m = 0; m < n; ++m) {
    if (k[m] == 1 || (sum[3 * m] == 0 && !streamed[m])) continue;
    out.push_back({scene.materials[m].name, k[m], static_cast<long long>(sum[3 * m]),
                   sum[3 * m + 1], sum[3 * m + 2], 2 * largest[m]});
  }
  return out;
}

std::vector<std::string> parcel_cell_warnings(const std::vector<ParcelClass>& classes,
                                              double smallest_cell, double typical_cell,
                                              const std::string& cell_what) {
  std::vector<std::string> out;
  if (!(smallest_cell > 0)) return out;
  for (const ParcelClass& c : classes) {
    const double d = c.largest_diameter;
    if (!(3 * d > smallest_cell)) continue;
    const std::string cells = "(smallest " + significant(smallest_cell) + " m, typical " +
                              significant(typical_cell) + " m)";
    std::ostringstream o;
    o << "warning: parcels '" << c.name << "' (diameter up to " << significant(d)
      << " m) are wider than a third of " << cell_what << " " << cells << ": cells of "
      << significant(smallest_cell / d, 3)
      << " parcel diameters, fewer than 3; the parcels' void fraction and drag are then not "
         "the real particles' (Radl et al. 2011); lower coarse_grain or enlarge the cells";
    out.push_back(o.str());
    if (smallest_cell < d) {
      std::ostringstream w;
      w << "warning: parcels '" << c.name << "' (diameter up to " << significant(d)
        << " m) are wider than " << cell_what << " " << cells
        << ": a parcel spans several cells, so the cells resolve structures (voids, bubbles, "
           "the bed surface) smaller than a parcel, which the parcels cannot have; "
           "coarse graining fails there (Radl et al. 2011)";
      out.push_back(w.str());
    }
  }
  return out;
}

std::vector<std::string> parcel_domain_warnings(const std::vector<ParcelClass>& classes,
                                                const Vec3& extent,
                                                const std::array<bool, 3>& periodic) {
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (extent[a] < extent[axis] || (extent[a] == extent[axis] && periodic[axis])) axis = a;
  const double narrowest_side = extent[axis];
  double widest = 0;
  const ParcelClass* by = nullptr;
  for (const ParcelClass& c : classes)
    if (c.largest_diameter > widest) {
      widest = c.largest_diameter;
      by = &c;
    }
  if (!by || !(narrowest_side < 10 * widest)) return {};
  std::ostringstream o;
  o << "warning: the domain's narrowest side (" << significant(narrowest_side) << " m"
    << (periodic[axis] ? std::string(", periodic along ") + "xyz"[axis] : std::string())
    << ") is less than 10 diameters of parcels '" << by->name << "' (" << significant(widest)
    << " m): "
    << (periodic[axis] ? "the bed's own structures" : "walls and the bed's own structures")
    << " (bubbles, shear bands) are then resolved by few parcels, where coarse graining is known "
       "to fail; lower coarse_grain";
  return {o.str()};
}

std::vector<std::string> parcel_opening_warnings(const std::vector<ParcelClass>& classes,
                                                 const WallSet& walls, const Domain& domain) {
  const ParcelClass* by = nullptr;
  for (const ParcelClass& c : classes)
    if (!by || c.largest_diameter > by->largest_diameter) by = &c;
  if (!by) return {};
  const double d = by->largest_diameter;
  const auto inside = [&](const Vec3& x) {
    for (int a = 0; a < 3; ++a) {
      const double tol = 1e-9 * (domain.hi[a] - domain.lo[a]);
      if (!domain.periodic[a] && (x[a] < domain.lo[a] - tol || x[a] > domain.hi[a] + tol))
        return false;
    }
    return true;
  };
  std::vector<std::string> out;
  for (const WallSet::Entry& e : walls.walls()) {
    if (e.kind != Wall::Kind::mesh) continue;
    for (const MeshOpening& o : mesh_openings(walls.mesh(e))) {
      // A moving mesh's openings are where it is at t = 0 (its body frame); anywhere counts.
      if (!e.pose.moving() && std::none_of(o.vertices.begin(), o.vertices.end(), inside)) continue;
      if (!(o.width < 10 * d)) break;  // narrowest first
      std::ostringstream w;
      w << "warning: wall '" << e.name << "' has an opening " << significant(o.width)
        << " m wide around (" << significant(o.centre[0]) << ", " << significant(o.centre[1])
        << ", " << significant(o.centre[2]) << ") m: " << significant(o.width / d, 3)
        << " diameters of parcels '" << by->name << "' (" << significant(d)
        << " m), fewer than 10; parcels pass through few of their diameters more slowly than "
           "the real particles through many of theirs (a hopper: 24 and 43 % short at 9 and 6 "
           "parcel diameters, docs/models/coarse-graining.md) and jam below about 5 (Zuriguel "
           "et al. 2005); lower coarse_grain or widen the opening";
      out.push_back(w.str());
      break;  // one line per mesh: its narrowest opening
    }
  }
  return out;
}

}  // namespace grainflow
