// Boundary conditions of the MSS disc (boundary.hpp): rotation vectors, plate poses and their
// inverse, the default plate centre, and the refusal of bad input.
#include "spinesim/mss/boundary.hpp"

#include "solver_fixtures.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>

namespace spinesim::mss {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::Matrix3d cross(const Eigen::Vector3d& w) {
  Eigen::Matrix3d W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return W;
}

TEST(Boundary, RotationFromVectorMatchesAngleAxis) {
  for (double angle : {1e-12, 1e-6, 1e-4, 0.99e-4, 1.01e-4, 0.01, 0.5, 2.0, 3.1}) {
    const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -1.0, 0.7).normalized();
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    const Eigen::Matrix3d R = rotation_from_vector(angle * axis);
    EXPECT_LT((R - expected).cwiseAbs().maxCoeff(), 1e-15) << "angle " << angle;
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
  }
  EXPECT_EQ(rotation_from_vector(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
}

TEST(Boundary, SmallRotationIsTheCrossProductToFirstOrder) {
  const Eigen::Vector3d dir(0.2, 0.9, -0.4);
  double previous = 0;
  for (double eps : {1e-2, 1e-3}) {
    const Eigen::Vector3d theta = eps * dir;
    const double err =
        (rotation_from_vector(theta) - Eigen::Matrix3d::Identity() - cross(theta)).norm();
    // The remainder is [theta]x^2 / 2 + O(eps^3): quadratic in eps.
    EXPECT_NEAR(err, (0.5 * cross(theta) * cross(theta)).norm(), 0.1 * err);
    if (previous > 0) EXPECT_NEAR(previous / err, 100.0, 2.0);
    previous = err;
  }
}

TEST(Boundary, PlatePoseMovesTheCentreByTAndInvertsToTheMotion) {
  const Eigen::Vector3d c(1.0, 11.3, -2.0);
  const Vector6d q = fixtures::vec6(0.3, -1.1, 0.2, 0.05, -0.1, 0.02);
  const RigidPose p = plate_pose(q, c);
  EXPECT_LT((p.apply(c) - (c + q.head<3>())).norm(), 1e-14);
  EXPECT_LT((plate_motion(p, c) - q).norm(), 1e-14);
  // To first order the pose is the FEM's small-rotation map X + t + theta x (X - c).
  const Eigen::Vector3d X(20.0, 11.3, 15.0);
  for (double eps : {1e-3, 1e-4}) {
    const Vector6d qe = eps * q;
    const Eigen::Vector3d lin = X + qe.head<3>() + qe.tail<3>().cross(X - c);
    EXPECT_LT((plate_pose(qe, c).apply(X) - lin).norm(),
              0.6 * qe.tail<3>().squaredNorm() * (X - c).norm());
  }
}

TEST(Boundary, DefaultPlateCentreIsTheMeanOfTheSuperiorNodes) {
  const mesh::TetMesh m = fixtures::small_box();
  const Eigen::Vector3d c = default_plate_center(m);
  EXPECT_LT((c - Eigen::Vector3d(0.0, 8.0, 0.0)).norm(), 1e-12);
  mesh::TetMesh no_plate = m;
  no_plate.surface.setZero();
  EXPECT_THROW(default_plate_center(no_plate), std::invalid_argument);
}

TEST(Boundary, ValidateRefusesBadInput) {
  const Eigen::Index n = 10;
  EXPECT_NO_THROW(validate(Boundary(), n));
  const auto refused = [&](auto edit) {
    Boundary bc;
    edit(bc);
    EXPECT_THROW(validate(bc, n), std::invalid_argument);
  };
  refused([](Boundary& b) { b.superior.translation_mm.x() = kNaN; });
  refused([](Boundary& b) { b.inferior.rotation(0, 1) = 0.1; });  // not orthonormal
  refused([](Boundary& b) { b.superior.rotation = -Eigen::Matrix3d::Identity(); });  // reflection
  refused([](Boundary& b) { b.wrench(4) = kNaN; });
  refused([](Boundary& b) { b.plate_center_mm.z() = std::numeric_limits<double>::infinity(); });
  refused([](Boundary& b) { b.probes.push_back(Probe{Eigen::Vector3d::Zero(), -1.0, 0.0}); });
  refused([](Boundary& b) { b.probes.push_back(Probe{Eigen::Vector3d::Zero(), 2.0, -5.0}); });
  refused([](Boundary& b) { b.probes.push_back(Probe{Eigen::Vector3d(kNaN, 0, 0), 2.0, 0.0}); });
  refused([](Boundary& b) { b.nodal_forces_n = Eigen::VectorXd::Zero(3 * n - 1); });
  refused([](Boundary& b) {
    b.nodal_forces_n = Eigen::VectorXd::Zero(3 * n);
    b.nodal_forces_n(7) = kNaN;
  });
  Boundary ok;
  ok.superior = plate_pose(fixtures::vec6(1, 2, 3, 0.1, 0.2, 0.3), Eigen::Vector3d(1, 2, 3));
  ok.nodal_forces_n = Eigen::VectorXd::Ones(3 * n);
  ok.probes.push_back(Probe{});
  EXPECT_NO_THROW(validate(ok, n));
}

}  // namespace
}  // namespace spinesim::mss
