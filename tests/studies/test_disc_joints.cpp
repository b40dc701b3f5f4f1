// Disc joints (studies/disc_joints.hpp): the shipped file is what the generator makes (the
// kernel, the rotational stiffness about the joint point, is tested in tests/fem).
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/common/constants.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/plate_stiffness.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/disc_joints.hpp"
#include "studies_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <functional>

using namespace spinesim;
using namespace spinesim::studies;

namespace {

TEST(DiscJoints, TheShippedFileIsWhatTheGeneratorMakes) {
  const std::string path =
      std::string(SPINESIM_DATA_DIR) + "/spine/disc_joints/fibre-reinforced.json";
  const nlohmann::json file = nlohmann::json::parse(std::ifstream(path));
  const DiscJointSet set =
      compute_disc_joints(SPINESIM_DATA_DIR, test::material("fibre-reinforced"),
                          fem::Formulation::displacement, {"L4-L5"});
  ASSERT_EQ(set.joints.size(), 1u);
  const auto& rows = file["joints"]["L4-L5"]["K_nmm_per_rad"];
  Eigen::Matrix3d shipped;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) shipped(r, c) = rows[std::size_t(r)][std::size_t(c)].get<double>();
  // Same mesher, seed and solver: equal up to floating-point differences between builds.
  EXPECT_LT((shipped - set.joints[0].K).norm(), 1e-3 * shipped.norm());
  // Mirror symmetry: no flexion-torsion or flexion-lateral coupling.
  EXPECT_EQ(set.joints[0].K(0, 1), 0.0);
  EXPECT_EQ(set.joints[0].K(0, 2), 0.0);
  EXPECT_LT(set.joints[0].mesh_asymmetry, 1e-2);
}

// A tuned set whose network has fibre elements (a `calibrate --nonlinear` fit) has no joint at
// rest: its fibres have no stiffness there, and the condensed network would leave them out.
TEST(DiscJoints, ATunedSetWithFibreElementsIsRefused) {
  const calibration::TunedSet shipped =
      calibration::read_tuned_set(calibration::shipped_tuned_set_path(SPINESIM_DATA_DIR));
  calibration::TunedSet set = shipped;
  const mesh::RegionMaterials fibres = test::material("fibre-reinforced");
  set.material_name = fibres.name;
  set.levels = {{"L4-L5", calibration::tuned_level(shipped, "L4-L5")}};
  calibration::TunedDisc& td = set.levels.at("L4-L5");
  td.material_name = fibres.name;
  td.material = calibration::material_signature(fibres);
  td.options.fibre_springs = true;
  td.scales["fibre"] = 1.0;
  const std::string path = std::string(SPINESIM_TEST_TMP) + "/fibre_tuned_set.json";
  std::ofstream(path) << calibration::to_json(set).dump(1);
  try {
    compute_tuned_disc_joints(SPINESIM_DATA_DIR, path, {"L4-L5"});
    ADD_FAILURE() << "a fibre network's rest linearisation was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fibre elements"), std::string::npos) << e.what();
  }
  // The same set without the fibre elements gives its joint.
  td.options.fibre_springs = false;
  td.scales.erase("fibre");
  std::ofstream(path) << calibration::to_json(set).dump(1);
  EXPECT_EQ(compute_tuned_disc_joints(SPINESIM_DATA_DIR, path, {"L4-L5"}).joints.size(), 1u);
}

// The nonlinear joints' plate kinematics (t = (R − I)(c − J), the moment moved to J) against
// the linear route K_J = Tᵀ K6 T: an isotropic disc, pointwise volume (as the linear P1 FEM),
// at a rotation small enough to be linear.
TEST(DiscJoints, NonlinearRotationAboutTheJointPointIsTheLinearJointStiffnessAtRest) {
  const mesh::TetMesh& m = test::structured("L4-L5");
  const mesh::RegionMaterials materials = test::material("rubber");
  const Eigen::Vector3d c = fem::DiscFem::default_plate_center(m);
  const Eigen::Vector3d J = spine::load_spine_model(SPINESIM_DATA_DIR)
                                .joints[std::size_t(spine::joint_index("L4-L5"))]
                                .point_mm;
  const fem::NonlinearDisc disc(m, fem::disc_element_materials(m, materials, 10), 1, c,
                                fem::VolumetricForm::pointwise);
  const fem::DiscFem linear(m, materials, 1, c);
  const Eigen::Matrix3d KJ = fem::joint_stiffness_about(linear.stiffness_6x6(), c, J);
  const double small = 1e-6;  // rad
  Eigen::Matrix3d K;
  for (int i = 0; i < 3; ++i)
    K.col(i) = nonlinear_joint_moment(disc, J, small * Eigen::Vector3d::Unit(i), 1) / small;
  EXPECT_LT((K - KJ).norm(), 1e-4 * KJ.norm()) << K << "\n\n" << KJ;
}

