#include "spinesim/calibration/tuned_disc.hpp"

#include "json_file.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <regex>
#include <stdexcept>

namespace spinesim::calibration {

namespace {

/// The plausible range of a fitted scale or multiplier (see read_tuned_disc).
constexpr double kMinScale = 1e-6, kMaxScale = 1e6;

constexpr const char* kFormat = "spinesim-tuned-disc";
constexpr int kVersion = 1;

struct Fnv1a {
  std::uint64_t h = 1469598103934665603ull;
  void add(std::int64_t v) {
    for (int b = 0; b < 8; ++b) {
      h ^= std::uint64_t((v >> (8 * b)) & 0xff);
      h *= 1099511628211ull;
    }
  }
};

bool same_number(double a, double b) {
  return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
}

}  // namespace

MeshFingerprint fingerprint(const mesh::TetMesh& m) {
  Fnv1a f;
  f.add(m.num_vertices());
  f.add(m.num_tets());
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
    for (int a = 0; a < 3; ++a) f.add(std::llround(m.V(i, a) * 1e6));
    f.add(m.surface.size() == m.num_vertices() ? m.surface(i) : -1);
  }
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    for (int a = 0; a < 4; ++a) f.add(m.T(t, a));
    f.add(m.region.size() == m.num_tets() ? m.region(t) : -1);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(f.h));
  return {m.num_vertices(), m.num_tets(), hex};
}

std::string disc_level(const mesh::TetMesh& m) {
  // Only the builders' provenance: a foreign VTU's `source` is its path, and "scans/L4-L5/x.vtu"
  // would otherwise name a level nobody checked.
  static const std::regex level(
      R"(^(?:parametric|structured) disc ([TLS][0-9]{1,2}-[TLS][0-9]{1,2})\b)");
  std::smatch match;
  return std::regex_search(m.source, match, level) ? match[1].str() : std::string();
}

nlohmann::json material_signature(const mesh::RegionMaterials& materials) {
  auto one = [](const mesh::IsotropicMaterial& m) {
    return nlohmann::json{{"E_mpa", m.youngs_modulus_mpa},
                          {"nu", m.poisson_ratio},
                          {"density_kg_m3", m.density_kg_m3}};
  };
  nlohmann::json sig = {{"annulus", one(materials.at(int(mesh::Region::annulus)))},
                        {"nucleus", one(materials.at(int(mesh::Region::nucleus)))}};
  // The annulus fibres, so that a file fitted with fibre elements rebuilds its material.
  const auto f = materials.fibres.find(int(mesh::Region::annulus));
  if (f != materials.fibres.end())
    sig["annulus"]["fibres"] = {{"E_inner_mpa", f->second.modulus_inner_mpa},
                                {"E_outer_mpa", f->second.modulus_outer_mpa},
                                {"angle_inner_deg", f->second.angle_inner_deg},
                                {"angle_outer_deg", f->second.angle_outer_deg},
                                {"k2", f->second.toe_k2}};
  return sig;
}

mss::MssOptions TunedDisc::mss_options() const {
  mss::MssOptions o = options;
  for (auto& s : o.scales) s.by_region = {1.0, 1.0};
  for (const auto& [name, value] : scales) {
    const Knob k = knob_from_name(name);
    o.scales[int(k.term)].by_region[std::size_t(k.region)] = value;
  }
  o.edge_multipliers = edge_multipliers;
  return o;
}

mesh::RegionMaterials TunedDisc::materials() const {
  return mesh::material_from_json({{"name", material_name},
                                   {"annulus", material.at("annulus")},
                                   {"nucleus", material.at("nucleus")}});
}

nlohmann::json terms_json(const mss::MssOptions& o) {
  return {{"radial_springs", o.radial_springs},
          {"torsion_springs", o.torsion_springs},
          {"volume_term", o.volume_term},
          {"disc_volume_term", o.disc_volume_term},
          {"radial_factor", o.radial_factor},
          {"volume_factor", o.volume_factor},
          {"disc_volume_factor", o.disc_volume_factor},
          {"fibre_springs", o.fibre_springs},
          {"isochoric_fibres", o.isochoric_fibres}};
}

