#pragma once
// Where coarse-grained parcels stop standing for their real particles
// (docs/models/coarse-graining.md, "Limits"). One rule for every program that knows the
// fluid cells: `grain check` / `grain run` (the one-way computed void fraction's cell) and
// grainFoam (its mesh, at start-up).
#include <mpi.h>

#include <string>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/scene/scene.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

// One parcel class (a material with k != 1) as the particles present show it.
struct ParcelClass {
  std::string name;  // the class's material name, e.g. "glass[k=3]"
  double k = 1;
  long long parcels = 0;
  double real = 0;              // real particles the parcels stand for (parcels x k^3)
  double mass = 0;              // [kg]
  double largest_diameter = 0;  // of a parcel [m]
};

// The scene's parcel classes with at least one parcel among the particles of every rank, or
// inserted by a stream (whose largest parcel then counts, before the first is in; collective
// over comm); empty without parcels. In material order.
std::vector<ParcelClass> parcel_classes(const Scene& scene, const Particles& p, MPI_Comm comm);

// Parcels against fluid cells (Radl et al. 2011): one line per class whose largest parcel is
// wider than a third of the smallest cell (cells under 3 parcel diameters), and one more when
// the smallest cell is narrower than that parcel. Each line starts with "warning: " and names
// the class, its parcel diameter, the smallest and the typical cell size [m] and
// `cell_what` (what the cells are, e.g. "the void-fraction cell"). Empty: nothing to warn.
std::vector<std::string> parcel_cell_warnings(const std::vector<ParcelClass>& classes,
                                              double smallest_cell, double typical_cell,
                                              const std::string& cell_what);

// Parcels against the domain: a line when the domain's narrowest side (`extent` per axis;
// of equally narrow sides, a bounded one before a periodic one) is less than 10 diameters of
// the widest parcel: walls (on a bounded side) and the bed's structures resolved by few
// parcels.
std::vector<std::string> parcel_domain_warnings(const std::vector<ParcelClass>& classes,
                                                const Vec3& extent,
                                                const std::array<bool, 3>& periodic);

// Parcels against the openings of mesh walls (a hopper's orifice, a hole in a floor: loops of
// open edges, dem/walls/mesh_openings.hpp) with a vertex inside the domain: a line per mesh
// whose narrowest opening is less than 10 diameters of the widest parcel. Parcels discharge
// through few of their diameters more slowly than the real particles through many of theirs
// (the hopper benchmark: 24 and 43 % short at 9 and 6 parcel diameters) and jam by arching
// below about 5 (Zuriguel et al. 2005).
std::vector<std::string> parcel_opening_warnings(const std::vector<ParcelClass>& classes,
                                                 const WallSet& walls, const Domain& domain);

}  // namespace grainflow
