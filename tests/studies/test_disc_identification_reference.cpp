// The disc identification on a disc (label reference): windows that the disc itself makes at
// known parameters are met by those parameters — the fit finds the material it was shown, on
// one thread or two alike, and a fine disc equal to the coarse one settles in one round.
#include "spinesim/studies/disc_identification.hpp"
#include "studies_fixtures.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace spinesim;
using namespace spinesim::studies;

namespace {

/// The six quantities of `m` with parameters p, as a targets file of ±10 % windows.
nlohmann::json windows_made_by(const mesh::TetMesh& m, const mesh::RegionMaterials& base,
                               const Eigen::VectorXd& p) {
  NonlinearDiscOptions o;
  o.load_increments = 2;
  const NonlinearDiscQuantities q =
      nonlinear_disc_quantities(m, disc_material_at(base, p, "truth"), o);
  nlohmann::json targets = nlohmann::json::array();
  for (const auto& [name, value] : q.values)
    targets.push_back({{"quantity", name}, {"low", value / 1.1}, {"high", value * 1.1}});
  return {{"targets", targets}};
}

}  // namespace

TEST(DiscIdentificationReference, FindsTheMaterialWhoseQuantitiesCentreTheWindows) {
  const mesh::TetMesh& m = test::structured("L4-L5");
  const auto base = test::material("fibre-reinforced");
  Eigen::VectorXd truth(4);
  truth << 2.0, 1.4, 20.0, 0.9;
  const nlohmann::json targets = windows_made_by(m, base, truth);
  ASSERT_EQ(targets.at("targets").size(), 6u);
  DiscIdentificationOptions o;
  o.fine_order = 1;  // fine = coarse: the ratios are 1 and settle at once
  o.leave_one_out = false;
  o.load_increments = 2;
  o.threads = 2;
  const DiscIdentificationResult r = identify_disc_material(
      m, m, base, targets, {{"targets", nlohmann::json::array()}}, o, "structured", "structured");
  ASSERT_TRUE(r.success) << r.status;
  EXPECT_EQ(r.rounds.size(), 1u);
  // k2 and the fibre scale both stiffen the fibres; six quantities still separate them.
  for (Eigen::Index j = 0; j < 4; ++j)
    EXPECT_NEAR(std::log(r.identified(j) / truth(j)), 0.0, 0.02)
        << r.parameters[size_t(j)].fit.name;
  for (const IdentifiedRow& row : r.fit_rows) EXPECT_TRUE(row.match()) << row.quantity;
  EXPECT_TRUE(r.active_bounds.empty());
}

// A compressive preload tensions the fibres through the nucleus pressure: every moment case is
// stiffer under it, and the rotation is measured from the preloaded state (so a preload of
// zero gives the unloaded numbers exactly).
TEST(DiscIdentificationReference, APreloadStiffensEveryMomentCase) {
  const mesh::TetMesh& m = test::structured("L4-L5");
  const auto material = test::material("fibre-reinforced");
  NonlinearDiscOptions o;
  o.load_increments = 2;
  const NonlinearDiscQuantities free = nonlinear_disc_quantities(m, material, o);
  o.preload_n = 0.0;
  EXPECT_EQ(nonlinear_disc_quantities(m, material, o).values, free.values);
  o.preload_n = 500.0;
  const NonlinearDiscQuantities loaded = nonlinear_disc_quantities(m, material, o);
  for (const char* name : {"torsion", "flexion", "extension", "lateral-bending"})
    EXPECT_GT(loaded.values.at(name), free.values.at(name)) << name;
  EXPECT_EQ(loaded.values.at("compression"), free.values.at("compression"));
  o.preload_n = -1.0;
  EXPECT_THROW(nonlinear_disc_quantities(m, material, o), std::invalid_argument);
}
