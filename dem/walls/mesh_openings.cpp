#include "dem/walls/mesh_openings.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>

namespace grainflow {
namespace {

using Vec2 = Eigen::Vector2d;

// The loop projected onto the plane that fits it best (Newell's normal; for a loop that bounds
// no area, the plane of its two widest directions), about its centre.
std::vector<Vec2> in_plane(const std::vector<Vec3>& p, const Vec3& centre) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i)
    n += (p[i] - centre).cross(p[(i + 1) % p.size()] - centre);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3& x : p) cov += (x - centre) * (x - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (!(n.norm() > 1e-12 * cov.trace())) n = eig.eigenvectors().col(0);  // least spread
  n.normalize();
  const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Vec2> q;
  q.reserve(p.size());
  for (const Vec3& x : p) q.emplace_back(u.dot(x - centre), v.dot(x - centre));
  return q;
}

double turn(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// The area of the convex hull of the points (Andrew's monotone chain, shoelace formula).
double hull_area(std::vector<Vec2> q) {
  std::sort(q.begin(), q.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  std::vector<Vec2> h(2 * q.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    while (k >= 2 && turn(h[k - 2], h[k - 1], q[i]) <= 0) --k;
    h[k++] = q[i];
  }
  for (std::size_t i = q.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && turn(h[k - 2], h[k - 1], q[i]) <= 0) --k;
    h[k++] = q[i];
  }
  double area = 0;
  for (std::size_t i = 0; i + 1 < k; ++i) area += h[i].x() * h[i + 1].y() - h[i + 1].x() * h[i].y();
  return std::abs(area) / 2;
}

// The diameter of the largest circle inside the polygon q (even-odd rule): twice the largest
// distance from an inside point to the polygon's edges. A grid of 40 x 40 points finds the
// region, then a compass search (8 directions, the step halved when none gains) climbs to the
// maximum, to 1e-12 of the polygon's size. This is what a sphere must pass through: a slot's
// width, a circle's diameter, a serpentine slit's width however long.
double inscribed_diameter(const std::vector<Vec2>& q) {
  Vec2 lo = q[0], hi = q[0];
  for (const Vec2& x : q) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const std::size_t m = q.size();
  const auto inside = [&](const Vec2& x) {
    bool in = false;
    for (std::size_t i = 0, j = m - 1; i < m; j = i++)
      if ((q[i].y() > x.y()) != (q[j].y() > x.y()) &&
          x.x() < q[j].x() + (x.y() - q[j].y()) * (q[i].x() - q[j].x()) / (q[i].y() - q[j].y()))
        in = !in;
    return in;
  };
  const auto clearance = [&](const Vec2& x) {
    double d2 = INFINITY;
    for (std::size_t i = 0, j = m - 1; i < m; j = i++) {
      const Vec2 e = q[i] - q[j];
      const double t = std::clamp((x - q[j]).dot(e) / std::max(e.squaredNorm(), 1e-300), 0.0, 1.0);
      d2 = std::min(d2, (x - q[j] - t * e).squaredNorm());
    }
    return std::sqrt(d2);
  };
  constexpr int kGrid = 40;
  const Vec2 cell = (hi - lo) / kGrid;
  double best = 0;
  Vec2 at = lo;
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      const Vec2 x = lo + Vec2((i + 0.5) * cell.x(), (j + 0.5) * cell.y());
      if (!inside(x)) continue;
      const double d = clearance(x);
      if (d > best) {
        best = d;
        at = x;
      }
    }
  if (best == 0) return 0;
  const double size = (hi - lo).maxCoeff();
  const double r = std::sqrt(0.5);
  const Vec2 dirs[8] = {Vec2(1, 0), Vec2(-1, 0), Vec2(0, 1),  Vec2(0, -1),
                        Vec2(r, r), Vec2(r, -r), Vec2(-r, r), Vec2(-r, -r)};
  for (double h = cell.maxCoeff(); h > 1e-12 * size;) {
    bool moved = false;
    for (const Vec2& d : dirs) {
      const Vec2 x = at + h * d;
      if (!inside(x)) continue;
      const double c = clearance(x);
      if (c > best) {
        best = c;
        at = x;
        moved = true;
      }
    }
    if (!moved) h /= 2;
  }
  return 2 * best;
}

}  // namespace

