// The thesis's functional test 2 (5.3, fig. 5.9) as a study driver: an L2-L3 disc, L3 (inferior)
// fixed, L2 (superior) driven by a motion schedule — compression, then flexion, back, release —
// once per material; the reaction shows how stiff each material is (the thesis: polyethylene
// stiffest, the real disc softest). Per material a VTU time series drive-<material>.pvd and a CSV
// drive-<material>.csv; drive.json sums them up. A run whose step diverges stops there (its files
// hold the finite states up to it); the other materials still run.
#pragma once

#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/studies/stepped_study.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

/// A superior-plate keyframe in the disc frame: axial translation (mm, negative = compression)
/// and flexion rotation about the lateral axis (deg); the motion is linear in between.
struct Keyframe {
  double time_s, axial_mm, flexion_deg;
};

/// The schedule: compress by `compression_mm`, flex by `flexion_deg`, back, release; times
/// (1.2 s in all) multiplied by `time_scale`.
std::vector<Keyframe> drive_schedule(double compression_mm, double flexion_deg, double time_scale);

/// The plate motion (t mm, theta rad) in the disc frame at time t (held after the last key).
mss::Vector6d schedule_motion(const std::vector<Keyframe>& keys, double t);

struct DriveStudyRequest {
  SteppedStudyOptions stepping;
  std::vector<mesh::RegionMaterials> materials;
  double compression_mm = 0.5, flexion_deg = 3.0, time_scale = 1.0;
};

/// Throws std::invalid_argument naming the bad value (before any work).
void check(const DriveStudyRequest& request);

/// One material through the schedule. Reactions in the disc frame, about the moved plate centre.
struct DriveRun {
  std::string material;
  double e_annulus_mpa = 0, e_nucleus_mpa = 0, damping_n_s_per_mm = 0;
  double peak_force_n = 0, peak_axial_n = 0, peak_moment_nmm = 0;
  Range volume_change;
  int steps = 0;
  StepStats stats;
  std::string pvd_path, csv_path;
  std::size_t frames = 0;
};

struct DriveStudyResult {
  DriveStudyRequest request;
  std::vector<Keyframe> schedule;
  std::vector<DriveRun> runs;
  std::string json_path;
  nlohmann::json summary;  ///< also written to json_path
  /// The materials whose run diverged, comma-separated; empty when none did.
  std::string diverged() const;
};

/// Stages: one per material. `m` needs endplate labels.
DriveStudyResult run_drive_study(const mesh::TetMesh& m, const DriveStudyRequest& request,
                                 const StageHooks& hooks = StageHooks());

/// The readable report: the set-up and schedule, then one row per material.
void print_drive_study(std::ostream& os, const mesh::TetMesh& m, const DriveStudyResult& r);

}  // namespace spinesim::studies
