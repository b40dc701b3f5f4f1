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

/// A named material assignment: one material per region label (1 annulus, 2 nucleus, ...).
/// `fallback` applies to every label not listed (the homogeneous case).
struct RegionMaterials {
  std::string name;
  IsotropicMaterial fallback;
  std::map<int, IsotropicMaterial> by_region;

  const IsotropicMaterial& at(int region) const {
    auto it = by_region.find(region);
    return it == by_region.end() ? fallback : it->second;
  }
};

/// Parses {"name","E_mpa","nu"|"G_mpa","density_kg_m3"} or
/// {"name","annulus":{...},"nucleus":{...}}; validates. Throws std::invalid_argument.
RegionMaterials material_from_json(const nlohmann::json& j);

/// A preset name (looked up in `data_dir`/materials/NAME.json) or a path to a JSON file.
RegionMaterials load_material(const std::string& name_or_path, const std::string& data_dir);

}  // namespace spinesim::mesh
