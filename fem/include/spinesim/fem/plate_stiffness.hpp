// Kernels on the superior plate's 6×6 stiffness K6 (rows: F N, M N·mm about the plate centre;
// columns: t mm, θ rad) and its motions: the program's degree units, the rotation into a disc's
// own frame, and the rotational stiffness about another point (a spine joint).
#pragma once

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

namespace spinesim::fem {

/// (t mm, θ deg) → (t mm, θ rad), and back.
Vector6d motion_deg_to_rad(const Vector6d& q_deg);
Vector6d motion_rad_to_deg(const Vector6d& q_rad);

/// K6 with its rotation columns per degree: rows (F N, M N·mm), columns (t mm, θ deg).
Matrix6d stiffness_per_degree(const Matrix6d& k_rad);

/// K6 in the disc frame: K_local = Rᵀ K R with R = diag(A, A), A the frame's axes as columns
/// (an orthonormal A; forces, moments, translations and rotations all turn with it).
Matrix6d to_disc_frame(const Matrix6d& k, const mesh::DiscFrame& frame);

/// The rotational stiffness a spherical joint at J sees: plate motion q = T θ with
/// T = [ −[c − J]× ; I ] (6×3), K_J = Tᵀ K6 T (3×3, N·mm/rad), symmetrised. c is the plate
/// centre K6 is taken about; both in mm.
Eigen::Matrix3d joint_stiffness_about(const Matrix6d& K6, const Eigen::Vector3d& plate_center_mm,
                                      const Eigen::Vector3d& joint_point_mm);

}  // namespace spinesim::fem
