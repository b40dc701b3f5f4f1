// Plate-stiffness kernels (fem/plate_stiffness.hpp): each checked by the energy it must keep.
#include "spinesim/fem/plate_stiffness.hpp"

#include "spinesim/common/constants.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

using namespace spinesim;

namespace {

/// A symmetric positive definite 6x6 with coupling everywhere (seeded).
fem::Matrix6d spd6(unsigned seed) {
  std::srand(seed);
  const fem::Matrix6d a = fem::Matrix6d::Random();
  fem::Matrix6d k = a * a.transpose() + 6 * fem::Matrix6d::Identity();
  k.topLeftCorner<3, 3>() *= 1e3;  // N/mm beside N·mm/rad: the plate's scales differ
  return k;
}

TEST(PlateStiffness, JointStiffnessKeepsTheEnergyOfEveryRotationAboutTheJoint) {
  // Any rotation θ about J moves the plate (centre c) by q = (θ × (c − J), θ):
  // ½ θᵀ K_J θ = ½ qᵀ K6 q.
  const fem::Matrix6d K6 = spd6(3);
  const Eigen::Vector3d c(1.5, 40.0, -2.0), J = c + Eigen::Vector3d(0.3, -5.2, 1.1);
  const Eigen::Matrix3d K = fem::joint_stiffness_about(K6, c, J);
  for (const Eigen::Vector3d theta :
       {Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d(0.002, -0.007, 0.004)}) {
    fem::Vector6d q;
    q << theta.cross(c - J), theta;
    const double disc = 0.5 * q.dot(K6 * q), joint = 0.5 * theta.dot(K * theta);
    EXPECT_NEAR(joint, disc, 1e-12 * disc);
  }
  EXPECT_LT((K - K.transpose()).norm(), 1e-12 * K.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(K).eigenvalues().minCoeff(), 0);
  // About the plate centre itself K_J is the 6x6's rotation block.
  EXPECT_LT((fem::joint_stiffness_about(K6, c, c) - K6.bottomRightCorner<3, 3>()).norm(),
            1e-12 * K6.norm());
}

TEST(PlateStiffness, TheDiscFrameKeepsTheEnergyOfAMotion) {
  const fem::Matrix6d K6 = spd6(5);
  mesh::DiscFrame frame;
  frame.axes = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  const fem::Matrix6d local = fem::to_disc_frame(K6, frame);
  fem::Vector6d q_local;
  q_local << 0.1, -0.2, 0.05, 0.01, -0.02, 0.03;
  fem::Vector6d q_global;  // the same motion in global components
  q_global << frame.axes * q_local.head<3>(), frame.axes * q_local.tail<3>();
  EXPECT_NEAR(q_local.dot(local * q_local), q_global.dot(K6 * q_global), 1e-12 * K6.norm());
  // The identity frame changes nothing.
  EXPECT_EQ(fem::to_disc_frame(K6, mesh::DiscFrame()), K6);
}

TEST(PlateStiffness, DegreesAreRadiansTimes180OverPi) {
  fem::Vector6d q;
  q << 1, 2, 3, 90, -45, 180;
  const fem::Vector6d r = fem::motion_deg_to_rad(q);
  EXPECT_EQ(r.head<3>(), q.head<3>());
  EXPECT_NEAR(r(3), kPi / 2, 1e-15);
  EXPECT_NEAR(r(5), kPi, 1e-15);
  EXPECT_LT((fem::motion_rad_to_deg(r) - q).norm(), 1e-13);
  // A force per degree is the force per radian times π/180; translations are untouched.
  const fem::Matrix6d K6 = spd6(7), per_deg = fem::stiffness_per_degree(K6);
  EXPECT_EQ(per_deg.leftCols<3>(), K6.leftCols<3>());
  EXPECT_LT((per_deg.rightCols<3>() * 180.0 / kPi - K6.rightCols<3>()).norm(), 1e-12 * K6.norm());
  // The work is the same in either unit: K q_rad = K_per_deg q_deg.
  EXPECT_LT((K6 * r - per_deg * q).norm(), 1e-12 * (K6 * r).norm());
}

}  // namespace
