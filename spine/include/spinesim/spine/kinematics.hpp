// Finite-rotation kinematics of the vertebra chain. Joint coordinates θ ∈ R^{3·17}: θ_j is the
// rotation vector of vertebra j relative to the one below (R_j = R_{j+1} · exp(θ_j)), about the
// joint point; the sacrum (below L5-S1) is fixed. Translations at the joints are constrained.
#pragma once

#include "spinesim/common/rotation.hpp"
#include "spinesim/spine/model.hpp"

#include <Eigen/Core>

#include <vector>

namespace spinesim::spine {

/// Rigid motion of a vertebra from the reference posture: x = R·X + t for a reference point X.
struct Pose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& X) const { return R * X + t; }
};

/// The rotation-vector maps (common/rotation.hpp), as the spine names them.
using spinesim::left_jacobian_inverse;
using spinesim::right_jacobian;
using spinesim::rotation_exp;
using spinesim::rotation_log;

/// The rigid motion that moves `centre_mm` by `translation_mm` and turns about it by the
/// rotation vector `rotation_deg` (SpineSolution::displacement's row as a pose).
Pose pose_from_displacement(const Eigen::Vector3d& centre_mm, const Eigen::Vector3d& translation_mm,
                            const Eigen::Vector3d& rotation_deg);

/// Poses of the 17 vertebrae for joint coordinates θ (size dof_count(m)).
std::vector<Pose> vertebra_poses(const SpineModel& m, const Eigen::VectorXd& theta);

/// World position of reference point X on `body` (kGround: X itself).
inline Eigen::Vector3d place(const std::vector<Pose>& poses, int body, const Eigen::Vector3d& X) {
  return body == kGround ? X : poses[std::size_t(body)].apply(X);
}

}  // namespace spinesim::spine
