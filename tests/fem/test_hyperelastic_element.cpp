// The total Lagrangian element (fem/hyperelastic_element.hpp), pointwise and mean-dilatation: its
// force is its energy's gradient and its tangent the force's Jacobian (central differences, P1
// and P2, fibres on), a rigid rotation costs nothing and rotates the forces, and at rest it is
// the linear element — the standard one, or for the mean dilatation the linear element with the
// volumetric part taken on the element's mean divergence (B-bar), built here from two linear
// element stiffnesses. Where J is constant (P1, or P2 under a homogeneous deformation) the two
// forms coincide.
#include "spinesim/fem/hyperelastic_element.hpp"

#include "hyperelastic_fixtures.hpp"
#include "spinesim/fem/quadrature.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <tuple>

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

class Element : public ::testing::TestWithParam<std::tuple<int, VolumetricForm>> {
 protected:
  int order = std::get<0>(GetParam());
  VolumetricForm form = std::get<1>(GetParam());
  HyperelasticElement element(const Eigen::MatrixX3d& u, const FibreHyperelastic& m) const {
    return hyperelastic_element(order, kX, u, m, true, form);
  }
};

TEST_P(Element, ForceIsTheEnergysGradientAndTangentItsJacobian) {
  const FibreHyperelastic m = annulus();
  const Eigen::MatrixX3d u = displacement(order);
  const HyperelasticElement e = element(u, m);
  ASSERT_TRUE(std::isfinite(e.energy));
  EXPECT_EQ(e.inverted_points, 0);
  const double h = 1e-6;
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    Eigen::MatrixX3d up = u, um = u;
    up(k / 3, k % 3) += h;
    um(k / 3, k % 3) -= h;
    const HyperelasticElement ep = element(up, m);
    const HyperelasticElement em = element(um, m);
    EXPECT_NEAR((ep.energy - em.energy) / (2 * h), e.force(k), 1e-6 * (1 + e.force.norm()))
        << "dof " << k;
    const Eigen::VectorXd column = (ep.force - em.force) / (2 * h);
    EXPECT_LE((column - e.tangent.col(k)).norm(), 1e-6 * e.tangent.norm()) << "dof " << k;
  }
  EXPECT_LE((e.tangent - e.tangent.transpose()).norm(), 1e-12 * e.tangent.norm());
}

TEST_P(Element, RigidRotationCostsNothingAndRotatesTheForces) {
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
  const HyperelasticElement r = element(rigid, m);
  EXPECT_NEAR(r.energy, 0, 1e-12);
  EXPECT_LE(r.force.norm(), 1e-12);
  // A deformed state, then rotated: the same energy, each nodal force rotated by R.
  const Eigen::MatrixX3d u = displacement(order);
  const Eigen::MatrixX3d x = X + u;
  const HyperelasticElement d = element(u, m);
  const HyperelasticElement dr = element(x * R.transpose() - X, m);
  EXPECT_NEAR(dr.energy, d.energy, 1e-12 * std::abs(d.energy));
  for (int a = 0; a < npe; ++a)
    EXPECT_LE((dr.force.segment<3>(3 * a) - R * d.force.segment<3>(3 * a)).norm(),
              1e-10 * d.force.norm());
}

