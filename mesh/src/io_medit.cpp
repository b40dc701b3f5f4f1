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
  const Eigen::MatrixX3i tris = boundary_faces(m.T);
  std::vector<int> tri_ref(std::size_t(tris.rows()));
  for (std::size_t i = 0; i < tri_ref.size(); ++i) {
    const Eigen::Index r = Eigen::Index(i);
    const int a = m.surface(tris(r, 0)), b = m.surface(tris(r, 1)), c = m.surface(tris(r, 2));
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
    os << "\nTriangles\n" << tris.rows() << "\n";
    for (Eigen::Index i = 0; i < tris.rows(); ++i)
      os << tris(i, 0) + 1 << ' ' << tris(i, 1) + 1 << ' ' << tris(i, 2) + 1 << ' '
         << tri_ref[std::size_t(i)] << '\n';
    os << "\nEnd\n";
  });
}

}  // namespace spinesim::mesh
