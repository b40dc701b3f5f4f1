// Embedded fibre springs of the mass-spring disc (elements.hpp fibre_spring, MssModel's
// Term::fibre): the spring between two points on the tet's faces has the stretch the
// coefficients give, gradient and Hessian against central differences, tension only, zero net
// force and moment, rigid invariance, the small-strain linear fibre, and the nonlinear FEM's
// fibre energy (fem/hyperelastic.hpp, an independent implementation) on isochoric deformations.
#include "spinesim/mss/elements.hpp"
#include "spinesim/mss/model.hpp"

#include "spinesim/fem/hyperelastic.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/fibre_field.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace spinesim::mss {
namespace {

constexpr double kStep = 1e-6;  // mm; as tests/mss/test_elements.cpp

TetPoints rest_tet() {
  TetPoints X;
  X << 0, 1.5, 0.3, 0.5,  //
      0, 0, 1.4, 0.5,     //
      0, 0, 0, 1.3;
  return X;
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

/// x = F X + t for a deformation gradient F.
TetPoints deformed(const TetPoints& X, const Eigen::Matrix3d& F,
                   const Eigen::Vector3d& t = Eigen::Vector3d(1, -2, 3)) {
  TetPoints x;
  for (int j = 0; j < 4; ++j) x.col(j) = F * X.col(j) + t;
  return x;
}

/// A stretch `lambda` along a, with lateral contraction 1/sqrt(lambda) (det F = 1), and a shear.
Eigen::Matrix3d stretch_along(const Eigen::Vector3d& a, double lambda, double shear) {
  const Eigen::Matrix3d aa = a * a.transpose();
  Eigen::Matrix3d F = lambda * aa + (Eigen::Matrix3d::Identity() - aa) / std::sqrt(lambda);
  Eigen::Vector3d b = a.unitOrthogonal();
  return (Eigen::Matrix3d::Identity() + shear * b * a.cross(b).transpose()) * F;
}

/// The nonlinear FEM's energy of one fibre family (k1 2.5 MPa, k2 20) along a in a tet of rest
/// volume V0 under F: the material point's energy with the family minus without it, times V0.
double fem_fibre_energy(const Eigen::Matrix3d& F, const Eigen::Vector3d& a, double V0,
                        double k1 = 2.5, double k2 = 20.0) {
  const fem::FibreHyperelastic matrix = fem::neo_hookean_from_linear(1.0, 0.45);
  fem::FibreHyperelastic with = matrix;
  with.fibres.push_back({a, k1, k2});
  const Eigen::Matrix3d C = F.transpose() * F;
  return V0 * (fem::fibre_hyperelastic_point(C, with, false).energy -
               fem::fibre_hyperelastic_point(C, matrix, false).energy);
}

double energy(const TetPoints& x, const Eigen::Vector4d& c, double V0, double k1, double k2) {
  return fibre_spring(x, c, V0, k1, k2);
}

TEST(FibreSpring, TheSpringBetweenTwoFacePointsHasTheCoefficientsStretch) {
  // The literal embedded spring: the line through the centroid along a meets the tet's
  // boundary at two points with fixed barycentric coordinates; after any deformation the
  // spring's length over its rest length is |sum c_i x_i|.
  std::mt19937 rng(7);
  const TetPoints X = rest_tet();
  const Eigen::Vector3d a = Eigen::Vector3d(0.3, 0.8, -0.5).normalized();
  const Eigen::Vector4d c = fibre_coefficients(X, a);
  EXPECT_NEAR(c.sum(), 0.0, 1e-14);
  EXPECT_LE((X * c - a).norm(), 1e-14);  // F = I: d = a
  // Barycentric coordinates along p(s) = centroid + s a are affine in s; each end is where the
  // first coordinate reaches zero.
  Eigen::Matrix4d A;
  A.topRows<3>() = X;
  A.row(3).setOnes();
  const Eigen::Matrix4d Ainv = A.inverse();
  const Eigen::Vector4d w_mid = Eigen::Vector4d::Constant(0.25);
  const Eigen::Vector4d w_dir = Ainv * Eigen::Vector4d(a.x(), a.y(), a.z(), 0.0);
  double s_plus = 1e300, s_minus = -1e300;
  for (int i = 0; i < 4; ++i) {
    if (w_dir(i) < 0) s_plus = std::min(s_plus, -w_mid(i) / w_dir(i));
    if (w_dir(i) > 0) s_minus = std::max(s_minus, -w_mid(i) / w_dir(i));
  }
  const Eigen::Vector4d w1 = w_mid + s_plus * w_dir, w0 = w_mid + s_minus * w_dir;
  EXPECT_GE(w1.minCoeff(), -1e-12);
  EXPECT_GE(w0.minCoeff(), -1e-12);
  const double rest_length = (X * w1 - X * w0).norm();
  EXPECT_NEAR(rest_length, s_plus - s_minus, 1e-12);
  std::normal_distribution<double> n(0.0, 0.2);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int k = 0; k < 9; ++k) F(k / 3, k % 3) += n(rng);
    const TetPoints x = deformed(X, random_rotation(rng) * F);
    const double spring_stretch = (x * w1 - x * w0).norm() / rest_length;
    EXPECT_NEAR(spring_stretch, (x * c).norm(), 1e-12) << "trial " << trial;
    EXPECT_NEAR((x * c).norm(), (F * a).norm(), 1e-12);
  }
}

