// The calibration protocol's promises: a disc's calibration is better than untuned on what it
// trained, its tuned file applies and the K6 it reports is the tuned model's; every level's
// calibration gathers its levels into one set with their settings and refuses a bad request
// before any work.
#include "spinesim/calibration/levels.hpp"
#include "spinesim/calibration/protocol.hpp"
#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mss/plate_stiffness.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace spinesim::calibration {
namespace {

/// The structured disc of `level` with default options, placed in the spine.
mesh::TetMesh level_disc(const std::string& level) {
  return mesh::mesh_structured_level(level, {}, SPINESIM_DATA_DIR);
}

mesh::RegionMaterials material(const std::string& name) {
  return mesh::load_material(name, SPINESIM_DATA_DIR);
}

TEST(CalibrationProtocol, TunedBeatsUntunedOnTrainingCasesAndTheFileApplies) {
  const mesh::TetMesh m = level_disc("L4-L5");
  const auto mat = material("real-disc");
  CalibrationRequest rq;
  rq.train = {fem::load_case("compression"), fem::load_case("flexion"), fem::load_case("shear-ap")};
  rq.holdout = {fem::load_case("torsion")};
  rq.fem_order = 1;
  rq.terms = TermSet::thesis_volume;
  const CalibrationOutcome o = calibrate_disc(m, mat, rq);
  ASSERT_TRUE(o.success) << o.result.status;
  for (const auto& row : o.tuned.report["train"]) {
    SCOPED_TRACE(row["name"].get<std::string>());
    EXPECT_LT(row["tuned_error_linear"].get<double>(), row["untuned_error_linear"].get<double>());
    EXPECT_LT(row["tuned_error"].get<double>(),
              row["untuned_error"].get<double>());  // nonlinear check
  }
  EXPECT_EQ(o.tuned.report["holdout"].size(), 1u);
  EXPECT_EQ(calibration::check_applies(o.tuned, m, mat), "");
  // The K6 the report states is the tuned model's own plate stiffness.
  const mss::MssModel tuned = calibration::build_tuned_model(o.tuned, m, mat);
  const fem::Matrix6d k6 = mss::plate_stiffness(tuned, fem::DiscFem::default_plate_center(m));
  EXPECT_LE((k6 - o.k6_tuned).norm(), 1e-6 * o.k6_tuned.norm());
  // A case both trained and held out is refused before any work.
  CalibrationRequest bad = rq;
  bad.holdout.push_back(fem::load_case("flexion"));
  EXPECT_THROW(calibrate_disc(m, mat, bad), std::invalid_argument);
}

TEST(LevelCalibration, OneLevelGoesIntoTheSetWithItsSettings) {
  AllLevelsRequest rq;
  rq.data_dir = SPINESIM_DATA_DIR;
  rq.levels = {"T7-T8"};
  rq.cell_size_mm = 3.0;
  rq.transfer = false;
  rq.calibration.train = {fem::load_case("compression"), fem::load_case("flexion")};
  rq.calibration.holdout = {fem::load_case("torsion")};
  rq.calibration.fem_order = 1;
  rq.calibration.nonlinear_check = false;
  rq.generated_by = "test";
  int reports = 0;
  const AllLevelsResult r = calibrate_all_levels(
      material("real-disc"), rq, [&reports](int, const std::string&) { ++reports; });
  ASSERT_EQ(r.failed(), "");
  ASSERT_EQ(r.levels.size(), 1u);
  EXPECT_GT(reports, 0);
  const auto& row = r.levels[0];
  EXPECT_TRUE(row.success);
  EXPECT_GT(row.tets, 0);
  EXPECT_EQ(row.cell_size_mm, 3.0);
  EXPECT_LT(row.train_tuned, row.train_untuned);
  EXPECT_LE(row.k6_ratio_min, row.k6_ratio_max);
  ASSERT_EQ(r.set.levels.count("T7-T8"), 1u);
  EXPECT_EQ(r.set.settings["cell_size_mm"]["T7-T8"].get<double>(), 3.0);
  EXPECT_EQ(r.set.settings["cell_size_rule"], "as given");
  EXPECT_EQ(r.set.generated_by, "test");
  EXPECT_EQ(r.set.material_name, "real-disc");

  AllLevelsRequest unknown = rq;
  unknown.levels = {"T7-T9"};
  EXPECT_THROW(calibrate_all_levels(material("real-disc"), unknown), std::invalid_argument);
  AllLevelsRequest per_spring = rq;
  per_spring.calibration.per_spring = true;
  EXPECT_THROW(calibrate_all_levels(material("real-disc"), per_spring), std::invalid_argument);
}

TEST(LevelCalibration, DefaultCellSizeGivesThinDiscsFiveCellsThroughTheirHeight) {
  for (const std::string& level : {"T1-T2", "T7-T8", "L4-L5"}) {
    const double h = mesh::disc_dimensions(level, SPINESIM_DATA_DIR).height_mm;
    EXPECT_DOUBLE_EQ(default_level_cell_size_mm(level, SPINESIM_DATA_DIR), std::min(2.0, h / 5));
  }
}

TEST(LevelCalibration, ACellSizeRuleCapsTheCellAndCountsCellsThroughTheHeight) {
  const CellSizeRule palpation{4.0, 2.5};
  EXPECT_EQ(CellSizeRule().describe(), "min(2 mm, disc height / 5)");
  EXPECT_EQ(palpation.describe(), "min(4 mm, disc height / 2.5)");
  for (const std::string& level : {"T4-T5", "T12-L1", "L4-L5"}) {
    const double h = mesh::disc_dimensions(level, SPINESIM_DATA_DIR).height_mm;
    const double cell = default_level_cell_size_mm(level, SPINESIM_DATA_DIR, palpation);
    EXPECT_DOUBLE_EQ(cell, std::min(4.0, h / 2.5));
    EXPECT_LE(cell, 4.0);
    EXPECT_GE(h / cell, 2.5 - 1e-12);
  }
  // The thinnest disc (T4-T5, 4.5 mm) gets 1.8 mm cells; the thickest is capped at 4 mm.
  EXPECT_DOUBLE_EQ(default_level_cell_size_mm("T4-T5", SPINESIM_DATA_DIR, palpation), 1.8);
  EXPECT_DOUBLE_EQ(default_level_cell_size_mm("L4-L5", SPINESIM_DATA_DIR, palpation), 4.0);
  EXPECT_THROW(validate(CellSizeRule{0.1, 5}), std::invalid_argument);
  EXPECT_THROW(validate(CellSizeRule{2, 0}), std::invalid_argument);
  EXPECT_THROW(validate(CellSizeRule{NAN, 5}), std::invalid_argument);
  EXPECT_NO_THROW(validate(palpation));
}

TEST(LevelCalibration, TheSecondResolutionIsTheProtocols) {
  // Structured: the same disc with 4 more sectors (finer), only when asked for.
  const LevelMeshes s =
      mesh_level("T7-T8", mesh::StructuredDiscOptions(), 0, true, SPINESIM_DATA_DIR);
  ASSERT_EQ(s.transfer.size(), 1u);
  EXPECT_EQ(
      s.transfer[0].first,
      "structured, " + std::to_string(mesh::StructuredDiscOptions().sectors + 4) + " sectors");
  EXPECT_GT(s.transfer[0].second.num_tets(), s.mesh.num_tets());
  EXPECT_TRUE(mesh_level("T7-T8", mesh::StructuredDiscOptions(), 0, false, SPINESIM_DATA_DIR)
                  .transfer.empty());
  // CGAL: the same disc at 1.5x the cell size (coarser), in the same place.
  const LevelMeshes c = mesh_level("T7-T8", std::nullopt, 3.0, true, SPINESIM_DATA_DIR);
  ASSERT_EQ(c.transfer.size(), 1u);
  EXPECT_NE(c.transfer[0].first.find("cell size 4.5 mm"), std::string::npos) << c.transfer[0].first;
  EXPECT_LT(c.transfer[0].second.num_tets(), c.mesh.num_tets());
  EXPECT_TRUE(c.transfer[0].second.frame.origin_mm.isApprox(c.mesh.frame.origin_mm));
  EXPECT_TRUE(c.transfer[0].second.frame.axes.isApprox(c.mesh.frame.axes));
  EXPECT_GT(c.mesh.frame.origin_mm.norm(), 0);  // placed in the spine, not at the origin
  EXPECT_THROW(mesh_level("T7-T9", std::nullopt, 3.0, false, SPINESIM_DATA_DIR),
               std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::calibration
