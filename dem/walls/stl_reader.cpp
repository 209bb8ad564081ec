#include "dem/walls/stl_reader.hpp"

#include <algorithm>
#include <cmath>
#include <climits>
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
    std::string key;
    if (!(words >> key)) continue;
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
      fail(label, at(lineno), "unexpected " + as_shown(key) +
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

}  // namespace

Vec3 MeshTransform::apply(const Vec3& x) const {
  return Eigen::AngleAxisd(rotation_angle, rotation_axis) * (scale * x) + translation;
}

TriangleMesh parse_stl(const std::string& bytes, const std::string& label,
                       const MeshTransform& transform, StlReport* report) {
  std::uint32_t count = 0;
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  std::vector<RawTriangle> raw;
  StlReport rep;
  const bool starts_solid = first != std::string::npos && bytes.compare(first, 5, "solid") == 0;
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

  // Weld vertices that are bit-identical in the file, then place them.
  std::unordered_map<std::array<std::uint64_t, 3>, int, BitsHash> index;
  std::vector<Vec3> verts;
  std::vector<std::array<int, 3>> tris;
  for (const RawTriangle& t : raw) {
    std::array<int, 3> ids;
    for (int k = 0; k < 3; ++k) {
      std::array<std::uint64_t, 3> key;
      for (int a = 0; a < 3; ++a) {
        const double c = t.v[k][a] == 0 ? 0.0 : t.v[k][a];  // -0 welds with +0
        std::memcpy(&key[a], &c, 8);
      }
      const auto [it, fresh] = index.emplace(key, static_cast<int>(verts.size()));
      if (fresh) verts.push_back(t.v[k]);
      ids[k] = it->second;
    }
    const Vec3 ab = t.v[1] - t.v[0], ac = t.v[2] - t.v[0], bc = t.v[2] - t.v[1];
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
  rep.vertices = static_cast<long>(verts.size());
  if (report) *report = rep;
  return TriangleMesh(std::move(verts), std::move(tris));
}

TriangleMesh read_stl(const std::string& path, const MeshTransform& transform,
                      StlReport* report) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw GeometryError(path + ": error: cannot open the STL file");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_stl(s.str(), path, transform, report);
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
