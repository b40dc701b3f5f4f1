// The MSS-vs-FEM comparison protocol: how well a mass-spring disc reproduces the linear FEM on
// the same mesh. It joins the two models, so it lives with the calibration that uses it (the
// tuned file's errors are the ones `spinesim mss compare --params` reproduces).
//
// MSS vs FEM protocol (`spinesim mss compare`, the calibration's checks, the studies). On one mesh,
// for each named load case (fem/load_cases.hpp, wrench w in the disc frame rotated to global):
//   (a) wrench-loaded: FEM (P1 or P2, displacement at the mesh vertices) and MSS static
//       equilibrium under the same w on the superior plate, inferior endplate fixed;
//         displacement_error = ||u_mss - u_fem||_F / ||u_fem||_F        (all vertices)
//         plate_motion_error = rms_i |r_i(q_mss) - r_i(q_fem)| / rms_i |r_i(q_fem)|,
//       r_i(q) = t + theta x (X_i - c) the rigid displacement of superior-plate node i — a
//       unit-free norm of the 6-DOF plate motion that weighs rotations by the plate's size;
//   (b) motion-loaded: the MSS plate is moved by the FEM's plate motion q_fem (exact rigid pose)
//       and its reaction wrench R_mss compared with the FEM's R_fem (= -w), with moments divided
//       by the plate's RMS radius rho (so N and N·mm/mm add up):
//         reaction_error        = |(dF, dM/rho)| / |(F_fem, M_fem/rho)|
//         reaction_force_error  = |dF| / |(F_fem, M_fem/rho)|,  reaction_moment_error = |dM/rho| / same
//       (each part relative to the FEM wrench's size; a pure-moment case has F_fem = 0, so a
//       ratio |dF|/|F_fem| would be meaningless);
//   (c) the 6x6 plate stiffness diagonal, MSS / FEM: MSS K6 by static condensation of the rest
//       Hessian onto the plate's 6 DOF (the linearisation of (b) at q = 0), FEM K6 as fem/.
// Reaction wrenches: force N and moment N·mm the disc exerts on the superior plate (the MSS's
// about the moved plate centre, the FEM's about the centre — equal to first order).
// Rigid plate: mesh/rigid_plate.hpp; MSS plate stiffness: mss/plate_stiffness.hpp.
#pragma once

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/solver.hpp"

#include <string>
#include <vector>

namespace spinesim::calibration {

struct CaseComparison {
  std::string name;
  fem::Vector6d wrench = fem::Vector6d::Zero();  ///< applied, global frame (N, N·mm)
  fem::Vector6d plate_motion_fem = fem::Vector6d::Zero(),
                plate_motion_mss = fem::Vector6d::Zero();  ///< (mm, rad)
  double displacement_error = 0, plate_motion_error = 0;
  fem::Vector6d reaction_fem = fem::Vector6d::Zero(),
                reaction_mss = fem::Vector6d::Zero();  ///< (N, N·mm)
  double reaction_error = 0, reaction_force_error = 0, reaction_moment_error = 0;
  double max_displacement_fem_mm = 0, max_displacement_mss_mm = 0;
  Eigen::Index inverted_tets = 0;  ///< inside-out tets in the MSS wrench-loaded solution
  bool converged = true;           ///< both MSS static solves converged
  int iterations = 0;              ///< Newton iterations of both MSS solves
  std::string message;             ///< why a solve did not converge
};

struct MssFemComparison {
  std::string material;
  std::string constants = "untuned Van Gelder";  ///< or "tuned (FILE)"
  double load_scale = 1.0;
  int fem_order = 2;
  Eigen::Index nodes = 0, tets = 0;
  double plate_rms_radius_mm = 0;
  std::vector<CaseComparison> cases;
  fem::Matrix6d k6_fem = fem::Matrix6d::Zero(), k6_mss = fem::Matrix6d::Zero();
  double fem_seconds = 0, mss_seconds = 0, stiffness_seconds = 0;
};

/// Runs the protocol on `fem` (already factorised, its plate centre is used) and `model` (same
/// mesh) for `cases`. A static solve that does not converge is recorded, not thrown.
/// `load_scale` multiplies every case's wrench (1: the standard loads of fem/load_cases.hpp; the
/// FEM is linear, so its relative errors do not depend on it, the nonlinear MSS's do).
MssFemComparison compare_mss_fem(const fem::DiscFem& fem, const mss::MssModel& model,
                                 const std::vector<fem::LoadCase>& cases,
                                 const std::string& material_name,
                                 const mss::StaticOptions& options = mss::StaticOptions(),
                                 double load_scale = 1.0);

}  // namespace spinesim::calibration
