// Medit .mesh writer (ASCII); contract in io.hpp.
#include "spinesim/mesh/io.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "write_checks.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <map>
#include <ostream>
#include <stdexcept>
#include <vector>

namespace spinesim::mesh {
namespace {

/// Outward faces of a positively oriented tet (det[v1-v0, v2-v0, v3-v0] > 0): the normal of
/// each (right-hand rule) points away from the opposite vertex.
constexpr int kOutwardFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

struct BoundaryFace {
  std::array<int, 3> v;  // outward orientation
  int count = 0;
};

/// Faces used by exactly one tet, outward oriented, in first-seen order.
std::vector<std::array<int, 3>> boundary_faces(const TetMesh& m) {
  std::map<std::array<int, 3>, BoundaryFace> faces;  // key: sorted vertex indices
  std::vector<std::array<int, 3>> order;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (const auto& f : kOutwardFaces) {
      const std::array<int, 3> v = {m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2])};
      std::array<int, 3> key = v;
      std::sort(key.begin(), key.end());
      auto [it, inserted] = faces.try_emplace(key);
      if (inserted) {
        it->second.v = v;
        order.push_back(key);
      }
      ++it->second.count;
    }
  std::vector<std::array<int, 3>> out;
  for (const auto& key : order) {
    const BoundaryFace& f = faces.at(key);
    if (f.count == 1) out.push_back(f.v);
  }
  return out;
}

void put_double(std::ostream& os, double x) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);  // shortest exact form
  os.write(buf, res.ptr - buf);
}

}  // namespace

void write_medit(const std::string& path, const TetMesh& m) {
  // 1. Refuse bad input before touching the disk.
  const std::string who = "write_medit: " + path + ": ";
  detail::check_mesh_for_writing(m, who);

  // 2. Boundary triangles and their labels: the label all three vertices share, if nonzero,
  //    else outer wall.
  const auto tris = boundary_faces(m);
  std::vector<int> tri_ref(tris.size());
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const int a = m.surface(tris[i][0]), b = m.surface(tris[i][1]), c = m.surface(tris[i][2]);
    tri_ref[i] = (a == b && b == c && a != 0) ? a : int(Surface::outer_wall);
  }

  // 3. Write (1-based indices).
  write_atomically("write_medit", path, [&](std::ostream& os) {
    os << "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n" << m.num_vertices() << "\n";
    for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
      for (int j = 0; j < 3; ++j) {
        put_double(os, m.V(i, j));
        os << ' ';
      }
      os << m.surface(i) << '\n';
    }
    os << "\nTetrahedra\n" << m.num_tets() << "\n";
    for (Eigen::Index t = 0; t < m.num_tets(); ++t)
      os << m.T(t, 0) + 1 << ' ' << m.T(t, 1) + 1 << ' ' << m.T(t, 2) + 1 << ' ' << m.T(t, 3) + 1
         << ' ' << m.region(t) << '\n';
    os << "\nTriangles\n" << tris.size() << "\n";
    for (std::size_t i = 0; i < tris.size(); ++i)
      os << tris[i][0] + 1 << ' ' << tris[i][1] + 1 << ' ' << tris[i][2] + 1 << ' ' << tri_ref[i]
         << '\n';
    os << "\nEnd\n";
  });
}

}  // namespace spinesim::mesh
