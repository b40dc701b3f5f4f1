#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include "spinesim/common/input_file.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace spinesim::mesh {
namespace {

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

IsotropicMaterial parse_one(const nlohmann::json& j, const std::string& what,
                            std::vector<std::string> also_known = {}) {
  if (!j.is_object()) throw std::invalid_argument(what + ": expected a JSON object");
  for (const char* k : {"E_mpa", "nu", "G_mpa", "density_kg_m3", "source", "notes"})
    also_known.push_back(k);
  require_known_keys(j, also_known, what);
  auto number = [&](const char* key) -> double {
    const auto& v = j.at(key);
    if (!v.is_number()) throw std::invalid_argument(what + ": '" + key + "' must be a number");
    return v.get<double>();
  };
  IsotropicMaterial m;
  if (!j.contains("E_mpa")) throw std::invalid_argument(what + ": missing 'E_mpa'");
  m.youngs_modulus_mpa = number("E_mpa");
  const bool has_nu = j.contains("nu"), has_g = j.contains("G_mpa");
  if (has_nu == has_g) throw std::invalid_argument(what + ": give exactly one of 'nu' and 'G_mpa'");
  if (has_nu) {
    m.poisson_ratio = number("nu");
  } else {
    const double g = number("G_mpa");
    if (!(g > 0)) throw std::invalid_argument(what + ": G_mpa must be > 0 (got " + fmt(g) + ")");
    const double nu = m.youngs_modulus_mpa / (2.0 * g) - 1.0;
    // An (E, G) pair is trusted only when it implies an ordinary isotropic solid: thesis
    // table 5.1 gives rubber E 30 / G 0.6 (nu = 24) and polyethylene E 200 / G 117 (nu < 0).
    if (!(nu >= 0.0 && nu < 0.5))
      throw std::invalid_argument(what + ": E_mpa = " + fmt(m.youngs_modulus_mpa) +
                                  " and G_mpa = " + fmt(g) + " imply nu = E/(2G) - 1 = " + fmt(nu) +
                                  ", outside [0, 0.5) of an isotropic solid; give E_mpa and nu");
    m.poisson_ratio = nu;
  }
  if (j.contains("density_kg_m3")) m.density_kg_m3 = number("density_kg_m3");
  validate(m, what);
  return m;
}

FibreReinforcement parse_fibres(const nlohmann::json& j, const std::string& what) {
  if (!j.is_object()) throw std::invalid_argument(what + ": expected a JSON object");
  require_known_keys(
      j,
      {"E_inner_mpa", "E_outer_mpa", "angle_inner_deg", "angle_outer_deg", "k2", "source", "notes"},
      what);
  auto number = [&](const char* key) -> double {
    if (!j.contains(key)) throw std::invalid_argument(what + ": missing '" + key + "'");
    const auto& v = j.at(key);
    if (!v.is_number()) throw std::invalid_argument(what + ": '" + key + "' must be a number");
    return v.get<double>();
  };
  FibreReinforcement f;
  f.modulus_inner_mpa = number("E_inner_mpa");
  f.modulus_outer_mpa = number("E_outer_mpa");
  f.angle_inner_deg = number("angle_inner_deg");
  f.angle_outer_deg = number("angle_outer_deg");
  if (j.contains("k2")) f.toe_k2 = number("k2");
  f.source = j.value("source", std::string());
  validate(f, what);
  return f;
}

}  // namespace

void validate(const FibreReinforcement& f, const std::string& what) {
  for (double e : {f.modulus_inner_mpa, f.modulus_outer_mpa})
    if (!(e > 0 && e <= 1e5))
      throw std::invalid_argument(what + ": fibre modulus must lie in (0, 1e5] MPa (got " + fmt(e) +
                                  ")");
  for (double a : {f.angle_inner_deg, f.angle_outer_deg})
    if (!(a >= 0 && a <= 90))
      throw std::invalid_argument(what + ": fibre angle must lie in [0, 90] degrees (got " +
                                  fmt(a) + ")");
  if (!(f.toe_k2 >= 0 && f.toe_k2 <= 1000))
    throw std::invalid_argument(what + ": the fibres' toe exponent k2 must lie in [0, 1000] (got " +
                                fmt(f.toe_k2) + ")");
}

