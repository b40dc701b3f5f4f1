// The drivers behind `fem`, `mss`, `study drive`, `calibrate --level all` and `spine database`,
// called directly: their results against independent solves and physical expectations.
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/rigid_plate.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"
#include "spinesim/output/files.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/drive_study.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/mss_run.hpp"
#include "spinesim/studies/spine_database.hpp"
#include "spinesim/studies/toolkit.hpp"

#include "studies_fixtures.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>

using namespace spinesim;
namespace fs = std::filesystem;

namespace {

using test::material;
using test::structured;

/// A fresh folder under the test tmp folder.
std::string tmp_dir(const std::string& name) {
  const fs::path p = fs::path(SPINESIM_TEST_TMP) / (name + "-" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

std::size_t count_lines(const std::string& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

}  // namespace

// --- the FEM reference ---------------------------------------------------------------------------

// Linear FEM: the wrench-loaded solve's plate motion, prescribed as a motion, gives back the
// wrench as the reaction (up to sign: the disc pushes back), and both agree with K6 q = w.
TEST(FemRunDriver, WrenchAndMotionRunsAreInverseThroughTheStiffness) {
  const mesh::TetMesh& m = structured("T7-T8");
  const auto mat = material("real-disc");
  studies::FemRunRequest by_case;
  by_case.order = 1;
  by_case.load_case = &fem::load_case("flexion");
  const studies::FemRunResult w = studies::run_fem_reference(m, mat, by_case);
  const fem::Vector6d applied = fem::global_wrench(fem::load_case("flexion"), m.frame);
  EXPECT_LE((w.applied_wrench - applied).norm(), 1e-12 * applied.norm());
  EXPECT_LE((w.stiffness * w.solution.plate_motion - applied).norm(), 1e-6 * applied.norm());

  studies::FemRunRequest by_motion;
  by_motion.order = 1;
  by_motion.motion = w.solution.plate_motion;
  const studies::FemRunResult q = studies::run_fem_reference(m, mat, by_motion);
  EXPECT_LE((q.solution.reaction_wrench + applied).norm(), 1e-6 * applied.norm());
  EXPECT_LE((q.solution.displacement_mm - w.solution.displacement_mm).norm(),
            1e-6 * w.solution.displacement_mm.norm());

  // The report's stiffness is per degree in its rotation columns.
  const nlohmann::json j = studies::fem_run_json(w, "mesh");
  EXPECT_NEAR(j["stiffness_6x6"][3][3].get<double>(), w.stiffness(3, 3) * M_PI / 180.0,
              1e-9 * w.stiffness(3, 3));
  EXPECT_EQ(j["case"], "flexion");
  EXPECT_EQ(j["dofs"].get<Eigen::Index>(), w.dofs);

  studies::FemRunRequest two = by_case;
  two.motion = fem::Vector6d::Zero();
  EXPECT_THROW(studies::run_fem_reference(m, mat, two), std::invalid_argument);
}

// --- the MSS under a plate load ------------------------------------------------------------------

TEST(MssRunDriver, StaticWrenchRunIsInEquilibriumAndItsMotionReproducesIt) {
  const mesh::TetMesh& m = structured("T7-T8");
  const mss::MssModel model(m, material("real-disc"));
  studies::MssRunRequest rq;
  rq.load.is_wrench = true;
  rq.load.value = 0.2 * fem::global_wrench(fem::load_case("compression"), m.frame);
  rq.load.center = fem::DiscFem::default_plate_center(m);
  const studies::MssRunResult w = studies::run_mss_load(model, rq);
  ASSERT_FALSE(w.failed) << w.failure;
  EXPECT_TRUE(w.statics.converged);
  // The disc's push on the plate balances the applied wrench: the force exactly, the moment (about
  // the moved plate centre, in N over the plate's RMS radius) up to the solver's second-order
  // difference between the applied and the reaction centre (mss tests: WrenchAndPoseModesAgree).
  const Eigen::Vector3d f = rq.load.value.head<3>();
  const double rho = mesh::plate_rms_radius(m, rq.load.center);
  EXPECT_LE((w.reaction_wrench.head<3>() + f).norm(), 1e-6 * f.norm());
  EXPECT_LE((w.reaction_wrench.tail<3>() + rq.load.value.tail<3>()).norm() / rho, 1e-2 * f.norm());
  EXPECT_LT(w.volume_change, 0);  // compressed
  EXPECT_GT(w.max_displacement_mm, 0);

  studies::MssRunRequest by_motion = rq;
  by_motion.load.is_wrench = false;
  by_motion.load.value = w.plate_motion;
  const studies::MssRunResult q = studies::run_mss_load(model, by_motion);
  ASSERT_FALSE(q.failed) << q.failure;
  EXPECT_LE((q.reaction_wrench - w.reaction_wrench).norm(), 1e-3 * rq.load.value.norm());
  const nlohmann::json j = studies::mss_run_json(w);
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_EQ(j.count("steps"), 0u);
}

TEST(MssRunDriver, DynamicRunRampsToTheFullMotionAndFramesAsAsked) {
  const mesh::TetMesh& m = structured("T7-T8");
  const mss::MssModel model(m, material("real-disc"));
  studies::MssRunRequest rq;
  rq.dynamic = true;
  rq.steps = 20;
  rq.frame_every = 5;
  rq.dynamics.matrix_update = mss::MatrixUpdate::frozen;
  rq.load.value << 0, -0.05, 0, 0, 0, 0;
  rq.load.value.head<3>() = m.frame.axes * rq.load.value.head<3>().eval();
  rq.load.center = fem::DiscFem::default_plate_center(m);
  const std::string dir = tmp_dir("mss-run");
  studies::VtuSeries frames(dir + "/run.pvd");
  const studies::MssRunResult r = studies::run_mss_load(model, rq, &frames);
  ASSERT_FALSE(r.failed) << r.failure;
  EXPECT_EQ(r.ramp_steps, 2);  // 10 % of 20
  EXPECT_EQ(r.stats.steps_done, 20);
  EXPECT_NEAR(r.time_s, 20 * rq.dynamics.dt_s, 1e-12);
  EXPECT_LE((r.plate_motion - rq.load.value).norm(), 1e-12);
  EXPECT_EQ(frames.num_frames(), 5u);  // t = 0, 5, 10, 15, 20 steps
  // Pushed down, the disc pushes the plate back up (along the disc axis).
  EXPECT_GT((m.frame.axes.transpose() * r.reaction_wrench.head<3>())(1), 0);
  frames.discard();
}

TEST(MssRunDriver, ExplicitStepBeyondStabilityFailsWithTheReason) {
  const mesh::TetMesh& m = structured("T7-T8");
  const mss::MssModel model(m, material("real-disc"));
  studies::MssRunRequest rq;
  rq.dynamic = true;
  rq.steps = 50;
  rq.dynamics.integrator = mss::Integrator::explicit_euler;
  rq.integrator_name = "explicit";
  rq.dynamics.dt_s = 1e-2;
  rq.load.value << 0, -0.2, 0, 0, 0, 0;
  rq.load.center = fem::DiscFem::default_plate_center(m);
  const studies::MssRunResult r = studies::run_mss_load(model, rq);
  ASSERT_TRUE(r.failed);
  EXPECT_TRUE(r.stats.diverged);
  EXPECT_LT(r.stats.steps_done, rq.steps);
  EXPECT_NE(r.failure.find("diverged at step"), std::string::npos) << r.failure;
  EXPECT_NE(r.failure.find("predicted stable dt"), std::string::npos) << r.failure;
  EXPECT_TRUE(r.x_mm.allFinite());  // the last good state
}

// --- the drive study -----------------------------------------------------------------------------

TEST(DriveStudyDriver, ScheduleIsPiecewiseLinearThroughItsKeyframes) {
  const auto keys = studies::drive_schedule(0.5, 3.0, 2.0);
  ASSERT_EQ(keys.size(), 9u);
  EXPECT_DOUBLE_EQ(keys.back().time_s, 2.4);
  for (const auto& k : keys) {
    const mss::Vector6d q = studies::schedule_motion(keys, k.time_s);
    EXPECT_NEAR(q(1), k.axial_mm, 1e-12);
    EXPECT_NEAR(q(3), k.flexion_deg * M_PI / 180, 1e-12);
  }
  // Half-way between compression (0.4 s) and full flexion hold (1.0 s): half the flexion.
  const mss::Vector6d mid = studies::schedule_motion(keys, 0.8);
  EXPECT_NEAR(mid(1), -0.5, 1e-12);
  EXPECT_NEAR(mid(3), 1.5 * M_PI / 180, 1e-12);
  EXPECT_EQ(mid(0), 0);
  EXPECT_EQ(mid(5), 0);
}

// Stiffer material, larger reaction to the same motion (the thesis's fig. 5.9 ordering), and the
// files say what ran.
TEST(DriveStudyDriver, PolyethyleneResistsMoreThanTheDiscAndTheFilesMatchTheRun) {
  const mesh::TetMesh& m = structured("T7-T8");
  studies::DriveStudyRequest rq;
  rq.stepping.out = tmp_dir("drive");
  rq.stepping.dynamics.matrix_update = mss::MatrixUpdate::frozen;
  rq.stepping.frame_every = 20;
  rq.time_scale = 0.05;  // 60 steps of 1 ms
  rq.materials = {material("real-disc"), material("polyethylene")};
  const studies::DriveStudyResult r = studies::run_drive_study(m, rq);
  ASSERT_EQ(r.runs.size(), 2u);
  EXPECT_EQ(r.diverged(), "");
  for (const auto& run : r.runs) {
    SCOPED_TRACE(run.material);
    EXPECT_EQ(run.steps, 60);
    EXPECT_EQ(run.stats.steps_done, 60);
    EXPECT_EQ(count_lines(run.csv_path), 61u);  // header + one row per step
    EXPECT_EQ(run.frames, 4u);                  // t = 0, 20, 40, 60 steps
    EXPECT_TRUE(fs::exists(run.pvd_path));
    EXPECT_GT(run.peak_axial_n, 0);  // compressed, the disc pushes the plate up
    EXPECT_LT(run.volume_change.lo, 0);
  }
  EXPECT_GT(r.runs[1].peak_force_n, 5 * r.runs[0].peak_force_n);
  EXPECT_TRUE(fs::exists(r.json_path));
  EXPECT_EQ(r.summary["materials"].size(), 2u);
  EXPECT_FALSE(r.summary["diverged"].get<bool>());

  studies::DriveStudyRequest none = rq;
  none.materials.clear();
  EXPECT_THROW(studies::run_drive_study(m, none), std::invalid_argument);
}

// --- the displacement-force database -------------------------------------------------------------

TEST(SpineDatabaseDriver, GeneratedFileChecksAndAWrongOneDoesNot) {
  const int t7 = spine::vertebra_index("T7");
  studies::DatabaseRequest rq;
  rq.loaded_vertebrae = {t7};
  rq.superposition_on = {t7};
  rq.magnitudes_n = {300};
  rq.generated_by = "test";
  const studies::DatabaseBuild b = studies::generate_database(SPINESIM_DATA_DIR, rq);
  EXPECT_EQ(b.loaded_vertebrae, 1);
  EXPECT_EQ(b.samples.solves, 1 + 6 * 12);  // baseline + 6 directions x 12 forces
  EXPECT_TRUE(b.db.has_vertebra(t7));
  EXPECT_TRUE(b.db.info.has_superposition);
  EXPECT_EQ(b.db.info.source, studies::kDatabaseSource);
  const std::string path = tmp_dir("database") + "/db.json";
  b.db.save(path);

  const studies::DatabaseCheck ok =
      studies::check_database(SPINESIM_DATA_DIR, path, {t7}, {300}, 0);
  EXPECT_TRUE(ok.ok);
  ASSERT_EQ(ok.grid.size(), 12u);  // 6 directions x (half, full force)
  for (const auto& row : ok.grid) {
    EXPECT_TRUE(row.ok()) << row.message;
    EXPECT_LE(row.error_mm, row.allowed_mm);
  }
  EXPECT_LE(ok.baseline_mm, ok.margin);
  EXPECT_EQ(studies::database_check_json(ok)["ok"], true);

  // Every fitted coefficient 20 % too large: the re-solved grid no longer matches.
  nlohmann::json file;
  std::ifstream(path) >> file;
  const std::function<void(nlohmann::json&)> scale = [&](nlohmann::json& v) {
    if (v.is_array())
      for (auto& x : v) scale(x);
    else if (v.is_number())
      v = 1.2 * v.get<double>();
  };
  for (auto& fit : file["fits"]) scale(fit["c"]);
  std::ofstream(path) << file.dump(1);
  const studies::DatabaseCheck wrong =
      studies::check_database(SPINESIM_DATA_DIR, path, {t7}, {300}, 0);
  EXPECT_FALSE(wrong.ok);
  int mismatches = 0;
  for (const auto& row : wrong.grid) mismatches += !row.ok();
  EXPECT_GT(mismatches, 0);
}
