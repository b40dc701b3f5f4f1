#include "spinesim/fem/plate_stiffness.hpp"

#include "spinesim/common/constants.hpp"
#include "spinesim/common/skew.hpp"

namespace spinesim::fem {

Vector6d motion_deg_to_rad(const Vector6d& q_deg) {
  Vector6d q = q_deg;
  q.tail<3>() *= kRadPerDeg;
  return q;
}

Vector6d motion_rad_to_deg(const Vector6d& q_rad) {
  Vector6d q = q_rad;
  q.tail<3>() *= kDegPerRad;
  return q;
}

Matrix6d stiffness_per_degree(const Matrix6d& k_rad) {
  Matrix6d k = k_rad;
  k.rightCols<3>() *= kRadPerDeg;
  return k;
}

Matrix6d to_disc_frame(const Matrix6d& k, const mesh::DiscFrame& frame) {
  Matrix6d r = Matrix6d::Zero();
  r.topLeftCorner<3, 3>() = frame.axes;
  r.bottomRightCorner<3, 3>() = frame.axes;
  return r.transpose() * k * r;
}

Eigen::Matrix3d joint_stiffness_about(const Matrix6d& K6, const Eigen::Vector3d& c,
                                      const Eigen::Vector3d& J) {
  Eigen::Matrix<double, 6, 3> T;
  T.topRows<3>() = -skew(c - J);  // θ × (c − J) = −[c − J]× θ
  T.bottomRows<3>().setIdentity();
  const Eigen::Matrix3d K = T.transpose() * K6 * T;
  return 0.5 * (K + K.transpose());
}

}  // namespace spinesim::fem
