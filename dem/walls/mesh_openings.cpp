#include "dem/walls/mesh_openings.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace grainflow {
namespace {

// The narrowest extent of a closed polyline across, in the plane that fits it best (Newell's
// normal; for a loop that bounds no area, the plane of its two widest directions): the least
// width of the convex hull of its projection, which lies across one of the hull's edges
// (rotating calipers; Toussaint 1983, "Solving geometric problems with the rotating calipers").
double loop_width(const std::vector<Vec3>& p, const Vec3& centre) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i)
    n += (p[i] - centre).cross(p[(i + 1) % p.size()] - centre);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3& x : p) cov += (x - centre) * (x - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (!(n.norm() > 1e-12 * cov.trace())) n = eig.eigenvectors().col(0);  // least spread
  n.normalize();
  const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Eigen::Vector2d> q;
  q.reserve(p.size());
  for (const Vec3& x : p) q.emplace_back(u.dot(x - centre), v.dot(x - centre));
  // Andrew's monotone chain: the hull counter-clockwise, without collinear points.
  std::sort(q.begin(), q.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  const auto turn = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> h(2 * q.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    while (k >= 2 && turn(h[k - 2], h[k - 1], q[i]) <= 0) --k;
    h[k++] = q[i];
  }
  for (std::size_t i = q.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && turn(h[k - 2], h[k - 1], q[i]) <= 0) --k;
    h[k++] = q[i];
  }
  h.resize(k > 1 ? k - 1 : k);
  if (h.size() < 3) return 0;  // the loop projects onto a line: no width
  // For each hull edge the farthest hull vertex from its line; the pointer only advances.
  double width = INFINITY;
  const std::size_t m = h.size();
  for (std::size_t i = 0, j = 1; i < m; ++i) {
    const Eigen::Vector2d& a = h[i];
    const Eigen::Vector2d& b = h[(i + 1) % m];
    const double len = (b - a).norm();
    while (turn(a, b, h[(j + 1) % m]) > turn(a, b, h[j])) j = (j + 1) % m;
    width = std::min(width, turn(a, b, h[j]) / len);
  }
  return width;
}

}  // namespace

std::vector<MeshOpening> mesh_openings(const TriangleMesh& mesh) {
  const auto key = [](int a, int b) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32 |
           static_cast<std::uint32_t>(b);
  };
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
  const std::vector<Vec3>& x = mesh.vertices();
  std::vector<MeshOpening> loops;
  while (!next.empty()) {
    const int start = next.begin()->first;
    MeshOpening loop;
    int at = start;
    while (true) {
      const auto it = next.find(at);
      if (it == next.end()) break;  // an open chain (a non-manifold rim): ends here
      const int to = it->second;
      next.erase(it);
      take(at, to);
      loop.vertices.push_back(x[static_cast<std::size_t>(at)]);
      loop.perimeter += (x[static_cast<std::size_t>(to)] - x[static_cast<std::size_t>(at)]).norm();
      at = to;
      if (at == start) break;
    }
    if (loop.vertices.size() < 3) continue;
    for (const Vec3& p : loop.vertices) loop.centre += p;
    loop.centre /= static_cast<double>(loop.vertices.size());
    loop.width = loop_width(loop.vertices, loop.centre);
    // A centre on an axis by symmetry stays there, not at round-off's 1e-18.
    for (int a = 0; a < 3; ++a)
      if (std::abs(loop.centre[a]) < 1e-12 * loop.perimeter) loop.centre[a] = 0;
    loops.push_back(std::move(loop));
  }
  if (loops.empty()) return loops;
  const auto rim = std::max_element(loops.begin(), loops.end(), [](const auto& a, const auto& b) {
    return a.perimeter < b.perimeter;
  });
  loops.erase(rim);
  std::sort(loops.begin(), loops.end(),
            [](const auto& a, const auto& b) { return a.width < b.width; });
  return loops;
}

}  // namespace grainflow
