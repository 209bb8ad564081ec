// Particle-triangle-mesh contact geometry: closest-point regions (Ericson 2005,
// §5.1.5), one contact per touching feature, grid search equal to brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "dem/walls/closest_point.hpp"
#include "dem/walls/triangle_mesh.hpp"
#include "tests/dem/walls/mesh_support.hpp"

namespace grainflow {
namespace {

using K = TriangleFeature::Kind;

TEST(ClosestPoint, EveryVoronoiRegion) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  struct Case {
    Vec3 p, q;
    K kind;
    int index;
  } cases[] = {
      {{0.2, 0.2, 1}, {0.2, 0.2, 0}, K::face, 0},     {{-1, -1, 0.5}, a, K::vertex, 0},
      {{2, -0.5, 0}, b, K::vertex, 1},                {{-0.5, 2, 0}, c, K::vertex, 2},
      {{0.5, -1, 0.3}, {0.5, 0, 0}, K::edge, 0},      {{1, 1, -2}, {0.5, 0.5, 0}, K::edge, 1},
      {{-1, 0.5, 0}, {0, 0.5, 0}, K::edge, 2},
  };
  for (const Case& k : cases) {
    TriangleFeature f;
    const Vec3 q = closest_point_on_triangle(k.p, a, b, c, f);
    EXPECT_NEAR((q - k.q).norm(), 0, 1e-15) << k.p.transpose();
    EXPECT_EQ(f.kind, k.kind) << k.p.transpose();
    EXPECT_EQ(f.index, k.index) << k.p.transpose();
  }
}

// A sphere over a flat mesh feels exactly one contact wherever it is: over a face,
// a shared edge or a vertex shared by up to 8 triangles (edges and vertices of the
// 0.01 grid are hit exactly by the sampling below), with the plane's overlap and normal.
TEST(MeshContact, FlatMeshGivesOneContactEverywhere) {
  const test::MeshData d = test::flat_grid(8, 0.01, 0, 0, 0);
  TriangleMesh mesh(d.v, d.t);
  mesh.build_grid(0.004);
  MeshTouch out[TriangleMesh::kMaxTouches];
  const double r = 0.003, z = 0.0025;
  int samples = 0;
  for (int j = 0; j <= 100; ++j)
    for (int i = 0; i <= 100; ++i) {
      const Vec3 c(0.01 + 0.0006 * i, 0.01 + 0.0006 * j, z);
      const int n = mesh.touches(c, r, out);
      ASSERT_EQ(n, 1) << "at " << c.transpose();
      EXPECT_NEAR(out[0].overlap, r - z, 1e-15);
      EXPECT_NEAR((out[0].n - Vec3::UnitZ()).norm(), 0, 1e-12);
      ++samples;
    }
  EXPECT_EQ(samples, 10201);
}

// Outside a convex box corner the sphere touches a vertex (one contact, not one
// per triangle); outside an edge, one contact; inside a corner, three face contacts.
TEST(MeshContact, ConvexFeaturesAndConcaveCorner) {
  const test::MeshData d = test::box(Vec3::Zero(), Vec3::Ones());
  TriangleMesh mesh(d.v, d.t);
  mesh.build_grid(0.5);
  MeshTouch out[TriangleMesh::kMaxTouches];
  const double r = 0.1, gap = 0.05;
  const Vec3 corner_dir = Vec3(1, 1, 1).normalized(), edge_dir = Vec3(1, 1, 0).normalized();
  ASSERT_EQ(mesh.touches(Vec3::Ones() + gap * corner_dir, r, out), 1);
  EXPECT_EQ(out[0].feature.kind, K::vertex);
  EXPECT_NEAR((out[0].n - corner_dir).norm(), 0, 1e-12);
  EXPECT_NEAR(out[0].overlap, r - gap, 1e-12);
  ASSERT_EQ(mesh.touches(Vec3(1, 1, 0.5) + gap * edge_dir, r, out), 1);
  EXPECT_EQ(out[0].feature.kind, K::edge);
  EXPECT_NEAR((out[0].n - edge_dir).norm(), 0, 1e-12);
  EXPECT_EQ(mesh.touches(Vec3(0.08, 0.08, 0.08), r, out), 3);  // inside, near a corner
  EXPECT_EQ(mesh.touches(Vec3(0.5, 0.5, 0.5), r, out), 0);
}

// The grid search finds exactly what the search over all triangles finds.
TEST(MeshContact, GridSearchEqualsBruteForce) {
  const test::MeshData d = test::flat_grid(20, 0.01, 0, 0, 0);
  // Fold the grid into a wavy surface so that edges and vertices are not coplanar.
  std::vector<Vec3> v = d.v;
  for (Vec3& x : v) x[2] = 0.01 * std::sin(40 * x[0]) * std::cos(30 * x[1]);
  TriangleMesh mesh(v, d.t);
  mesh.build_grid(0.007);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.02, 0.22), w(-0.02, 0.02), rad(0.002, 0.012);
  MeshTouch a[TriangleMesh::kMaxTouches], b[TriangleMesh::kMaxTouches];
  long contacts = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec3 c(u(rng), u(rng), w(rng));
    const double r = rad(rng);
    const int n = mesh.touches(c, r, a);
    ASSERT_EQ(n, mesh.touches_brute_force(c, r, b));
    // Same contacts; the order follows the visiting order, which differs.
    auto by_triangle = [](const MeshTouch& x, const MeshTouch& y) { return x.triangle < y.triangle; };
    std::vector<MeshTouch> sa(a, a + n), sb(b, b + n);
    std::sort(sa.begin(), sa.end(), by_triangle);
    std::sort(sb.begin(), sb.end(), by_triangle);
    for (int j = 0; j < n; ++j) {
      EXPECT_EQ(sa[j].triangle, sb[j].triangle);
      EXPECT_EQ(sa[j].overlap, sb[j].overlap);
    }
    contacts += n;
  }
  EXPECT_GT(contacts, 5000);  // the comparison covered many contacts
}

}  // namespace
}  // namespace grainflow