// The secants (fibre-reinforced, a coarse CGAL mesh): at a tiny moment they are the rest
// tangent in flexion, lateral bending and torsion (the directions its columns were taken in);
// at the standard moment the rotation they give does reach it, within the interpolation's error.
TEST(DiscJoints, NonlinearSecantsAreTheRestTangentAtATinyMomentAndReachTheirMoment) {
  const mesh::RegionMaterials materials = test::material("fibre-reinforced");
  NonlinearJointOptions o;
  o.cell_size_mm = 4;
  o.moment_nm = 0.01;
  const DiscJoint tiny =
      compute_nonlinear_disc_joints(SPINESIM_DATA_DIR, materials, o, {"L4-L5"}).joints.at(0);
  EXPECT_NEAR(tiny.secant(0), tiny.rest_tangent(0, 0), 1e-2 * tiny.rest_tangent(0, 0));
  EXPECT_NEAR(tiny.secant(2), tiny.rest_tangent(2, 2), 1e-2 * tiny.rest_tangent(2, 2));
  EXPECT_NEAR(tiny.secant(3), tiny.rest_tangent(1, 1), 1e-2 * tiny.rest_tangent(1, 1));
  o.moment_nm = 7.5;
  const DiscJointSet set =
      compute_nonlinear_disc_joints(SPINESIM_DATA_DIR, materials, o, {"L4-L5"});
  const DiscJoint& d = set.joints.at(0);
  EXPECT_EQ(set.formulation, "nonlinear P1");
  const mesh::TetMesh m = mesh::mesh_disc_level("L4-L5", 4.0, SPINESIM_DATA_DIR);
  const fem::NonlinearDisc disc(
      m, fem::disc_element_materials(m, materials, fem::material_fibre_k2(materials)), 1,
      d.plate_center_mm);
  const Eigen::Vector3d e = -Eigen::Vector3d::UnitX();  // extension
  const double phi = d.rotation_deg(1) / spinesim::kDegPerRad;
  EXPECT_NEAR(d.secant(1), 7500 / phi, 1e-9 * d.secant(1));
  const double reached = e.dot(nonlinear_joint_moment(disc, d.joint_point_mm, phi * e, 4));
  EXPECT_NEAR(reached, 7500, 5e-3 * 7500);
  // The disc stiffens along its toe: every secant at 7.5 N·m above the rest tangent's, and the
  // file's matrix keeps the rest tangent's correlation.
  EXPECT_GT(d.secant(0), d.rest_tangent(0, 0));
  EXPECT_GT(d.secant(3), d.rest_tangent(1, 1));
  const double rho = d.K(1, 2) / std::sqrt(d.K(1, 1) * d.K(2, 2)),
               rho0 = d.rest_tangent(1, 2) / std::sqrt(d.rest_tangent(1, 1) * d.rest_tangent(2, 2));
  EXPECT_NEAR(rho, rho0, 1e-12);
  EXPECT_DOUBLE_EQ(d.K(2, 2), d.secant(2));
}

TEST(DiscJoints, NonlinearOptionsOutOfRangeAreRefused) {
  const mesh::RegionMaterials materials = test::material("fibre-reinforced");
  for (const auto& set :
       {std::function<void(NonlinearJointOptions&)>(
            [](NonlinearJointOptions& o) { o.moment_nm = 0.001; }),
        std::function<void(NonlinearJointOptions&)>(
            [](NonlinearJointOptions& o) { o.moment_nm = 60; }),
        std::function<void(NonlinearJointOptions&)>([](NonlinearJointOptions& o) { o.order = 3; }),
        std::function<void(NonlinearJointOptions&)>(
            [](NonlinearJointOptions& o) { o.cell_size_mm = -1; }),
        std::function<void(NonlinearJointOptions&)>(
            [](NonlinearJointOptions& o) { o.load_increments = 0; })}) {
    NonlinearJointOptions o;
    set(o);
    EXPECT_THROW(compute_nonlinear_disc_joints(SPINESIM_DATA_DIR, materials, o, {"L4-L5"}),
                 std::invalid_argument);
  }
}

TEST(DiscJoints, TheShippedNonlinearFileIsWhatTheGeneratorMakes) {
  const nlohmann::json file = nlohmann::json::parse(std::ifstream(
      std::string(SPINESIM_DATA_DIR) + "/spine/disc_joints/fibre-reinforced-nonlinear.json"));
  const DiscJointSet set = compute_nonlinear_disc_joints(
      SPINESIM_DATA_DIR, test::material("fibre-reinforced"), NonlinearJointOptions(), {"L4-L5"});
  const nlohmann::json generated = disc_joints_json(set);
  const auto& shipped = file["joints"]["L4-L5"]["secant_nmm_per_rad"];
  for (const auto& [key, value] : generated["joints"]["L4-L5"]["secant_nmm_per_rad"].items())
    EXPECT_NEAR(shipped[key].get<double>(), value.get<double>(), 1e-3 * value.get<double>()) << key;
  // By default each secant is taken at the joint's range of motion (thesis F.5).
  EXPECT_EQ(file["moment_nm"].get<double>(), 0.0);
  const spine::Joint& joint =
      spine::load_spine_model(SPINESIM_DATA_DIR).joints[std::size_t(spine::joint_index("L4-L5"))];
  const DiscJoint& d = set.joints.at(0);
  EXPECT_NEAR(d.rotation_deg(0), joint.rom_flexion * spinesim::kDegPerRad, 1e-12);
  EXPECT_NEAR(d.rotation_deg(1), joint.rom_extension * spinesim::kDegPerRad, 1e-12);
  EXPECT_NEAR(d.rotation_deg(2), joint.rom_lateral * spinesim::kDegPerRad, 1e-12);
  EXPECT_NEAR(d.rotation_deg(3), joint.rom_torsion * spinesim::kDegPerRad, 1e-12);
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR(d.secant(k) * d.rotation_deg(k) / spinesim::kDegPerRad, 1e3 * d.moment_nm(k),
                1e-9 * d.secant(k));
}

}  // namespace