TEST(FibreSpring, GradientAndHessianMatchCentralDifferences) {
  const TetPoints X = rest_tet();
  const double V0 = tet_signed_volume(X);
  const Eigen::Vector3d a = Eigen::Vector3d(1, 0.4, 0.2).normalized();
  const Eigen::Vector4d c = fibre_coefficients(X, a);
  for (const double k2 : {0.0, 10.0, 100.0}) {
    SCOPED_TRACE(k2);
    const TetPoints x = deformed(X, stretch_along(a, 1.08, 0.1));
    Vector12d g;
    Matrix12d H;
    const double e = fibre_spring(x, c, V0, 2.5, k2, &g, &H);
    ASSERT_GT(e, 0.0);
    Vector12d fd_g;
    Matrix12d fd_H;
    for (int i = 0; i < 12; ++i) {
      TetPoints xp = x, xm = x;
      xp(i % 3, i / 3) += kStep;
      xm(i % 3, i / 3) -= kStep;
      fd_g(i) = (energy(xp, c, V0, 2.5, k2) - energy(xm, c, V0, 2.5, k2)) / (2 * kStep);
      Vector12d gp, gm;
      fibre_spring(xp, c, V0, 2.5, k2, &gp);
      fibre_spring(xm, c, V0, 2.5, k2, &gm);
      fd_H.col(i) = (gp - gm) / (2 * kStep);
    }
    EXPECT_LE((fd_g - g).cwiseAbs().maxCoeff(), 1e-6 * g.cwiseAbs().maxCoeff());
    EXPECT_LE((fd_H - H).cwiseAbs().maxCoeff(), 1e-6 * H.cwiseAbs().maxCoeff());
    EXPECT_LE((H - H.transpose()).cwiseAbs().maxCoeff(), 1e-13 * H.norm());
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Matrix12d>(H).eigenvalues().minCoeff(),
              -1e-10 * H.norm());
    // Zero net force and moment: the forces of one spring balance.
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    for (int j = 0; j < 4; ++j)
      force += g.segment<3>(3 * j), moment += x.col(j).cross(g.segment<3>(3 * j));
    EXPECT_LE(force.norm(), 1e-13 * g.norm());
    EXPECT_LE(moment.norm(), 1e-12 * g.norm() * x.norm());
  }
}

