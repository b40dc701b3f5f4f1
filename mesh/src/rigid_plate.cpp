#include "spinesim/mesh/rigid_plate.hpp"
#include "spinesim/common/skew.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace spinesim::mesh {

PlateMap plate_map(const Eigen::Vector3d& r) {
  PlateMap R;
  R.leftCols<3>().setIdentity();
  R.rightCols<3>() = -skew(r);  // theta × r = −[r]× theta
  return R;
}

namespace {
bool on_plate(const TetMesh& m, Eigen::Index i) {
  return m.surface(i) == int(Surface::superior_endplate);
}
}  // namespace

double plate_rms_displacement(const TetMesh& m, const Eigen::Vector3d& c,
                              const Eigen::Matrix<double, 6, 1>& q) {
  double sum = 0;
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    if (on_plate(m, i)) {
      const Eigen::Vector3d r = m.V.row(i).transpose() - c;
      sum += (q.head<3>() + q.tail<3>().cross(r)).squaredNorm();
      ++n;
    }
  return n ? std::sqrt(sum / double(n)) : 0.0;
}

double plate_rms_radius(const TetMesh& m, const Eigen::Vector3d& c) {
  double sum = 0;
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    if (on_plate(m, i)) {
      sum += (m.V.row(i).transpose() - c).squaredNorm();
      ++n;
    }
  return n ? std::sqrt(sum / double(n)) : 1.0;
}

}  // namespace spinesim::mesh
