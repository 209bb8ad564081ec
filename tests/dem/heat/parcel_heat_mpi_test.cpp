// Random scenes of coarse-grained parcels among real beads with heat, cohesion and rolling
// resistance, on 2 ranks (docs/models/coarse-graining.md, "Heat transfer"). Invariants, not
// earlier output: in a closed box of adiabatic walls without fluid or sources,
//  - the thermal energy sum m c T is conserved to round-off (each pair's heat is exchanged
//    exactly, parcel-bead pairs and pairs across the cut included);
//  - every temperature stays within the initial range (explicit conduction at a stable step
//    is a weighted average: no new extremum), and is finite;
//  - no particle is lost, and the real-particle count sum k^3 is what was inserted.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>

#include "dem/engine/simulation.hpp"
#include "dem/heat/heat_transfer.hpp"
#include "dem/scene/scene_parser.hpp"

namespace grainflow {
namespace {

std::string num(double x) {
  std::ostringstream o;
  o.precision(17);
  o << x;
  return o.str();
}

struct Sums {
  double energy = 0, real = 0, t_min = 1e300, t_max = -1e300;
  double bead_max = -1e300;  // the warmest real bead (k = 1)
  long particles = 0;
  bool finite = true;
};

Sums sums(const Simulation& sim, const Scene& s) {
  const Particles& p = sim.particles();
  Sums local;
  local.energy = sim.heat()->thermal_energy(p);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double k = s.materials[p.material[i]].coarse_grain;
    local.real += k * k * k;
    local.t_min = std::min(local.t_min, p.temperature[i]);
    local.t_max = std::max(local.t_max, p.temperature[i]);
    if (k == 1) local.bead_max = std::max(local.bead_max, p.temperature[i]);
    local.finite = local.finite && std::isfinite(p.temperature[i]) && p.x[i].allFinite();
  }
  local.particles = static_cast<long>(p.size());
  Sums all;
  MPI_Allreduce(&local.energy, &all.energy, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&local.real, &all.real, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(&local.t_min, &all.t_min, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&local.t_max, &all.t_max, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&local.bead_max, &all.bead_max, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&local.particles, &all.particles, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  int finite = local.finite ? 1 : 0, every = 0;
  MPI_Allreduce(&finite, &every, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  all.finite = every == 1;
  return all;
}

TEST(ParcelHeatRandom, ClosedBoxesConserveHeatAndParticles) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    const double k = 1.5 + 1.5 * u(rng);  // parcels of k in [1.5, 3]
    const double kc = 2e5 * u(rng);       // SJKR energy density [J/m^3]
    const double mu_r = 0.1 * u(rng);
    const double gx = 4 * (u(rng) - 0.5), gy = 4 * (u(rng) - 0.5);
    const long beads = 150, parcels = 12;
    const std::string walls =
        "  - {type: plane, point: [0, 0, 0], normal: [1, 0, 0], material: glass}\n"
        "  - {type: plane, point: [0.02, 0, 0], normal: [-1, 0, 0], material: glass}\n"
        "  - {type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: glass}\n"
        "  - {type: plane, point: [0, 0.02, 0], normal: [0, -1, 0], material: glass}\n"
        "  - {type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: glass}\n"
        "  - {type: plane, point: [0, 0, 0.02], normal: [0, 0, -1], material: glass}\n";
    const std::string yaml =
        "domain: {min: [0, 0, 0], max: [0.02, 0.02, 0.02]}\n"
        "gravity: [" +
        num(gx) + ", " + num(gy) +
        ", -9.81]\n"
        "time: {rayleigh_fraction: 0.15, end: 1}\n"
        "heat: {}\n"
        "materials:\n"
        // Stiff enough that a parcel of k = 3 resting on a single bead stays within the
        // overlap guard (its weight is k^3 a bead's).
        "  - {name: glass, youngs_modulus: 5e7, poisson_ratio: 0.3, density: 2500,\n"
        "     heat_capacity: 2, conductivity: 1}\n"
        "interaction_defaults: {restitution: 0.5, friction: 0.4, rolling_friction: " +
        num(mu_r) + ", cohesion_energy_density: " + num(kc) +
        "}\n"
        "contact: {normal: hertz, rolling: cdt, cohesion: sjkr}\n"
        "walls:\n" +
        walls +
        "insert:\n"
        "  - {type: fill, region: {box: {min: [0, 0, 0], max: [0.02, 0.02, 0.012]}},\n"
        "     count: " +
        std::to_string(beads) + ", material: glass, seed: " + std::to_string(seed) +
        ",\n"
        "     radius: {distribution: uniform, min: 4e-4, max: 6e-4}, temperature: 300}\n"
        "  - {type: fill, region: {box: {min: [0, 0, 0.012], max: [0.02, 0.02, 0.02]}},\n"
        "     count: " +
        std::to_string(parcels) + ", material: glass, seed: " + std::to_string(seed + 100) +
        ",\n"
        "     radius: {distribution: uniform, min: 4e-4, max: 6e-4}, temperature: 400,\n"
        "     coarse_grain: " +
        num(k) + "}\n";
    const Scene s = parse_scene(yaml, "random_parcels.yaml");
    Simulation sim(s, true, MPI_COMM_WORLD);
    sim.initialise();
    const Sums before = sums(sim, s);
    sim.advance_to(0.1);
    const Sums after = sums(sim, s);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (rank == 0)
      std::printf(
          "seed %u: k = %.3f, k_c = %.4g J/m^3, mu_r = %.3f: %ld particles, %.6g real; "
          "m c T %.12g -> %.12g J (relative change %.2e), T in [%.4f, %.4f] K, warmest bead %.4f "
          "K\n",
          seed, k, kc, mu_r, after.particles, after.real, before.energy, after.energy,
          std::abs(after.energy - before.energy) / before.energy, after.t_min, after.t_max,
          after.bead_max);
    EXPECT_TRUE(after.finite) << "seed " << seed;
    EXPECT_EQ(after.particles, beads + parcels) << "seed " << seed;
    EXPECT_NEAR(after.real, static_cast<double>(beads) + parcels * k * k * k, 1e-9)
        << "seed " << seed;
    EXPECT_NEAR(after.energy / before.energy, 1, 1e-12) << "seed " << seed;
    EXPECT_GE(after.t_min, 300 - 1e-9) << "seed " << seed;
    EXPECT_LE(after.t_max, 400 + 1e-9) << "seed " << seed;
    // Heat moved: the parcels landed on the beads and warmed some of them.
    EXPECT_GT(after.bead_max, 300.01) << "seed " << seed;
  }
}

}  // namespace
}  // namespace grainflow
