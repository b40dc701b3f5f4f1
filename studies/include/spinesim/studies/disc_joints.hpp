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
#pragma once

#include "spinesim/fem/disc_fem.hpp"
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
};

struct DiscJointSet {
  std::string material, formulation;  ///< formulation: "displacement", "mixed" or "tuned MSS"
  std::string tuned_set;              ///< the tuned set's path (tuned MSS only)
  std::vector<DiscJoint> joints;      ///< T1-T2 … L5-S1
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

/// The file ModelOptions::disc_joints reads (with provenance and the F.4 values beside).
nlohmann::json disc_joints_json(const DiscJointSet& set);

/// Per level: the diagonal in N·mm/deg beside F.4.
void print_disc_joints(std::ostream& os, const DiscJointSet& set);

}  // namespace spinesim::studies
