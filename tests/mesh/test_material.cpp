// Material presets (data/materials/*.json) load and validate; bad input — non-positive E,
// nu outside (-1, 0.5), non-finite numbers, missing keys, and thesis table 5.1's raw (E, G)
// pairs — is refused with std::invalid_argument saying why.
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace {

using spinesim::mesh::IsotropicMaterial;
using spinesim::mesh::load_material;
using spinesim::mesh::material_from_json;
using spinesim::mesh::Region;

const std::string kData = SPINESIM_DATA_DIR;

/// The message of the std::invalid_argument thrown by f, or "" (a test failure) if none.
template <class F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected std::invalid_argument";
  return "";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST(MaterialPresets, AllLoadAndValidate) {
  for (const char* name :
       {"real-disc", "annulus-nucleus", "fibre-reinforced", "rubber", "polyethylene"}) {
    SCOPED_TRACE(name);
    const auto m = load_material(name, kData);
    EXPECT_EQ(m.name, name);
    for (int region : {1, 2}) {
      const IsotropicMaterial& mat = m.at(region);
      EXPECT_NO_THROW(spinesim::mesh::validate(mat));
      EXPECT_GT(mat.youngs_modulus_mpa, 0);
      EXPECT_GE(mat.poisson_ratio, 0.0);  // none of our materials is auxetic
      EXPECT_LT(mat.poisson_ratio, 0.5);
      EXPECT_GT(mat.density_kg_m3, 500);
      EXPECT_LT(mat.density_kg_m3, 2000);
    }
  }
}

TEST(MaterialPresets, RealDiscMatchesTable51) {
  const auto m = load_material("real-disc", kData).at(1);
  EXPECT_DOUBLE_EQ(m.youngs_modulus_mpa, 3.22);
  // Table 5.1: E 3.22, G 1.106 -> nu = E/(2G) - 1 = 0.4557, and G is recovered from (E, nu).
  EXPECT_NEAR(m.poisson_ratio, 3.22 / (2 * 1.106) - 1, 1e-4);
  EXPECT_NEAR(m.shear_modulus_mpa(), 1.106, 1e-3);
  EXPECT_DOUBLE_EQ(m.density_kg_m3, 1038);
  EXPECT_NEAR(m.density_t_mm3(), 1.038e-9, 1e-15);
}

TEST(MaterialPresets, RubberAndPolyethyleneKeepTable51YoungsModulus) {
  EXPECT_DOUBLE_EQ(load_material("rubber", kData).at(1).youngs_modulus_mpa, 30);
  EXPECT_DOUBLE_EQ(load_material("polyethylene", kData).at(1).youngs_modulus_mpa, 200);
}

TEST(MaterialPresets, AnnulusNucleusDiffersPerRegion) {
  const auto m = load_material("annulus-nucleus", kData);
  const auto& annulus = m.at(int(Region::annulus));
  const auto& nucleus = m.at(int(Region::nucleus));
  EXPECT_DOUBLE_EQ(annulus.youngs_modulus_mpa, 4.2);
  EXPECT_DOUBLE_EQ(annulus.poisson_ratio, 0.45);
  EXPECT_DOUBLE_EQ(nucleus.youngs_modulus_mpa, 1.0);
  EXPECT_DOUBLE_EQ(nucleus.poisson_ratio, 0.49);
  EXPECT_NE(annulus.youngs_modulus_mpa, nucleus.youngs_modulus_mpa);
}

TEST(MaterialPresets, Table51RawEGPairsAreRefusedWithTheImpliedNu) {
  const std::string rubber =
      refusal([] { load_material(kData + "/materials/invalid/table5.1-rubber-EG.json", kData); });
  EXPECT_TRUE(contains(rubber, "nu")) << rubber;
  EXPECT_TRUE(contains(rubber, "24")) << rubber;  // E/(2G) - 1 = 30/1.2 - 1
  const std::string pe = refusal(
      [] { load_material(kData + "/materials/invalid/table5.1-polyethylene-EG.json", kData); });
  EXPECT_TRUE(contains(pe, "nu")) << pe;
  EXPECT_TRUE(contains(pe, "-0.145")) << pe;  // 200/234 - 1
}

TEST(MaterialJson, ConsistentEGPairIsAccepted) {
  const auto m = material_from_json({{"name", "eg"}, {"E_mpa", 3.22}, {"G_mpa", 1.106}});
  EXPECT_NEAR(m.at(1).poisson_ratio, 0.4557, 1e-4);
}

TEST(MaterialJson, BadConstantsAreRefusedWithTheReason) {
  using nlohmann::json;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto msg = [](const json& j) { return refusal([&] { material_from_json(j); }); };

  EXPECT_TRUE(contains(msg({{"E_mpa", 0.0}, {"nu", 0.3}}), "Young's modulus"));
  EXPECT_TRUE(contains(msg({{"E_mpa", -1.0}, {"nu", 0.3}}), "Young's modulus"));
  EXPECT_TRUE(contains(msg({{"E_mpa", 1.0}, {"nu", 0.5}}), "Poisson"));
  EXPECT_TRUE(contains(msg({{"E_mpa", 1.0}, {"nu", 0.7}}), "Poisson"));
  EXPECT_TRUE(contains(msg({{"E_mpa", 1.0}, {"nu", -1.0}}), "Poisson"));
  EXPECT_TRUE(contains(msg({{"E_mpa", 1.0}, {"nu", 0.3}, {"density_kg_m3", 0.0}}), "density"));
  // nlohmann stores NaN as a number; validate() must catch it.
  EXPECT_TRUE(contains(msg({{"E_mpa", nan}, {"nu", 0.3}}), "non-finite"));
  EXPECT_TRUE(contains(msg({{"E_mpa", 1.0}, {"nu", nan}}), "non-finite"));
  EXPECT_TRUE(contains(msg({{"nu", 0.3}}), "E_mpa"));
  EXPECT_TRUE(contains(msg({{"E_mpa", 1.0}}), "nu"));
  EXPECT_TRUE(contains(msg({{"E_mpa", "soft"}, {"nu", 0.3}}), "number"));
  // Found by fuzzing: a name that is not a string escaped as the parser's own exception.
  EXPECT_TRUE(contains(msg({{"name", 910}, {"E_mpa", 1.0}, {"nu", 0.3}}), "wrong type"));
  EXPECT_TRUE(contains(msg({{"E_mpa", 1.0}, {"nu", 0.3}, {"G_mpa", 0.4}}), "exactly one"));
  EXPECT_TRUE(contains(msg({{"annulus", {{"E_mpa", 4.2}, {"nu", 0.45}}}}), "both"));
  EXPECT_TRUE(contains(
      msg({{"annulus", {{"E_mpa", 4.2}, {"nu", 0.45}}}, {"nucleus", {{"E_mpa", 1.0}}}}), "nu"));
}

TEST(MaterialFiles, UnknownPresetListsTheKnownOnes) {
  const std::string m = refusal([] { load_material("no-such-material", kData); });
  EXPECT_TRUE(contains(m, "no-such-material")) << m;
  EXPECT_TRUE(contains(m, "real-disc")) << m;
}

}  // namespace

