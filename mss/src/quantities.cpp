#include "spinesim/mss/quantities.hpp"

#include <cmath>

#include "spinesim/mss/elements.hpp"

namespace spinesim::mss {

Eigen::MatrixX3d displacement(const MssModel& model, const Eigen::VectorXd& x_mm) {
  using RowMatrixX3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  const Eigen::VectorXd u = x_mm - model.rest_positions_mm();
  return Eigen::Map<const RowMatrixX3>(u.data(), model.num_nodes(), 3);
}

double max_displacement_mm(const MssModel& model, const Eigen::VectorXd& x_mm) {
  return displacement(model, x_mm).rowwise().norm().maxCoeff();
}

Eigen::VectorXd tet_volume_change(const MssModel& model, const Eigen::VectorXd& x_mm) {
  const mesh::TetMesh& m = model.mesh();
  const Eigen::VectorXd& X = model.rest_positions_mm();
  Eigen::VectorXd dv(m.num_tets());
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    TetPoints x, x0;
    for (int k = 0; k < 4; ++k) {
      x.col(k) = x_mm.segment<3>(3 * m.T(t, k));
      x0.col(k) = X.segment<3>(3 * m.T(t, k));
    }
    const double v0 = tet_signed_volume(x0);
    dv(t) = (tet_signed_volume(x) - v0) / v0;
  }
  return dv;
}

Eigen::VectorXd tet_edge_strain(const MssModel& model, const Eigen::VectorXd& x_mm) {
  const mesh::TetMesh& m = model.mesh();
  const Eigen::VectorXd& X = model.rest_positions_mm();
  static constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  Eigen::VectorXd strain(m.num_tets());
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    double extreme = 0;
    for (const auto& e : kEdges) {
      const Eigen::Index a = 3 * m.T(t, e[0]), b = 3 * m.T(t, e[1]);
      const double rest = (X.segment<3>(b) - X.segment<3>(a)).norm();
      const double e_ab = (x_mm.segment<3>(b) - x_mm.segment<3>(a)).norm() / rest - 1.0;
      if (std::abs(e_ab) > std::abs(extreme)) extreme = e_ab;
    }
    strain(t) = extreme;
  }
  return strain;
}

double volume_change(const MssModel& model, const Eigen::VectorXd& x_mm) {
  const double v0 = model.rest_volume_mm3();
  return (model.volume_mm3(x_mm) - v0) / v0;
}

StateFields state_fields(const MssModel& model, const Eigen::VectorXd& x_mm) {
  StateFields f;
  f.point.push_back({"displacement", displacement(model, x_mm)});
  f.cell.push_back({"volume_change", Eigen::MatrixXd(tet_volume_change(model, x_mm))});
  return f;
}

}  // namespace spinesim::mss
