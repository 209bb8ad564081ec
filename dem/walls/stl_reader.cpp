#include "dem/walls/stl_reader.hpp"

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <unordered_map>

namespace grainflow {
namespace {

// Vertex and triangle indices are ints: at most three vertices per triangle must fit.
constexpr std::size_t kMaxTriangles = INT_MAX / 3;

struct RawTriangle {
  std::array<Vec3, 3> v;
  long where;  // ASCII: line of the facet; binary: triangle number (1-based)
};

[[noreturn]] void fail(const std::string& label, const std::string& where,
                       const std::string& what) {
  throw GeometryError(label + where + ": error: " + what);
}

// A word of the file for a message: at most 40 characters, bytes that are not
// printable shown as '?', so a binary file read as text cannot flood the terminal.
std::string as_shown(const std::string& word) {
  std::string out = "'";
  for (std::size_t i = 0; i < std::min<std::size_t>(word.size(), 40); ++i) {
    const unsigned char c = static_cast<unsigned char>(word[i]);
    out += c >= 32 && c < 127 ? static_cast<char>(c) : '?';
  }
  return out + (word.size() > 40 ? "...'" : "'");
}

// An ASCII STL is plain text; a binary STL's float data almost always holds bytes that
// no text has (NUL, control characters), even when its header starts with "solid".
bool is_text(const std::string& b) {
  return std::none_of(b.begin(), b.end(), [](char ch) {
    const unsigned char c = static_cast<unsigned char>(ch);
    return c < 32 && c != '\t' && c != '\n' && c != '\r' && c != '\f' && c != '\v';
  });
}

bool looks_binary(const std::string& b, std::uint32_t& count) {
  if (b.size() < 84) return false;
  std::memcpy(&count, b.data() + 80, 4);  // little-endian on every supported platform
  return b.size() == 84 + 50 * static_cast<std::uint64_t>(count);
}

std::vector<RawTriangle> read_binary(const std::string& b, std::uint32_t count,
                                     const std::string& label) {
  if (count > kMaxTriangles)
    fail(label, "", "binary STL declares " + std::to_string(count) + " triangles; at most " +
                        std::to_string(kMaxTriangles) + " are supported");
  std::vector<RawTriangle> out(count);
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* rec = b.data() + 84 + 50 * static_cast<std::size_t>(t);
    float f[12];
    std::memcpy(f, rec, sizeof f);
    for (int k = 0; k < 3; ++k) {
      out[t].v[k] = Vec3(f[3 + 3 * k], f[4 + 3 * k], f[5 + 3 * k]);
      if (!out[t].v[k].allFinite())
        fail(label, "", "binary triangle " + std::to_string(t + 1) + " of " +
                            std::to_string(count) + ": vertex " + std::to_string(k + 1) +
                            " has a non-finite coordinate (NaN or inf); repair the mesh in "
                            "its CAD tool");
    }
    out[t].where = t + 1;
  }
  return out;
}

std::vector<RawTriangle> read_ascii(const std::string& b, const std::string& label) {
  std::vector<RawTriangle> out;
  std::istringstream in(b);
  std::string line;
  long lineno = 0;
  bool in_facet = false, in_loop = false;
  long facet_line = 0;
  int nv = 0;
  RawTriangle cur{};
  auto at = [](long l) {
    std::string where = ":";  // (not ":" + to_string: GCC 12 false -Wrestrict)
    where += std::to_string(l);
    return where;
  };
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream words(line);
    std::string word;
    if (!(words >> word)) continue;
    // Keywords in any case: some exporters write "SOLID", "FACET NORMAL", "VERTEX".
    std::string key = word;
    std::transform(key.begin(), key.end(), key.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (key == "solid" || key == "endsolid") {
      if (in_facet) fail(label, at(lineno), "'" + key + "' inside the facet begun at line " +
                                                std::to_string(facet_line));
    } else if (key == "facet") {
      if (in_facet) fail(label, at(lineno), "'facet' before 'endfacet' of the facet at line " +
                                                std::to_string(facet_line));
      in_facet = true;
      facet_line = lineno;
      nv = 0;
    } else if (key == "outer") {
      if (!in_facet || in_loop) fail(label, at(lineno), "'outer loop' outside a facet");
      in_loop = true;
    } else if (key == "vertex") {
      if (!in_loop) fail(label, at(lineno), "'vertex' outside 'outer loop'");
      Vec3 x;
      for (int a = 0; a < 3; ++a) {
        std::string s;
        char* end = nullptr;
        if (!(words >> s)) fail(label, at(lineno), "a vertex needs three coordinates");
        x[a] = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0')
          fail(label, at(lineno), "coordinate " + as_shown(s) + " is not a number");
        if (!std::isfinite(x[a]))
          fail(label, at(lineno), "vertex coordinate " + as_shown(s) +
                                      " is not finite (NaN or inf); repair the mesh in its CAD "
                                      "tool");
      }
      if (std::string extra; words >> extra)
        fail(label, at(lineno), "a vertex has three coordinates, but " + as_shown(extra) +
                                    " follows the third");
      if (nv < 3) cur.v[nv] = x;
      ++nv;
    } else if (key == "endloop") {
      if (!in_loop) fail(label, at(lineno), "'endloop' without 'outer loop'");
      if (nv != 3)
        fail(label, at(facet_line), "facet " + std::to_string(out.size() + 1) + " has " +
                                        std::to_string(nv) +
                                        " vertices; STL facets must be triangles");
      in_loop = false;
    } else if (key == "endfacet") {
      if (!in_facet || in_loop || nv != 3)
        fail(label, at(lineno), "'endfacet' without a complete 'outer loop' of three vertices");
      cur.where = facet_line;
      if (out.size() == kMaxTriangles)
        fail(label, at(lineno), "more than " + std::to_string(kMaxTriangles) +
                                    " triangles; at most that many are supported");
      out.push_back(cur);
      in_facet = false;
    } else {
      fail(label, at(lineno),
           "unexpected " + as_shown(word) +
               " in an ASCII STL file (expected solid, facet, outer loop, "
               "vertex, endloop, endfacet, endsolid)");
    }
  }
  if (in_facet)
    fail(label, at(lineno), "the file ends inside the facet begun at line " +
                                std::to_string(facet_line) + " (truncated file?)");
  return out;
}

struct BitsHash {
  std::size_t operator()(const std::array<std::uint64_t, 3>& k) const {
    return (k[0] * 0x9E3779B97F4A7C15ull) ^ (k[1] * 0xC2B2AE3D27D4EB4Full) ^ k[2];
  }
};

// Points in cells of edge h from `origin` (a hashed grid: only occupied cells are stored).
// Cell numbers are clamped to +-2^62: a tolerance far below the coordinates' spacing puts
// distant points into one extreme cell, which costs time but never a wrong answer (the
// distance is always checked).
class PointCells {
 public:
  PointCells(double h, const Vec3& origin) : inv_(1 / h), origin_(origin) {}
  std::array<std::int64_t, 3> cell(const Vec3& x) const {
    constexpr double kMax = 4.6e18;  // < 2^62
    std::array<std::int64_t, 3> c;
    for (int a = 0; a < 3; ++a) {
      double v = std::floor((x[a] - origin_[a]) * inv_);
      if (!(v > -kMax)) v = -kMax;  // also NaN (0 * inf)
      if (!(v < kMax)) v = kMax;
      c[a] = static_cast<std::int64_t>(v);
    }
    return c;
  }
  void add(const Vec3& x, int k) { cells_[key(cell(x))].push_back(k); }
  // Calls f(k) for every point stored in the 27 cells around x.
  template <class F>
  void around(const Vec3& x, F&& f) const {
    const auto c = cell(x);
    for (std::int64_t dz = -1; dz <= 1; ++dz)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it != cells_.end())
            for (int k : it->second) f(k);
        }
  }

 private:
  static std::array<std::uint64_t, 3> key(const std::array<std::int64_t, 3>& c) {
    return {static_cast<std::uint64_t>(c[0]), static_cast<std::uint64_t>(c[1]),
            static_cast<std::uint64_t>(c[2])};
  }
  double inv_;
  Vec3 origin_;
  std::unordered_map<std::array<std::uint64_t, 3>, std::vector<int>, BitsHash> cells_;
};

