// The disc-validation driver (studies/disc_validation.hpp) on a small structured disc: its
// stiffnesses are the FEM's own answers, the verdicts follow the windows, and the pressure row
// needs the mixed formulation.
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/studies/disc_validation.hpp"
#include "studies_fixtures.hpp"

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

using namespace spinesim;
using namespace spinesim::studies;

namespace {

const nlohmann::json& targets() {
  static const nlohmann::json j =
      read_disc_targets(std::string(SPINESIM_DATA_DIR) + "/validation/disc_in_vitro.json");
  return j;
}

const DiscValidationRow& row(const DiscValidationResult& r, const std::string& q) {
  for (const auto& x : r.rows)
    if (x.quantity == q) return x;
  throw std::runtime_error("no row " + q);
}

TEST(DiscValidation, StiffnessesAreTheFemsOwnAnswersInTheDiscFrame) {
  const mesh::TetMesh& m = test::structured("L4-L5");
  const auto mat = test::material("fibre-reinforced");
  const DiscValidationResult r =
      run_disc_validation(m, mat, fem::Formulation::mixed, targets(), "structured L4-L5");
  ASSERT_EQ(r.rows.size(), targets().at("targets").size());
  // Independently: the plate motion from the condensed 6x6, K6 q = w.
  fem::SolverOptions o;
  o.formulation = fem::Formulation::mixed;
  const fem::DiscFem fem(m, mat, 2, fem::DiscFem::default_plate_center(m), o);
  const auto motion = [&](const char* c) {
    const fem::Vector6d w = fem::global_wrench(fem::load_case(c), m.frame);
    const fem::Vector6d q = fem.stiffness_6x6().ldlt().solve(w);
    fem::Vector6d local;
    local << m.frame.axes.transpose() * q.head<3>(), m.frame.axes.transpose() * q.tail<3>();
    return local;
  };
  const double deg = 180 / 3.14159265358979323846;
  EXPECT_NEAR(row(r, "compression").ours, 0.5 / std::abs(motion("compression")(1)),
              1e-6 * row(r, "compression").ours);
  EXPECT_NEAR(row(r, "torsion").ours, 7.5 / std::abs(motion("torsion")(4) * deg),
              1e-6 * row(r, "torsion").ours);
  EXPECT_NEAR(row(r, "lateral-bending").ours, 7.5 / std::abs(motion("lateral-bending")(5) * deg),
              1e-6 * row(r, "lateral-bending").ours);
  for (const auto& x : r.rows) {
    ASSERT_TRUE(std::isfinite(x.ours)) << x.quantity;
    EXPECT_GT(x.ours, 0) << x.quantity;
    EXPECT_EQ(x.match(), x.ours >= x.low && x.ours <= x.high);
  }
  // A linear disc: flexion and extension differ only by the small coupling terms.
  EXPECT_NEAR(row(r, "flexion").ours, row(r, "extension").ours, 0.02 * row(r, "flexion").ours);
  EXPECT_GT(r.nucleus_pressure_mpa, 0);
}

TEST(DiscValidation, ThePressureRowNeedsTheMixedFormulation) {
  const DiscValidationResult r =
      run_disc_validation(test::structured("L4-L5"), test::material("fibre-reinforced"),
                          fem::Formulation::displacement, targets(), "structured L4-L5");
  const DiscValidationRow& p = row(r, "nucleus-pressure-ratio");
  EXPECT_FALSE(std::isfinite(p.ours));
  EXPECT_NE(p.note.find("mixed"), std::string::npos);
  EXPECT_TRUE(std::isfinite(row(r, "torsion").ours));
}

TEST(DiscValidation, EveryTargetCarriesASource) {
  for (const auto& t : targets().at("targets")) {
    EXPECT_FALSE(t.value("source", std::string()).empty()) << t.dump();
    EXPECT_LT(t.at("low").get<double>(), t.at("high").get<double>()) << t.dump();
  }
}

TEST(DiscValidation, ABadTargetsFileIsRefusedInOneLine) {
  EXPECT_THROW(read_disc_targets("/nonexistent/targets.json"), std::invalid_argument);
  EXPECT_THROW(read_disc_targets(std::string(SPINESIM_DATA_DIR) + "/spine/spine_model.json"),
               std::invalid_argument);
}

}  // namespace

namespace {

TEST(DiscValidation, FieldsOfTheWrongTypeAreRefusedInOneLine) {
  const std::string path = std::string(SPINESIM_TEST_TMP) + "/bad_targets.json";
  for (const char* text :
       {R"({"targets": [{"quantity": "torsion", "low": 1, "high": 2, "units": 5}]})",
        R"({"targets": [{"quantity": "torsion", "low": 1, "high": 2, "facets_removed": "yes"}]})",
        R"({"targets": [{"quantity": "torsion", "low": "1", "high": 2}]})",
        R"({"source": 3, "targets": []})", R"({"targets": [], "whole_segments": {}})"}) {
    std::ofstream(path) << text;
    EXPECT_THROW(read_disc_targets(path), std::invalid_argument) << text;
  }
}

// The nonlinear disc in the same study: every quantity computed from a converged solve, each
// stiffness the load over the last point of its path, each path rising from the first increment
// to the standard load; options out of range are refused before any work.
TEST(DiscValidation, TheNonlinearDiscGivesEveryRowAndItsLoadPaths) {
  const mesh::TetMesh& m = test::structured("L4-L5");
  const auto mat = test::material("fibre-reinforced");
  NonlinearDiscOptions o;
  o.load_increments = 5;
  const DiscValidationResult r =
      run_nonlinear_disc_validation(m, mat, o, targets(), "structured L4-L5");
  ASSERT_EQ(r.paths.size(), 5u);
  for (const DiscLoadPath& p : r.paths) {
    ASSERT_EQ(p.load.size(), 5u) << p.load_case;
    for (std::size_t k = 1; k < p.load.size(); ++k) {
      EXPECT_GT(p.load[k], p.load[k - 1]) << p.load_case;
      EXPECT_GT(p.motion[k], p.motion[k - 1]) << p.load_case;
    }
    const double stiffness = p.load.back() / p.motion.back() / (p.load_units == "N" ? 1000 : 1);
    EXPECT_NEAR(row(r, p.load_case).ours, stiffness, 1e-9 * stiffness) << p.load_case;
  }
  EXPECT_NEAR(row(r, "compression").ours * 1000, 500.0 / r.paths[0].motion.back(), 1e-6);
  EXPECT_GT(r.nucleus_pressure_mpa, 0);
  EXPECT_NEAR(row(r, "nucleus-pressure-ratio").ours,
              r.nucleus_pressure_mpa / (500.0 / r.disc_area_mm2), 1e-12);
  std::ostringstream csv;
  write_disc_paths_csv(csv, r);
  const std::string text = csv.str();
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + 5 * 5);

  for (const auto& bad : {NonlinearDiscOptions{3, 10.0, 4}, NonlinearDiscOptions{1, -1.0, 4},
                          NonlinearDiscOptions{1, 10.0, 0}})
    EXPECT_THROW(run_nonlinear_disc_validation(m, mat, bad, targets(), "x"), std::invalid_argument);
}

}  // namespace
