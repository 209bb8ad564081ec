#include "dem/walls/triangle_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace grainflow {
namespace {

void build_csr(std::size_t n, const std::vector<std::pair<int, int>>& owner_item,
               std::vector<int>& start, std::vector<int>& items) {
  start.assign(n + 1, 0);
  for (const auto& [o, t] : owner_item) ++start[o + 1];
  for (std::size_t k = 0; k < n; ++k) start[k + 1] += start[k];
  items.assign(owner_item.size(), 0);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (const auto& [o, t] : owner_item) items[fill[o]++] = t;
}

// Ranking of features for ties: a face wins over an edge, an edge over a vertex.
int rank(const TriangleFeature& f) { return static_cast<int>(f.kind); }

}  // namespace

TriangleMesh::TriangleMesh(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles)
    : verts_(std::move(vertices)), tris_(std::move(triangles)) {
  std::unordered_map<std::uint64_t, int> edge_id;
  std::vector<std::pair<int, int>> edge_tri, vert_tri;
  edge_of_.resize(tris_.size());
  normal_.resize(tris_.size());
  offset_.resize(tris_.size());
  for (std::size_t t = 0; t < tris_.size(); ++t) {
    const auto& v = tris_[t];
    normal_[t] = (verts_[v[1]] - verts_[v[0]]).cross(verts_[v[2]] - verts_[v[0]]).normalized();
    offset_[t] = normal_[t].dot(verts_[v[0]]);
    for (int e = 0; e < 3; ++e) {
      const auto a = static_cast<std::uint64_t>(std::min(v[e], v[(e + 1) % 3]));
      const auto b = static_cast<std::uint64_t>(std::max(v[e], v[(e + 1) % 3]));
      const auto [it, fresh] = edge_id.emplace(a << 32 | b, static_cast<int>(edge_id.size()));
      edge_of_[t][e] = it->second;
      edge_tri.emplace_back(it->second, static_cast<int>(t));
      vert_tri.emplace_back(v[e], static_cast<int>(t));
    }
  }
  build_csr(edge_id.size(), edge_tri, edge_start_, edge_tris_);
  build_csr(verts_.size(), vert_tri, vert_start_, vert_tris_);
  lo_ = hi_ = verts_.empty() ? Vec3::Zero() : verts_[0];
  for (const Vec3& x : verts_) {
    lo_ = lo_.cwiseMin(x);
    hi_ = hi_.cwiseMax(x);
  }
}

double TriangleMesh::mean_edge_length() const {
  double sum = 0;
  for (const auto& t : tris_)
    for (int e = 0; e < 3; ++e) sum += (verts_[t[(e + 1) % 3]] - verts_[t[e]]).norm();
  return tris_.empty() ? 0 : sum / (3.0 * static_cast<double>(tris_.size()));
}