double diagonal_of(const std::vector<Vec3>& x) {
  if (x.empty()) return 0;
  Vec3 lo = x[0], hi = x[0];
  for (const Vec3& v : x) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return (hi - lo).norm();
}

// For each vertex, the kept vertex it joins (itself if kept): the first kept vertex, in
// order, within `tol`. Counts the joined ones in `welded`.
std::vector<int> weld(const std::vector<Vec3>& x, double tol, long& welded) {
  std::vector<int> to(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) to[k] = static_cast<int>(k);
  if (!(tol > 0)) return to;
  PointCells cells(tol, x.empty() ? Vec3::Zero() : x[0]);
  for (std::size_t k = 0; k < x.size(); ++k) {
    int into = -1;
    cells.around(x[k], [&](int q) {
      if ((into < 0 || q < into) && (x[q] - x[k]).norm() <= tol) into = q;
    });
    if (into >= 0) {
      to[k] = into;
      ++welded;
    } else {
      cells.add(x[k], static_cast<int>(k));
    }
  }
  return to;
}

// An undirected edge a - b as one number, and how many triangles use each edge.
std::uint64_t edge_key(int a, int b) {
  return static_cast<std::uint64_t>(std::min(a, b)) << 32 |
         static_cast<std::uint32_t>(std::max(a, b));
}
std::unordered_map<std::uint64_t, int> edge_uses(const std::vector<std::array<int, 3>>& tris) {
  std::unordered_map<std::uint64_t, int> uses;
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) ++uses[edge_key(t[e], t[(e + 1) % 3])];
  return uses;
}

