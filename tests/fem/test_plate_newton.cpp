// The rigid plate's kinematics inside the nonlinear disc's Newton (fem/src/plate_newton.hpp,
// private to fem/): ∂(R(θ) a)/∂θ against central differences, at rest and at large rotations.
#include "plate_newton.hpp"

#include "spinesim/common/rotation.hpp"

#include <gtest/gtest.h>

namespace spinesim::fem::detail {
namespace {

TEST(PlateKinematics, RotatedArmJacobianIsTheDerivativeOfTheRotation) {
  const Eigen::Vector3d arm(12.0, -3.0, 7.5);
  for (const Eigen::Vector3d theta :
       {Eigen::Vector3d::Zero().eval(), Eigen::Vector3d(0.01, -0.02, 0.005),
        Eigen::Vector3d(0.3, 0.9, -0.4), Eigen::Vector3d(0, 2.5, 0)}) {
    const Eigen::Matrix3d J = rotated_arm_jacobian(theta, arm);
    const double h = 1e-6;
    for (int d = 0; d < 3; ++d) {
      Eigen::Vector3d tp = theta, tm = theta;
      tp(d) += h, tm(d) -= h;
      const Eigen::Vector3d fd = (rotation_exp(tp) * arm - rotation_exp(tm) * arm) / (2 * h);
      EXPECT_LE((fd - J.col(d)).norm(), 1e-8 * arm.norm()) << "theta " << theta.transpose();
    }
  }
  // R(θ) is the rotation by |θ| about θ: it keeps the axis and turns the arm by |θ|.
  const Eigen::Vector3d axis_turn(0, 0.5, 0);
  EXPECT_LE((rotation_exp(axis_turn) * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitY()).norm(),
            1e-15);
  EXPECT_NEAR((rotation_exp(axis_turn) * Eigen::Vector3d::UnitX()).dot(Eigen::Vector3d::UnitX()),
              std::cos(0.5), 1e-15);
}

}  // namespace
}  // namespace spinesim::fem::detail