std::vector<MeshOpening> mesh_openings(const TriangleMesh& mesh) {
  const auto key = [](int a, int b) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32 |
           static_cast<std::uint32_t>(b);
  };
  // Connected parts of the mesh (triangles sharing vertices): each has its own outer rim.
  const std::vector<Vec3>& x = mesh.vertices();
  std::vector<int> part(x.size());
  std::iota(part.begin(), part.end(), 0);
  const auto root = [&](int v) {
    while (part[static_cast<std::size_t>(v)] != v)
      v = part[static_cast<std::size_t>(v)] =
          part[static_cast<std::size_t>(part[static_cast<std::size_t>(v)])];
    return v;
  };
  for (const auto& t : mesh.triangles())
    for (int e = 1; e < 3; ++e) part[static_cast<std::size_t>(root(t[e]))] = root(t[0]);
  // Uses of each edge; the open ones (one use) are walked as loops, in either direction (an
  // STL's triangles need not all turn the same way).
  std::unordered_map<std::uint64_t, int> uses;
  for (const auto& t : mesh.triangles())
    for (int e = 0; e < 3; ++e)
      ++uses[key(std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3]))];
  std::unordered_multimap<int, int> next;  // each open edge a - b, as a -> b and b -> a
  for (const auto& [k, n] : uses)
    if (n == 1) {
      const int a = static_cast<int>(k >> 32), b = static_cast<int>(k & 0xffffffffu);
      next.emplace(a, b);
      next.emplace(b, a);
    }
  const auto take = [&](int a, int b) {  // removes the edge's reverse entry b -> a
    const auto range = next.equal_range(b);
    for (auto it = range.first; it != range.second; ++it)
      if (it->second == a) {
        next.erase(it);
        return;
      }
  };
  struct Loop {
    MeshOpening opening;
    int part;
    double hull_area;
    std::vector<Vec2> plane;
  };
  std::vector<Loop> loops;
  while (!next.empty()) {
    const int start = next.begin()->first;
    Loop loop;
    loop.part = root(start);
    MeshOpening& o = loop.opening;
    int at = start;
    while (true) {
      const auto it = next.find(at);
      if (it == next.end()) break;  // an open chain (a non-manifold rim): ends here
      const int to = it->second;
      next.erase(it);
      take(at, to);
      o.vertices.push_back(x[static_cast<std::size_t>(at)]);
      o.perimeter += (x[static_cast<std::size_t>(to)] - x[static_cast<std::size_t>(at)]).norm();
      at = to;
      if (at == start) break;
    }
    if (o.vertices.size() < 3) continue;
    for (const Vec3& p : o.vertices) o.centre += p;
    o.centre /= static_cast<double>(o.vertices.size());
    loop.plane = in_plane(o.vertices, o.centre);
    loop.hull_area = hull_area(loop.plane);
    // A centre on an axis by symmetry stays there, not at round-off's 1e-18.
    for (int a = 0; a < 3; ++a)
      if (std::abs(o.centre[a]) < 1e-12 * o.perimeter) o.centre[a] = 0;
    loops.push_back(std::move(loop));
  }
  // Each part's outer rim: its loop of the largest hull (a hole lies inside its rim's hull).
  std::unordered_map<int, std::size_t> rim;
  for (std::size_t k = 0; k < loops.size(); ++k) {
    const auto it = rim.find(loops[k].part);
    if (it == rim.end() || loops[k].hull_area > loops[it->second].hull_area) rim[loops[k].part] = k;
  }
  std::vector<MeshOpening> out;
  for (std::size_t k = 0; k < loops.size(); ++k) {
    if (rim[loops[k].part] == k) continue;
    loops[k].opening.width = inscribed_diameter(loops[k].plane);
    out.push_back(std::move(loops[k].opening));
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.width < b.width; });
  return out;
}

}  // namespace grainflow