TEST(FibreSpring, CarriesTensionOnly) {
  const TetPoints X = rest_tet();
  const Eigen::Vector3d a = Eigen::Vector3d(0.2, 0.1, 1).normalized();
  const Eigen::Vector4d c = fibre_coefficients(X, a);
  Vector12d g;
  Matrix12d H;
  for (const double lambda : {0.7, 0.95, 1.0}) {
    const double e =
        fibre_spring(deformed(X, stretch_along(a, lambda, 0.0)), c, 1.0, 3.0, 10.0, &g, &H);
    EXPECT_EQ(e, 0.0) << lambda;
    EXPECT_EQ(g.norm(), 0.0) << lambda;
    EXPECT_EQ(H.norm(), 0.0) << lambda;
  }
  EXPECT_GT(fibre_spring(deformed(X, stretch_along(a, 1.01, 0.0)), c, 1.0, 3.0, 10.0), 0.0);
}

TEST(FibreSpring, IsRigidInvariantAndTheLinearFibreAtSmallStrain) {
  std::mt19937 rng(3);
  const TetPoints X = rest_tet();
  const double V0 = tet_signed_volume(X);
  const Eigen::Vector3d a = Eigen::Vector3d(0.6, -0.3, 0.7).normalized();
  const Eigen::Vector4d c = fibre_coefficients(X, a);
  const Eigen::Matrix3d F = stretch_along(a, 1.05, 0.2);
  const double e = fibre_spring(deformed(X, F), c, V0, 2.0, 10.0);
  const double e_moved =
      fibre_spring(deformed(X, random_rotation(rng) * F, {5, 6, 7}), c, V0, 2.0, 10.0);
  EXPECT_NEAR(e_moved, e, 1e-12 * e);
  // Uniaxial strain eps along a: V0 (k/2) eps^2 with k = 4 k1, to first order in eps.
  const double k1 = 2.0, eps = 1e-5;
  const Eigen::Matrix3d Fs = Eigen::Matrix3d::Identity() + eps * a * a.transpose();
  const double linear = V0 * 0.5 * (4.0 * k1) * eps * eps;
  EXPECT_NEAR(fibre_spring(deformed(X, Fs), c, V0, k1, 10.0), linear, 3 * eps * linear);
}

TEST(FibreSpring, EqualsTheNonlinearFemFibreEnergyOnIsochoricDeformations) {
  // On det F = 1 the FEM's isochoric I4 is the spring's I4: the element's fibre energy
  // (FEM energy with the family minus without it, times V0) must be the spring's.
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 0.1);
  const TetPoints X = rest_tet();
  const double V0 = tet_signed_volume(X);
  const Eigen::Vector3d a = Eigen::Vector3d(0.5, 0.5, -0.7).normalized();
  const Eigen::Vector4d c = fibre_coefficients(X, a);
  int in_tension = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int k = 0; k < 9; ++k) F(k / 3, k % 3) += n(rng);
    F /= std::cbrt(F.determinant());
    const double fem_energy = fem_fibre_energy(F, a, V0);
    const double spring = fibre_spring(deformed(X, F), c, V0, 2.5, 20.0);
    EXPECT_NEAR(spring, fem_energy, 1e-9 * std::max(fem_energy, 1e-6)) << "trial " << trial;
    in_tension += spring > 0.0;
  }
  EXPECT_GT(in_tension, 3);
  EXPECT_LT(in_tension, 17);  // both sides of the kink were sampled
}

// The isochoric fibre element: the FEM's fibre energy on every deformation (not only det F = 1),
// gradient and exact Hessian against central differences, the projected Hessian positive
// semi-definite, balanced forces, and an inverted tet without energy.
double rest_det(const TetPoints& X) {
  Eigen::Matrix3d D;
  D << X.col(1) - X.col(0), X.col(2) - X.col(0), X.col(3) - X.col(0);
  EXPECT_NEAR(arm_determinant(X), D.determinant(), 1e-14 * std::abs(D.determinant()));
  return arm_determinant(X);
}

