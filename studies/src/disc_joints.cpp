#include "spinesim/studies/disc_joints.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/calibration/linear_mss.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/plate_stiffness.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <cmath>

namespace spinesim::studies {
namespace {

/// The parametric disc is mirror-symmetric about the sagittal plane, its CGAL mesh only nearly:
/// under x -> -x, θ_x is even and θ_y, θ_z odd, so the exact disc has no flexion-torsion or
/// flexion-lateral coupling. The mesh's share is removed (and recorded): the spine solves a
/// symmetric model under sagittal loads in the sagittal plane.
void set_mirror_symmetric(DiscJoint& d, const Eigen::Matrix3d& K) {
  const Eigen::DiagonalMatrix<double, 3> P(1, -1, -1);
  d.K = 0.5 * (K + P * K * P);
  d.mesh_asymmetry = (K - d.K).norm() / K.norm();
}

DiscJoint joint_entry(const spine::Joint& joint, const std::string& data_dir) {
  DiscJoint d;
  d.level = joint.name;
  d.joint_point_mm = joint.point_mm;
  d.thesis_nmm_per_deg << joint.k_flexion, joint.k_extension, joint.k_lateral, joint.k_torsion;
  d.thesis_nmm_per_deg /= kDegPerRad;
  d.cell_size_mm = std::min(2.0, mesh::disc_dimensions(joint.name, data_dir).height_mm / 5.0);
  return d;
}

bool wanted(const std::vector<std::string>& levels, const std::string& level) {
  return levels.empty() || std::find(levels.begin(), levels.end(), level) != levels.end();
}

}  // namespace

DiscJointSet compute_disc_joints(const std::string& data_dir,
                                 const mesh::RegionMaterials& materials,
                                 fem::Formulation formulation,
                                 const std::vector<std::string>& levels, const StageHooks& hooks) {
  const Timer timer;
  DiscJointSet set;
  set.material = materials.name;
  set.formulation = formulation_name(formulation);
  const spine::SpineModel model = spine::load_spine_model(data_dir);
  for (const spine::Joint& joint : model.joints) {
    if (!wanted(levels, joint.name)) continue;
    DiscJoint d = joint_entry(joint, data_dir);
    hooks.begin_stage(joint.name + " disc (cell " + fixed(d.cell_size_mm, 2) + " mm)");
    const mesh::TetMesh m = mesh::mesh_disc_level(joint.name, d.cell_size_mm, data_dir);
    d.tets = m.num_tets();
    d.plate_center_mm = fem::DiscFem::default_plate_center(m);
    fem::SolverOptions options;
    options.formulation = formulation;
    const fem::DiscFem solver(m, materials, 2, d.plate_center_mm, options);
    set_mirror_symmetric(
        d, fem::joint_stiffness_about(solver.stiffness_6x6(), d.plate_center_mm, d.joint_point_mm));
    hooks.end_stage(std::to_string(d.tets) + " tets");
    set.joints.push_back(d);
  }
  set.seconds = timer.seconds();
  return set;
}

DiscJointSet compute_tuned_disc_joints(const std::string& data_dir, const std::string& tuned_set,
                                       const std::vector<std::string>& levels,
                                       const StageHooks& hooks) {
  const Timer timer;
  const calibration::TunedSet tuned = calibration::read_tuned_set(tuned_set);
  DiscJointSet set;
  set.material = tuned.material_name;
  set.formulation = "tuned MSS";
  set.tuned_set = tuned_set;
  const spine::SpineModel model = spine::load_spine_model(data_dir);
  for (const spine::Joint& joint : model.joints) {
    if (!wanted(levels, joint.name)) continue;
    DiscJoint d = joint_entry(joint, data_dir);
    const calibration::TunedDisc& td = calibration::tuned_level(tuned, joint.name);
    if (tuned.settings.contains("cell_size_mm") &&
        tuned.settings["cell_size_mm"].contains(joint.name))
      d.cell_size_mm = tuned.settings["cell_size_mm"][joint.name].get<double>();
    hooks.begin_stage(joint.name + " tuned MSS (cell " + fixed(d.cell_size_mm, 2) + " mm)");
    const mesh::TetMesh m = mesh::mesh_disc_level(joint.name, d.cell_size_mm, data_dir);
    d.tets = m.num_tets();
    d.plate_center_mm = fem::DiscFem::default_plate_center(m);
    const mss::MssModel mss = calibration::build_tuned_model(td, m, td.materials());
    std::vector<calibration::Knob> knobs;
    Eigen::VectorXd scales(Eigen::Index(td.scales.size()));
    for (const auto& [name, scale] : td.scales) {
      scales(Eigen::Index(knobs.size())) = scale;
      knobs.push_back(calibration::knob_from_name(name));
    }
    calibration::LinearMss linear(mss, knobs, d.plate_center_mm);
    const calibration::LinearState state =
        td.per_spring() ? linear.solve(scales, Eigen::Map<const Eigen::VectorXd>(
                                                   td.edge_multipliers.data(),
                                                   Eigen::Index(td.edge_multipliers.size())))
                        : linear.solve(scales);
    set_mirror_symmetric(d,
                         fem::joint_stiffness_about(state.k6, d.plate_center_mm, d.joint_point_mm));
    hooks.end_stage(std::to_string(d.tets) + " tets");
    set.joints.push_back(d);
  }
  set.seconds = timer.seconds();
  return set;
}

nlohmann::json disc_joints_json(const DiscJointSet& set) {
  nlohmann::json joints = nlohmann::json::object();
  for (const DiscJoint& d : set.joints) {
    nlohmann::json K = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) K.push_back({d.K(r, 0), d.K(r, 1), d.K(r, 2)});
    joints[d.level] = {
        {"K_nmm_per_rad", K},
        {"diagonal_nmm_per_deg",
         {{"flexion_extension", d.K(0, 0) / kDegPerRad},
          {"torsion", d.K(1, 1) / kDegPerRad},
          {"lateral_bending", d.K(2, 2) / kDegPerRad}}},
        {"thesis_F4_nmm_per_deg",
         {{"flexion", d.thesis_nmm_per_deg(0)},
          {"extension", d.thesis_nmm_per_deg(1)},
          {"lateral_bending", d.thesis_nmm_per_deg(2)},
          {"torsion", d.thesis_nmm_per_deg(3)}}},
        {"plate_center_mm", {d.plate_center_mm.x(), d.plate_center_mm.y(), d.plate_center_mm.z()}},
        {"joint_point_mm", {d.joint_point_mm.x(), d.joint_point_mm.y(), d.joint_point_mm.z()}},
        {"tets", d.tets},
        {"mesh_asymmetry_removed", d.mesh_asymmetry},
        {"cell_size_mm", d.cell_size_mm}};
  }
  const bool tuned = !set.tuned_set.empty();
  const std::string what = tuned ? "tuned MSS disc (" + set.material + ", " + set.tuned_set + ")"
                                 : "FEM disc (" + set.material + ", P2 " + set.formulation + ")";
  return {{"source", what + ", condensed onto the superior plate and restricted to rotations about "
                            "the thesis F.2 joint point: K_J = T^T K6 T (studies/disc_joints.hpp)"},
          {"material", set.material},
          {"formulation", set.formulation},
          {"generated_by", tuned ? "spinesim spine disc-joints --tuned " + set.tuned_set
                                 : "spinesim spine disc-joints --material " + set.material +
                                       " --formulation " + set.formulation},
          {"units",
           "N*mm/rad; theta = (flexion +, axial torsion, lateral bending) as the spine's "
           "joints"},
          {"joints", joints}};
}