// Counts the edges of one triangle, and finds the closest two vertices on such edges that
// share no triangle, if closer than 1e-3 of the diagonal (a seam the welding left open).
void find_open_edges(const std::vector<Vec3>& x, const std::vector<std::array<int, 3>>& tris,
                     StlReport& rep) {
  const std::unordered_map<std::uint64_t, int> uses = edge_uses(tris);
  std::vector<char> on_rim(x.size(), 0);
  std::vector<double> shortest(x.size(), INFINITY);  // open edge at each rim vertex
  for (const auto& [key, n] : uses)
    if (n == 1) {
      ++rep.open_edges;
      const auto a = static_cast<std::size_t>(key >> 32),
                 b = static_cast<std::size_t>(key & 0xffffffffu);
      on_rim[a] = on_rim[b] = 1;
      const double len = (x[a] - x[b]).norm();
      shortest[a] = std::min(shortest[a], len);
      shortest[b] = std::min(shortest[b], len);
    }
  const double reach = 1e-3 * diagonal_of(x);
  if (rep.open_edges == 0 || !(reach > 0)) return;
  // Triangles around each rim vertex, to skip pairs of one triangle (a rim's own edges).
  std::unordered_map<int, std::vector<int>> around;
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int v : tris[t])
      if (on_rim[v]) around[v].push_back(static_cast<int>(t));
  PointCells cells(reach, x[0]);
  double best = reach;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!on_rim[k]) continue;
    cells.around(x[k], [&](int q) {
      const double d = (x[q] - x[k]).norm();
      // A seam's gap is small against the edges around it; vertices a rim's edge or two
      // apart along a finely divided rim are not one.
      if (d >= best || !(d < 0.5 * std::min(shortest[k], shortest[q]))) return;
      for (int t : around[q])
        if (std::find(around[k].begin(), around[k].end(), t) != around[k].end()) return;
      best = d;
      rep.seam_gap = d;
      rep.seam_at = x[k];
    });
    cells.add(x[k], static_cast<int>(k));
  }
}

