// Regenerating one level of the shipped fibre-network set (data/tuned_fibre_discs.json) with the
// settings its file records: the nonlinear P2 reference and the fit take about a minute.
#include "spinesim/calibration/levels.hpp"
#include "spinesim/calibration/nonlinear_protocol.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mss/model.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <set>

namespace spinesim::calibration {
namespace {

std::vector<fem::LoadCase> report_cases(const nlohmann::json& rows) {
  std::vector<fem::LoadCase> cases;
  std::set<std::string> seen;
  for (const auto& r : rows)
    if (seen.insert(r["name"].get<std::string>()).second)
      cases.push_back(fem::load_case(r["name"]));
  return cases;
}

// T1-T2 (2 mm cells, 1,418 tets). The scales are printed, not compared: most knobs end near the
// lower bound 0.001, where the fit is flat, and one run on the very mesh of the file (on a
// loaded machine) missed a 1e-4 comparison of their logarithms while a quiet run matched to the
// printed digits; the cause was not found. What the file promises is what its scales do: on a
// fresh reference they reach every (case, load level) error within 2 points of a fresh fit's.
TEST(ShippedFibreDiscs, RegeneratingOneLevelReproducesItsFit) {
  const TunedSet set = read_tuned_set(shipped_fibre_tuned_set_path(SPINESIM_DATA_DIR));
  const std::string level = "T1-T2";
  const TunedDisc& shipped = tuned_level(set, level);
  const nlohmann::json& rep = shipped.report;

  mesh::MeshOptions mo;
  mo.cell_size_mm = set.settings["cell_size_mm"][level].get<double>();
  const mesh::TetMesh m = mesh::mesh_disc_level(level, mo, SPINESIM_DATA_DIR);
  const mesh::RegionMaterials materials = shipped.materials();

  NonlinearCalibrationRequest rq;
  rq.train = report_cases(rep["train"]);
  rq.holdout = report_cases(rep["holdout"]);
  rq.load_levels = rep["load_levels"].get<std::vector<double>>();
  rq.load_increments = rep["load_increments"].get<int>();
  rq.fem_order = shipped.fem_order;
  rq.terms = parse_term_set(rep["terms"].get<std::string>());
  rq.isochoric_fibres = rep["fibre_stretch"] == "isochoric";
  rq.fit.lower_scale = rep["scale_bounds"][0].get<double>();
  rq.fit.upper_scale = rep["scale_bounds"][1].get<double>();
  const NonlinearCalibrationOutcome fresh = calibrate_disc_nonlinear(m, materials, rq);
  ASSERT_TRUE(fresh.success) << fresh.fit.fit.status;
  ASSERT_EQ(fresh.tuned.scales.size(), shipped.scales.size());

  std::printf("%s mesh (%lld tets, shipped %lld)\n",
              fingerprint(m) == shipped.mesh ? "the shipped" : "another build's",
              static_cast<long long>(m.num_tets()), static_cast<long long>(shipped.mesh.tets));
  for (const auto& [knob, scale] : shipped.scales)
    std::printf("  %-16s shipped %.9g fresh %.9g\n", knob.c_str(), scale,
                fresh.tuned.scales.at(knob));
  const mss::MssModel model = build_tuned_model(shipped, m, materials);
  const std::vector<NonlinearCaseError> with_shipped = nonlinear_errors(model, fresh.reference);
  ASSERT_EQ(with_shipped.size(), fresh.fit.after.size());
  for (std::size_t i = 0; i < with_shipped.size(); ++i) {
    SCOPED_TRACE(with_shipped[i].name + " x" + std::to_string(with_shipped[i].level));
    EXPECT_NEAR(with_shipped[i].displacement_error, fresh.fit.after[i].displacement_error, 0.02);
    EXPECT_NEAR(with_shipped[i].reaction_error, fresh.fit.after[i].reaction_error, 0.02);
  }
}

}  // namespace
}  // namespace spinesim::calibration