TEST(IsochoricFibre, EqualsTheNonlinearFemFibreEnergyOnEveryDeformation) {
  std::mt19937 rng(12);
  std::normal_distribution<double> n(0.0, 0.12);
  const TetPoints X = rest_tet();
  const double V0 = tet_signed_volume(X);
  const Eigen::Vector3d a = Eigen::Vector3d(0.5, 0.5, -0.7).normalized();
  const Eigen::Vector4d c = fibre_coefficients(X, a);
  int in_tension = 0, spring_differs = 0;
  for (int trial = 0; trial < 30; ++trial) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int k = 0; k < 9; ++k) F(k / 3, k % 3) += n(rng);
    ASSERT_GT(F.determinant(), 0.2);
    const double fem_energy = fem_fibre_energy(F, a, V0);
    const TetPoints x = deformed(X, F);
    const double element = isochoric_fibre(x, c, V0, 2.5, 20.0, rest_det(X));
    EXPECT_NEAR(element, fem_energy, 1e-9 * std::max(fem_energy, 1e-6)) << "trial " << trial;
    in_tension += element > 0.0;
    spring_differs += std::abs(fibre_spring(x, c, V0, 2.5, 20.0) - element) > 1e-3 * element;
  }
  EXPECT_GT(in_tension, 5);
  EXPECT_LT(in_tension, 25);
  EXPECT_GT(spring_differs, 3);  // det F != 1: the spring's own stretch is another measure
}

TEST(IsochoricFibre, GradientAndHessiansMatchCentralDifferences) {
  const TetPoints X = rest_tet();
  const double V0 = tet_signed_volume(X), D = rest_det(X);
  const Eigen::Vector3d a = Eigen::Vector3d(1, 0.4, 0.2).normalized();
  const Eigen::Vector4d c = fibre_coefficients(X, a);
  for (const double k2 : {0.0, 10.0, 100.0}) {
    SCOPED_TRACE(k2);
    // Stretched along a and swollen by 6 %: every J term of the Hessian is at work.
    const TetPoints x = deformed(X, 1.02 * stretch_along(a, 1.08, 0.1));
    Vector12d g;
    Matrix12d H, Hp;
    const double e = isochoric_fibre(x, c, V0, 2.5, k2, D, &g, &H);
    isochoric_fibre(x, c, V0, 2.5, k2, D, nullptr, &Hp, 1.0, HessianMode::projected);
    ASSERT_GT(e, 0.0);
    Vector12d fd_g;
    Matrix12d fd_H;
    for (int i = 0; i < 12; ++i) {
      TetPoints xp = x, xm = x;
      xp(i % 3, i / 3) += kStep;
      xm(i % 3, i / 3) -= kStep;
      fd_g(i) = (isochoric_fibre(xp, c, V0, 2.5, k2, D) - isochoric_fibre(xm, c, V0, 2.5, k2, D)) /
                (2 * kStep);
      Vector12d gp, gm;
      isochoric_fibre(xp, c, V0, 2.5, k2, D, &gp);
      isochoric_fibre(xm, c, V0, 2.5, k2, D, &gm);
      fd_H.col(i) = (gp - gm) / (2 * kStep);
    }
    EXPECT_LE((fd_g - g).cwiseAbs().maxCoeff(), 1e-6 * g.cwiseAbs().maxCoeff());
    EXPECT_LE((fd_H - H).cwiseAbs().maxCoeff(), 1e-6 * H.cwiseAbs().maxCoeff());
    EXPECT_LE((H - H.transpose()).cwiseAbs().maxCoeff(), 1e-13 * H.norm());
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Matrix12d>(Hp).eigenvalues().minCoeff(),
              -1e-10 * Hp.norm());
    EXPECT_GT((H - Hp).norm(), 1e-3 * H.norm());  // the J terms are not negligible here
    Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    for (int j = 0; j < 4; ++j)
      force += g.segment<3>(3 * j), moment += x.col(j).cross(g.segment<3>(3 * j));
    EXPECT_LE(force.norm(), 1e-13 * g.norm());
    EXPECT_LE(moment.norm(), 1e-12 * g.norm() * x.norm());
  }
  TetPoints inverted = X;
  inverted.col(3) = X.col(0) - (X.col(3) - X.col(0));
  EXPECT_TRUE(std::isnan(isochoric_fibre(inverted, c, V0, 2.5, 10.0, D)));
}