nlohmann::json to_json(const TunedDisc& t) {
  const mss::MssOptions& o = t.options;
  nlohmann::json j = {
      {"format", kFormat},
      {"version", kVersion},
      {"kind", t.kind()},
      {"level", t.level},
      {"material", {{"name", t.material_name}, {"regions", t.material}}},
      {"mesh", {{"nodes", t.mesh.nodes}, {"tets", t.mesh.tets}, {"fingerprint", t.mesh.hash}}},
      {"fem_order", t.fem_order},
      {"terms", terms_json(o)},
      {"scales", t.scales},
      {"report", t.report}};
  if (t.per_spring()) {
    j["edge_springs"] = t.edge_multipliers.size();
    j["edge_multipliers"] = t.edge_multipliers;
    j["edge_order"] = t.edge_order;
  }
  return j;
}

TunedDisc tuned_disc_from_json(const nlohmann::json& j) {
  try {
    if (!j.is_object() || j.value("format", "") != kFormat)
      throw std::invalid_argument("not a spinesim tuned-disc file (\"format\": \"" +
                                  std::string(kFormat) + "\" missing)");
    if (j.at("version") != kVersion)  // compares the number, not a truncated int (1.5, 2^32 + 1)
      throw std::invalid_argument("tuned-disc file version " + j.at("version").dump() +
                                  " is not supported (expected " + std::to_string(kVersion) + ")");
    const std::string kind = j.value("kind", "region");
    if (kind != "region" && kind != "per-spring")
      throw std::invalid_argument("tuned-disc kind '" + kind +
                                  "' is not supported (region, per-spring)");
    TunedDisc t;
    t.level = j.value("level", "");
    t.material_name = j.at("material").at("name").get<std::string>();
    t.material = j.at("material").at("regions");
    t.materials();  // every region's constants present and valid (check_applies compares them)
    t.mesh.nodes = j.at("mesh").at("nodes").get<Eigen::Index>();
    t.mesh.tets = j.at("mesh").at("tets").get<Eigen::Index>();
    t.mesh.hash = j.at("mesh").at("fingerprint").get<std::string>();
    t.fem_order = j.value("fem_order", 2);
    if (t.fem_order != 1 && t.fem_order != 2)
      throw std::invalid_argument("fem_order must be 1 or 2");
    const auto& terms = j.at("terms");
    t.options.radial_springs = terms.at("radial_springs").get<bool>();
    t.options.torsion_springs = terms.at("torsion_springs").get<bool>();
    t.options.volume_term = terms.at("volume_term").get<bool>();
    t.options.disc_volume_term = terms.at("disc_volume_term").get<bool>();
    t.options.fibre_springs = terms.value("fibre_springs", false);  // files before fibre springs
    // Files from before the isochoric fibres: the spring's own stretch.
    t.options.isochoric_fibres = terms.value("isochoric_fibres", false);
    if (t.options.fibre_springs && !t.materials().has_fibres())
      throw std::invalid_argument(
          "fibre springs in a tuned-disc file whose material has no fibres");
    t.options.radial_factor = terms.at("radial_factor").get<double>();
    t.options.volume_factor = terms.at("volume_factor").get<double>();
    t.options.disc_volume_factor = terms.at("disc_volume_factor").get<double>();
    for (const double f :
         {t.options.radial_factor, t.options.volume_factor, t.options.disc_volume_factor})
      if (!std::isfinite(f) || f <= 0)
        throw std::invalid_argument("term factors must be finite and > 0");
    for (const auto& [name, value] : j.at("scales").items()) {
      const Knob k = knob_from_name(name);
      const double s = value.get<double>();
      // A scale is a factor on Van Gelder's constants, fitted within [1e-3, 1e3] by default
      // (IpoptSettings): beyond 1e-6..1e6 the constants are not a disc's (and at 1e300 the
      // forces overflow while the solve reports a meaningless "converged").
      if (!std::isfinite(s) || !(s >= kMinScale && s <= kMaxScale))
        throw std::invalid_argument("scale '" + name + "' = " + value.dump() +
                                    ": must be a finite number in [1e-6, 1e6]");
      if (!mss::term_enabled(t.options, k.term))
        throw std::invalid_argument("scale '" + name + "' belongs to a term the file switches off");
      t.scales[name] = s;
    }
    if (t.scales.empty()) throw std::invalid_argument("tuned-disc file has no scales");
    if (kind == "region" && j.contains("edge_multipliers"))
      throw std::invalid_argument(
          "a region-level tuned-disc file has edge_multipliers (kind 'per-spring' expected)");
    if (kind == "per-spring") {
      t.edge_multipliers = j.at("edge_multipliers").get<std::vector<double>>();
      if (t.edge_multipliers.empty())
        throw std::invalid_argument("per-spring tuned-disc file has no edge_multipliers");
      for (const double mu : t.edge_multipliers)
        if (!std::isfinite(mu) || !(mu >= kMinScale && mu <= kMaxScale))
          throw std::invalid_argument("edge_multipliers must be finite numbers in [1e-6, 1e6]");
      t.edge_order = j.at("edge_order").get<std::string>();
      if (j.at("edge_springs").get<std::size_t>() != t.edge_multipliers.size())
        throw std::invalid_argument(
            "edge_springs (" + j.at("edge_springs").dump() + ") does not match the " +
            std::to_string(t.edge_multipliers.size()) + " edge_multipliers");
    }
    t.report = j.value("report", nlohmann::json::object());
    return t;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(std::string("tuned-disc file: missing or malformed field (") +
                                e.what() + ")");
  }
}