void print_disc_joints(std::ostream& os, const DiscJointSet& set) {
  os << "Disc joints: "
     << (set.tuned_set.empty() ? "FEM " + set.material + " (P2 " + set.formulation + ")"
                               : "tuned MSS " + set.material + " (" + set.tuned_set + ")")
     << ", rotational stiffness about the F.2 joint point, N·mm/deg (F.4 beside)\n\n";
  TextTable t({"joint", "tets", "flex/ext", "F.4 flex", "F.4 ext", "torsion", "F.4 torsion",
               "lateral", "F.4 lateral", "max coupling"},
              1);
  for (const DiscJoint& d : set.joints) {
    Eigen::Matrix3d off = d.K;
    off.diagonal().setZero();
    const double coupling = off.cwiseAbs().maxCoeff() /
                            std::sqrt(d.K.diagonal().minCoeff() * d.K.diagonal().maxCoeff());
    t.add({d.level, std::to_string(d.tets), fixed(d.K(0, 0) / kDegPerRad, 0),
           fixed(d.thesis_nmm_per_deg(0), 0), fixed(d.thesis_nmm_per_deg(1), 0),
           fixed(d.K(1, 1) / kDegPerRad, 0), fixed(d.thesis_nmm_per_deg(3), 0),
           fixed(d.K(2, 2) / kDegPerRad, 0), fixed(d.thesis_nmm_per_deg(2), 0),
           fixed(coupling, 3)});
  }
  t.print(os, false);
  os << "\n  max coupling: largest off-diagonal term / geometric mean of the diagonal extremes. "
        "Total "
     << fixed(set.seconds, 1) << " s\n";
}

}  // namespace spinesim::studies
