// The nonlinear disc's material point (fem/hyperelastic.hpp) against what it must be: its stress
// the derivative of its energy and its tangent the derivative of its stress (central
// differences), the linear isotropic material at rest, fibres that carry tension only, and the
// closed forms of simple shear and of an isochoric stretch along a fibre.
#include "spinesim/fem/hyperelastic.hpp"

#include "hyperelastic_fixtures.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <cmath>
#include <stdexcept>

namespace spinesim::fem {
namespace {

using fixtures::annulus;

/// A deformation with one family stretched and the other shortened.
Eigen::Matrix3d deformation() {
  Eigen::Matrix3d F;
  F << 1.0, 0.25, 0.01,   //
      0.02, 0.99, -0.03,  //
      -0.01, 0.02, 1.0;
  return F;
}

/// The symmetric unit perturbation of Voigt component I of C.
Eigen::Matrix3d unit(int I) {
  static const int idx[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
  E(idx[I][0], idx[I][1]) = E(idx[I][1], idx[I][0]) = 1.0;
  return E;
}

TEST(FibreHyperelastic, StressIsTheEnergysDerivative) {
  const FibreHyperelastic m = annulus();
  const Eigen::Matrix3d F = deformation(), C = F.transpose() * F;
  const MaterialPointState p = fibre_hyperelastic_point(C, m);
  EXPECT_EQ(p.fibres_in_tension, 1);
  const double h = 1e-6;
  for (int I = 0; I < 6; ++I) {
    const double dW = (fibre_hyperelastic_point(C + h * unit(I), m, false).energy -
                       fibre_hyperelastic_point(C - h * unit(I), m, false).energy) /
                      (2 * h);
    // dW = S : dE with dE = dC / 2: S_ii / 2 on the diagonal, S_ij off it (both entries moved).
    const Vector6d S = to_voigt(p.S);
    EXPECT_NEAR(dW, I < 3 ? S(I) / 2 : S(I), 1e-7 * (1 + std::abs(S(I)))) << "component " << I;
  }
}

TEST(FibreHyperelastic, TangentIsTheStresssDerivative) {
  const FibreHyperelastic m = annulus();
  const Eigen::Matrix3d F = deformation(), C = F.transpose() * F;
  const MaterialPointState p = fibre_hyperelastic_point(C, m);
  const double h = 1e-6;
  for (int J = 0; J < 6; ++J) {
    const Vector6d dS = (to_voigt(fibre_hyperelastic_point(C + h * unit(J), m, false).S) -
                         to_voigt(fibre_hyperelastic_point(C - h * unit(J), m, false).S)) /
                        (2 * h);
    // dC = unit(J) per unit h: dE = dC/2, engineering shear 2 dE_ij = 1 off the diagonal.
    const double dE = J < 3 ? 0.5 : 1.0;
    EXPECT_LE((dS - p.tangent.col(J) * dE).norm(), 1e-6 * p.tangent.norm()) << "column " << J;
  }
  EXPECT_LE((p.tangent - p.tangent.transpose()).norm(), 1e-12 * p.tangent.norm());
}

// The split the mean-dilatation element uses: W̄ has no volumetric stress (S̄ : C = 0, the
// isochoric part is deviatoric in the sense of C), the pressure part at fixed p is p J C⁻¹ with
// the fixed-p tangent (central differences), and the parts sum to the whole point.
TEST(FibreHyperelastic, IsochoricAndPressurePartsSumToThePoint) {
  const FibreHyperelastic m = annulus();
  const Eigen::Matrix3d F = deformation(), C = F.transpose() * F;
  const double J = F.determinant();
  const MaterialPointState whole = fibre_hyperelastic_point(C, m);
  const MaterialPointState iso = isochoric_point(C, m);
  EXPECT_NEAR((iso.S * C).trace(), 0, 1e-12 * iso.S.norm());
  const VolumetricEnergy U = volumetric_energy(J, m);
  EXPECT_NEAR(U.value, (J - 1) * (J - 1) / m.d1_per_mpa, 1e-15);
  const double h = 1e-6;
  EXPECT_NEAR(U.first,
              (volumetric_energy(J + h, m).value - volumetric_energy(J - h, m).value) / (2 * h),
              1e-8);
  const MaterialPointState vol = pressure_point(C, U.first);
  EXPECT_NEAR(vol.energy, 0, 0);
  EXPECT_LE((vol.S - U.first * J * C.inverse()).norm(), 1e-14 * vol.S.norm());
  for (int K = 0; K < 6; ++K) {
    const Vector6d dS = (to_voigt(pressure_point(C + h * unit(K), U.first, false).S) -
                         to_voigt(pressure_point(C - h * unit(K), U.first, false).S)) /
                        (2 * h);
    EXPECT_LE((dS - vol.tangent.col(K) * (K < 3 ? 0.5 : 1.0)).norm(), 1e-6 * vol.tangent.norm());
  }
  const Eigen::Matrix3d Ci = C.inverse();
  Matrix6d CiCi;
  for (int I = 0; I < 6; ++I)
    for (int K = 0; K < 6; ++K) CiCi(I, K) = to_voigt(Ci)(I) * to_voigt(Ci)(K);
  EXPECT_NEAR(whole.energy, iso.energy + U.value, 1e-14 * whole.energy);
  EXPECT_LE((whole.S - iso.S - vol.S).norm(), 1e-13 * whole.S.norm());
  EXPECT_LE((whole.tangent - iso.tangent - vol.tangent - U.second * J * J * CiCi).norm(),
            1e-12 * whole.tangent.norm());
  EXPECT_EQ(iso.fibres_in_tension, whole.fibres_in_tension);
}

TEST(FibreHyperelastic, AtRestTheMatrixIsTheLinearIsotropicMaterial) {
  const mesh::IsotropicMaterial lin{4.2, 0.45, 1200.0};
  const FibreHyperelastic m = neo_hookean_from_linear(lin.youngs_modulus_mpa, lin.poisson_ratio);
  const MaterialPointState p = fibre_hyperelastic_point(Eigen::Matrix3d::Identity(), m);
  EXPECT_NEAR(p.energy, 0, 1e-15);
  EXPECT_LE(p.S.norm(), 1e-14);
  const Matrix6d D = isotropic_elasticity(lin);
  EXPECT_LE((p.tangent - D).norm(), 1e-12 * D.norm()) << p.tangent << "\n\n" << D;
}

TEST(FibreHyperelastic, FibresCarryTensionOnly) {
  FibreHyperelastic matrix = annulus();
  matrix.fibres.clear();
  FibreHyperelastic along_x = matrix;
  along_x.fibres.push_back({Eigen::Vector3d::UnitX(), 3.0, 45.0});
  for (const double stretch : {0.9, 0.97, 1.03, 1.1}) {
    SCOPED_TRACE(stretch);
    const Eigen::Matrix3d F = Eigen::Vector3d(stretch, 1, 1).asDiagonal();
    const Eigen::Matrix3d C = F.transpose() * F;
    const MaterialPointState with = fibre_hyperelastic_point(C, along_x);
    const MaterialPointState without = fibre_hyperelastic_point(C, matrix);
    // Ī4 = J^(-2/3) λ² = λ^(4/3) for this stretch: above 1 exactly when λ > 1.
    if (stretch < 1) {
      EXPECT_EQ(with.fibres_in_tension, 0);
      EXPECT_EQ(with.S, without.S);
      EXPECT_EQ(with.energy, without.energy);
    } else {
      EXPECT_EQ(with.fibres_in_tension, 1);
      EXPECT_GT(with.S(0, 0), without.S(0, 0));
      EXPECT_GT(with.energy, without.energy);
    }
  }
}

TEST(FibreHyperelastic, SimpleShearOfTheMatrixIsNeoHookean) {
  FibreHyperelastic m = annulus();
  m.fibres.clear();
  const double mu = 2 * m.c10_mpa;
  for (const double gamma : {0.01, 0.2, 0.5}) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(0, 1) = gamma;
    const Eigen::Matrix3d s = cauchy_stress(F, m);
    EXPECT_NEAR(s(0, 1), mu * gamma, 1e-12);
    EXPECT_NEAR(s(0, 0) - s(1, 1), mu * gamma * gamma, 1e-12);  // the Poynting effect
    EXPECT_NEAR(s(1, 1), s(2, 2), 1e-12);
  }
}

TEST(FibreHyperelastic, IsochoricStretchAlongAFibreHasItsClosedForm) {
  // F = diag(λ, λ^-1/2, λ^-1/2), fibre along x: Ī1 = λ² + 2/λ, Ī4 = λ², J = 1, and
  //   σ_xx − σ_yy = 2 C10 (λ² − 1/λ) + 2 λ² k1 (λ² − 1) exp(k2 (λ² − 1)²).
  FibreHyperelastic m = annulus();
  m.fibres = {{Eigen::Vector3d::UnitX(), 2.5, 12.0}};
  for (const double l : {1.0, 1.02, 1.05, 1.1}) {
    const Eigen::Matrix3d F = Eigen::Vector3d(l, 1 / std::sqrt(l), 1 / std::sqrt(l)).asDiagonal();
    const Eigen::Matrix3d s = cauchy_stress(F, m);
    const double x = l * l - 1;
    const double expected =
        2 * m.c10_mpa * (l * l - 1 / l) + 2 * l * l * 2.5 * x * std::exp(12.0 * x * x);
    EXPECT_NEAR(s(0, 0) - s(1, 1), expected, 1e-12 * (1 + expected)) << "stretch " << l;
    EXPECT_NEAR(s(1, 1), s(2, 2), 1e-12);
  }
}

TEST(FibreHyperelastic, VolumeChangeMeetsTheBulkModulus) {
  // Pure dilatation F = s I: Ī1 = 3, Ī4 = 1, so only the volumetric term acts:
  //   σ = p I,  p = dU/dJ = 2 (J − 1) / D1,  J = s³.
  const FibreHyperelastic m = annulus();
  for (const double s : {0.98, 1.0, 1.01}) {
    const Eigen::Matrix3d sig = cauchy_stress(s * Eigen::Matrix3d::Identity(), m);
    const double J = s * s * s;
    EXPECT_NEAR(sig(0, 0), 2 * (J - 1) / m.d1_per_mpa, 1e-12);
    EXPECT_LE((sig - sig(0, 0) * Eigen::Matrix3d::Identity()).norm(), 1e-12);
  }
}

TEST(FibreHyperelastic, BadParametersAndStatesAreRefused) {
  FibreHyperelastic m = annulus();
  EXPECT_NO_THROW(validate(m));
  FibreHyperelastic bad = m;
  bad.c10_mpa = 0;
  EXPECT_THROW(validate(bad), std::invalid_argument);
  bad = m;
  bad.d1_per_mpa = NAN;
  EXPECT_THROW(validate(bad), std::invalid_argument);
  bad = m;
  bad.fibres[0].direction = Eigen::Vector3d::Zero();
  EXPECT_THROW(validate(bad, "annulus"), std::invalid_argument);
  bad = m;
  bad.fibres[1].k2 = -1;
  EXPECT_THROW(validate(bad), std::invalid_argument);
  EXPECT_THROW(neo_hookean_from_linear(1, 0.5), std::invalid_argument);
  // An inverted element and a fibre past the exponential's range give no number to step on.
  EXPECT_TRUE(std::isnan(fibre_hyperelastic_point(-Eigen::Matrix3d::Identity(), m).energy));
  const Eigen::Matrix3d far = Eigen::Vector3d(100, 1, 1).asDiagonal();
  EXPECT_TRUE(std::isnan(fibre_hyperelastic_point(far, m).energy));
}

}  // namespace
}  // namespace spinesim::fem
