#include "spinesim/mss/quantities.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "spinesim/mss/elements.hpp"

#include <Eigen/LU>

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

Eigen::MatrixXd tet_green_lagrange_strain(const MssModel& model, const Eigen::VectorXd& x_mm) {
  const mesh::TetMesh& m = model.mesh();
  const Eigen::VectorXd& X = model.rest_positions_mm();
  Eigen::MatrixXd out(m.num_tets(), 6);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    Eigen::Matrix3d dx, dX;  // edge vectors from vertex 0, as columns
    for (int k = 1; k < 4; ++k) {
      dx.col(k - 1) = x_mm.segment<3>(3 * m.T(t, k)) - x_mm.segment<3>(3 * m.T(t, 0));
      dX.col(k - 1) = X.segment<3>(3 * m.T(t, k)) - X.segment<3>(3 * m.T(t, 0));
    }
    const Eigen::Matrix3d F = dx * dX.inverse();
    const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    out.row(t) << E(0, 0), E(1, 1), E(2, 2), E(0, 1), E(1, 2), E(0, 2);
  }
  return out;
}

Eigen::MatrixXd tet_edge_spring_forces(const MssModel& model, const Eigen::VectorXd& x_mm) {
  const mesh::TetMesh& m = model.mesh();
  const std::vector<EdgeSpringInfo> springs = model.edge_springs();  // sorted by (i, j)
  static constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  Eigen::MatrixXd out(m.num_tets(), 6);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (int k = 0; k < 6; ++k) {
      const int a = m.T(t, kEdges[k][0]), b = m.T(t, kEdges[k][1]);
      const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      const auto it = std::lower_bound(
          springs.begin(), springs.end(), key,
          [](const EdgeSpringInfo& e, const std::pair<int, int>& q) {
            return std::make_pair(e.i, e.j) < q;
          });
      const double l = (x_mm.segment<3>(3 * b) - x_mm.segment<3>(3 * a)).norm();
      out(t, k) = it->multiplier * it->k_region * (l - it->rest_mm);
    }
  return out;
}

StateFields state_fields(const MssModel& model, const Eigen::VectorXd& x_mm) {
  StateFields f;
  f.point.push_back({"displacement", displacement(model, x_mm)});
  f.cell.push_back({"volume_change", Eigen::MatrixXd(tet_volume_change(model, x_mm))});
  f.cell.push_back({"green_lagrange_strain", tet_green_lagrange_strain(model, x_mm)});
  f.cell.push_back({"edge_spring_force_N", tet_edge_spring_forces(model, x_mm)});
  return f;
}

}  // namespace spinesim::mss