void TriangleMesh::build_grid(double cell, std::size_t max_cells) {
  const Vec3 extent = (hi_ - lo_).cwiseMax(1e-300);
  cell = std::max(cell, 1e-9 * extent.maxCoeff());
  auto count = [&](double h) {
    double n = 1;
    for (int a = 0; a < 3; ++a) n *= std::floor(extent[a] / h) + 1;
    return n;
  };
  // (cell, triangle) entries: a triangle is listed in every cell its bounding box
  // overlaps, so a few large or slanted triangles could fill the whole grid each.
  // Bounded too, so a hostile mesh cannot make the grid use unbounded memory.
  auto entries = [&](double h) {
    double n = 0;
    for (const auto& t : tris_) {
      Vec3 a = verts_[t[0]], b = a;
      for (int k = 1; k < 3; ++k) {
        a = a.cwiseMin(verts_[t[k]]);
        b = b.cwiseMax(verts_[t[k]]);
      }
      double cells = 1;
      for (int d = 0; d < 3; ++d)
        cells *= std::floor((b[d] - lo_[d]) / h) - std::floor((a[d] - lo_[d]) / h) + 1;
      n += cells;
    }
    return n;
  };
  const double max_entries =
      std::max(2.0 * static_cast<double>(max_cells), 8.0 * static_cast<double>(tris_.size()));
  while (count(cell) > static_cast<double>(max_cells) || entries(cell) > max_entries) cell *= 1.25;
  cell_ = cell;
  inv_cell_ = 1 / cell;
  for (int a = 0; a < 3; ++a) dims_[a] = static_cast<int>(std::floor(extent[a] * inv_cell_)) + 1;
  auto cell_of = [&](const Vec3& x, int a) {
    return std::clamp(static_cast<int>(std::floor((x[a] - lo_[a]) * inv_cell_)), 0, dims_[a] - 1);
  };
  std::vector<std::pair<int, int>> cell_tri;
  tri_cell_lo_.resize(tris_.size());
  for (std::size_t t = 0; t < tris_.size(); ++t) {
    Vec3 a = verts_[tris_[t][0]], b = a;
    for (int k = 1; k < 3; ++k) {
      a = a.cwiseMin(verts_[tris_[t][k]]);
      b = b.cwiseMax(verts_[tris_[t][k]]);
    }
    for (int d = 0; d < 3; ++d) tri_cell_lo_[t][d] = cell_of(a, d);
    for (int k = cell_of(a, 2); k <= cell_of(b, 2); ++k)
      for (int j = cell_of(a, 1); j <= cell_of(b, 1); ++j)
        for (int i = cell_of(a, 0); i <= cell_of(b, 0); ++i)
          cell_tri.emplace_back((k * dims_[1] + j) * dims_[0] + i, static_cast<int>(t));
  }
  build_csr(static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2], cell_tri, cell_start_,
            cell_tris_);
}

// Gathers the triangles within r of c (for_each_triangle calls back with candidate
// triangle ids, each at most once) and applies the contact rule:
//  - every face contact counts;
//  - an edge or vertex contact counts only if no other triangle around that edge or
//    vertex is closer to c (ties: a face beats an edge beats a vertex, then the
//    lower triangle index wins). This keeps exactly the local minima of the
//    distance from c to the surface: one contact per touching feature.
//  - contacts whose points coincide (round-off at a shared boundary) count once.
template <class ForEach>
int TriangleMesh::resolve(const Vec3& c, double r, ForEach&& for_each_triangle,
                          MeshTouch* out) const {
  constexpr int kMaxCandidates = 64;
  Candidate cand[kMaxCandidates];
  int n = 0;
  const double r2 = r * r;
  for_each_triangle([&](int t) {
    // Cheap rejection: the sphere does not reach the triangle's plane.
    if (std::abs(normal_[t].dot(c) - offset_[t]) >= r) return;
    const auto& v = tris_[t];
    TriangleFeature f;
    const Vec3 q = closest_point_on_triangle(c, verts_[v[0]], verts_[v[1]], verts_[v[2]], f);
    const double d2 = (c - q).squaredNorm();
    if (d2 >= r2) return;
    if (n < kMaxCandidates) {
      cand[n++] = {t, f, q, d2};
      return;
    }
    // More touching triangles than slots (triangles far smaller than the sphere):
    // keep the closest ones.
    int far = 0;
    for (int k = 1; k < n; ++k)
      if (cand[k].d2 > cand[far].d2) far = k;
    if (d2 < cand[far].d2) cand[far] = {t, f, q, d2};
  });
  const double tie = 1e-12 * r2;  // relative round-off of squared distances
  int m = 0;
  for (int k = 0; k < n && m < kMaxTouches; ++k) {
    const Candidate& ck = cand[k];
    bool keep = true;
    if (ck.f.kind != TriangleFeature::Kind::face) {
      const bool edge = ck.f.kind == TriangleFeature::Kind::edge;
      const int id = edge ? edge_of_[ck.tri][ck.f.index] : tris_[ck.tri][ck.f.index];
      const int* first = edge ? &edge_tris_[edge_start_[id]] : &vert_tris_[vert_start_[id]];
      const int* last = edge ? &edge_tris_[edge_start_[id + 1]] : &vert_tris_[vert_start_[id + 1]];
      for (const int* it = first; it != last && keep; ++it) {
        if (*it == ck.tri) continue;
        for (int j = 0; j < n; ++j) {
          if (cand[j].tri != *it) continue;
          const Candidate& o = cand[j];
          const bool closer = o.d2 < ck.d2 - tie;
          const bool tied = !closer && o.d2 <= ck.d2 + tie;
          if (closer || (tied && (rank(o.f) < rank(ck.f) || (rank(o.f) == rank(ck.f) && o.tri < ck.tri))))
            keep = false;
          break;
        }
      }
    }
    if (!keep) continue;
    for (int j = 0; j < m && keep; ++j)
      if ((out[j].point - ck.q).squaredNorm() <= tie) keep = false;
    if (!keep) continue;
    MeshTouch& o = out[m++];
    const double d = std::sqrt(ck.d2);
    if (d > 1e-12 * r) {
      o.n = (c - ck.q) / d;
    } else {  // centre on the surface: push along the face normal
      o.n = normal_[ck.tri];
    }
    o.point = ck.q;
    o.overlap = r - d;
    o.triangle = ck.tri;
    o.feature = ck.f;
  }
  return m;
}

