#include "spinesim/spine/kinematics.hpp"
#include "spinesim/common/constants.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::spine {

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
