#include "spinesim/spine/kinematics.hpp"
#include "spinesim/common/constants.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::spine {
namespace {

Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d h;
  h << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return h;
}

}  // namespace

Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = hat(phi);
  if (a < 1e-8) return Eigen::Matrix3d::Identity() + K + 0.5 * K * K;
  return Eigen::Matrix3d::Identity() + std::sin(a) / a * K + (1 - std::cos(a)) / (a * a) * K * K;
}

Eigen::Vector3d rotation_log(const Eigen::Matrix3d& R) {
  const double c = std::clamp(0.5 * (R.trace() - 1), -1.0, 1.0);
  const double a = std::acos(c);
  const Eigen::Vector3d w(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  if (a < 1e-8) return 0.5 * w;
  if (kPi - a < 1e-6) throw std::domain_error("rotation_log: rotation of 180 degrees");
  return a / (2 * std::sin(a)) * w;
}

Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = hat(phi);
  if (a < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 6.0;
  return Eigen::Matrix3d::Identity() - (1 - std::cos(a)) / (a * a) * K +
         (a - std::sin(a)) / (a * a * a) * K * K;
}

Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = hat(phi);
  if (a < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 12.0;
  const double c = 1 / (a * a) - (1 + std::cos(a)) / (2 * a * std::sin(a));
  return Eigen::Matrix3d::Identity() - 0.5 * K + c * K * K;
}

std::vector<Pose> vertebra_poses(const SpineModel& m, const Eigen::VectorXd& theta) {
  const std::size_t n = m.joints.size();
  if (theta.size() != dof_count(m))
    throw std::invalid_argument("vertebra_poses: theta has the wrong size");
  std::vector<Pose> poses(n);
  Pose below;  // the sacrum: identity
  for (std::size_t k = n; k-- > 0;) {
    const Eigen::Vector3d& J = m.joints[k].point_mm;
    Pose p;
    p.R = below.R * rotation_exp(theta.segment<3>(3 * Eigen::Index(k)));
    p.t = below.apply(J) - p.R * J;  // the joint point moves with the vertebra below
    poses[k] = p;
    below = p;
  }
  return poses;
}

Pose pose_from_displacement(const Eigen::Vector3d& centre_mm, const Eigen::Vector3d& translation_mm,
                            const Eigen::Vector3d& rotation_deg) {
  Pose p;
  p.R = rotation_exp(rotation_deg * kRadPerDeg);
  p.t = centre_mm + translation_mm - p.R * centre_mm;
  return p;
}

}  // namespace spinesim::spine
