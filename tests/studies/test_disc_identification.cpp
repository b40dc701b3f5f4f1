// The disc identification's parameters, the material they make, the preset file it writes and
// its refusals (studies/disc_identification.hpp). The identification itself on a disc:
// test_disc_identification_reference.cpp.
#include "spinesim/studies/disc_identification.hpp"
#include "studies_fixtures.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace spinesim;
using namespace spinesim::studies;

namespace {

constexpr int kAnnulus = int(mesh::Region::annulus), kNucleus = int(mesh::Region::nucleus);

Eigen::VectorXd some_parameters() {
  Eigen::VectorXd p(4);
  p << 2.5, 1.5, 20.0, 0.9;
  return p;
}

}  // namespace

TEST(DiscIdentification, ParametersStartAtThePresetInsideSourcedBounds) {
  const auto base = test::material("fibre-reinforced");
  const std::vector<DiscParameter> ps = disc_parameters(base);
  ASSERT_EQ(ps.size(), 4u);
  EXPECT_EQ(ps[0].fit.name, "annulus-E");
  EXPECT_DOUBLE_EQ(ps[0].fit.start, base.at(kAnnulus).youngs_modulus_mpa);
  EXPECT_DOUBLE_EQ(ps[3].fit.start, base.at(kNucleus).youngs_modulus_mpa);
  for (const DiscParameter& p : ps) {
    EXPECT_GT(p.fit.lower, 0) << p.fit.name;
    EXPECT_LT(p.fit.lower, p.fit.upper) << p.fit.name;
    EXPECT_GE(p.fit.start, p.fit.lower) << p.fit.name;
    EXPECT_LE(p.fit.start, p.fit.upper) << p.fit.name;
    EXPECT_FALSE(p.source.empty()) << p.fit.name;
  }
}

TEST(DiscIdentification, TheMaterialAtParametersChangesThoseFourAndNothingElse) {
  const auto base = test::material("fibre-reinforced");
  const mesh::RegionMaterials m = disc_material_at(base, some_parameters(), "x");
  EXPECT_EQ(m.name, "x");
  EXPECT_DOUBLE_EQ(m.at(kAnnulus).youngs_modulus_mpa, 2.5);
  EXPECT_DOUBLE_EQ(m.at(kNucleus).youngs_modulus_mpa, 0.9);
  EXPECT_DOUBLE_EQ(m.at(kAnnulus).poisson_ratio, base.at(kAnnulus).poisson_ratio);
  EXPECT_DOUBLE_EQ(m.at(kNucleus).poisson_ratio, base.at(kNucleus).poisson_ratio);
  const auto& f = m.fibres.at(kAnnulus);
  const auto& f0 = base.fibres.at(kAnnulus);
  EXPECT_DOUBLE_EQ(f.modulus_inner_mpa, 1.5 * f0.modulus_inner_mpa);
  EXPECT_DOUBLE_EQ(f.modulus_outer_mpa, 1.5 * f0.modulus_outer_mpa);
  EXPECT_DOUBLE_EQ(f.toe_k2, 20.0);
  EXPECT_DOUBLE_EQ(f.angle_inner_deg, f0.angle_inner_deg);
  EXPECT_DOUBLE_EQ(f.angle_outer_deg, f0.angle_outer_deg);
}

TEST(DiscIdentification, ThePresetFileReadsBackAsTheIdentifiedMaterial) {
  const auto base = test::material("fibre-reinforced");
  DiscIdentificationResult r;
  r.material_name = base.name;
  r.parameters = disc_parameters(base);
  r.identified = some_parameters();
  const mesh::RegionMaterials back = mesh::material_from_json(identified_material_json(r, base));
  const mesh::RegionMaterials expected = disc_material_at(base, r.identified, "disc-identified");
  EXPECT_EQ(back.name, "disc-identified");
  for (int region : {kAnnulus, kNucleus}) {
    EXPECT_DOUBLE_EQ(back.at(region).youngs_modulus_mpa, expected.at(region).youngs_modulus_mpa);
    EXPECT_DOUBLE_EQ(back.at(region).poisson_ratio, expected.at(region).poisson_ratio);
    EXPECT_DOUBLE_EQ(back.at(region).density_kg_m3, expected.at(region).density_kg_m3);
  }
  EXPECT_DOUBLE_EQ(back.fibres.at(kAnnulus).modulus_outer_mpa,
                   expected.fibres.at(kAnnulus).modulus_outer_mpa);
  EXPECT_DOUBLE_EQ(back.fibres.at(kAnnulus).toe_k2, 20.0);
}

TEST(DiscIdentification, RefusesAMaterialWithoutFibresAnEmptyDataSetAndAnUnknownQuantity) {
  EXPECT_THROW(disc_parameters(test::material("annulus-nucleus")), std::invalid_argument);
  const mesh::TetMesh& m = test::structured("L4-L5");
  const auto base = test::material("fibre-reinforced");
  const nlohmann::json none = {{"targets", nlohmann::json::array()}};
  EXPECT_THROW(identify_disc_material(m, m, base, none, none, {}, "c", "f"), std::invalid_argument);
  const nlohmann::json unknown = {
      {"targets", {{{"quantity", "shear"}, {"low", 1.0}, {"high", 2.0}}}}};
  EXPECT_THROW(identify_disc_material(m, m, base, unknown, none, {}, "c", "f"),
               std::invalid_argument);
  const nlohmann::json inverted = {
      {"targets", {{{"quantity", "torsion"}, {"low", 3.0}, {"high", 2.0}}}}};
  EXPECT_THROW(identify_disc_material(m, m, base, inverted, none, {}, "c", "f"),
               std::invalid_argument);
  const nlohmann::json newton_metres = {
      {"targets", {{{"quantity", "torsion"}, {"units", "N mm/deg"}, {"low", 2.0}, {"high", 3.0}}}}};
  EXPECT_THROW(identify_disc_material(m, m, base, newton_metres, none, {}, "c", "f"),
               std::invalid_argument);
  DiscIdentificationOptions bad;
  bad.fine_order = 3;
  EXPECT_THROW(identify_disc_material(m, m, base, unknown, none, bad, "c", "f"),
               std::invalid_argument);
}
