#include "spinesim/mss/plate_stiffness.hpp"

#include "spinesim/mesh/rigid_plate.hpp"

#include <Eigen/SparseCholesky>

#include <stdexcept>
#include <vector>

namespace spinesim::mss {

namespace {
bool is_superior(const mesh::TetMesh& m, Eigen::Index i) {
  return m.surface(i) == int(mesh::Surface::superior_endplate);
}
bool is_inferior(const mesh::TetMesh& m, Eigen::Index i) {
  return m.surface(i) == int(mesh::Surface::inferior_endplate);
}
}  // namespace

Matrix6d plate_stiffness(const MssModel& model, const Eigen::Vector3d& center_mm) {
  const mesh::TetMesh& m = model.mesh();
  const Eigen::VectorXd& X = model.rest_positions_mm();
  Eigen::SparseMatrix<double> H;
  model.hessian(X, HessianMode::exact, H);

  // 1. Classify the DOF: free (numbered), plate (rigid map rows), fixed (dropped).
  const Eigen::Index ndof = model.num_dofs();
  std::vector<Eigen::Index> free_index(std::size_t(ndof), -1);
  Eigen::Matrix<double, Eigen::Dynamic, 6> map(ndof, 6);
  map.setZero();
  Eigen::Index nf = 0;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    for (int a = 0; a < 3; ++a) {
      if (is_superior(m, i))
        map.row(3 * i + a) = mesh::plate_map(X.segment<3>(3 * i) - center_mm).row(a);
      else if (!is_inferior(m, i))
        free_index[std::size_t(3 * i + a)] = nf++;
    }

  // 2. Blocks K_ff, B = K_fp T and T'K_pp T from the Hessian's entries.
  std::vector<Eigen::Triplet<double>> kff;
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(nf, 6);
  Matrix6d kpp = Matrix6d::Zero();
  for (Eigen::Index col = 0; col < H.outerSize(); ++col) {
    const bool col_plate = is_superior(m, col / 3);
    const Eigen::Index fc = free_index[std::size_t(col)];
    for (Eigen::SparseMatrix<double>::InnerIterator it(H, col); it; ++it) {
      const Eigen::Index row = it.row();
      const Eigen::Index fr = free_index[std::size_t(row)];
      const bool row_plate = is_superior(m, row / 3);
      if (fr >= 0 && fc >= 0)
        kff.emplace_back(fr, fc, it.value());
      else if (fr >= 0 && col_plate)
        b.row(fr) += it.value() * map.row(col);
      else if (row_plate && col_plate)
        kpp += map.row(row).transpose() * it.value() * map.row(col);
    }
  }
  Eigen::SparseMatrix<double> k(nf, nf);
  k.setFromTriplets(kff.begin(), kff.end());

  // 3. The whole-disc volume term's dense rank-one part k_g u u^T (model.hpp), split like the
  //    blocks: free part u_f, plate part T'u_p.
  Eigen::VectorXd u;
  const double kg = model.disc_volume_rank_one(X, u);
  Eigen::VectorXd u_f = Eigen::VectorXd::Zero(nf);
  Vector6d u_p = Vector6d::Zero();
  if (kg != 0.0)
    for (Eigen::Index dof = 0; dof < ndof; ++dof) {
      if (free_index[std::size_t(dof)] >= 0)
        u_f(free_index[std::size_t(dof)]) = u(dof);
      else if (is_superior(m, dof / 3))
        u_p += u(dof) * map.row(dof).transpose();
    }
  b += kg * u_f * u_p.transpose();
  kpp += kg * u_p * u_p.transpose();

  // 4. Condense: K_ff + k_g u_f u_f' inverted by Sherman–Morrison on the sparse factor.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
  if (ldlt.info() != Eigen::Success)
    throw std::runtime_error("MSS plate stiffness: the free-node stiffness does not factorise");
  Eigen::MatrixXd z = ldlt.solve(b);
  if (kg != 0.0) {
    const Eigen::VectorXd a_u = ldlt.solve(u_f);
    z -= a_u * (kg * (u_f.transpose() * z)) / (1.0 + kg * u_f.dot(a_u));
  }
  Matrix6d k6 = kpp - b.transpose() * z;
  k6 = 0.5 * (k6 + k6.transpose()).eval();
  if (!k6.allFinite()) throw std::runtime_error("MSS plate stiffness: non-finite result");
  return k6;
}

}  // namespace spinesim::mss
