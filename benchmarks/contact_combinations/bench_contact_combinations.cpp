// Time per step of every contact-slot combination on one settled bed.
//
// Promise 3 ("an effect a scene does not name costs nothing"): each combination is
// its own compiled force loop, so `none` slots must cost nothing. This program
// settles one bed of spheres once, then runs the same state with each of the 24
// combinations, interleaved over several rounds (so machine noise hits all alike),
// and reports the median time per step and its ratio to the cheapest law.
//
// usage: bench_contact_combinations [--particles N] [--steps S] [--rounds R] [--markdown FILE]
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "dem/engine/simulation.hpp"
#include "dem/insert/insertion.hpp"

using namespace grainflow;

namespace {

Scene bed_scene(long particles) {
  Scene s;
  s.file = "<benchmark>";
  const double r = 1e-3, L = 0.03;
  const double height = particles * sphere_volume(r) / (0.3 * L * L) + 4 * r;
  s.domain.lo = Vec3(0, 0, 0);
  s.domain.hi = Vec3(L, L, height * 1.2);
  s.domain.periodic = {true, true, false};
  s.gravity = Vec3(0, 0, -9.81);
  s.materials.push_back({"glass", 5e7, 0.25, 2500});
  MaterialPair pair;
  pair.restitution = 0.5;
  pair.friction = 0.5;
  pair.rolling_friction = 0.05;
  pair.cohesion_energy_density = 1e3;
  s.pairs.push_back(pair);
  Wall floor;
  floor.name = "floor";
  floor.plane.point = Vec3::Zero();
  floor.plane.normal = Vec3::UnitZ();
  s.walls.push_back(floor);
  Insertion fill;
  fill.region.lo = Vec3(0, 0, 0);
  fill.region.hi = Vec3(L, L, height);
  fill.count = particles;
  fill.radius.kind = SizeDistribution::Kind::uniform;
  fill.radius.min = 0.9 * r;
  fill.radius.max = 1.1 * r;
  fill.source = "benchmark";
  s.insertions.push_back(fill);
  s.time.end = 1;
  s.contact.hooke_characteristic_velocity = 1.0;
  return s;
}

double seconds_per_step(Scene scene, const Particles& start, double dt, long steps) {
  Simulation sim(scene, false);
  sim.particles() = start;
  sim.set_dt(dt);
  sim.initialise();
  for (int k = 0; k < 20; ++k) sim.step();  // warm-up: lists built, caches filled
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < steps; ++k) sim.step();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / steps;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);  // the engine runs on a communicator, even on one rank
  long particles = 8000, steps = 400;
  int rounds = 3;
  std::string markdown;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--particles" && k + 1 < argc) particles = std::atol(argv[++k]);
    else if (a == "--steps" && k + 1 < argc) steps = std::atol(argv[++k]);
    else if (a == "--rounds" && k + 1 < argc) rounds = std::atoi(argv[++k]);
    else if (a == "--markdown" && k + 1 < argc) markdown = argv[++k];
    else {
      std::cerr << "usage: bench_contact_combinations [--particles N] [--steps S] [--rounds R] "
                   "[--markdown FILE]\n";
      MPI_Finalize();
      return 2;
    }
  }

  // Settle the bed once with the most common law (Hertz + history).
  Scene scene = bed_scene(particles);
  scene.contact.tangential = TangentialModel::history;
  Simulation settle(scene);
  const double dt = 0.15 * rayleigh_time(scene.materials[0], 0.9e-3);
  settle.set_dt(dt);
  settle.initialise();
  const auto t0 = std::chrono::steady_clock::now();
  settle.advance_to(0.25);
  for (auto& v : settle.particles().v) v.setZero();
  for (auto& w : settle.particles().omega) w.setZero();
  std::cerr << "settled " << settle.particles().size() << " particles in "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()
            << " s (dt = " << dt << " s)\n";
  const Particles bed = settle.particles();

  struct Row {
    ContactSettings c;
    std::string name;
    std::vector<double> times;
  };
  std::vector<Row> rows;
  for (auto n : {NormalModel::hertz, NormalModel::hooke})
    for (auto t : {TangentialModel::none, TangentialModel::history})
      for (auto r : {RollingModel::none, RollingModel::cdt, RollingModel::epsd})
        for (auto c : {CohesionModel::none, CohesionModel::sjkr}) {
          Row row;
          row.c = scene.contact;
          row.c.normal = n;
          row.c.tangential = t;
          row.c.rolling = r;
          row.c.cohesion = c;
          row.name = select_sweep(row.c).name;
          rows.push_back(row);
        }
  for (int round = 0; round < rounds; ++round)
    for (Row& row : rows) {
      Scene s = scene;
      s.contact = row.c;
      row.times.push_back(seconds_per_step(s, bed, dt, steps));
    }
  double best = 1e300;
  for (Row& row : rows) {
    std::sort(row.times.begin(), row.times.end());
    best = std::min(best, row.times[row.times.size() / 2]);
  }
  std::ostringstream table;
  table << "| normal + tangential + rolling + cohesion | time per step [ms] | "
           "particle-steps/s | relative to cheapest |\n|---|---:|---:|---:|\n";
  for (const Row& row : rows) {
    const double med = row.times[row.times.size() / 2];
    table << "| " << row.name << " | " << std::fixed << std::setprecision(3) << med * 1e3 << " | "
          << std::scientific << std::setprecision(2) << bed.size() / med << " | " << std::fixed
          << std::setprecision(2) << med / best << " |\n";
  }
  std::cout << table.str();
  if (!markdown.empty()) {
    std::ofstream out(markdown);
    out << "Bed of " << bed.size() << " spheres (r = 0.9-1.1 mm, glass-like, Y = 50 MPa), settled "
        << "under gravity on a floor, periodic sides; dt = " << dt << " s; median of " << rounds
        << " interleaved rounds of " << steps << " steps each.\n\n"
        << table.str();
  }
  MPI_Finalize();
  return 0;
}