// Closes T-junctions: a vertex lying inside another triangle's open edge (a CAD export that
// split one side of a seam and not the other). Welding cannot join them (no vertex is near
// another), and a sphere on that line would feel the triangle's edge as a second contact
// besides the neighbours' face (rule 2 of docs/theory/walls.md sees no shared edge). The
// triangle is split at such vertices (a fan from its opposite vertex, the same turning), so the
// edge is shared. `tol`: how far off the edge a vertex may lie [m]. Repeats until none is
// left (a triangle with such vertices on two edges); returns the vertices joined.
long close_t_junctions(const std::vector<Vec3>& x, std::vector<std::array<int, 3>>& tris,
                       double tol) {
  long joined = 0;
  for (int pass = 0; pass < 8; ++pass) {
    const std::unordered_map<std::uint64_t, int> uses = edge_uses(tris);
    std::vector<char> on_rim(x.size(), 0);
    double length = 0;
    long open = 0;
    for (const auto& [key, n] : uses)
      if (n == 1) {
        const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
        on_rim[a] = on_rim[b] = 1;
        length += (x[a] - x[b]).norm();
        ++open;
      }
    if (open == 0) return joined;
    const double h = std::max(length / open, 4 * tol);
    PointCells cells(h, x[0]);
    for (std::size_t k = 0; k < x.size(); ++k)
      if (on_rim[k]) cells.add(x[k], static_cast<int>(k));
    std::vector<std::array<int, 3>> out;
    out.reserve(tris.size());
    long split = 0;
    for (const auto& t : tris) {
      bool done = false;
      for (int e = 0; e < 3 && !done; ++e) {
        const int a = t[e], b = t[(e + 1) % 3], c = t[(e + 2) % 3];
        if (uses.at(edge_key(a, b)) != 1) continue;
        const Vec3 ab = x[b] - x[a];
        const double len = ab.norm();
        // Rim vertices within tol of the edge's inside, by their place along it.
        std::vector<std::pair<double, int>> on;
        const int samples = static_cast<int>(std::ceil(len / h));
        for (int q = 0; q <= samples; ++q)
          cells.around(x[a] + (static_cast<double>(q) / samples) * ab, [&](int v) {
            if (v == a || v == b || v == c) return;
            const double s = (x[v] - x[a]).dot(ab) / (len * len);
            if (!(s * len > tol && (1 - s) * len > tol)) return;
            if ((x[v] - (x[a] + s * ab)).norm() > tol) return;
            for (const auto& [s0, v0] : on)
              if (v0 == v) return;
            on.emplace_back(s, v);
          });
        if (on.empty()) continue;
        std::sort(on.begin(), on.end());
        int from = a;
        for (const auto& [s0, v] : on) {
          out.push_back({from, v, c});
          from = v;
        }
        out.push_back({from, b, c});
        split += static_cast<long>(on.size());
        done = true;
      }
      if (!done) out.push_back(t);
    }
    tris.swap(out);
    joined += split;
    if (split == 0) return joined;
  }
  return joined;
}

