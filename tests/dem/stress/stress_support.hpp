#pragma once
// Shared pieces of the stress suite (issue 8, docs/stability.md): the horizon scale
// read from GRAINFLOW_STRESS_SCALE, whole-state gathers, finiteness checks, and an
// energy and contact count computed by brute force from positions — independent of
// the engine's neighbour lists, so a missed contact or a wrong force shows up.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "dem/engine/simulation.hpp"
#include "tests/dem/parallel/support.hpp"

namespace grainflow::test {

// Multiplies every stress test's horizon: 1 in CTest, e.g. 10 in
// benchmarks/hard_cases/run_hard_cases.sh.
inline long stress_scale() {
  const char* s = std::getenv("GRAINFLOW_STRESS_SCALE");
  if (s == nullptr) return 1;
  const long k = std::atol(s);
  return k > 0 ? k : 1;
}

// Everything the checks need about one particle.
struct Grain {
  GlobalId id;
  double x[3], v[3], w[3];
  double r, m, inertia;
};

// All particles of `comm`, by global id, on rank 0 of `comm` (empty elsewhere).
inline std::vector<Grain> gather_grains(const Particles& p, MPI_Comm comm) {
  std::vector<Grain> mine(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    Grain& g = mine[i];
    g.id = p.id[i];
    for (int a = 0; a < 3; ++a) {
      g.x[a] = p.x[i][a];
      g.v[a] = p.v[i][a];
      g.w[a] = p.omega[i][a];
    }
    g.r = p.radius[i];
    g.m = p.mass[i];
    g.inertia = p.inertia[i];
  }
  return gather_by_id(mine, comm);
}

inline bool all_finite(const Particles& p) {
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!p.x[i].allFinite() || !p.v[i].allFinite() || !p.omega[i].allFinite()) return false;
  return true;
}

// Collective: true when every rank's particles are finite.
inline bool all_finite(const Particles& p, MPI_Comm comm) {
  int ok = all_finite(p) ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, comm);
  return ok == 1;
}

// Separation x_a - x_b under the minimum-image convention along periodic axes.
inline Vec3 separation(const Grain& a, const Grain& b, const Domain& d) {
  Vec3 s(a.x[0] - b.x[0], a.x[1] - b.x[1], a.x[2] - b.x[2]);
  for (int k = 0; k < 3; ++k)
    if (d.periodic[k]) {
      const double L = d.hi[k] - d.lo[k];
      s[k] -= L * std::round(s[k] / L);
    }
  return s;
}

// Brute-force contact census of the gathered particles against each other and the
// scene's plane walls. One material: Y* = Y / (2 (1 - nu^2)) for pairs and for walls
// of that material (docs/models/contact-models.md).
struct Census {
  long contacts = 0;             // touching pairs + particle-wall contacts
  double max_overlap_ratio = 0;  // overlap / smaller radius
  double hertz_energy = 0;       // sum of (2/5) K delta^{5/2}, K = (4/3) Y* sqrt(R*)
};

inline Census census(const std::vector<Grain>& g, const Scene& s) {
  const Material& mat = s.materials.at(0);
  const double y_star = mat.youngs_modulus / (2 * (1 - mat.poisson_ratio * mat.poisson_ratio));
  Census c;
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (std::size_t j = i + 1; j < g.size(); ++j) {
      const double d = g[i].r + g[j].r - separation(g[i], g[j], s.domain).norm();
      if (d <= 0) continue;
      ++c.contacts;
      const double rs = g[i].r * g[j].r / (g[i].r + g[j].r);
      c.max_overlap_ratio = std::max(c.max_overlap_ratio, d / std::min(g[i].r, g[j].r));
      c.hertz_energy += 0.4 * (4.0 / 3.0) * y_star * std::sqrt(rs) * std::pow(d, 2.5);
    }
    for (const Wall& w : s.walls) {
      if (w.kind != Wall::Kind::plane) continue;
      const Vec3 x(g[i].x[0], g[i].x[1], g[i].x[2]);
      const double d = g[i].r - (x - w.plane.point).dot(w.plane.normal);
      if (d <= 0) continue;
      ++c.contacts;
      c.max_overlap_ratio = std::max(c.max_overlap_ratio, d / g[i].r);
      c.hertz_energy += 0.4 * (4.0 / 3.0) * y_star * std::sqrt(g[i].r) * std::pow(d, 2.5);
    }
  }
  return c;
}

// Kinetic (translation + rotation) plus gravitational potential energy, -sum m g.x.
inline double mechanical_energy(const std::vector<Grain>& g, const Vec3& gravity) {
  double e = 0;
  for (const Grain& q : g) {
    const Vec3 x(q.x[0], q.x[1], q.x[2]), v(q.v[0], q.v[1], q.v[2]), w(q.w[0], q.w[1], q.w[2]);
    e += 0.5 * q.m * v.squaredNorm() + 0.5 * q.inertia * w.squaredNorm() - q.m * gravity.dot(x);
  }
  return e;
}

// Total energy (kinetic + gravity + elastic Hertz) from positions alone.
inline double total_energy(const std::vector<Grain>& g, const Scene& s) {
  return mechanical_energy(g, s.gravity) + census(g, s).hertz_energy;
}

// Value after `key` in an error message (e.g. "at most " -> 1.2e-06), NaN if absent.
inline double number_after(const std::string& message, const std::string& key) {
  const auto at = message.find(key);
  if (at == std::string::npos) return std::nan("");
  return std::stod(message.substr(at + key.size()));
}

inline int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

}  // namespace grainflow::test
