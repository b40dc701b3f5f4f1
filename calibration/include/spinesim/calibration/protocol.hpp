// One disc's calibration protocol (`spinesim calibrate`, `study materials`, the demo): FEM
// reference on the mesh, the untuned (Van Gelder) baseline, Ipopt, and the checks — training and
// held-out cases by the *nonlinear* MSS at the cases' loads (the protocol of compare.hpp, so the
// numbers in tuned.json are the ones `mss compare --params` reproduces) beside the linearised
// errors the optimiser saw. Optionally a second stage (per_spring.hpp): one multiplier per main
// spring on top of the region fit, reported beside the region-only fit; its multipliers belong
// to the mesh and are not carried to transfer meshes. The tuned file's report (TunedDisc::report)
// is filled here; the readable summary is the program's (studies/calibration_summary.hpp).
#pragma once

#include "spinesim/calibration/calibrate.hpp"
#include "spinesim/calibration/compare.hpp"
#include "spinesim/calibration/per_spring.hpp"
#include "spinesim/calibration/tuned_disc.hpp"

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::calibration {

/// Which MSS terms the calibration tunes (each per region).
enum class TermSet {
  thesis,         ///< main, radial, torsion springs (thesis 5.2-5.8): 6 knobs
  thesis_volume,  ///< + per-tet volume term (beyond the thesis; the Cauchy-gap closer): 8 knobs
  all             ///< + the whole-disc volume term: 9 knobs
};
TermSet parse_term_set(const std::string& name);  ///< "thesis", "thesis+volume", "all"
std::string term_set_name(TermSet t);
mss::MssOptions term_set_options(TermSet t);

/// Throws std::invalid_argument (one line) for no training case or a case both trained and held
/// out.
void check_cases(const std::vector<fem::LoadCase>& train,
                 const std::vector<fem::LoadCase>& holdout);

/// The standard load cases (fem/load_cases.hpp) not in `train`, in their standard order: the
/// held-out set when none is named.
std::vector<fem::LoadCase> held_out_cases(const std::vector<fem::LoadCase>& train);

struct CalibrationRequest {
  std::vector<fem::LoadCase> train, holdout;
  int fem_order = 2;
  TermSet terms = TermSet::thesis_volume;
  Weights weights;
  IpoptSettings ipopt;
  bool nonlinear_check = true;  ///< also run the nonlinear MSS-vs-FEM protocol (compare.hpp)
  /// Load factor of the nonlinear check: the calibration protocol asks for cases "small enough
  /// for linear theory", and the standard 7.5 N·m moments turn a disc by 10-20 deg, where any
  /// geometrically exact model departs from the linear FEM by O(theta/2) in displacement. 0.1
  /// keeps every level within a few degrees (the error against the load factor is in
  /// calibration/README.md).
  double check_load_scale = 0.1;
  /// Other meshes of the same disc on which the tuned region scales are also checked (the
  /// "second mesh resolution" of the protocol): FEM on each, untuned and tuned MSS, same cases
  /// and load scale. Labels name them in the report.
  std::vector<std::pair<std::string, mesh::TetMesh>> transfer_meshes;
  /// Second stage after a successful region fit: per-spring multipliers (per_spring.hpp); the
  /// prior weight is weights.regularisation, the smoothness weight per_spring_weights.smoothness.
  bool per_spring = false;
  PerSpringWeights per_spring_weights;
  IpoptSettings per_spring_ipopt = per_spring_ipopt_defaults();
};

/// The tuned region-level scales applied to another mesh of the disc (per-spring multipliers
/// do not transfer), against the FEM on that mesh.
struct TransferCheck {
  std::string label;
  MssFemComparison untuned, tuned;
  double seconds = 0;
};

struct CalibrationOutcome {
  TunedDisc tuned;             ///< report filled; written only if `success`
  bool success = false;        ///< every requested stage succeeded
  CalibrationResult result;    ///< the region fit
  PerSpringResult per_spring;  ///< the per-spring stage (if requested and the region fit succeeded)
  bool per_spring_ran = false;
  Evaluation untuned_linear;  ///< thesis model, scales 1, linearised
  /// k6_tuned: the tuned file's model (per-spring when that stage ran); k6_region: the region fit.
  fem::Matrix6d k6_fem = fem::Matrix6d::Zero(), k6_untuned = fem::Matrix6d::Zero(),
                k6_tuned = fem::Matrix6d::Zero(), k6_region = fem::Matrix6d::Zero();
  /// Nonlinear, all cases (empty if not requested): tuned_check is the tuned file's model,
  /// region_check the region-only fit when the per-spring stage ran.
  MssFemComparison untuned_check, tuned_check, region_check;
  std::vector<TransferCheck> transfer;  ///< one per request.transfer_meshes
  double fem_seconds = 0, setup_seconds = 0, check_seconds = 0, total_seconds = 0;
};

/// Called with a one-line status as the calibration proceeds (stage names, Ipopt iterations).
using StatusLine = std::function<void(const std::string&)>;

/// Calibrates `mesh` with `materials`. Throws std::invalid_argument for bad requests (no
/// training case, a case both trained and held out, bad Ipopt settings or per-spring weights).
/// A failed Ipopt run is returned (success false; result / per_spring say which stage and why),
/// not thrown.
CalibrationOutcome calibrate_disc(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
                                  const CalibrationRequest& request,
                                  const StatusLine& status = StatusLine());

}  // namespace spinesim::calibration
