#pragma once
// Closest point of a triangle to a point, with the feature (face, edge or vertex)
// it lies on. Ericson, Real-Time Collision Detection (2005), §5.1.5
// "ClosestPtPointTriangle": the Voronoi regions of the three vertices and three
// edges are tested in turn with dot products only; what remains is the face.
#include "dem/core/types.hpp"

namespace grainflow {

// Which part of triangle (a, b, c) holds the closest point. Edges are numbered
// AB = 0, BC = 1, CA = 2 and vertices A = 0, B = 1, C = 2.
struct TriangleFeature {
  enum class Kind : unsigned char { face, edge, vertex } kind = Kind::face;
  unsigned char index = 0;  // edge or vertex number; 0 for the face
};

inline Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                      TriangleFeature& f) {
  using K = TriangleFeature::Kind;
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) {
    f = {K::vertex, 0};
    return a;
  }
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) {
    f = {K::vertex, 1};
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    f = {K::edge, 0};
    return a + (d1 / (d1 - d3)) * ab;
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) {
    f = {K::vertex, 2};
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    f = {K::edge, 2};
    return a + (d2 / (d2 - d6)) * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    f = {K::edge, 1};
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  f = {K::face, 0};
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace grainflow
