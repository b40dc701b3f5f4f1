// Disc joints (studies/disc_joints.hpp): the rotational stiffness about the joint point is the
// plate stiffness seen through rigid rotations about it, and the shipped file is what the
// generator makes.
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/studies/disc_joints.hpp"
#include "studies_fixtures.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

using namespace spinesim;
using namespace spinesim::studies;

namespace {

TEST(DiscJoints, EnergyOfARotationAboutTheJointPointIsTheDiscsEnergy) {
  // Any rotation θ about J moves the plate by q = (θ × (c − J), θ): ½ θᵀ K_J θ = ½ qᵀ K6 q.
  const mesh::TetMesh& m = test::structured("L4-L5");
  const Eigen::Vector3d c = fem::DiscFem::default_plate_center(m);
  const fem::DiscFem fem(m, test::material("fibre-reinforced"), 2, c);
  const Eigen::Vector3d J = c + Eigen::Vector3d(0.3, -5.2, 1.1);
  const Eigen::Matrix3d K = joint_stiffness_about(fem.stiffness_6x6(), c, J);
  for (const Eigen::Vector3d theta :
       {Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d(0.002, -0.007, 0.004)}) {
    fem::Vector6d q;
    q << theta.cross(c - J), theta;
    const double disc = 0.5 * q.dot(fem.stiffness_6x6() * q), joint = 0.5 * theta.dot(K * theta);
    EXPECT_NEAR(joint, disc, 1e-10 * disc);
  }
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(K).eigenvalues().minCoeff(), 0);
  // About the plate centre itself K_J is the 6x6's rotation block.
  EXPECT_LT((joint_stiffness_about(fem.stiffness_6x6(), c, c) -
             fem.stiffness_6x6().bottomRightCorner<3, 3>())
                .norm(),
            1e-9 * K.norm());
}

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

}  // namespace
