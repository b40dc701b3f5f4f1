// Disc-joint stiffness for the spine model (`spinesim spine disc-joints`): each level's FEM disc,
// condensed onto its superior plate (6×6 about the plate centre c) and restricted to rotations of
// the upper vertebra about the spine's joint point J (thesis F.2, mid-disc):
//   plate motion q = T θ,  T = [ −[c − J]× ; I ]  (6×3)   →   K_J = Tᵀ K6 T  (3×3, N·mm/rad;
//   fem::joint_stiffness_about),
// the disc's rotational stiffness as the spherical joint sees it (the joint holds J in place, so
// the disc's translational stiffness acts only through the lever c − J). The spine model reads
// the file through ModelOptions::disc_joints in place of the thesis's F.4 joint springs.
// Meshes: each level's parametric disc in the spine frame, CGAL cell size min(2 mm, h/5) (as
// `calibrate --level all`); FEM P2, the displacement or the mixed formulation. The CGAL mesh of
// the mirror-symmetric parametric disc is symmetric only to mesh noise: K_J is made exactly
// mirror-symmetric (no flexion-torsion or flexion-lateral coupling), the removed share recorded.
//
// Nonlinear disc joints (compute_nonlinear_disc_joints): the nonlinear disc (fem/nonlinear_disc.hpp:
// tension-only toe-law fibres, finite strain) turned about J — plate motion t = (R(θ) − I)(c − J),
// rotation θ — in each of four directions (flexion +x, extension −x, torsion +y, lateral bending
// +z; the disc is mirror-symmetric, so −y and −z are the same): by default to the joint's range
// of motion in that direction (thesis F.5), or to the rotation at which the moment about J along
// the direction reaches a chosen moment. The spine's joints are bilinear (flexion and extension
// apart): each direction gets its secant stiffness there. The coupling keeps the rest tangent's correlation: with K0 the
// nonlinear disc's tangent at rest (three small rotations) and S the secants (flexion and
// extension averaged), K = S^½ D0^-½ K0 D0^-½ S^½, D0 = diag K0 — positive definite with K0.
#pragma once

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace spinesim::studies {

struct DiscJoint {
  std::string level;
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();  ///< N·mm/rad, θ = (flexion, torsion, lateral)
  Eigen::Vector3d plate_center_mm = Eigen::Vector3d::Zero(),
                  joint_point_mm = Eigen::Vector3d::Zero();
  Eigen::Index tets = 0;
  double cell_size_mm = 0;
  double mesh_asymmetry = 0;  ///< ‖K − K_mirror‖/‖K‖ of the mesh, removed (see compute_disc_joints)
  Eigen::Vector4d thesis_nmm_per_deg = Eigen::Vector4d::Zero();  ///< F.4: flex, ext, lat, torsion
  /// Nonlinear joints only, per direction (flexion, extension, lateral bending, torsion): the
  /// secant (N·mm/rad), its rotation (deg) and moment about J (N·m); and the nonlinear disc's
  /// tangent at rest (N·mm/rad).
  Eigen::Vector4d secant = Eigen::Vector4d::Zero();
  Eigen::Vector4d rotation_deg = Eigen::Vector4d::Zero();
  Eigen::Vector4d moment_nm = Eigen::Vector4d::Zero();
  Eigen::Matrix3d rest_tangent = Eigen::Matrix3d::Zero();
};

struct DiscJointSet {
  std::string material, formulation;  ///< formulation: "displacement", "mixed" or "tuned MSS"
  std::string tuned_set;              ///< the tuned set's path (tuned MSS only)
  bool nonlinear = false;
  double moment_nm = 0;  ///< nonlinear joints: the secants' moment (0: over the range of motion)
  std::vector<DiscJoint> joints;  ///< T1-T2 … L5-S1
  double seconds = 0;
};

/// Meshes and solves every level (`levels` empty: all 17). Stages: one per level.
DiscJointSet compute_disc_joints(const std::string& data_dir,
                                 const mesh::RegionMaterials& materials,
                                 fem::Formulation formulation,
                                 const std::vector<std::string>& levels = {},
                                 const StageHooks& hooks = StageHooks());

/// The same from a tuned MSS set (`spinesim calibrate --level all`; data/tuned_discs.json): each
/// level's mesh remade as the set's settings say, the tuned network's rest stiffness condensed
/// onto the plate (calibration::LinearMss) in place of the FEM's. Throws std::invalid_argument
/// when a remade mesh is not the one the level was fitted on.
DiscJointSet compute_tuned_disc_joints(const std::string& data_dir, const std::string& tuned_set,
                                       const std::vector<std::string>& levels = {},
                                       const StageHooks& hooks = StageHooks());

struct NonlinearJointOptions {
  /// 0: each direction's secant over the joint's range of motion (F.5); else the secants'
  /// moment about J (0.01 … 50 N·m).
  double moment_nm = 0;
  int order = 1;            ///< 1 (nodal-average volume) or 2 (mean dilatation)
  double cell_size_mm = 0;  ///< 0: min(2 mm, h/5) per level, as the linear joints
  int load_increments = 4;  ///< per rotation solve (>= 1)
};

/// The nonlinear disc's joints (see the header): per level three rest solves and one solve per
/// direction (at the range of motion) or two (a secant step, then the rotation interpolated to
/// the moment; a rotation beyond 30° is refused). Throws
/// std::invalid_argument for options out of range, std::runtime_error when a solve does not
/// converge (which level, which direction, why). Stages: one per level.
DiscJointSet compute_nonlinear_disc_joints(const std::string& data_dir,
                                           const mesh::RegionMaterials& materials,
                                           const NonlinearJointOptions& options,
                                           const std::vector<std::string>& levels = {},
                                           const StageHooks& hooks = StageHooks());

/// One rotation θ (rad, spine axes) of the upper plate about J on a nonlinear disc: the moment
/// about J that holds it (N·mm; the negative of the disc's reaction moment about J). Throws
/// std::runtime_error when the solve does not converge.
Eigen::Vector3d nonlinear_joint_moment(const fem::NonlinearDisc& disc,
                                       const Eigen::Vector3d& joint_point_mm,
                                       const Eigen::Vector3d& theta, int load_increments);

/// The file ModelOptions::disc_joints reads (with provenance and the F.4 values beside).
nlohmann::json disc_joints_json(const DiscJointSet& set);

/// Per level: the diagonal in N·mm/deg beside F.4.
void print_disc_joints(std::ostream& os, const DiscJointSet& set);

}  // namespace spinesim::studies
