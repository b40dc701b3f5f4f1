// The thesis's functional test 1 (5.3, fig. 5.8) as a study driver: a rigid sphere pressed into
// the outer wall of a disc whose endplates are both fixed, held, withdrawn, then at a second site
// while the first recovers; the disc volume is tracked (the thesis claimed it is preserved and
// never measured it). Implicit Euler at dt 1 ms by default (the thesis's 1 kHz); a VTU time
// series, a CSV per step and a JSON summary in the output folder. A diverging step stops the
// run: the files hold the finite states up to it and the result says so.
#pragma once

#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/solver.hpp"
#include "spinesim/studies/mss_run.hpp"
#include "spinesim/studies/stepped_study.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

struct ProbeSite {
  std::string name;
  Eigen::Index node = 0;
  Eigen::Vector3d point_mm, normal;  ///< surface point and outward unit normal, global
  double start_s = 0;
};

/// Outward area-weighted normals (unnormalised) at the boundary vertices; zero inside.
Eigen::MatrixX3d boundary_normals(const mesh::TetMesh& m);

/// The outer-wall node where the ray from the disc centre in the disc-frame direction named
/// `name` (anterior, posterior, left, right) leaves the disc: the wall node closest to the ray.
ProbeSite pick_site(const mesh::TetMesh& m, const Eigen::MatrixX3d& normals,
                    const std::string& name);

struct ProbeStudyRequest {
  SteppedStudyOptions stepping;
  /// Penalty per node: 0 = the solver's default (mss::default_probe_stiffness, ~540 N/mm on
  /// L4-L5). The implicit step resolves the contacts by an active set inside each step, so the
  /// stiff default withdraws smoothly.
  double radius_mm = 3.0, depth_mm = 2.0, speed_mm_s = 20.0, hold_s = 0.1, rest_s = 0.2,
         stiffness_n_per_mm = 0.0;
  std::vector<std::string> sites = {"anterior", "left"};
};

/// Throws std::invalid_argument naming the bad value (before any work).
void check(const ProbeStudyRequest& request);

struct ProbeStudyResult {
  ProbeStudyRequest request;
  std::vector<ProbeSite> sites;
  double stiffness_n_per_mm = 0;  ///< the penalty used
  int steps = 0;
  StepStats stats;
  double max_force_n = 0, max_displacement_mm = 0;
  Range volume_change;
  std::string pvd_path, csv_path, json_path;
  std::size_t frames = 0;
  nlohmann::json summary;  ///< also written to json_path
};

/// Stages: model, stepping, files (3). `m` needs endplate labels.
ProbeStudyResult run_probe_study(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                                 const ProbeStudyRequest& request,
                                 const StageHooks& hooks = StageHooks());

/// The readable summary.
void print_probe_study(std::ostream& os, const mesh::TetMesh& m, const std::string& material,
                       const ProbeStudyResult& r);

}  // namespace spinesim::studies