// The tension side of the rest Hessian (fibre_rest_tangent), for both stretch measures: the
// limit of the exact Hessian as the fibre is stretched from rest, first order in the stretch;
// from the compression side the Hessian is zero. A rank-one positive semi-definite matrix.
TEST(FibreRestTangent, IsTheLimitOfTheHessianFromTheTensionSide) {
  const TetPoints X = rest_tet();
  const double V0 = tet_signed_volume(X), D = rest_det(X);
  const Eigen::Vector3d a = Eigen::Vector3d(0.2, -0.6, 0.7).normalized();
  const Eigen::Vector4d c = fibre_coefficients(X, a);
  for (const bool isochoric : {false, true})
    for (const double k2 : {0.0, 20.0}) {
      SCOPED_TRACE(std::string(isochoric ? "isochoric" : "spring") + ", k2 " + std::to_string(k2));
      const Matrix12d T = fibre_rest_tangent(X, c, V0, 2.5, D, 1.0, isochoric);
      auto hessian = [&](double lambda) {
        Matrix12d H;
        const TetPoints x = deformed(X, stretch_along(a, lambda, 0.0));
        if (isochoric)
          isochoric_fibre(x, c, V0, 2.5, k2, D, nullptr, &H);
        else
          fibre_spring(x, c, V0, 2.5, k2, nullptr, &H);
        return H;
      };
      const double e3 = (hessian(1 + 1e-3) - T).norm(), e4 = (hessian(1 + 1e-4) - T).norm();
      EXPECT_LT(e4, 1e-3 * T.norm());
      EXPECT_NEAR(e3 / e4, 10.0, 1.0);  // first order
      EXPECT_EQ(hessian(1 - 1e-4).norm(), 0.0);
      const Eigen::SelfAdjointEigenSolver<Matrix12d> eig(T);
      EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * T.norm());
      EXPECT_LE(eig.eigenvalues()(10), 1e-12 * T.norm());  // rank one
    }
}

TEST(FibreSpring, DegenerateTetIsRefused) {
  TetPoints flat = rest_tet();
  flat.row(2).setZero();
  EXPECT_THROW(fibre_coefficients(flat, Eigen::Vector3d::UnitX()), std::invalid_argument);
}

// The model: one spring per family in every fibre-reinforced tet, and its term behaves like the
// others (scale, term energy, assembled gradient and Hessian).
class FibreModel : public ::testing::Test {
 protected:
  static mesh::TetMesh disc() {
    return mesh::mesh_structured_level("L4-L5", {}, SPINESIM_DATA_DIR);
  }
  static mesh::RegionMaterials material() {
    mesh::RegionMaterials m;
    m.name = "test-fibres";
    m.fallback = {4.2, 0.45, 1200.0};
    m.by_region[2] = {1.0, 0.49, 1000.0};
    mesh::FibreReinforcement f;
    f.modulus_inner_mpa = 100, f.modulus_outer_mpa = 200;
    f.angle_inner_deg = 45, f.angle_outer_deg = 30;
    f.toe_k2 = 10;
    m.fibres[1] = f;
    return m;
  }
  static void none_at_rest(bool isochoric);
  static void assembled_derivatives(bool isochoric);
};

TEST_F(FibreModel, OneSpringPerFamilyInEveryAnnulusTetAndNoneAtRest) {
  for (const bool isochoric : {false, true}) {
    SCOPED_TRACE(isochoric);
    none_at_rest(isochoric);
  }
}