int TriangleMesh::touches(const Vec3& c, double r, MeshTouch* out) const {
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    if (c[a] + r < lo_[a] || c[a] - r > hi_[a]) return 0;  // outside the bounding box
    lo[a] = std::max(0, static_cast<int>(std::floor((c[a] - r - lo_[a]) * inv_cell_)));
    hi[a] = std::min(dims_[a] - 1, static_cast<int>(std::floor((c[a] + r - lo_[a]) * inv_cell_)));
  }
  return resolve(
      c, r,
      [&](auto&& visit) {
        for (int k = lo[2]; k <= hi[2]; ++k)
          for (int j = lo[1]; j <= hi[1]; ++j)
            for (int i = lo[0]; i <= hi[0]; ++i) {
              const int cell = (k * dims_[1] + j) * dims_[0] + i;
              for (int s = cell_start_[cell]; s < cell_start_[cell + 1]; ++s) {
                // A triangle spanning several cells is visited only in the first
                // cell it shares with the query box.
                const int t = cell_tris_[s];
                const auto& tc = tri_cell_lo_[t];
                if (i == std::max(tc[0], lo[0]) && j == std::max(tc[1], lo[1]) &&
                    k == std::max(tc[2], lo[2]))
                  visit(t);
              }
            }
      },
      out);
}

int TriangleMesh::touches_brute_force(const Vec3& c, double r, MeshTouch* out) const {
  return resolve(
      c, r,
      [&](auto&& visit) {
        for (std::size_t t = 0; t < tris_.size(); ++t) visit(static_cast<int>(t));
      },
      out);
}

bool TriangleMesh::encloses(const Vec3& x) const {
  if ((x.array() < lo_.array()).any() || (x.array() > hi_.array()).any()) return false;
  // A skew direction, so that the ray meets no edge or vertex of an axis-aligned mesh exactly
  // (Moller & Trumbore 1997, ray-triangle intersection).
  const Vec3 d = Vec3(1, 0.0014142135623730951, 0.0017320508075688772).normalized();
  bool inside = false;
  for (const auto& t : tris_) {
    const Vec3& a = verts_[t[0]];
    const Vec3 e1 = verts_[t[1]] - a, e2 = verts_[t[2]] - a;
    const Vec3 pv = d.cross(e2);
    const double det = e1.dot(pv);
    if (std::abs(det) < 1e-300) continue;  // parallel to the ray
    const Vec3 tv = x - a;
    const double u = tv.dot(pv) / det;
    if (u < 0 || u > 1) continue;
    const Vec3 qv = tv.cross(e1);
    const double v = d.dot(qv) / det;
    if (v < 0 || u + v > 1) continue;
    if (e2.dot(qv) / det > 0) inside = !inside;
  }
  return inside;
}

}  // namespace grainflow
