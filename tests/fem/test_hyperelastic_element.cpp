// The total Lagrangian element (fem/hyperelastic_element.hpp): its force is its energy's
// gradient and its tangent the force's Jacobian (central differences, P1 and P2, fibres on),
// a rigid rotation costs nothing and rotates the forces, and at rest it is the linear element.
#include "spinesim/fem/hyperelastic_element.hpp"

#include "hyperelastic_fixtures.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

namespace spinesim::fem {
namespace {

const TetVertices kX =
    (TetVertices() << 0, 0, 0, 2, 0.1, 0, 0.2, 1.5, 0.1, 0.3, 0.2, 1.8).finished();

using fixtures::annulus;

/// A displacement with one fibre family stretched: a shear plus a smooth wrinkle (P2 nodes
/// are the vertices, then the edge midpoints).
Eigen::MatrixX3d displacement(int order) {
  const int npe = order == 1 ? 4 : 10;
  Eigen::MatrixX3d u(npe, 3);
  for (int a = 0; a < npe; ++a)
    u.row(a) << 0.2 * std::sin(1.3 * a), 0.05 * std::cos(0.7 * a) - 0.02 * a, 0.03 * std::sin(a);
  return u;
}

class Element : public ::testing::TestWithParam<int> {};

TEST_P(Element, ForceIsTheEnergysGradientAndTangentItsJacobian) {
  const int order = GetParam();
  const FibreHyperelastic m = annulus();
  const Eigen::MatrixX3d u = displacement(order);
  const HyperelasticElement e = hyperelastic_element(order, kX, u, m);
  ASSERT_TRUE(std::isfinite(e.energy));
  EXPECT_EQ(e.inverted_points, 0);
  const double h = 1e-6;
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    Eigen::MatrixX3d up = u, um = u;
    up(k / 3, k % 3) += h;
    um(k / 3, k % 3) -= h;
    const HyperelasticElement ep = hyperelastic_element(order, kX, up, m);
    const HyperelasticElement em = hyperelastic_element(order, kX, um, m);
    EXPECT_NEAR((ep.energy - em.energy) / (2 * h), e.force(k), 1e-6 * (1 + e.force.norm()))
        << "dof " << k;
    const Eigen::VectorXd column = (ep.force - em.force) / (2 * h);
    EXPECT_LE((column - e.tangent.col(k)).norm(), 1e-6 * e.tangent.norm()) << "dof " << k;
  }
  EXPECT_LE((e.tangent - e.tangent.transpose()).norm(), 1e-12 * e.tangent.norm());
}

TEST_P(Element, RigidRotationCostsNothingAndRotatesTheForces) {
  const int order = GetParam();
  const FibreHyperelastic m = annulus();
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  // Node positions of the element (P2: edge midpoints of straight edges).
  const int npe = order == 1 ? 4 : 10;
  static const int edges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  Eigen::MatrixX3d X(npe, 3);
  X.topRows(4) = kX;
  for (int e = 4; e < npe; ++e)
    X.row(e) = 0.5 * (kX.row(edges[e - 4][0]) + kX.row(edges[e - 4][1]));
  const Eigen::MatrixX3d rigid = X * R.transpose() - X;
  const HyperelasticElement r = hyperelastic_element(order, kX, rigid, m);
  EXPECT_NEAR(r.energy, 0, 1e-12);
  EXPECT_LE(r.force.norm(), 1e-12);
  // A deformed state, then rotated: the same energy, each nodal force rotated by R.
  const Eigen::MatrixX3d u = displacement(order);
  const Eigen::MatrixX3d x = X + u;
  const HyperelasticElement d = hyperelastic_element(order, kX, u, m);
  const HyperelasticElement dr = hyperelastic_element(order, kX, x * R.transpose() - X, m);
  EXPECT_NEAR(dr.energy, d.energy, 1e-12 * std::abs(d.energy));
  for (int a = 0; a < npe; ++a)
    EXPECT_LE((dr.force.segment<3>(3 * a) - R * d.force.segment<3>(3 * a)).norm(),
              1e-10 * d.force.norm());
}

TEST_P(Element, AtRestItIsTheLinearElement) {
  const int order = GetParam();
  const mesh::IsotropicMaterial lin{4.2, 0.45, 1200.0};
  const FibreHyperelastic m = neo_hookean_from_linear(lin.youngs_modulus_mpa, lin.poisson_ratio);
  const int npe = order == 1 ? 4 : 10;
  const HyperelasticElement e = hyperelastic_element(order, kX, Eigen::MatrixX3d::Zero(npe, 3), m);
  const Eigen::MatrixXd K = element_stiffness(order, kX, lin);
  EXPECT_LE((e.tangent - K).norm(), 1e-12 * K.norm());
  EXPECT_LE(e.force.norm(), 1e-14);
}

INSTANTIATE_TEST_SUITE_P(P1AndP2, Element, ::testing::Values(1, 2));

TEST(HyperelasticElementInput, AnInvertedElementHasNoEnergy) {
  Eigen::MatrixX3d u = Eigen::MatrixX3d::Zero(4, 3);
  u(3, 2) = -4;  // the apex pushed through the base
  const HyperelasticElement e = hyperelastic_element(1, kX, u, annulus());
  EXPECT_EQ(e.inverted_points, 1);
  EXPECT_TRUE(std::isnan(e.energy));
  EXPECT_THROW(hyperelastic_element(3, kX, u, annulus()), std::invalid_argument);
  EXPECT_THROW(hyperelastic_element(2, kX, u, annulus()), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::fem