void FibreModel::none_at_rest(bool isochoric) {
  const mesh::TetMesh m = disc();
  MssOptions o;
  o.fibre_springs = true;
  o.isochoric_fibres = isochoric;
  const MssModel model(m, material(), o);
  Eigen::Index annulus = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) annulus += m.region(t) == 1;
  ASSERT_GT(annulus, 0);
  EXPECT_EQ(model.num_fibre_springs(), 2 * annulus);
  const Eigen::VectorXd X = model.rest_positions_mm();
  EXPECT_EQ(model.term_energy(X, Term::fibre, 0), 0.0);
  Eigen::SparseMatrix<double> H;
  model.term_hessian(X, Term::fibre, 0, HessianMode::exact, H);
  EXPECT_EQ(H.norm(), 0.0);  // the tension-only kink: no stiffness at rest
  MssOptions off;
  EXPECT_EQ(MssModel(m, material(), off).num_fibre_springs(), 0);
}

TEST_F(FibreModel, ScaledTermAssembledGradientAndHessianAgree) {
  for (const bool isochoric : {false, true}) {
    SCOPED_TRACE(isochoric);
    assembled_derivatives(isochoric);
  }
}

void FibreModel::assembled_derivatives(bool isochoric) {
  const mesh::TetMesh m = disc();
  MssOptions o;
  o.fibre_springs = true;
  o.isochoric_fibres = isochoric;
  o.volume_term = true;
  MssModel model(m, material(), o);
  // Twist the disc about its axis (y) in proportion to height: the ±angle families stretch.
  Eigen::VectorXd x = model.rest_positions_mm();
  for (Eigen::Index i = 0; i < model.num_nodes(); ++i) {
    const Eigen::Vector3d p = x.segment<3>(3 * i);
    x.segment<3>(3 * i) = Eigen::AngleAxisd(0.02 * p.y(), Eigen::Vector3d::UnitY()) * p;
  }
  const double fibre = model.term_energy(x, Term::fibre, 0);
  ASSERT_GT(fibre, 0.0);
  EXPECT_EQ(model.term_energy(x, Term::fibre, 1), 0.0);
  const double total = model.energy(x);
  auto scales = o.scales;
  scales[int(Term::fibre)].by_region[0] = 3.0;
  model.set_scales(scales);
  EXPECT_NEAR(model.energy(x) - total, 2.0 * fibre, 1e-9 * total);

  Eigen::VectorXd g;
  model.gradient(x, g);
  Eigen::SparseMatrix<double> H;
  model.hessian(x, HessianMode::exact, H);
  std::mt19937 rng(5);
  std::normal_distribution<double> n;
  Eigen::VectorXd v(x.size());
  for (Eigen::Index i = 0; i < v.size(); ++i) v(i) = n(rng);
  const double h = 1e-6;
  const double fd = (model.energy(x + h * v) - model.energy(x - h * v)) / (2 * h);
  EXPECT_NEAR(fd, g.dot(v), 1e-6 * std::abs(g.dot(v)));
  Eigen::VectorXd gp, gm;
  model.gradient(x + h * v, gp);
  model.gradient(x - h * v, gm);
  const Eigen::VectorXd Hv = H * v;
  EXPECT_LE(((gp - gm) / (2 * h) - Hv).norm(), 1e-6 * Hv.norm());
}

