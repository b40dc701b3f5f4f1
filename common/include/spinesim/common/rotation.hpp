// Finite rotations by the rotation vector φ (rad; axis φ/|φ|, angle |φ|), one definition for
// every module (the spine's joint coordinates, the nonlinear disc's plate):
//   exp: φ → R,   log: R → φ (|φ| < π; rotation_log_total: every R, never throwing),
//   right Jacobian:         exp(φ + δ) ≈ exp(φ) exp(J_r(φ) δ),
//   inverse left Jacobian:  log(exp(δ) R) ≈ log(R) + J_l⁻¹(log R) δ
// (Barfoot, State Estimation for Robotics, 2017, §7.1; small-angle series below 1e-6 rad).
#pragma once

#include "spinesim/common/constants.hpp"
#include "spinesim/common/skew.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim {

inline Eigen::Matrix3d rotation_exp(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (a < 1e-8) return Eigen::Matrix3d::Identity() + K + 0.5 * K * K;
  return Eigen::Matrix3d::Identity() + std::sin(a) / a * K + (1 - std::cos(a)) / (a * a) * K * K;
}

/// exp(φ) − I formed directly, without subtracting I from exp(φ): the displacement (exp(φ) − I) a
/// of a point at arm a then keeps its relative precision at small angles, where R a − a loses
/// |a| ε absolutely (about 4e-15 mm at 20 mm — enough, through a nearly incompressible nucleus,
/// to hold a Newton residual above its tolerance). 1 − cos a = 2 sin²(a/2).
inline Eigen::Matrix3d rotation_exp_minus_identity(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (a < 1e-8) return K + 0.5 * K * K;
  const double s = std::sin(0.5 * a);
  return std::sin(a) / a * K + 2 * s * s / (a * a) * K * K;
}

/// Throws std::domain_error for a rotation of 180° (its axis is not defined by R − Rᵀ).
inline Eigen::Vector3d rotation_log(const Eigen::Matrix3d& R) {
  const double c = std::clamp(0.5 * (R.trace() - 1), -1.0, 1.0);
  const double a = std::acos(c);
  const Eigen::Vector3d w(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  if (a < 1e-8) return 0.5 * w;
  if (kPi - a < 1e-6) throw std::domain_error("rotation_log: rotation of 180 degrees");
  return a / (2 * std::sin(a)) * w;
}

/// log for every rotation, never throwing (for the real-time code): by way of the unit
/// quaternion, φ = 2 atan2(|v|, w) v / |v| with w ≥ 0; at 180° one of the two opposite axes.
inline Eigen::Vector3d rotation_log_total(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double n = q.vec().norm();
  if (n < 1e-12) return 2.0 * q.vec();  // w = 1 to round-off
  return 2.0 * std::atan2(n, q.w()) / n * q.vec();
}

inline Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (a < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 6.0;
  return Eigen::Matrix3d::Identity() - (1 - std::cos(a)) / (a * a) * K +
         (a - std::sin(a)) / (a * a * a) * K * K;
}

inline Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (a < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 12.0;
  const double c = 1 / (a * a) - (1 + std::cos(a)) / (2 * a * std::sin(a));
  return Eigen::Matrix3d::Identity() - 0.5 * K + c * K * K;
}

}  // namespace spinesim
