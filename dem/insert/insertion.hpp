#pragma once
// Initial particle insertion: fill a region with non-overlapping spheres
// (random sequential addition) or read them from a CSV file.
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem/core/particles.hpp"
#include "dem/scene/scene.hpp"
#include "dem/walls/wall_set.hpp"

namespace grainflow {

// A request that cannot be met (region too small, file malformed); the message
// names the insertion entry (file:line) and what to change.
class InsertionError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Draws one radius from the distribution.
double sample_radius(const SizeDistribution& d, std::mt19937_64& rng);

// Largest radius the distribution can produce (for neighbour and insertion grids).
double max_radius(const SizeDistribution& d);
double min_radius(const SizeDistribution& d);  // the smallest radius d can give

// Appends the particles of every insertion entry of the scene, ids continuing
// from `next_id`. New particles overlap neither each other, earlier particles,
// nor walls, and lie inside the domain.
// Stream entries are left to StreamInsertion; snapshot entries add the particles of
// a grainflow HDF5 snapshot (new ids, same order). `walls`, when given, adds mesh
// walls (and moving walls at t = 0) to the walls new particles must not touch. `notes`, when
// given, receives a line per fill whose outcome differs from what it asked (a volume fraction
// overshot by its last particle).
void insert_particles(const Scene& scene, Particles& p, GlobalId& next_id,
                      const WallSet* walls = nullptr, std::vector<std::string>* notes = nullptr);

}  // namespace grainflow