std::string edge_order_hash(const mss::MssModel& model) {
  Fnv1a f;
  for (const mss::EdgeSpringInfo& e : model.edge_springs()) f.add(e.i), f.add(e.j);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(f.h));
  return hex;
}

mss::MssModel build_tuned_model(const TunedDisc& t, const mesh::TetMesh& mesh,
                                const mesh::RegionMaterials& materials) {
  check_applies(t, mesh, materials);
  mss::MssModel model(mesh, materials, t.mss_options());
  if (t.per_spring() && edge_order_hash(model) != t.edge_order)
    throw std::invalid_argument(
        "the per-spring multipliers were fitted on another ordering of the edge springs (edge "
        "order " +
        t.edge_order + ", this model " + edge_order_hash(model) + "): refit them");
  return model;
}

TunedDisc read_tuned_disc(const std::string& path) {
  const nlohmann::json j = detail::read_json_file(path, "tuned-disc file");
  return detail::naming_file(path, [&] { return tuned_disc_from_json(j); });
}

std::string check_applies(const TunedDisc& t, const mesh::TetMesh& mesh,
                          const mesh::RegionMaterials& materials) {
  const nlohmann::json sig = material_signature(materials);
  bool same = materials.name == t.material_name;
  for (const char* region : {"annulus", "nucleus"})
    for (const char* key : {"E_mpa", "nu"})
      same = same && t.material.contains(region) && t.material[region].contains(key) &&
             same_number(t.material[region][key].get<double>(), sig[region][key].get<double>());
  // Fibres: files from before the signature carried them have none; only compared when both do.
  if (t.material.contains("annulus") && t.material["annulus"].contains("fibres") &&
      sig["annulus"].contains("fibres"))
    for (const auto& [key, value] : sig["annulus"]["fibres"].items())
      same = same && t.material["annulus"]["fibres"].contains(key) &&
             same_number(t.material["annulus"]["fibres"][key].get<double>(), value.get<double>());
  if (!same)
    throw std::invalid_argument("the tuned parameters were fitted for material '" +
                                t.material_name + "' and do not apply to material '" +
                                materials.name + "' (calibrate it first)");
  const MeshFingerprint here = fingerprint(mesh);
  if (t.per_spring() && !(here == t.mesh))
    throw std::invalid_argument(
        "per-spring tuned parameters belong to the mesh they were fitted on (" +
        std::to_string(t.mesh.nodes) + " nodes, " + std::to_string(t.mesh.tets) +
        " tets, fingerprint " + t.mesh.hash + ") and do not apply to this mesh (" +
        std::to_string(here.nodes) + " nodes, " + std::to_string(here.tets) +
        " tets, fingerprint " + here.hash +
        "): region-level tuned files transfer to other meshes of the disc, per-spring ones do not");
  const std::string level = disc_level(mesh);
  if (!level.empty() && !t.level.empty()) {
    if (level != t.level)
      throw std::invalid_argument("the tuned parameters were fitted for disc " + t.level +
                                  " and do not apply to a " + level + " mesh");
    return "";
  }
  if (here == t.mesh) return "";  // the very mesh they were fitted on
  if (level.empty())
    return "mesh level unknown: applying the " +
           (t.level.empty() ? std::string("tuned") : t.level) + " parameters as given";
  return "the tuned parameters' disc level is unknown: applying them to this " + level +
         " mesh as given";
}

}  // namespace spinesim::calibration