// The closest rim vertex to another triangle's open edge, inside the edge, within `reach`
// and under half the edge's length and the vertex's own open edges, that the T-junction
// closing left (beyond its tolerance): a T-junction left open (rep.t_gap, rep.t_gap_at).
void find_t_gap(const std::vector<Vec3>& x, const std::vector<std::array<int, 3>>& tris,
                double reach, StlReport& rep) {
  const std::unordered_map<std::uint64_t, int> uses = edge_uses(tris);
  std::vector<double> shortest(x.size(), INFINITY);
  std::vector<std::pair<int, int>> open;
  double length = 0;
  for (const auto& [key, n] : uses)
    if (n == 1) {
      const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
      const double len = (x[a] - x[b]).norm();
      shortest[static_cast<std::size_t>(a)] = std::min(shortest[static_cast<std::size_t>(a)], len);
      shortest[static_cast<std::size_t>(b)] = std::min(shortest[static_cast<std::size_t>(b)], len);
      open.emplace_back(a, b);
      length += len;
    }
  if (open.empty() || !(reach > 0)) return;
  const double h = std::max(length / static_cast<double>(open.size()), reach);
  PointCells cells(h, x[0]);
  for (std::size_t k = 0; k < x.size(); ++k)
    if (std::isfinite(shortest[k])) cells.add(x[k], static_cast<int>(k));
  double best = reach;
  for (const auto& edge : open) {
    const int a = edge.first, b = edge.second;  // named: a lambda below uses them
    const Vec3 ab = x[b] - x[a];
    const double len = ab.norm();
    const int samples = static_cast<int>(std::ceil(len / h));
    for (int q = 0; q <= samples; ++q)
      cells.around(x[a] + (static_cast<double>(q) / samples) * ab, [&](int v) {
        if (v == a || v == b) return;
        const double s = (x[v] - x[a]).dot(ab) / (len * len);
        if (!(s > 0 && s < 1)) return;
        const double d = (x[v] - (x[a] + s * ab)).norm();
        if (!(d < best) || !(d < 0.5 * std::min(len, shortest[static_cast<std::size_t>(v)])) ||
            !(s * len > d && (1 - s) * len > d))
          return;
        best = d;
        rep.t_gap = d;
        rep.t_gap_at = x[v];
      });
  }
}

}  // namespace

Vec3 MeshTransform::apply(const Vec3& x) const {
  return Eigen::AngleAxisd(rotation_angle, rotation_axis) * (scale * x) + translation;
}

