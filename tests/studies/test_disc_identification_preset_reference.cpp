// The shipped identified material (data/materials/disc-identified.json) against the preset it
// started from, on the coarse disc the fits ran on (label reference): it is nearer the in-vitro
// windows — the sum of squared window residuals (calibration/window_fit.hpp) is smaller — and
// its parameters lie inside the identification's bounds.
#include "spinesim/calibration/window_fit.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/studies/disc_identification.hpp"
#include "studies_fixtures.hpp"

#include <gtest/gtest.h>

using namespace spinesim;
using namespace spinesim::studies;

namespace {

double squared_residuals(const mesh::TetMesh& m, const mesh::RegionMaterials& material,
                         const nlohmann::json& targets) {
  NonlinearDiscOptions o;
  o.load_increments = 4;
  const NonlinearDiscQuantities q = nonlinear_disc_quantities(m, material, o);
  double sum = 0;
  for (const auto& t : targets.at("targets")) {
    const std::string name = t.at("quantity").get<std::string>();
    EXPECT_TRUE(q.values.count(name)) << name;
    const double r = calibration::window_residual(
        q.values.at(name), {name, t.at("low").get<double>(), t.at("high").get<double>()});
    sum += r * r;
  }
  return sum;
}

}  // namespace

TEST(DiscIdentificationPreset, IsNearerTheInVitroWindowsThanThePresetItStartedFrom) {
  const mesh::TetMesh m = mesh::mesh_disc_level("L4-L5", 3.0, SPINESIM_DATA_DIR);
  const nlohmann::json targets =
      read_disc_targets(std::string(SPINESIM_DATA_DIR) + "/validation/disc_in_vitro.json");
  const auto start = test::material("fibre-reinforced");
  const auto identified = test::material("disc-identified");
  EXPECT_LT(squared_residuals(m, identified, targets), squared_residuals(m, start, targets));

  // Its four parameters inside their bounds.
  const std::vector<DiscParameter> ps = disc_parameters(start);
  const double scale =
      identified.fibres.at(1).modulus_outer_mpa / start.fibres.at(1).modulus_outer_mpa;
  const double values[] = {identified.at(1).youngs_modulus_mpa, scale,
                           identified.fibres.at(1).toe_k2, identified.at(2).youngs_modulus_mpa};
  for (std::size_t j = 0; j < ps.size(); ++j) {
    EXPECT_GE(values[j], ps[j].fit.lower * (1 - 1e-9)) << ps[j].fit.name;
    EXPECT_LE(values[j], ps[j].fit.upper * (1 + 1e-9)) << ps[j].fit.name;
  }
}
