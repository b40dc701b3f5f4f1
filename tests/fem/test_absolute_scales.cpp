// An absolute scale against a number worked out by hand rather than a golden file: the strain
// energy of one P1 tetrahedron under a uniform strain (catches a factor in the element volume or
// in the elasticity matrix, which displacement-only checks such as the patch test cannot see).
#include "spinesim/fem/elasticity.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>

using namespace spinesim;

// W = ½ V ε:σ, σ = λ tr(ε) I + 2μ ε, for a uniform (arbitrary, symmetric) strain ε; the nodal
// displacements of the linear field u = ε X give ½ uᵀ K u exactly for P1.
TEST(AbsoluteScales, OneTetrahedronStoresTheStrainEnergyOfItsUniformStrain) {
  fem::TetVertices X;
  X << 0.3, 0.1, -0.2,  //
      2.9, 0.4, 0.1,    //
      0.2, 3.3, 0.5,    //
      0.6, 0.2, 4.1;    // rows: vertices, mm
  const double V =
      std::abs((X.row(1) - X.row(0)).dot((X.row(2) - X.row(0)).cross(X.row(3) - X.row(0)))) / 6.0;
  mesh::IsotropicMaterial mat;
  mat.youngs_modulus_mpa = 3.22;
  mat.poisson_ratio = 0.4557;
  const double E = mat.youngs_modulus_mpa, nu = mat.poisson_ratio;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  Eigen::Matrix3d eps;
  eps << 0.010, 0.002, -0.003,  //
      0.002, -0.020, 0.004,     //
      -0.003, 0.004, 0.005;
  const Eigen::Matrix3d sigma = lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * mu * eps;
  const double w_exact = 0.5 * V * (eps.cwiseProduct(sigma)).sum();  // N·mm
  const Eigen::MatrixXd K = fem::element_stiffness(1, X, mat);
  Eigen::VectorXd u(12);
  for (int a = 0; a < 4; ++a) u.segment<3>(3 * a) = eps * X.row(a).transpose();
  const double w = 0.5 * u.dot(K * u);
  EXPECT_NEAR(w, w_exact, 1e-12 * w_exact);
}
