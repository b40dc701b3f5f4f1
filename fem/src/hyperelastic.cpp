#include "spinesim/fem/hyperelastic.hpp"

#include <Eigen/LU>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace spinesim::fem {

namespace {

/// Voigt index I → tensor indices (i, j), order (xx, yy, zz, yz, xz, xy).
constexpr int kVoigt[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};

/// (X ⊗ Y)_ijkl = X_ij Y_kl as a Voigt 6×6.
Matrix6d outer(const Eigen::Matrix3d& X, const Eigen::Matrix3d& Y) {
  Matrix6d out;
  for (int I = 0; I < 6; ++I)
    for (int J = 0; J < 6; ++J)
      out(I, J) = X(kVoigt[I][0], kVoigt[I][1]) * Y(kVoigt[J][0], kVoigt[J][1]);
  return out;
}

/// −∂C⁻¹/∂C: ½ (C⁻¹_ik C⁻¹_jl + C⁻¹_il C⁻¹_jk) as a Voigt 6×6.
Matrix6d inverse_derivative(const Eigen::Matrix3d& Ci) {
  Matrix6d out;
  for (int I = 0; I < 6; ++I)
    for (int J = 0; J < 6; ++J) {
      const int i = kVoigt[I][0], j = kVoigt[I][1], k = kVoigt[J][0], l = kVoigt[J][1];
      out(I, J) = 0.5 * (Ci(i, k) * Ci(j, l) + Ci(i, l) * Ci(j, k));
    }
  return out;
}

/// An isochoric invariant Ī_M = J^(−2/3) I_M, I_M = tr(M C), of a structure tensor M (I for
/// Ī1, a⊗a for Ī4), with its derivatives
///   G = ∂Ī_M/∂C = J^(−2/3) (M − I_M/3 C⁻¹),
///   ∂G/∂C = J^(−2/3) [ −(M ⊗ C⁻¹ + C⁻¹ ⊗ M)/3 + I_M/9 C⁻¹ ⊗ C⁻¹ + I_M/3 (−∂C⁻¹/∂C) ].
struct IsochoricInvariant {
  double value = 0;
  Eigen::Matrix3d first;
  Matrix6d second;
};

IsochoricInvariant isochoric(const Eigen::Matrix3d& M, const Eigen::Matrix3d& C,
                             const Eigen::Matrix3d& Ci, double j23, const Matrix6d* dCi,
                             const Matrix6d* CiCi) {
  IsochoricInvariant out;
  const double I = (M * C).trace();
  out.value = j23 * I;
  out.first = j23 * (M - I / 3.0 * Ci);
  if (dCi)
    out.second = j23 * (-(outer(M, Ci) + outer(Ci, M)) / 3.0 + I / 9.0 * *CiCi + I / 3.0 * *dCi);
  return out;
}

/// ψ(Ī4) of one family and its first two derivatives; zero below Ī4 = 1 (the tangent at exactly
/// Ī4 = 1 is the tension side's, as CalculiX takes it).
struct FibreLaw {
  double psi = 0, d1 = 0, d2 = 0;
};

FibreLaw fibre_law(const FibreFamily& f, double i4) {
  const double x = i4 - 1.0;
  if (x < 0) return {};
  const double e = std::exp(f.k2 * x * x);
  FibreLaw law;
  law.psi = f.k2 > 0 ? f.k1_mpa / (2.0 * f.k2) * (e - 1.0) : 0.5 * f.k1_mpa * x * x;
  law.d1 = f.k1_mpa * x * e;
  law.d2 = f.k1_mpa * e * (1.0 + 2.0 * f.k2 * x * x);
  return law;
}

bool finite_and_at_least(double v, double min, bool strict) {
  return std::isfinite(v) && (strict ? v > min : v >= min);
}

}  // namespace

void validate(const FibreHyperelastic& m, const char* what) {
  const std::string w(what);
  if (!finite_and_at_least(m.c10_mpa, 0, true))
    throw std::invalid_argument(w + ": C10 must be a finite number > 0 MPa");
  if (!finite_and_at_least(m.d1_per_mpa, 0, true))
    throw std::invalid_argument(w + ": D1 must be a finite number > 0 1/MPa");
  for (const FibreFamily& f : m.fibres) {
    if (!finite_and_at_least(f.k1_mpa, 0, false))
      throw std::invalid_argument(w + ": fibre k1 must be a finite number >= 0 MPa");
    if (!finite_and_at_least(f.k2, 0, false))
      throw std::invalid_argument(w + ": fibre k2 must be a finite number >= 0");
    if (!f.direction.allFinite() || std::abs(f.direction.norm() - 1.0) > 1e-9)
      throw std::invalid_argument(w + ": a fibre direction must be a unit vector");
  }
}

FibreHyperelastic neo_hookean_from_linear(double young_mpa, double poisson) {
  if (!(young_mpa > 0) || !std::isfinite(young_mpa) || !(poisson > -1) || !(poisson < 0.5))
    throw std::invalid_argument("neo-Hookean from E, nu: E > 0 and -1 < nu < 0.5 required");
  FibreHyperelastic m;
  const double mu = young_mpa / (2.0 * (1.0 + poisson));
  const double bulk = young_mpa / (3.0 * (1.0 - 2.0 * poisson));
  m.c10_mpa = mu / 2.0;
  m.d1_per_mpa = 2.0 / bulk;
  return m;
}