TEST_P(Element, AtRestItIsTheLinearElement) {
  const mesh::IsotropicMaterial lin{4.2, 0.45, 1200.0};
  const FibreHyperelastic m = neo_hookean_from_linear(lin.youngs_modulus_mpa, lin.poisson_ratio);
  const int npe = order == 1 ? 4 : 10;
  const HyperelasticElement e = element(Eigen::MatrixX3d::Zero(npe, 3), m);
  EXPECT_LE(e.force.norm(), 1e-14);
  // The linear element is λ K_λ + μ K_μ; two materials give K_λ = ∫ Bᵀ m mᵀ B and K_μ.
  const auto lame = [](const mesh::IsotropicMaterial& l) {
    const double E = l.youngs_modulus_mpa, nu = l.poisson_ratio;
    return Eigen::Vector2d(E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu)));
  };
  const mesh::IsotropicMaterial other{1.0, 0.2, 1200.0};
  const Eigen::MatrixXd K1 = element_stiffness(order, kX, lin),
                        K2 = element_stiffness(order, kX, other);
  Eigen::Matrix2d A;
  A << lame(lin).transpose(), lame(other).transpose();
  const Eigen::Matrix2d Ai = A.inverse();
  const Eigen::MatrixXd K_lambda = Ai(0, 0) * K1 + Ai(0, 1) * K2;
  const Eigen::MatrixXd K_mu = Ai(1, 0) * K1 + Ai(1, 1) * K2;
  const double mu = lame(lin)(1), bulk = lame(lin)(0) + 2.0 * mu / 3.0;
  Eigen::MatrixXd expected = K1;
  if (form == VolumetricForm::mean_dilatation) {
    // B-bar: the volumetric part K ∫ (∇·N)(∇·N) replaced by K V b̄ b̄ᵀ, b̄_a = ∫ ∇N_a dV / V.
    double volume = 0;
    const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(kX, volume);
    const TetQuadrature rule = tet_rule_degree2();
    Eigen::VectorXd b = Eigen::VectorXd::Zero(3 * npe);
    for (Eigen::Index q = 0; q < rule.weights.size(); ++q) {
      const Eigen::MatrixX3d G = shape_gradients(order, gL, rule.barycentric.row(q).transpose());
      for (int a = 0; a < npe; ++a) b.segment<3>(3 * a) += rule.weights(q) * G.row(a).transpose();
    }
    expected = mu * K_mu - 2.0 * mu / 3.0 * K_lambda + bulk * volume * b * b.transpose();
  }
  EXPECT_LE((e.tangent - expected).norm(), 1e-12 * expected.norm());
  if (order == 2 && form == VolumetricForm::mean_dilatation)
    EXPECT_GT((expected - K1).norm(), 1e-3 * K1.norm());  // on P2 the two forms differ
}

INSTANTIATE_TEST_SUITE_P(OrdersAndForms, Element,
                         ::testing::Combine(::testing::Values(1, 2),
                                            ::testing::Values(VolumetricForm::pointwise,
                                                              VolumetricForm::mean_dilatation)));

// Where J is the same at every point the mean dilatation changes nothing: P1 at any state, P2
// under a homogeneous deformation (nodal displacements linear in X) — in energy and force; the P2
// tangent still differs, as the variations it answers are not homogeneous.
TEST(MeanDilatation, WhereJIsConstantItIsThePointwiseElement) {
  const FibreHyperelastic m = annulus();
  const Eigen::Matrix3d H =
      (Eigen::Matrix3d() << 0.1, 0.05, -0.02, 0.0, -0.08, 0.03, 0.04, 0.01, 0.06).finished();
  static const int edges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  Eigen::MatrixX3d X(10, 3);
  X.topRows(4) = kX;
  for (int e = 4; e < 10; ++e) X.row(e) = 0.5 * (kX.row(edges[e - 4][0]) + kX.row(edges[e - 4][1]));
  const Eigen::MatrixX3d homogeneous = X * H.transpose();
  for (const auto& [order, u] : {std::pair{1, displacement(1)}, std::pair{2, homogeneous}}) {
    const HyperelasticElement a =
        hyperelastic_element(order, kX, u, m, true, VolumetricForm::pointwise);
    const HyperelasticElement b =
        hyperelastic_element(order, kX, u, m, true, VolumetricForm::mean_dilatation);
    EXPECT_NEAR(a.energy, b.energy, 1e-12 * std::abs(a.energy)) << "P" << order;
    EXPECT_LE((a.force - b.force).norm(), 1e-12 * a.force.norm()) << "P" << order;
    if (order == 1) EXPECT_LE((a.tangent - b.tangent).norm(), 1e-12 * a.tangent.norm());
  }
  // A non-homogeneous P2 state: the forms differ.
  const HyperelasticElement a = hyperelastic_element(2, kX, displacement(2), m);
  const HyperelasticElement b =
      hyperelastic_element(2, kX, displacement(2), m, true, VolumetricForm::mean_dilatation);
  EXPECT_GT((a.force - b.force).norm(), 1e-6 * a.force.norm());
}

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
