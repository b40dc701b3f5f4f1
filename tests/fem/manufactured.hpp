// Manufactured-solution convergence study shared by test_convergence{,_slow}.cpp:
// u_i = A sin(k_i . x + phi_i) on the unit cube, Dirichlet data = exact on the whole boundary,
// body force f = -div sigma,
//   f_i = (lambda + mu) sum_m k_mm k_mi sin(k_m . x + phi_m) + mu |k_i|^2 sin(k_i . x + phi_i)
// (k_mj = component j of wave vector k_m). Expected L² error orders: 2 (P1), 3 (P2).
#pragma once

#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/dirichlet.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/mesh/box_mesh.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

namespace spinesim::fem::manufactured {

struct Manufactured {
  Eigen::Matrix3d k;  ///< row m: wave vector of component m
  Eigen::Vector3d phase;
  double amplitude = 0.01;
  double lambda = 0, mu = 0;

  Eigen::Vector3d u(const Eigen::Vector3d& x) const {
    return amplitude * (k * x + phase).array().sin().matrix();
  }
  Eigen::Vector3d body_force(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d s = (k * x + phase).array().sin().matrix();
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      for (int m = 0; m < 3; ++m) f(i) += (lambda + mu) * k(m, m) * k(m, i) * s(m);
      f(i) += mu * k.row(i).squaredNorm() * s(i);
    }
    return amplitude * f;
  }
};

inline double solve_and_measure(int order, int n, const Manufactured& ms,
                                const mesh::RegionMaterials& mat) {
  const mesh::TetMesh m = mesh::unit_cube_mesh(n);
  const FeSpace space = make_fe_space(m, order);
  const Eigen::SparseMatrix<double> K = assemble_stiffness(space, m.region, mat);
  const Eigen::VectorXd f = assemble_body_force(
      space, [&](const Eigen::Vector3d& x) { return ms.body_force(x); }, 5);
  std::vector<Eigen::Index> fixed;
  std::vector<double> values;
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i) {
    const Eigen::Vector3d x = space.X.row(i).transpose();
    if ((x.array().abs() < 1e-12).any() || ((x.array() - 1).abs() < 1e-12).any()) {
      const Eigen::Vector3d ue = ms.u(x);
      for (int d = 0; d < 3; ++d) fixed.push_back(3 * i + d), values.push_back(ue(d));
    }
  }
  const Eigen::VectorXd u = solve_dirichlet(
      K, f, fixed, Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())));
  return l2_error(
      space, u, [&](const Eigen::Vector3d& x) { return ms.u(x); }, 6);
}

/// Prints and returns the measured orders between successive n.
inline std::vector<double> measured_orders(int order, const std::vector<int>& ns) {
  mesh::RegionMaterials mat;
  mat.fallback = {5.0, 0.3, 1000.0};
  Manufactured ms;
  ms.k << 2.0, 1.0, 0.5,  //
      -1.0, 1.5, 1.0,     //
      0.5, -0.7, 2.2;
  ms.phase << 0.3, -0.4, 1.1;
  ms.lambda = mat.fallback.lame_lambda_mpa();
  ms.mu = mat.fallback.shear_modulus_mpa();
  std::vector<double> err, rates;
  for (int n : ns) err.push_back(solve_and_measure(order, n, ms, mat));
  for (std::size_t i = 0; i < ns.size(); ++i) {
    std::printf("P%d n=%2d  L2 error %.4e", order, ns[i], err[i]);
    if (i > 0) {
      rates.push_back(std::log(err[i - 1] / err[i]) / std::log(double(ns[i]) / ns[i - 1]));
      std::printf("  order %.3f", rates.back());
    }
    std::printf("\n");
  }
  return rates;
}

}  // namespace spinesim::fem::manufactured
