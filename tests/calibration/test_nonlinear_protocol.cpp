// One disc calibrated against the nonlinear FEM (nonlinear_protocol.hpp): the tuned file holds
// the fitted network (rebuilt from the file, it gives the report's errors again on the same
// reference), every (case, level) is reported in its set, the fit does not make the training
// cases worse, a fibre material gets fibre elements and an isotropic one none, and bad requests
// are refused before any work.
#include "spinesim/calibration/nonlinear_protocol.hpp"

#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace spinesim::calibration {
namespace {

mesh::TetMesh disc() { return mesh::mesh_structured_level("L4-L5", {}, SPINESIM_DATA_DIR); }

NonlinearCalibrationRequest small_request() {
  NonlinearCalibrationRequest rq;
  rq.train = fem::parse_load_cases("compression,flexion");
  rq.holdout = fem::parse_load_cases("torsion");
  rq.load_levels = {0.1, 1.0};
  rq.fem_order = 1;
  rq.terms = TermSet::thesis;
  rq.load_increments = 2;
  return rq;
}

double sum_squares(const nlohmann::json& rows, const char* key) {
  double s = 0;
  for (const auto& r : rows) s += r[key].get<double>() * r[key].get<double>();
  return s;
}

TEST(NonlinearProtocol, TheTunedFileHoldsTheFittedNetwork) {
  const mesh::TetMesh m = disc();
  const mesh::RegionMaterials materials =
      mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR);
  const NonlinearCalibrationRequest rq = small_request();
  const NonlinearCalibrationOutcome o = calibrate_disc_nonlinear(m, materials, rq);
  ASSERT_TRUE(o.success) << o.fit.fit.status;
  EXPECT_TRUE(o.tuned.options.fibre_springs);
  EXPECT_TRUE(o.tuned.options.isochoric_fibres);
  EXPECT_EQ(o.tuned.fem_order, 1);
  EXPECT_EQ(o.tuned.level, "L4-L5");
  const nlohmann::json& rep = o.tuned.report;
  EXPECT_EQ(rep["reference"], "nonlinear FEM");
  ASSERT_EQ(rep["train"].size(), 4u);  // 2 cases x 2 levels
  ASSERT_EQ(rep["holdout"].size(), 2u);
  for (const auto& row : rep["holdout"]) EXPECT_EQ(row["name"], "torsion");
  // The fit lowers the training objective's reaction + displacement sum of squares.
  EXPECT_LT(
      sum_squares(rep["train"], "tuned_error") + sum_squares(rep["train"], "tuned_reaction_error"),
      sum_squares(rep["train"], "untuned_error") +
          sum_squares(rep["train"], "untuned_reaction_error"));

  // Written, read back and rebuilt, the network gives the report's errors on the reference.
  const TunedDisc back = tuned_disc_from_json(to_json(o.tuned));
  EXPECT_NO_THROW(check_applies(back, m, materials));
  const mss::MssModel model = build_tuned_model(back, m, back.materials());
  EXPECT_TRUE(model.options().fibre_springs);
  EXPECT_EQ(model.num_fibre_springs(), rep["fibre_elements"].get<Eigen::Index>());
  const std::vector<NonlinearCaseError> again = nonlinear_errors(model, o.reference);
  ASSERT_EQ(again.size(), o.fit.after.size());
  for (std::size_t i = 0; i < again.size(); ++i) {
    EXPECT_NEAR(again[i].reaction_error, o.fit.after[i].reaction_error, 1e-9) << i;
    EXPECT_NEAR(again[i].displacement_error, o.fit.after[i].displacement_error, 1e-9) << i;
  }
}

TEST(NonlinearProtocol, OnlyAFibreMaterialGetsFibreElements) {
  const NonlinearCalibrationRequest rq = small_request();
  const auto fibres = mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR);
  const auto isotropic = mesh::load_material("real-disc", SPINESIM_DATA_DIR);
  EXPECT_TRUE(nonlinear_network(fibres, rq).fibre_springs);
  EXPECT_FALSE(nonlinear_network(isotropic, rq).fibre_springs);
  EXPECT_FALSE(nonlinear_network(isotropic, rq).isochoric_fibres);
  NonlinearCalibrationRequest spring = rq;
  spring.isochoric_fibres = false;
  EXPECT_FALSE(nonlinear_network(fibres, spring).isochoric_fibres);
}

TEST(NonlinearProtocol, BadRequestsAreRefused) {
  const auto bad = [](auto change) {
    NonlinearCalibrationRequest rq = small_request();
    change(rq);
    return rq;
  };
  EXPECT_NO_THROW(validate(small_request()));
  for (const NonlinearCalibrationRequest& rq :
       {bad([](auto& r) { r.train.clear(); }),
        bad([](auto& r) { r.holdout = fem::parse_load_cases("flexion"); }),
        bad([](auto& r) { r.load_levels.clear(); }), bad([](auto& r) { r.load_levels = {0.0}; }),
        bad([](auto& r) { r.load_levels = {2.5}; }),
        bad([](auto& r) { r.load_levels = {std::nan("")}; }), bad([](auto& r) { r.fem_order = 3; }),
        bad([](auto& r) { r.load_increments = 0; })})
    EXPECT_THROW(validate(rq), std::invalid_argument);
  // calibrate_disc_nonlinear checks its request before the FEM runs.
  EXPECT_THROW(
      calibrate_disc_nonlinear(disc(), mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR),
                               bad([](auto& r) { r.fem_order = 0; })),
      std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::calibration
