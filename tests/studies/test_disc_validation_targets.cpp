// In-vitro disc behaviour the fibre-reinforced FEM disc does NOT reproduce yet (measured, not
// loosened; `spinesim study disc-validation`, docs/disc-model.md "Validation"). Label `targets`:
// left out of the default run; `ctest --test-dir build/release -L targets`.
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/studies/disc_validation.hpp"
#include "studies_fixtures.hpp"

#include <gtest/gtest.h>

using namespace spinesim;
using namespace spinesim::studies;

namespace {

void expect_every_row_inside(const DiscValidationResult& r) {
  for (const auto& row : r.rows)
    EXPECT_TRUE(row.match()) << row.quantity << ": ours " << row.ours << " " << row.units
                             << ", in vitro " << row.low << " - " << row.high << " (" << row.source
                             << ")";
}

}  // namespace

TEST(DiscValidationTargets, L4L5FibreReinforcedDiscInsideEveryInVitroWindow) {
  const mesh::TetMesh m = mesh::mesh_disc_level("L4-L5", 2.0, SPINESIM_DATA_DIR);
  const DiscValidationResult r = run_disc_validation(
      m, test::material("fibre-reinforced"), fem::Formulation::mixed,
      read_disc_targets(std::string(SPINESIM_DATA_DIR) + "/validation/disc_in_vitro.json"),
      "L4-L5");
  expect_every_row_inside(r);
}

// The identified material (data/materials/disc-identified.json, `spinesim study disc-identify`)
// on the disc it was identified on: the in-vitro windows it still misses stay here.
TEST(DiscValidationTargets, L4L5IdentifiedNonlinearDiscInsideEveryInVitroWindow) {
  const mesh::TetMesh m = mesh::mesh_disc_level("L4-L5", 3.0, SPINESIM_DATA_DIR);
  NonlinearDiscOptions o;
  o.order = 2;
  o.load_increments = 4;
  const DiscValidationResult r = run_nonlinear_disc_validation(
      m, test::material("disc-identified"), o,
      read_disc_targets(std::string(SPINESIM_DATA_DIR) + "/validation/disc_in_vitro.json"),
      "L4-L5");
  expect_every_row_inside(r);
}
