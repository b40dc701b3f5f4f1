#include "spinesim/studies/disc_joints.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/calibration/linear_mss.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/common/rotation.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/plate_stiffness.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

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
    if (mss.num_fibre_springs() > 0)
      throw std::invalid_argument(
          "disc joints: " + joint.name +
          "'s tuned network has fibre elements (a nonlinear fit), which have no stiffness at rest; "
          "its joint comes from the nonlinear disc, not from a rest linearisation");
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

Eigen::Vector3d nonlinear_joint_moment(const fem::NonlinearDisc& disc,
                                       const Eigen::Vector3d& joint_point_mm,
                                       const Eigen::Vector3d& theta, int load_increments) {
  // Plate nodes x = J + R (X − J) = c + t + R (X − c) with t = (R − I)(c − J).
  const Eigen::Vector3d arm = disc.plate_center() - joint_point_mm;
  Eigen::Matrix<double, 6, 1> motion;
  motion << rotation_exp_minus_identity(theta) * arm, theta;
  fem::NewtonOptions newton;
  newton.load_increments = load_increments;
  const fem::NonlinearPlateSolution s = disc.solve_motion(motion, newton);
  if (!s.body.converged) throw std::runtime_error(s.body.failure);
  // The disc's wrench on the plate, moved from c + t to J; the joint holds its negative.
  const Eigen::Vector3d F = s.reaction_wrench.head<3>(), M = s.reaction_wrench.tail<3>();
  return -(M + (disc.plate_center() + motion.head<3>() - joint_point_mm).cross(F));
}

namespace {

/// The four directions of the nonlinear joints, in DiscJoint::secant's order: flexion (+x),
/// extension (−x), lateral bending (+z), torsion (+y).
const std::array<std::pair<const char*, Eigen::Vector3d>, 4>& joint_directions() {
  static const std::array<std::pair<const char*, Eigen::Vector3d>, 4> d{
      {{"flexion", Eigen::Vector3d::UnitX()},
       {"extension", -Eigen::Vector3d::UnitX()},
       {"lateral bending", Eigen::Vector3d::UnitZ()},
       {"torsion", Eigen::Vector3d::UnitY()}}};
  return d;
}

/// The rest tangent (three small rotations, a column each) and each direction's secant: at the
/// joint's range of motion (`moment_nmm` 0), or at `moment_nmm`: a secant step from the
/// tangent's rotation, then the rotation interpolated linearly to the moment through the two
/// points.
void nonlinear_joint(DiscJoint& d, const spine::Joint& joint, const fem::NonlinearDisc& disc,
                     double moment_nmm, int load_increments) {
  constexpr double kMaxRotation = 30 / kDegPerRad;
  constexpr double kRestRotation = 1e-4;  // rad: linear to ~1e-4 relative
  Eigen::Matrix3d K0;
  for (int i = 0; i < 3; ++i)
    K0.col(i) = nonlinear_joint_moment(disc, d.joint_point_mm,
                                       kRestRotation * Eigen::Vector3d::Unit(i), 1) /
                kRestRotation;
  d.rest_tangent = 0.5 * (K0 + K0.transpose());
  for (std::size_t k = 0; k < 4; ++k) {
    const Eigen::Vector3d& e = joint_directions()[k].second;
    const char* name = joint_directions()[k].first;
    const auto moment_at = [&](double phi) {
      try {
        return e.dot(nonlinear_joint_moment(disc, d.joint_point_mm, phi * e, load_increments));
      } catch (const std::runtime_error& error) {
        throw std::runtime_error(std::string(name) + " to " + fixed(phi * kDegPerRad, 2) +
                                 " deg: " + error.what());
      }
    };
    const auto check = [&](double phi) {
      if (!(phi > 0 && phi <= kMaxRotation))
        throw std::runtime_error(std::string(name) + ": the moment needs a rotation of " +
                                 fixed(phi * kDegPerRad, 1) + " deg (beyond 30 deg)");
    };
    const std::array<double, 4> rom{joint.rom_flexion, joint.rom_extension, joint.rom_lateral,
                                    joint.rom_torsion};
    double phi = rom[k], moment = 0;
    if (moment_nmm == 0) {
      moment = moment_at(phi);
    } else {
      const double phi1 = moment_nmm / e.cwiseAbs().dot(d.rest_tangent.diagonal());
      check(phi1);
      const double m1 = moment_at(phi1);
      const double phi2 = phi1 * moment_nmm / m1;
      check(phi2);
      const double m2 = moment_at(phi2);
      phi = std::abs(m2 - m1) > 1e-12 * moment_nmm
                ? phi1 + (moment_nmm - m1) * (phi2 - phi1) / (m2 - m1)
                : phi2;
      check(phi);
      moment = moment_nmm;
    }
    if (!(moment > 0)) throw std::runtime_error(std::string(name) + ": the disc does not resist");
    d.secant(Eigen::Index(k)) = moment / phi;
    d.rotation_deg(Eigen::Index(k)) = phi * kDegPerRad;
    d.moment_nm(Eigen::Index(k)) = moment / 1e3;
  }
  // Mirror symmetry of the parametric disc (set_mirror_symmetric), then the secants on the
  // diagonal with the rest tangent's correlation.
  set_mirror_symmetric(d, d.rest_tangent);
  d.rest_tangent = d.K;
  const Eigen::Vector3d secant_diagonal(0.5 * (d.secant(0) + d.secant(1)), d.secant(3),
                                        d.secant(2));
  const Eigen::Vector3d scale =
      (secant_diagonal.array() / d.rest_tangent.diagonal().array()).sqrt();
  d.K = scale.asDiagonal() * d.rest_tangent * scale.asDiagonal();
}

}  // namespace