TriangleMesh parse_stl(const std::string& bytes, const std::string& label,
                       const MeshTransform& transform, StlReport* report, double weld_tolerance) {
  std::uint32_t count = 0;
  // An ASCII STL saved with a UTF-8 byte-order mark (some editors on Windows): read past it.
  if (bytes.starts_with("\xEF\xBB\xBF") && !looks_binary(bytes, count))
    return parse_stl(bytes.substr(3), label, transform, report, weld_tolerance);
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  std::vector<RawTriangle> raw;
  StlReport rep;
  const auto lower = [](unsigned char c) { return static_cast<char>(std::tolower(c)); };
  bool starts_solid = first != std::string::npos && bytes.size() >= first + 5;
  for (std::size_t k = 0; starts_solid && k < 5; ++k)
    starts_solid = lower(bytes[first + k]) == "solid"[k];
  if (looks_binary(bytes, count)) {
    rep.binary = true;
    raw = read_binary(bytes, count, label);
  } else if (starts_solid && (bytes.size() < 84 || is_text(bytes))) {
    raw = read_ascii(bytes, label);
  } else if (bytes.size() >= 84) {
    // The count is only compared with the file's size: nothing is allocated for it.
    const std::uint64_t expected = 84 + 50 * static_cast<std::uint64_t>(count);
    fail(label, "", "binary STL header declares " + std::to_string(count) + " triangles (" +
                        std::to_string(expected) + " bytes) but the file has " +
                        std::to_string(bytes.size()) + " bytes; " +
                        (expected > bytes.size()
                             ? "the file is truncated or not an STL file"
                             : "bytes are left over after the declared triangles (a wrong count, "
                               "or not an STL file)") +
                        (starts_solid ? " (it starts with 'solid' but holds NUL or control "
                                        "bytes, so it is not an ASCII STL either)"
                                      : ""));
  } else {
    fail(label, "", "not an STL file: it neither starts with 'solid' (ASCII) nor holds the " +
                        std::string("84-byte header of a binary STL"));
  }
  rep.facets_read = static_cast<long>(raw.size());

  // Vertices that are bit-identical in the file are one vertex; then the welding of
  // near-coincident ones (stl_reader.hpp), then the placement.
  std::unordered_map<std::array<std::uint64_t, 3>, int, BitsHash> index;
  std::vector<Vec3> unique;
  std::vector<std::array<int, 3>> raw_ids(raw.size());
  for (std::size_t t = 0; t < raw.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      std::array<std::uint64_t, 3> key;
      for (int a = 0; a < 3; ++a) {
        const double c = raw[t].v[k][a] == 0 ? 0.0 : raw[t].v[k][a];  // -0 welds with +0
        std::memcpy(&key[a], &c, 8);
      }
      const auto [it, fresh] = index.emplace(key, static_cast<int>(unique.size()));
      if (fresh) unique.push_back(raw[t].v[k]);
      raw_ids[t][k] = it->second;
    }
  decltype(index)().swap(index);
  const double diagonal = diagonal_of(unique);
  const std::vector<int> into = weld(unique, weld_tolerance * diagonal, rep.welded);
  std::vector<int> number(unique.size(), -1);  // kept vertices, numbered in order
  std::vector<Vec3> verts;
  for (std::size_t k = 0; k < unique.size(); ++k)
    if (into[k] == static_cast<int>(k)) {
      number[k] = static_cast<int>(verts.size());
      verts.push_back(unique[k]);
    }
  std::vector<std::array<int, 3>> tris;
  for (std::size_t t = 0; t < raw.size(); ++t) {
    std::array<int, 3> ids;
    for (int k = 0; k < 3; ++k) ids[k] = number[into[raw_ids[t][k]]];
    const Vec3 a = verts[ids[0]], b = verts[ids[1]], c = verts[ids[2]];
    const Vec3 ab = b - a, ac = c - a, bc = c - b;
    const double longest2 = std::max({ab.squaredNorm(), ac.squaredNorm(), bc.squaredNorm()});
    if (ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] ||
        ab.cross(ac).norm() <= 1e-12 * longest2) {
      ++rep.degenerate_removed;
      continue;
    }
    tris.push_back(ids);
  }
  if (tris.empty())
    fail(label, "", raw.empty() ? "the STL file holds no triangles"
                                : "all " + std::to_string(raw.size()) +
                                      " triangles of the STL file are degenerate (zero area)");
  for (Vec3& x : verts) {
    x = transform.apply(x);
    if (!x.allFinite()) {
      std::ostringstream scale;
      scale << transform.scale;
      fail(label, "", "the placement (scale " + scale.str() +
                          ") moves a vertex to a non-finite position; use a smaller scale");
    }
  }
  rep.diagonal = diagonal * transform.scale;
  rep.weld_distance = weld_tolerance * rep.diagonal;
  rep.t_junctions =
      close_t_junctions(verts, tris, std::max(rep.weld_distance, 1e-9 * rep.diagonal));
  find_open_edges(verts, tris, rep);
  find_t_gap(verts, tris, 1e-3 * rep.diagonal, rep);
  rep.vertices = static_cast<long>(verts.size());
  if (report) *report = rep;
  return TriangleMesh(std::move(verts), std::move(tris));
}

TriangleMesh read_stl(const std::string& path, const MeshTransform& transform, StlReport* report,
                      double weld_tolerance) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw GeometryError(path + ": error: cannot open the STL file");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_stl(s.str(), path, transform, report, weld_tolerance);
}

void write_ascii_stl(const std::string& path, const std::vector<Vec3>& vertices,
                     const std::vector<std::array<int, 3>>& triangles) {
  std::ofstream out(path);
  out << std::setprecision(17) << "solid grainflow\n";
  for (const auto& t : triangles) {
    const Vec3 n =
        (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]).normalized();
    out << "  facet normal " << n[0] << ' ' << n[1] << ' ' << n[2] << "\n    outer loop\n";
    for (int k = 0; k < 3; ++k)
      out << "      vertex " << vertices[t[k]][0] << ' ' << vertices[t[k]][1] << ' '
          << vertices[t[k]][2] << "\n";
    out << "    endloop\n  endfacet\n";
  }
  out << "endsolid grainflow\n";
  if (!out) throw GeometryError(path + ": error: cannot write the STL file");
}

}  // namespace grainflow
