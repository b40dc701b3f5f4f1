// Finite rotations: exp/log, their Jacobians against finite differences, and the chain.
#include "spinesim/spine/kinematics.hpp"

#include <gtest/gtest.h>

namespace sp = spinesim::spine;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {
Vector3d vee_of_log(const Matrix3d& R) { return sp::rotation_log(R); }
}  // namespace

TEST(SpineKinematics, ExpAndLogAreInverse) {
  for (const Vector3d phi :
       {Vector3d(0.3, -0.2, 0.1), Vector3d(1e-10, 0, 0), Vector3d(0, 2.5, 0.4)}) {
    const Matrix3d R = sp::rotation_exp(phi);
    EXPECT_NEAR((R.transpose() * R - Matrix3d::Identity()).norm(), 0, 1e-14);
    EXPECT_NEAR(R.determinant(), 1, 1e-14);
    EXPECT_NEAR((sp::rotation_log(R) - phi).norm(), 0, 1e-12);
  }
}

TEST(SpineKinematics, RightJacobianAndLeftJacobianInverseMatchFiniteDifferences) {
  const Vector3d phi(0.4, -0.7, 0.2);
  const double h = 1e-6;
  Matrix3d Jr_fd, Jli_fd;
  for (int i = 0; i < 3; ++i) {
    const Vector3d d = h * Vector3d::Unit(i);
    // exp(φ+δ) = exp(φ) exp(J_r δ)  ⇒  J_r e_i = log(exp(φ)ᵀ exp(φ+δ)) / h
    Jr_fd.col(i) = (vee_of_log(sp::rotation_exp(phi).transpose() * sp::rotation_exp(phi + d)) -
                    vee_of_log(sp::rotation_exp(phi).transpose() * sp::rotation_exp(phi - d))) /
                   (2 * h);
    Jli_fd.col(i) = (sp::rotation_log(sp::rotation_exp(d) * sp::rotation_exp(phi)) -
                     sp::rotation_log(sp::rotation_exp(-d) * sp::rotation_exp(phi))) /
                    (2 * h);
  }
  EXPECT_NEAR((sp::right_jacobian(phi) - Jr_fd).norm(), 0, 1e-8);
  EXPECT_NEAR((sp::left_jacobian_inverse(phi) - Jli_fd).norm(), 0, 1e-8);
}

TEST(SpineKinematics, JointPointsStayTogetherAndRotationsCompose) {
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(sp::dof_count(m));
  for (Eigen::Index i = 0; i < theta.size(); ++i) theta[i] = 0.02 * std::sin(1.3 * double(i));
  const auto P = sp::vertebra_poses(m, theta);
  for (std::size_t k = 0; k < m.joints.size(); ++k) {
    const Vector3d& J = m.joints[k].point_mm;
    const Vector3d below = k + 1 < P.size() ? P[k + 1].apply(J) : J;
    EXPECT_NEAR((P[k].apply(J) - below).norm(), 0, 1e-10) << m.joints[k].name;  // spherical joint
    const Matrix3d R_below = k + 1 < P.size() ? P[k + 1].R : Matrix3d::Identity();
    EXPECT_NEAR(
        (R_below.transpose() * P[k].R - sp::rotation_exp(theta.segment<3>(3 * Eigen::Index(k))))
            .norm(),
        0, 1e-12);
  }
  // Zero coordinates: the reference posture.
  for (const auto& p : sp::vertebra_poses(m, Eigen::VectorXd::Zero(sp::dof_count(m)))) {
    EXPECT_TRUE(p.R.isIdentity(0));
    EXPECT_TRUE(p.t.isZero(0));
  }
  EXPECT_THROW(sp::vertebra_poses(m, Eigen::VectorXd::Zero(3)), std::invalid_argument);
}