// The model sums its isochoric fibre forces per tet (J and ∇J once for both families): it must
// be the element kernel summed, element by element, on a twisted disc (one family stretched, the
// other slack), a stretched one (both stretched), and with one tet inverted (NaN energy, no
// force from that tet's fibres, as the element).
TEST_F(FibreModel, TheIsochoricFibreForceIsTheElementKernelSummed) {
  const mesh::TetMesh m = disc();
  MssOptions o;
  o.fibre_springs = true;
  const MssModel model(m, material(), o);
  const Eigen::VectorXd X = model.rest_positions_mm();
  const mesh::ElementFibres field = mesh::fibre_field(m, material());
  auto reference = [&](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
    g.setZero(x.size());
    double e = 0;
    for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
      if (!(field.stiffness_mpa(t) > 0.0)) continue;
      TetPoints P, p;
      for (int k = 0; k < 4; ++k)
        P.col(k) = X.segment<3>(3 * m.T(t, k)), p.col(k) = x.segment<3>(3 * m.T(t, k));
      for (const Eigen::MatrixX3d* dir : {&field.direction_1, &field.direction_2}) {
        const Eigen::Vector4d c = fibre_coefficients(P, dir->row(t).transpose().normalized());
        Vector12d g12;
        e += isochoric_fibre(p, c, tet_signed_volume(P), field.stiffness_mpa(t) / 4.0,
                             field.toe_k2(t), arm_determinant(P), &g12, nullptr,
                             (P * c).squaredNorm());
        for (int k = 0; k < 4; ++k) g.segment<3>(3 * m.T(t, k)) += g12.segment<3>(3 * k);
      }
    }
    return e;
  };
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 0.01);
  Eigen::VectorXd twisted = X, stretched = X;
  for (Eigen::Index i = 0; i < model.num_nodes(); ++i) {
    const Eigen::Vector3d p = X.segment<3>(3 * i);
    twisted.segment<3>(3 * i) = Eigen::AngleAxisd(0.02 * p.y(), Eigen::Vector3d::UnitY()) * p;
    stretched.segment<3>(3 * i) = Eigen::Vector3d(p.x(), 1.05 * p.y(), p.z());
  }
  Eigen::VectorXd inverted = twisted;
  const Eigen::Index t0 = [&] {
    for (Eigen::Index t = 0; t < m.num_tets(); ++t)
      if (field.stiffness_mpa(t) > 0.0) return t;
    return Eigen::Index(-1);
  }();
  ASSERT_GE(t0, 0);
  // Move vertex 0 of an annulus tet through its opposite face.
  const Eigen::Vector3d q0 = X.segment<3>(3 * m.T(t0, 0)),
                        face = (X.segment<3>(3 * m.T(t0, 1)) + X.segment<3>(3 * m.T(t0, 2)) +
                                X.segment<3>(3 * m.T(t0, 3))) /
                               3.0;
  inverted.segment<3>(3 * m.T(t0, 0)) = q0 + 2.0 * (face - q0);
  for (Eigen::VectorXd* x : {&twisted, &stretched, &inverted}) {
    for (Eigen::Index i = 0; i < x->size(); ++i) (*x)(i) += n(rng);
    Eigen::VectorXd g, g_ref;
    const double e = model.term_energy(*x, Term::fibre, 0);
    model.term_gradient(*x, Term::fibre, 0, g);
    const double e_ref = reference(*x, g_ref);
    ASSERT_GT(g_ref.norm(), 0.0);
    EXPECT_LE((g - g_ref).norm(), 1e-12 * g_ref.norm());
    if (x == &inverted) {
      EXPECT_TRUE(std::isnan(e) && std::isnan(e_ref));
    } else {
      EXPECT_NEAR(e, e_ref, 1e-12 * e_ref);
      EXPECT_GT(e, 0.0);
    }
  }
}

