// The material point of the nonlinear disc: a compressible neo-Hookean matrix reinforced by
// fibre families that resist tension only, with an exponential toe (Holzapfel, Gasser & Ogden
// 2000, the form disc models use, e.g. Eberlein et al. 2001), written as CalculiX's built-in
// ELASTIC_FIBER material writes it so that the two can be compared term by term:
//
//   W(C) = C10 (Ī1 − 3) + (J − 1)² / D1 + Σ_f k1_f / (2 k2_f) [exp(k2_f ⟨Ī4f − 1⟩²) − 1]
//
//   C = FᵀF,  J = √det C,  Ī1 = J^(−2/3) tr C,  Ī4f = J^(−2/3) a_f·C a_f,  ⟨x⟩ = max(x, 0),
//
// a_f the unit fibre direction in the reference configuration. A family carries load only while
// its (isochoric) stretch exceeds 1: a fibre in compression buckles and carries nothing, which
// the linear fibres of fibres.hpp do not model. At small strain the matrix is the isotropic
// linear material with μ = 2 C10 and K = 2 / D1; a fibre family in tension adds
// 2 k1 (a·ε̄ a)² to the energy (ε̄ the deviatoric strain), i.e. the linear fibre stiffness
// k = 4 k1 along a.
//
// S = 2 ∂W/∂C (second Piola–Kirchhoff, MPa) and the material tangent ℂ = 4 ∂²W/∂C∂C
// (dS = ℂ : dE, E = (C − I)/2), in Voigt form as elasticity.hpp: order (xx, yy, zz, yz, xz, xy),
// dS_voigt = ℂ_voigt dE_voigt with engineering shear strains. Units: MPa; k2 dimensionless.
#pragma once

#include "spinesim/fem/elasticity.hpp"

#include <Eigen/Core>

#include <vector>

namespace spinesim::fem {

/// One fibre family: unit direction (reference configuration) and the exponential law.
struct FibreFamily {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double k1_mpa = 0;  ///< stress-like, MPa (> 0)
  double k2 = 0;      ///< dimensionless toe exponent (>= 0; 0: a quadratic law)
};

/// The material of one element or region: neo-Hookean matrix and its fibre families.
struct FibreHyperelastic {
  double c10_mpa = 0;     ///< > 0; shear modulus μ = 2 C10
  double d1_per_mpa = 0;  ///< > 0; bulk modulus K = 2 / D1
  std::vector<FibreFamily> fibres;
};

/// Throws std::invalid_argument (one line, naming `what`) for C10 or D1 not finite and > 0,
/// k1 not finite and >= 0, k2 not finite and >= 0, or a fibre direction not of unit length
/// (1e-9).
void validate(const FibreHyperelastic& m, const char* what = "material");

/// The parameters of the isotropic linear material with these small-strain moduli (E, ν).
FibreHyperelastic neo_hookean_from_linear(double young_mpa, double poisson);

struct MaterialPointState {
  double energy = 0;                            ///< W, MPa (= mJ/mm³)
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();  ///< second Piola–Kirchhoff stress, MPa
  Matrix6d tangent = Matrix6d::Zero();          ///< ℂ, Voigt, MPa
  int fibres_in_tension = 0;                    ///< families with Ī4 > 1
};

/// W, S and ℂ at the right Cauchy–Green tensor C (symmetric, det C > 0). Non-finite results
/// (a fibre stretched past the exponential's range, det C <= 0) are returned as NaN energy, for
/// a Newton line search to step back from.
MaterialPointState fibre_hyperelastic_point(const Eigen::Matrix3d& C, const FibreHyperelastic& m,
                                            bool with_tangent = true);

/// The split W = W̄(C) + U(J) the mean-dilatation element (hyperelastic_element.hpp) needs:
/// U(J) = (J − 1)²/D1 and its first two derivatives (MPa) ...
struct VolumetricEnergy {
  double value = 0, first = 0, second = 0;
};
VolumetricEnergy volumetric_energy(double J, const FibreHyperelastic& m);

/// ... W̄ alone — the matrix's Ī1 term and the fibres, with its S and ℂ ...
MaterialPointState isochoric_point(const Eigen::Matrix3d& C, const FibreHyperelastic& m,
                                   bool with_tangent = true);

/// ... and the volumetric stress at a pressure p held fixed: S = p J C⁻¹, ℂ = 2 ∂S/∂C at fixed p
/// (energy 0). fibre_hyperelastic_point is isochoric_point + pressure_point(U'(J)) + U''(J) J²
/// C⁻¹ ⊗ C⁻¹ in ℂ.
MaterialPointState pressure_point(const Eigen::Matrix3d& C, double pressure_mpa,
                                  bool with_tangent = true);

/// The Cauchy stress σ = J⁻¹ F S Fᵀ (MPa) of the deformation gradient F.
Eigen::Matrix3d cauchy_stress(const Eigen::Matrix3d& F, const FibreHyperelastic& m);

/// Voigt vector (xx, yy, zz, yz, xz, xy) of a symmetric tensor (no factor 2 on the shears).
Vector6d to_voigt(const Eigen::Matrix3d& T);

}  // namespace spinesim::fem
