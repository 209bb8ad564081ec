#pragma once
// Meshes for wall tests: written as ASCII STL into the build tree and wrapped as
// scene walls.
#include <unistd.h>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "dem/scene/scene.hpp"
#include "dem/walls/stl_reader.hpp"

namespace grainflow::test {

struct MeshData {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
};

// A flat square [x0, x0 + n h] x [y0, y0 + n h] at height z, n x n squares each cut
// into two triangles (alternating diagonals, so vertices have 4 to 8 triangles).
inline MeshData flat_grid(int n, double h, double x0, double y0, double z) {
  MeshData m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.v.emplace_back(x0 + i * h, y0 + j * h, z);
  auto id = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0) {
        m.t.push_back({a, b, c});
        m.t.push_back({a, c, d});
      } else {
        m.t.push_back({a, b, d});
        m.t.push_back({b, c, d});
      }
    }
  return m;
}

// The six faces of the box [lo, hi], two triangles each, normals pointing inwards.
inline MeshData box(const Vec3& lo, const Vec3& hi) {
  MeshData m;
  for (int k = 0; k < 8; ++k)
    m.v.emplace_back(k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]);
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.t.push_back({q[0], q[1], q[2]});
    m.t.push_back({q[0], q[2], q[3]});
  }
  return m;
}

// `m` with the triangles right of the line x = x_seam given their own copies of the
// vertices on that line, moved by `offset`: the near-miss seam of a CAD export.
inline MeshData split_at(const MeshData& m, double x_seam, const Vec3& offset) {
  MeshData out = m;
  std::vector<int> copy(m.v.size(), -1);
  for (auto& t : out.t) {
    const double xc = (m.v[t[0]][0] + m.v[t[1]][0] + m.v[t[2]][0]) / 3;
    if (xc <= x_seam) continue;
    for (int& k : t) {
      if (m.v[k][0] != x_seam) continue;
      if (copy[k] < 0) {
        copy[k] = static_cast<int>(out.v.size());
        out.v.push_back(m.v[k] + offset);
      }
      k = copy[k];
    }
  }
  return out;
}

// Writes `m` as build/test_output/walls/<name> and returns the path. CTest runs each test in
// a process of its own, several at once, and tests may write the same name: the file is
// written under a name of this process's own and renamed onto `name` (atomic on POSIX), so a
// reader sees either the whole old file or the whole new one, never a truncated one. Tests
// whose meshes differ must still use names of their own.
inline std::string write_mesh(const MeshData& m, const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::path(GRAINFLOW_BINARY_DIR) / "test_output" / "walls";
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / name;
  const std::filesystem::path part = dir / (name + ".tmp." + std::to_string(::getpid()));
  write_ascii_stl(part.string(), m.v, m.t);
  std::filesystem::rename(part, path);
  return path.string();
}

inline Wall mesh_wall(const std::string& file, const std::string& name = "mesh") {
  Wall w;
  w.kind = Wall::Kind::mesh;
  w.name = name;
  w.mesh.file = file;
  return w;
}

}  // namespace grainflow::test