void validate(const IsotropicMaterial& m, const std::string& what) {
  const double e = m.youngs_modulus_mpa, nu = m.poisson_ratio, rho = m.density_kg_m3;
  if (!std::isfinite(e) || !std::isfinite(nu) || !std::isfinite(rho))
    throw std::invalid_argument(what + ": non-finite material constant");
  if (!(e > 0))
    throw std::invalid_argument(what + ": Young's modulus must be > 0 MPa (got " + fmt(e) + ")");
  // Diamond is 1.2e6 MPa, a hydrogel 1e-3 MPa: beyond these the solvers work with numbers near
  // the ends of double precision (a wrench on an E = 1e300 disc overflows), so they are refused.
  if (e > 1e7 || e < 1e-9)
    throw std::invalid_argument(what + ": Young's modulus " + fmt(e) +
                                " MPa is outside [1e-9, 1e7] MPa, beyond any solid");
  if (rho > 1e5 || rho < 1e-3)
    throw std::invalid_argument(what + ": density " + fmt(rho) +
                                " kg/m^3 is outside [1e-3, 1e5] kg/m^3");
  if (!(nu > -1.0 && nu < 0.5))
    throw std::invalid_argument(what + ": Poisson's ratio must lie in (-1, 0.5) (got " + fmt(nu) +
                                ")");
  if (!(rho > 0))
    throw std::invalid_argument(what + ": density must be > 0 kg/m^3 (got " + fmt(rho) + ")");
}

RegionMaterials material_from_json(const nlohmann::json& j) {
  if (!j.is_object()) throw std::invalid_argument("material: expected a JSON object");
  RegionMaterials r;
  r.name = "unnamed";
  const bool per_region = j.contains("annulus") || j.contains("nucleus");
  try {
    r.name = j.value("name", std::string("unnamed"));
    if (per_region) {
      if (!j.contains("annulus") || !j.contains("nucleus"))
        throw std::invalid_argument("material '" + r.name +
                                    "': per-region files need both 'annulus' and 'nucleus'");
      require_known_keys(j,
                         {"name", "source", "description", "notes", "annulus", "nucleus",
                          "provenance"},
                         "material '" + r.name + "'");
      r.by_region[int(Region::annulus)] =
          parse_one(j.at("annulus"), "material '" + r.name + "' annulus", {"fibres"});
      r.by_region[int(Region::nucleus)] =
          parse_one(j.at("nucleus"), "material '" + r.name + "' nucleus");
      r.fallback = r.by_region[int(Region::annulus)];
      const nlohmann::json& annulus = j.at("annulus");
      if (annulus.is_object() && annulus.contains("fibres"))
        r.fibres[int(Region::annulus)] =
            parse_fibres(annulus.at("fibres"), "material '" + r.name + "' annulus fibres");
    } else {
      if (j.contains("fibres"))
        throw std::invalid_argument(
            "material '" + r.name +
            "': fibres need a per-region file (they reinforce the annulus)");
      r.fallback = parse_one(j, "material '" + r.name + "'", {"name", "description"});
    }
  } catch (const nlohmann::json::exception& e) {
    std::string what = e.what();  // "[json.exception.type_error.302] type must be ...": the reason
    if (!what.empty() && what[0] == '[' && what.find("] ") != std::string::npos)
      what = what.substr(what.find("] ") + 2);
    throw std::invalid_argument("material '" + r.name + "': a field has the wrong type (" + what +
                                ")");
  }
  return r;
}

RegionMaterials load_material(const std::string& name_or_path, const std::string& data_dir) {
  const std::filesystem::path path = resolve_preset(
      name_or_path, (std::filesystem::path(data_dir) / "materials").string(), "material");
  const nlohmann::json j = read_json_file(path.string(), "material file");
  try {
    return material_from_json(j);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("material file '" + path.string() + "': " + e.what());
  }
}

}  // namespace spinesim::mesh
