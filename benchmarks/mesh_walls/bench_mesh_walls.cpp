// Particle-mesh contact search time against the triangle count.
//
// 2000 spheres (r = 1 mm) lie in contact with a flat floor mesh. Two series:
//  A. the floor grows (triangles of fixed size, 2 mm legs), the spheres stay on a
//     5 cm patch: with the grid the cost per sphere stays flat; a search over all
//     triangles grows linearly;
//  B. the same 10 cm floor is refined: once triangles are smaller than the spheres,
//     more triangles touch each sphere and the cost grows as (d / edge)^2 -- that is
//     the contact count growing, not the search.
// Prints a markdown table (docs/theory/walls.md quotes it). Run:
//   build/bin/bench_mesh_walls
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "dem/walls/triangle_mesh.hpp"

namespace {

using grainflow::MeshTouch;
using grainflow::TriangleMesh;
using grainflow::Vec3;

TriangleMesh floor_mesh(int n, double h) {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) v.emplace_back(i * h, j * h, 0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      t.push_back({a, b, c});
      t.push_back({a, c, d});
    }
  TriangleMesh m(std::move(v), std::move(t));
  m.build_grid(2e-3);  // as the engine: cells of one particle diameter
  return m;
}

struct Timing {
  double grid_ns, brute_ns, contacts;
};

Timing measure(const TriangleMesh& m, double patch, bool brute) {
  constexpr double r = 1e-3;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.0, patch);
  std::vector<Vec3> x(2000);
  for (Vec3& c : x) c = Vec3(u(rng), u(rng), 0.9 * r);
  MeshTouch out[TriangleMesh::kMaxTouches];
  auto run = [&](bool all, int reps) {
    long contacts = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < reps; ++k)
      for (const Vec3& c : x) contacts += all ? m.touches_brute_force(c, r, out) : m.touches(c, r, out);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::pair<double, double>(1e9 * s / (reps * static_cast<double>(x.size())),
                                     static_cast<double>(contacts) / (reps * x.size()));
  };
  const auto [g, c] = run(false, 50);
  double b = 0;
  if (brute) b = run(true, 1).first;
  return {g, b, c};
}

}  // namespace

int main() {
  std::printf("A. floor grows, triangles of 2 mm legs, 2000 spheres on a 5 cm patch\n\n");
  std::printf("| triangles | grid search [ns/sphere] | all triangles [ns/sphere] | contacts/sphere |\n");
  std::printf("|---:|---:|---:|---:|\n");
  for (int n : {25, 50, 100, 200, 400, 800}) {
    const TriangleMesh m = floor_mesh(n, 2e-3);
    const Timing t = measure(m, 0.05, n <= 200);
    if (n <= 200)
      std::printf("| %zu | %.0f | %.0f | %.2f |\n", m.triangle_count(), t.grid_ns, t.brute_ns, t.contacts);
    else
      std::printf("| %zu | %.0f | – | %.2f |\n", m.triangle_count(), t.grid_ns, t.contacts);
  }
  std::printf("\nB. a 10 cm floor refined, 2000 spheres (d = 2 mm) spread over it\n\n");
  std::printf("| triangles | leg [mm] | grid search [ns/sphere] | contacts/sphere |\n");
  std::printf("|---:|---:|---:|---:|\n");
  for (int n : {5, 10, 25, 50, 100, 200, 400}) {
    const TriangleMesh m = floor_mesh(n, 0.1 / n);
    const Timing t = measure(m, 0.1, false);
    std::printf("| %zu | %.2f | %.0f | %.2f |\n", m.triangle_count(), 100.0 / n, t.grid_ns, t.contacts);
  }
  return 0;
}
