// The rotation-vector maps of common/rotation.hpp that the others lean on: exp(φ) − I formed
// directly equals exp(φ) − I, is exact to rounding at angles where exp(φ) − I loses the
// small displacement's digits (checked in long double from the closed form), and is
// continuous across its small-angle series; the total log inverts exp everywhere, half a turn
// included.
#include "spinesim/common/rotation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace spinesim {
namespace {

/// (exp(φ) − I) a in long double from Rodrigues' formula.
Eigen::Vector3d displacement_long_double(const Eigen::Vector3d& phi, const Eigen::Vector3d& a) {
  using L = long double;
  const L angle = std::sqrt(L(phi.x()) * phi.x() + L(phi.y()) * phi.y() + L(phi.z()) * phi.z());
  const L half = std::sin(angle / 2);
  const L A = std::sin(angle) / angle, B = 2 * half * half / (angle * angle);
  const L k[3] = {phi.x(), phi.y(), phi.z()}, v[3] = {a.x(), a.y(), a.z()};
  const L kxv[3] = {k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2],
                    k[0] * v[1] - k[1] * v[0]};
  const L kxkxv[3] = {k[1] * kxv[2] - k[2] * kxv[1], k[2] * kxv[0] - k[0] * kxv[2],
                      k[0] * kxv[1] - k[1] * kxv[0]};
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i) out(i) = double(A * kxv[i] + B * kxkxv[i]);
  return out;
}

TEST(RotationExpMinusIdentity, IsExpMinusIdentityAndKeepsSmallDisplacementsExact) {
  const Eigen::Vector3d arm(18.0, -4.5, 21.0);  // a plate node some 25 mm from its centre
  for (const double angle : {0.6, 1e-2, 1e-4, 1e-6}) {
    const Eigen::Vector3d phi = angle * Eigen::Vector3d(0.3, -0.8, 0.52).normalized();
    const Eigen::Matrix3d E = rotation_exp_minus_identity(phi);
    EXPECT_LE((E - (rotation_exp(phi) - Eigen::Matrix3d::Identity())).norm(), 1e-15) << angle;
    const Eigen::Vector3d exact = displacement_long_double(phi, arm);
    const double direct = (E * arm - exact).norm() / exact.norm();
    const double subtracted = ((rotation_exp(phi) * arm - arm) - exact).norm() / exact.norm();
    EXPECT_LE(direct, 1e-14) << angle;  // a few roundings of the cross products
    if (angle <= 1e-4) EXPECT_GT(subtracted, 100 * direct) << angle;  // what the direct form saves
  }
  // The small-angle series just below its switch at 1e-8 rad is the closed form.
  const Eigen::Vector3d phi = 0.999999e-8 * Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d exact = displacement_long_double(phi, arm);
  EXPECT_LE((rotation_exp_minus_identity(phi) * arm - exact).norm(), 1e-14 * exact.norm());
}

TEST(RotationLogTotal, InvertsExpEverywhereAndAtHalfATurnGivesOneOfItsAxes) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> angle(0, kPi * (1 - 1e-9));
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    const Eigen::Vector3d phi = angle(rng) * axis;
    const Eigen::Vector3d back = rotation_log_total(rotation_exp(phi));
    EXPECT_LT((back - phi).norm(), 1e-9 * std::max(1.0, 1 / (kPi - phi.norm()))) << phi.norm();
    if (phi.norm() < kPi - 1e-3 && phi.norm() > 1e-3)
      EXPECT_LT((back - rotation_log(rotation_exp(phi))).norm(), 1e-9);
  }
  EXPECT_LT(rotation_log_total(rotation_exp(Eigen::Vector3d(1e-10, 0, 0))).x() - 1e-10, 1e-20);
  // Half a turn, where rotation_log throws: one of the two axes, and exp of it is the rotation.
  const Eigen::Vector3d axes[] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                  Eigen::Vector3d(1, 1, 1).normalized()};
  for (const Eigen::Vector3d& axis : axes) {
    const Eigen::Matrix3d R = rotation_exp(kPi * axis);
    EXPECT_THROW(rotation_log(R), std::domain_error);
    const Eigen::Vector3d phi = rotation_log_total(R);
    EXPECT_NEAR(phi.norm(), kPi, 1e-9);
    EXPECT_NEAR(std::abs(phi.normalized().dot(axis)), 1.0, 1e-9);
    EXPECT_LT((rotation_exp(phi) - R).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace spinesim
