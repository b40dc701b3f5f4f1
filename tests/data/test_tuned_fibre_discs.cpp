// The shipped fibre-network discs (data/tuned_fibre_discs.json, `spinesim calibrate --level all
// --material fibre-reinforced --nonlinear`): every level present, fitted against the nonlinear
// FEM at both load levels, and better than the untuned network on every case it reports.
#include "spinesim/calibration/levels.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/mesh/disc_geometry.hpp"

#include <gtest/gtest.h>

#include <set>

namespace spinesim::calibration {
namespace {

const TunedSet& shipped() {
  static const TunedSet set = read_tuned_set(shipped_fibre_tuned_set_path(SPINESIM_DATA_DIR));
  return set;
}

/// Every level of `set` is a P2-fitted fibre network whose fit beats the untuned network.
void expect_fibre_networks_fitted_to_the_nonlinear_disc(const TunedSet& set) {
  EXPECT_EQ(set.material_name, "fibre-reinforced");
  for (const std::string& level : mesh::disc_levels()) {
    SCOPED_TRACE(level);
    const TunedDisc& d = tuned_level(set, level);
    EXPECT_EQ(d.fem_order, 2);
    EXPECT_TRUE(d.options.fibre_springs);
    EXPECT_TRUE(d.options.isochoric_fibres);
    const nlohmann::json& r = d.report;
    EXPECT_EQ(r["reference"], "nonlinear FEM");
    EXPECT_TRUE(r["ipopt"]["success"].get<bool>()) << r["ipopt"]["status"];
    EXPECT_GT(r["fibre_elements"].get<long>(), 0);
    EXPECT_EQ(r["load_levels"], nlohmann::json({0.1, 1.0}));
    // Both load levels of every case, trained and held out; every solve converged, and the fit
    // beats the untuned network on every (case, level) in both the plate's reaction and the
    // displacement field.
    for (const char* part : {"train", "holdout"}) {
      std::set<double> levels;
      for (const auto& c : r[part]) {
        SCOPED_TRACE(std::string(part) + " " + c["name"].get<std::string>());
        levels.insert(c["level"].get<double>());
        EXPECT_TRUE(c["converged"].get<bool>());
        EXPECT_LT(c["tuned_error"].get<double>(), c["untuned_error"].get<double>());
        EXPECT_LT(c["tuned_reaction_error"].get<double>(),
                  c["untuned_reaction_error"].get<double>());
      }
      EXPECT_EQ(levels, std::set<double>({0.1, 1.0})) << part;
    }
  }
}

TEST(ShippedFibreDiscs, EveryLevelIsAFibreNetworkFittedToTheNonlinearDisc) {
  const TunedSet& set = shipped();
  EXPECT_EQ(set.settings["cell_size_rule"], CellSizeRule({4.0, 2.5}).describe());
  for (const std::string& level : mesh::disc_levels())
    EXPECT_DOUBLE_EQ(set.settings["cell_size_mm"][level].get<double>(),
                     default_level_cell_size_mm(level, SPINESIM_DATA_DIR, {4.0, 2.5}))
        << level;
  expect_fibre_networks_fitted_to_the_nonlinear_disc(set);
}

// The spine's offline discs with fibres (data/tuned_structured_fibre_discs.json, `calibrate
// --level all --structured --sectors 24 --rings 4 --layers 4 --material fibre-reinforced
// --nonlinear --order 2`): the resolution it records is the one it was fitted on.
TEST(ShippedStructuredFibreDiscs, EveryLevelIsAFibreNetworkAtItsRecordedResolution) {
  const TunedSet set = read_tuned_set(shipped_structured_fibre_tuned_set_path(SPINESIM_DATA_DIR));
  const mesh::StructuredDiscOptions r = structured_resolution(set);
  EXPECT_EQ(r.sectors, 24);
  EXPECT_EQ(r.rings, 4);
  EXPECT_EQ(r.layers, 4);
  for (const std::string& level : mesh::disc_levels())
    EXPECT_EQ(tuned_level(set, level).mesh.tets, 3 * r.layers * r.sectors * (2 * r.rings - 1))
        << level;
  expect_fibre_networks_fitted_to_the_nonlinear_disc(set);
}

}  // namespace
}  // namespace spinesim::calibration