TEST(MaterialFibres, ThePresetCarriesSourcedAnnulusFibres) {
  const auto m = load_material("fibre-reinforced", kData);
  ASSERT_TRUE(m.has_fibres());
  ASSERT_EQ(m.fibres.count(int(Region::annulus)), 1u);
  const auto& f = m.fibres.at(int(Region::annulus));
  EXPECT_DOUBLE_EQ(f.angle_inner_deg, 45);
  EXPECT_DOUBLE_EQ(f.angle_outer_deg, 28);
  EXPECT_DOUBLE_EQ(f.modulus_mpa(0.5), 0.5 * (59 + 136));
  EXPECT_FALSE(f.source.empty());
  EXPECT_EQ(m.fibres.count(int(Region::nucleus)), 0u);
}

TEST(MaterialFibres, BadFibresAreRefusedInOneLine) {
  const auto with = [](nlohmann::json fibres) {
    nlohmann::json j = {{"name", "f"},
                        {"annulus", {{"E_mpa", 4.2}, {"nu", 0.45}, {"fibres", fibres}}},
                        {"nucleus", {{"E_mpa", 1.0}, {"nu", 0.49}}}};
    return j;
  };
  const nlohmann::json good = {
      {"E_inner_mpa", 59}, {"E_outer_mpa", 136}, {"angle_inner_deg", 45}, {"angle_outer_deg", 28}};
  EXPECT_NO_THROW(material_from_json(with(good)));
  auto bad = good;
  bad["angle_outer_deg"] = 95;
  EXPECT_TRUE(contains(refusal([&] { material_from_json(with(bad)); }), "fibre angle"));
  bad = good;
  bad["E_inner_mpa"] = -1;
  EXPECT_TRUE(contains(refusal([&] { material_from_json(with(bad)); }), "fibre modulus"));
  bad = good;
  bad.erase("E_outer_mpa");
  EXPECT_TRUE(contains(refusal([&] { material_from_json(with(bad)); }), "E_outer_mpa"));
  bad = good;
  bad["k2"] = -0.5;
  EXPECT_TRUE(contains(refusal([&] { material_from_json(with(bad)); }), "toe exponent k2"));
  bad["k2"] = 12.5;
  EXPECT_DOUBLE_EQ(material_from_json(with(bad)).fibres.at(int(Region::annulus)).toe_k2, 12.5);
  EXPECT_DOUBLE_EQ(material_from_json(with(good)).fibres.at(int(Region::annulus)).toe_k2, 10.0);
  bad = good;
  bad["angle_inner_deg"] = "steep";
  EXPECT_TRUE(contains(refusal([&] { material_from_json(with(bad)); }), "must be a number"));
  nlohmann::json homogeneous = {{"name", "h"}, {"E_mpa", 3}, {"nu", 0.4}, {"fibres", good}};
  EXPECT_TRUE(contains(refusal([&] { material_from_json(homogeneous); }), "per-region"));
}