DiscJointSet compute_nonlinear_disc_joints(const std::string& data_dir,
                                           const mesh::RegionMaterials& materials,
                                           const NonlinearJointOptions& options,
                                           const std::vector<std::string>& levels,
                                           const StageHooks& hooks) {
  if (!(options.moment_nm == 0 || (options.moment_nm >= 0.01 && options.moment_nm <= 50)))
    throw std::invalid_argument(
        "nonlinear disc joints: the moment must be 0 (range of motion) or 0.01 to 50 N·m");
  if (options.order != 1 && options.order != 2)
    throw std::invalid_argument("nonlinear disc joints: order must be 1 or 2");
  if (!(options.cell_size_mm == 0 || (options.cell_size_mm >= 0.5 && options.cell_size_mm <= 10)))
    throw std::invalid_argument("nonlinear disc joints: the cell size must be 0.5 to 10 mm");
  if (options.load_increments < 1 || options.load_increments > 1000)
    throw std::invalid_argument("nonlinear disc joints: load increments must be 1 to 1000");
  const Timer timer;
  DiscJointSet set;
  set.material = materials.name;
  set.formulation = std::string("nonlinear P") + std::to_string(options.order);
  set.nonlinear = true;
  set.moment_nm = options.moment_nm;
  const double k2 = fem::material_fibre_k2(materials);
  const spine::SpineModel model = spine::load_spine_model(data_dir);
  for (const spine::Joint& joint : model.joints) {
    if (!wanted(levels, joint.name)) continue;
    DiscJoint d = joint_entry(joint, data_dir);
    if (options.cell_size_mm > 0) d.cell_size_mm = options.cell_size_mm;
    hooks.begin_stage(joint.name + " nonlinear disc (cell " + fixed(d.cell_size_mm, 2) + " mm)");
    const mesh::TetMesh m = mesh::mesh_disc_level(joint.name, d.cell_size_mm, data_dir);
    d.tets = m.num_tets();
    d.plate_center_mm = fem::DiscFem::default_plate_center(m);
    const fem::NonlinearDisc disc(m, fem::disc_element_materials(m, materials, k2), options.order,
                                  d.plate_center_mm);
    try {
      nonlinear_joint(d, joint, disc, 1e3 * options.moment_nm, options.load_increments);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("nonlinear disc joints: " + joint.name + ": " + e.what());
    }
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
    if (set.nonlinear) {
      nlohmann::json K0 = nlohmann::json::array();
      for (int r = 0; r < 3; ++r)
        K0.push_back({d.rest_tangent(r, 0), d.rest_tangent(r, 1), d.rest_tangent(r, 2)});
      nlohmann::json secant = nlohmann::json::object(), rotation = nlohmann::json::object(),
                     moment = nlohmann::json::object();
      for (std::size_t k = 0; k < 4; ++k) {
        std::string key = joint_directions()[k].first;
        std::replace(key.begin(), key.end(), ' ', '_');
        secant[key] = d.secant(Eigen::Index(k));
        rotation[key] = d.rotation_deg(Eigen::Index(k));
        moment[key] = d.moment_nm(Eigen::Index(k));
      }
      joints[d.level]["secant_nmm_per_rad"] = secant;
      joints[d.level]["secant_rotation_deg"] = rotation;
      joints[d.level]["secant_moment_nm"] = moment;
      joints[d.level]["rest_tangent_nmm_per_rad"] = K0;
    }
  }
  const std::string at = set.moment_nm > 0 ? "at " + significant(set.moment_nm, 4) + " N*m"
                                           : "over the joint's range of motion (thesis F.5)";
  if (set.nonlinear)
    return {{"source", "nonlinear FEM disc (" + set.material + ", " + set.formulation +
                           ") turned about the thesis F.2 joint point: each direction's secant "
                           "stiffness " +
                           at +
                           ", the coupling with the rest tangent's correlation "
                           "(studies/disc_joints.hpp)"},
            {"material", set.material},
            {"formulation", set.formulation},
            {"moment_nm", set.moment_nm},
            {"generated_by", "spinesim spine disc-joints --nonlinear --material " + set.material +
                                 (set.moment_nm > 0 ? " --moment " + significant(set.moment_nm, 4)
                                                    : std::string())},
            {"units",
             "N*mm/rad; theta = (flexion +, axial torsion, lateral bending) as the spine's "
             "joints"},
            {"joints", joints}};
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
  const bool nonlinear = set.nonlinear;
  os << "Disc joints: "
     << (nonlinear ? "nonlinear FEM " + set.material + " (" + set.formulation + "), secants " +
                         (set.moment_nm > 0 ? "at " + significant(set.moment_nm, 4) + " N·m"
                                            : std::string("over the range of motion"))
         : set.tuned_set.empty() ? "FEM " + set.material + " (P2 " + set.formulation + ")"
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
    const std::string flexion =
        nonlinear ? fixed(d.secant(0) / kDegPerRad, 0) + " / " + fixed(d.secant(1) / kDegPerRad, 0)
                  : fixed(d.K(0, 0) / kDegPerRad, 0);
    t.add({d.level, std::to_string(d.tets), flexion, fixed(d.thesis_nmm_per_deg(0), 0),
           fixed(d.thesis_nmm_per_deg(1), 0), fixed(d.K(1, 1) / kDegPerRad, 0),
           fixed(d.thesis_nmm_per_deg(3), 0), fixed(d.K(2, 2) / kDegPerRad, 0),
           fixed(d.thesis_nmm_per_deg(2), 0), fixed(coupling, 3)});
  }
  t.print(os, false);
  if (nonlinear)
    os << "\n  flex/ext: the flexion / extension secants; rest tangent of the same disc beside "
          "in the JSON (secant_nmm_per_rad, rest_tangent_nmm_per_rad).";
  os << "\n  max coupling: largest off-diagonal term / geometric mean of the diagonal extremes. "
        "Total "
     << fixed(set.seconds, 1) << " s\n";
}

}  // namespace spinesim::studies
