// Boundary conditions of the MSS disc — the same interface as the FEM reference (fem/disc_fem.hpp)
// plus the two cases only a dynamic model has: two moving vertebrae and a probe.
//
//   - nodes labelled 1 (inferior endplate) move rigidly with `inferior` (identity: fixed);
//   - nodes labelled 2 (superior endplate) either move rigidly with `superior` (PlateMode::pose,
//     prescribed motion), or are slaved to a rigid plate loaded by `wrench` (PlateMode::wrench):
//     x_i = X_i + t + theta x (X_i - c), the FEM's small-rotation map, plate DOF (t, theta) unknown;
//   - optional spherical probes push surface nodes (label != 0) out by penalty contact
//     (elements.hpp probe_contact); interior nodes are never touched directly;
//   - optional nodal forces, N.
// Poses: x = R X + t in the global (mesh) frame, mm. A 6-DOF plate motion q = (t mm, theta rad)
// about the plate centre c becomes the exact rigid pose x = c + t + R(theta)(X - c), R the
// rotation by the vector theta (Rodrigues); to first order this is the FEM's map.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace spinesim::mss {

using Vector6d = Eigen::Matrix<double, 6, 1>;

struct RigidPose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& X) const { return rotation * X + translation_mm; }
};

/// Rotation by the rotation vector theta (rad), Rodrigues.
Eigen::Matrix3d rotation_from_vector(const Eigen::Vector3d& theta_rad);

/// Exact rigid pose of a plate moved by q = (t mm, theta rad) about centre c.
RigidPose plate_pose(const Vector6d& motion, const Eigen::Vector3d& center_mm);

/// Inverse of plate_pose: q = (pose(c) - c, rotation vector of pose.rotation), |theta| <= pi.
Vector6d plate_motion(const RigidPose& pose, const Eigen::Vector3d& center_mm);

/// Default plate centre (docs/units-and-frame.md): the mean of the vertices labelled 2.
/// Throws std::invalid_argument if there are none.
Eigen::Vector3d default_plate_center(const mesh::TetMesh& mesh);

struct Probe {
  Eigen::Vector3d center_mm = Eigen::Vector3d::Zero();
  double radius_mm = 2.0;
  /// Penalty per node, N/mm. 0 → 100 k̄ with k̄ = trace(K_rest) / (2 #edge springs): the mean
  /// main-spring k when the model has main springs only (the other terms raise it a little).
  double stiffness_n_per_mm = 0.0;
};

enum class PlateMode { pose, wrench };

struct Boundary {
  RigidPose inferior;  ///< pose of the nodes labelled 1
  RigidPose superior;  ///< pose of the nodes labelled 2 (PlateMode::pose)
  PlateMode plate_mode = PlateMode::pose;
  Vector6d wrench = Vector6d::Zero();  ///< (F N, M N·mm about plate_center) for PlateMode::wrench
  /// Centre c of the plate map, wrench and reported moments, mm; taken as given (set it to
  /// default_plate_center(mesh) for the documented default).
  Eigen::Vector3d plate_center_mm = Eigen::Vector3d::Zero();
  std::vector<Probe> probes;
  Eigen::VectorXd nodal_forces_n;  ///< empty, or 3#nodes external forces, N
};

/// Throws std::invalid_argument (one line) for non-finite poses, wrench, probes or forces,
/// a non-orthonormal rotation, a negative probe radius or stiffness, or forces of wrong size.
void validate(const Boundary& bc, Eigen::Index num_nodes);

}  // namespace spinesim::mss