// A mesh that brings its own fibre paths: the network's isochoric fibre elements lie along them.
// Under a homogeneous isochoric deformation the fibre term's energy is then the nonlinear FEM's
// fibre energy summed over the tets with the paths' directions (an independent implementation),
// and it differs from the energy with the annulus geometry's directions.
TEST_F(FibreModel, FollowsTheMeshsFibrePathsAsTheNonlinearFemDoes) {
  const mesh::TetMesh bare = disc();
  mesh::TetMesh m = bare;
  const Eigen::Index nt = m.num_tets();
  std::mt19937 rng(5);
  std::normal_distribution<double> n;
  m.fibre_paths.direction_1.setZero(nt, 3);
  m.fibre_paths.direction_2.setZero(nt, 3);
  for (Eigen::Index t = 0; t < nt; ++t)
    if (m.region(t) == 1) {
      m.fibre_paths.direction_1.row(t) = Eigen::RowVector3d(n(rng), n(rng), n(rng)).normalized();
      m.fibre_paths.direction_2.row(t) = Eigen::RowVector3d(n(rng), n(rng), n(rng)).normalized();
    }
  MssOptions o;
  o.fibre_springs = true;
  const MssModel model(m, material(), o), geometric(bare, material(), o);
  const mesh::ElementFibres k = mesh::fibre_field(bare, material());  // E_f by depth
  const Eigen::Matrix3d F = stretch_along(Eigen::Vector3d(0.3, 1, -0.2).normalized(), 1.06, 0.1);
  const Eigen::VectorXd X = model.rest_positions_mm();
  Eigen::VectorXd x(X.size());
  for (Eigen::Index i = 0; i < model.num_nodes(); ++i) x.segment<3>(3 * i) = F * X.segment<3>(3 * i);
  double reference = 0;
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (!(k.stiffness_mpa(t) > 0)) continue;
    const double V0 = mesh::tet_volume(m, t);
    for (const Eigen::MatrixX3d* d : {&m.fibre_paths.direction_1, &m.fibre_paths.direction_2})
      reference += fem_fibre_energy(F, d->row(t).transpose(), V0, k.stiffness_mpa(t) / 4,
                                    k.toe_k2(t));
  }
  const double e = model.term_energy(x, Term::fibre, 0);
  ASSERT_GT(reference, 0.0);
  EXPECT_NEAR(e, reference, 1e-10 * reference);
  EXPECT_GT(std::abs(geometric.term_energy(x, Term::fibre, 0) - e), 0.05 * e);
}

// rest_tangent: the rest Hessian plus every fibre's tension side. At rest each fibre is in
// tension for exactly one of ±v (unless v leaves its stretch alone), so the fibre energies at
// X + hv and X - hv add up to h²/2 vᵀ (T - H0) v to O(h³): the tension sides, seen through the
// element energies alone. Without fibre elements T is the rest Hessian itself.
TEST_F(FibreModel, RestTangentAddsEveryFibresTensionSide) {
  for (const bool isochoric : {false, true}) {
    SCOPED_TRACE(isochoric);
    MssOptions o;
    o.fibre_springs = true;
    o.isochoric_fibres = isochoric;
    const MssModel model(disc(), material(), o);
    const Eigen::VectorXd X = model.rest_positions_mm();
    Eigen::SparseMatrix<double> T, H0;
    model.rest_tangent(T);
    model.hessian(X, HessianMode::exact, H0);
    std::mt19937 rng(3);
    std::normal_distribution<double> n;
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::VectorXd v(X.size());
      for (Eigen::Index i = 0; i < v.size(); ++i) v(i) = n(rng);
      const double h = 1e-5;
      const double both = model.term_energy(X + h * v, Term::fibre, 0) +
                          model.term_energy(X - h * v, Term::fibre, 0);
      const double quad = v.dot((T - H0) * v);
      ASSERT_GT(quad, 0.0);
      EXPECT_NEAR(2.0 * both / (h * h), quad, 1e-4 * quad) << "trial " << trial;
    }
  }
  const MssModel plain(disc(), material(), MssOptions());
  Eigen::SparseMatrix<double> T, H0;
  plain.rest_tangent(T);
  plain.hessian(plain.rest_positions_mm(), HessianMode::exact, H0);
  EXPECT_EQ((T - H0).norm(), 0.0);
}

TEST_F(FibreModel, FibreSpringsNeedAFibreReinforcedMaterial) {
  mesh::RegionMaterials plain = material();
  plain.fibres.clear();
  MssOptions o;
  o.fibre_springs = true;
  EXPECT_THROW(MssModel(disc(), plain, o), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::mss