namespace {

/// C⁻¹, J and the Voigt tensors of C⁻¹ a material point needs; false when det C <= 0.
struct Kinematics {
  double J = 0;
  Eigen::Matrix3d Ci;
  Matrix6d dCi, CiCi;  ///< −∂C⁻¹/∂C and C⁻¹ ⊗ C⁻¹ (only with the tangent)
};

bool kinematics(const Eigen::Matrix3d& C, bool with_tangent, Kinematics& k) {
  const double det = C.determinant();
  if (!(det > 0) || !C.allFinite()) return false;
  k.J = std::sqrt(det);
  k.Ci = C.inverse();
  if (with_tangent) k.dCi = inverse_derivative(k.Ci), k.CiCi = outer(k.Ci, k.Ci);
  return true;
}

MaterialPointState invalid_state() {
  MaterialPointState out;
  out.energy = std::numeric_limits<double>::quiet_NaN();
  return out;
}

MaterialPointState checked(MaterialPointState out) {
  if (!std::isfinite(out.energy) || !out.S.allFinite() || !out.tangent.allFinite())
    out.energy = std::numeric_limits<double>::quiet_NaN();
  return out;
}

MaterialPointState isochoric_part(const Eigen::Matrix3d& C, const FibreHyperelastic& m,
                                  const Kinematics& k, bool with_tangent) {
  MaterialPointState out;
  const double j23 = std::pow(k.J, -2.0 / 3.0);
  const Matrix6d* pdCi = with_tangent ? &k.dCi : nullptr;
  const Matrix6d* pCiCi = with_tangent ? &k.CiCi : nullptr;
  // ∂W/∂C, term by term; S = 2 ∂W/∂C, ℂ = 4 ∂²W/∂C².
  const IsochoricInvariant i1 = isochoric(Eigen::Matrix3d::Identity(), C, k.Ci, j23, pdCi, pCiCi);
  out.energy = m.c10_mpa * (i1.value - 3.0);
  Eigen::Matrix3d dW = m.c10_mpa * i1.first;
  Matrix6d d2W = Matrix6d::Zero();
  if (with_tangent) d2W = m.c10_mpa * i1.second;
  for (const FibreFamily& f : m.fibres) {
    const Eigen::Matrix3d A = f.direction * f.direction.transpose();
    const IsochoricInvariant i4 = isochoric(A, C, k.Ci, j23, pdCi, pCiCi);
    const FibreLaw law = fibre_law(f, i4.value);
    if (i4.value > 1.0) ++out.fibres_in_tension;
    if (i4.value < 1.0) continue;
    out.energy += law.psi;
    dW += law.d1 * i4.first;
    if (with_tangent) d2W += law.d2 * outer(i4.first, i4.first) + law.d1 * i4.second;
  }
  out.S = 2.0 * dW;
  out.tangent = 4.0 * d2W;
  return out;
}

/// S = p J C⁻¹ and ℂ = 2 ∂S/∂C at fixed p = p J (C⁻¹ ⊗ C⁻¹ − 2 (−∂C⁻¹/∂C)).
void add_pressure(double p, const Kinematics& k, bool with_tangent, MaterialPointState& out) {
  out.S += p * k.J * k.Ci;
  if (with_tangent) out.tangent += p * k.J * (k.CiCi - 2.0 * k.dCi);
}

}  // namespace

VolumetricEnergy volumetric_energy(double J, const FibreHyperelastic& m) {
  return {(J - 1.0) * (J - 1.0) / m.d1_per_mpa, 2.0 * (J - 1.0) / m.d1_per_mpa, 2.0 / m.d1_per_mpa};
}

MaterialPointState fibre_hyperelastic_point(const Eigen::Matrix3d& C, const FibreHyperelastic& m,
                                            bool with_tangent) {
  Kinematics k;
  if (!kinematics(C, with_tangent, k)) return invalid_state();
  MaterialPointState out = isochoric_part(C, m, k, with_tangent);
  // U(J) with ∂J/∂C = J C⁻¹/2: S gains U'(J) J C⁻¹, ℂ the fixed-pressure part and U'' J² C⁻¹⊗C⁻¹.
  const VolumetricEnergy U = volumetric_energy(k.J, m);
  out.energy += U.value;
  add_pressure(U.first, k, with_tangent, out);
  if (with_tangent) out.tangent += U.second * k.J * k.J * k.CiCi;
  return checked(out);
}

MaterialPointState isochoric_point(const Eigen::Matrix3d& C, const FibreHyperelastic& m,
                                   bool with_tangent) {
  Kinematics k;
  if (!kinematics(C, with_tangent, k)) return invalid_state();
  return checked(isochoric_part(C, m, k, with_tangent));
}

MaterialPointState pressure_point(const Eigen::Matrix3d& C, double pressure_mpa,
                                  bool with_tangent) {
  Kinematics k;
  if (!kinematics(C, with_tangent, k)) return invalid_state();
  MaterialPointState out;
  add_pressure(pressure_mpa, k, with_tangent, out);
  return checked(out);
}

Eigen::Matrix3d cauchy_stress(const Eigen::Matrix3d& F, const FibreHyperelastic& m) {
  const MaterialPointState p = fibre_hyperelastic_point(F.transpose() * F, m, false);
  return F * p.S * F.transpose() / F.determinant();
}

Vector6d to_voigt(const Eigen::Matrix3d& T) {
  Vector6d v;
  for (int I = 0; I < 6; ++I) v(I) = T(kVoigt[I][0], kVoigt[I][1]);
  return v;
}

}  // namespace spinesim::fem
