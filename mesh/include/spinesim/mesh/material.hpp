// Isotropic linear-elastic materials per region, and their parsing/validation.
//
// A material is (E, nu, rho). Input may give (E, nu) or (E, G); (E, G) is accepted only when
// the implied nu = E/(2G) - 1 lies in [0, 0.5): thesis table 5.1's rubber (E 30, G 0.6 ->
// nu = 24) and polyethylene (E 200, G 117 -> nu = -0.145) pairs are refused with the reason
// (an auxetic polyethylene contradicts its measured nu ~ 0.46; data/materials/README.md).
// Given directly, any -1 < nu < 0.5 is accepted.
// Units: E and G in MPa (= N/mm^2), density in kg/m^3 (converted to t/mm^3 where used).
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <map>
#include <string>

namespace spinesim::mesh {

struct IsotropicMaterial {
  double youngs_modulus_mpa = 0.0;
  double poisson_ratio = 0.0;
  double density_kg_m3 = 1000.0;

  double shear_modulus_mpa() const { return youngs_modulus_mpa / (2.0 * (1.0 + poisson_ratio)); }
  double lame_lambda_mpa() const {
    return youngs_modulus_mpa * poisson_ratio /
           ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
  }
  /// Density in the mm–N–tonne–s system, t/mm^3.
  double density_t_mm3() const { return density_kg_m3 * 1e-12; }
};

/// Throws std::invalid_argument unless E > 0, -1 < nu < 0.5, rho > 0, all finite.
void validate(const IsotropicMaterial& m, const std::string& what = "material");

/// Linear collagen-fibre reinforcement of a region (the annulus fibrosus), added to its isotropic
/// matrix. The annulus is a laminate of lamellae whose fibres alternate between +angle and
/// -angle to the transverse plane, in the plane tangent to the lamella. Lamellae (0.1-0.5 mm) are
/// thinner than the elements, so every element carries both families, each with the stiffness of
/// half the lamellae (a cross-ply laminate, homogenised): family f adds
///   sigma = (E_f / 2) (a_f . eps a_f) a_f (x) a_f,
/// E_f the modulus the fibres give one lamella along its fibre direction. Angle and modulus
/// vary linearly with the depth s in the annulus, s = 0 at the nucleus, s = 1 at the outer wall.
/// Linear fibres also resist compression along their length (real fibres buckle): a stated
/// limitation of a linear reference.
struct FibreReinforcement {
  double modulus_inner_mpa = 0, modulus_outer_mpa = 0;  ///< E_f at s = 0 and s = 1
  double angle_inner_deg = 0, angle_outer_deg = 0;      ///< to the transverse plane
  /// The nonlinear disc's toe exponent k2 (fem/hyperelastic.hpp: tension-only exponential
  /// fibres), dimensionless, >= 0; the linear FEM does not use it. Files: optional "k2".
  double toe_k2 = 10.0;
  std::string source;

  double modulus_mpa(double depth) const {
    return modulus_inner_mpa + (modulus_outer_mpa - modulus_inner_mpa) * depth;
  }
  double angle_deg(double depth) const {
    return angle_inner_deg + (angle_outer_deg - angle_inner_deg) * depth;
  }
};

/// Throws std::invalid_argument unless 0 < E_f <= 1e5 MPa, 0 <= angle <= 90 deg and
/// 0 <= k2 <= 1000, finite.
void validate(const FibreReinforcement& f, const std::string& what = "fibres");

/// A named material assignment: one material per region label (1 annulus, 2 nucleus, ...).
/// `fallback` applies to every label not listed (the homogeneous case). `fibres` reinforces
/// the regions it lists (in the files: an annulus with a "fibres" object).
struct RegionMaterials {
  std::string name;
  IsotropicMaterial fallback;
  std::map<int, IsotropicMaterial> by_region;
  std::map<int, FibreReinforcement> fibres;

  bool has_fibres() const { return !fibres.empty(); }

  const IsotropicMaterial& at(int region) const {
    auto it = by_region.find(region);
    return it == by_region.end() ? fallback : it->second;
  }
};

/// Parses {"name","E_mpa","nu"|"G_mpa","density_kg_m3"} or
/// {"name","annulus":{...},"nucleus":{...}}; the annulus may carry
/// "fibres": {"E_inner_mpa","E_outer_mpa","angle_inner_deg","angle_outer_deg","source"} and
/// optionally "k2".
/// Validates. Throws std::invalid_argument.
RegionMaterials material_from_json(const nlohmann::json& j);

/// A preset name (looked up in `data_dir`/materials/NAME.json) or a path to a JSON file.
RegionMaterials load_material(const std::string& name_or_path, const std::string& data_dir);

}  // namespace spinesim::mesh
