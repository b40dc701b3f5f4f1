#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace spinesim::mesh {

double tet_volume(const TetMesh& m, Eigen::Index t) {
  const Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)),
                        d = m.V.row(m.T(t, 3));
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

double mesh_volume(const TetMesh& m) {
  double v = 0.0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) v += tet_volume(m, t);
  return v;
}

void validate_frame(const DiscFrame& f, const std::string& what) {
  const Eigen::Matrix3d& A = f.axes;
  if (!A.allFinite() || !f.origin_mm.allFinite())
    throw std::invalid_argument(what + ": non-finite axes or origin");
  if (f.origin_mm.cwiseAbs().maxCoeff() > 1e6)
    throw std::invalid_argument(what + ": origin beyond 1e6 mm (1 km): not in mm, or corrupt");
  const double off = (A.transpose() * A - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(off <= 1e-6)) {
    std::ostringstream os;
    os << what << ": the axes are not orthonormal (|A^T A - I| = " << off
       << "): they must be the disc's unit lateral, axial and anterior directions";
    throw std::invalid_argument(os.str());
  }
}

void validate_fibre_paths(const TetMesh& m) {
  const FibrePaths& f = m.fibre_paths;
  if (f.empty()) return;
  const Eigen::MatrixX3d* family[2] = {&f.direction_1, &f.direction_2};
  for (int k = 0; k < 2; ++k) {
    const std::string name = "mesh fibre_path_direction_" + std::to_string(k + 1);
    const Eigen::MatrixX3d& d = *family[k];
    if (d.rows() != m.num_tets())
      throw std::invalid_argument(name + ": " + std::to_string(d.rows()) + " rows for " +
                                  std::to_string(m.num_tets()) +
                                  " tetrahedra (both families, one row per tet)");
    for (Eigen::Index t = 0; t < d.rows(); ++t) {
      const double n = d.row(t).norm();
      if (!std::isfinite(n) || (n != 0.0 && std::abs(n - 1.0) > 1e-4)) {
        std::ostringstream os;
        os << name << ": tet #" << t << " has a direction of length " << n
           << " (expected a unit vector, or zero where the tet has no fibres)";
        throw std::invalid_argument(os.str());
      }
    }
  }
}

void validate(const TetMesh& m) {
  validate_frame(m.frame, "mesh disc_frame");
  if (m.num_vertices() == 0 || m.num_tets() == 0)
    throw std::invalid_argument("mesh is empty (no vertices or no tetrahedra)");
  if (!m.V.allFinite()) throw std::invalid_argument("mesh has non-finite vertex coordinates");
  // Beyond a kilometre no body is in mm, and volumes of such coordinates overflow or lose every
  // digit (a 1e200 mm point would be reported as a "zero-volume" tetrahedron).
  Eigen::Index row = 0, col = 0;
  if (m.V.cwiseAbs().maxCoeff(&row, &col) > 1e6) {
    std::ostringstream os;
    os << "mesh vertex #" << row << " has a coordinate of " << m.V(row, col)
       << " mm, beyond 1e6 mm (1 km): the mesh is not in mm, or the file is corrupt";
    throw std::invalid_argument(os.str());
  }
  if (m.region.size() != m.num_tets())
    throw std::invalid_argument("mesh region labels: expected one per tetrahedron");
  if (m.surface.size() != m.num_vertices())
    throw std::invalid_argument("mesh surface labels: expected one per vertex");
  if (m.T.minCoeff() < 0 || m.T.maxCoeff() >= m.num_vertices())
    throw std::invalid_argument("mesh has a tetrahedron with a vertex index out of range");
  validate_fibre_paths(m);
  // Zero volume is judged relative to the mean edge length cubed (scale-free).
  double edge_sum = 0.0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    edge_sum += (m.V.row(m.T(t, 1)) - m.V.row(m.T(t, 0))).norm();
  const double h = edge_sum / double(m.num_tets());
  const double tiny = 1e-12 * h * h * h;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    const double v = tet_volume(m, t);
    if (!(v > tiny)) {
      std::ostringstream os;
      os << "mesh has an " << (v < -tiny ? "inverted" : "zero-volume") << " tetrahedron (#" << t
         << ", signed volume " << v << " mm^3)";
      throw std::invalid_argument(os.str());
    }
  }
}

void require_endplate_labels(const TetMesh& m) {
  const bool has_inferior = (m.surface.array() == int(Surface::inferior_endplate)).any();
  const bool has_superior = (m.surface.array() == int(Surface::superior_endplate)).any();
  if (!has_inferior || !has_superior)
    throw std::invalid_argument(
        "mesh has no endplate labels (point data 'surface' needs nodes labelled 1 = inferior "
        "and 2 = superior endplate)");
}

Eigen::MatrixX3i boundary_faces(const Eigen::MatrixXi& T, Eigen::VectorXi* owner) {
  // Face k of a tet is opposite corner k, ordered so that its normal points away from it.
  static constexpr int kOutward[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  struct Seen {
    int count = 0;
    Eigen::Index tet = 0;
    int face = 0;
  };
  std::map<std::array<int, 3>, Seen> faces;  // key: sorted vertex indices
  std::vector<std::array<int, 3>> order;
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> key = {T(t, kOutward[f][0]), T(t, kOutward[f][1]), T(t, kOutward[f][2])};
      std::sort(key.begin(), key.end());
      auto [it, inserted] = faces.try_emplace(key);
      if (inserted) {
        it->second.tet = t, it->second.face = f;
        order.push_back(key);
      }
      ++it->second.count;
    }
  std::vector<const Seen*> once;
  for (const auto& key : order)
    if (const Seen& s = faces.at(key); s.count == 1) once.push_back(&s);
  Eigen::MatrixX3i F(Eigen::Index(once.size()), 3);
  if (owner) owner->resize(F.rows());
  for (Eigen::Index i = 0; i < F.rows(); ++i) {
    const Seen& s = *once[std::size_t(i)];
    for (int k = 0; k < 3; ++k) F(i, k) = T(s.tet, kOutward[s.face][k]);
    if (owner) (*owner)(i) = int(s.tet);
  }
  return F;
}

}  // namespace spinesim::mesh
