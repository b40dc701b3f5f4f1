// The mass-spring disc fitted to the nonlinear FEM disc at several load levels.
//
// Why not linearised at rest (linear_mss.hpp): the fibre springs (mss/model.hpp) have no
// stiffness at rest — a fibre at its rest length sits at the tension-only kink — and the disc
// stiffens with load, so what must match is the response at the loads the disc carries.
//
// Reference: for each load case c (fem/load_cases.hpp) and load level l (a factor on the case's
// standard wrench), the nonlinear FEM disc (fem/nonlinear_disc.hpp) under that wrench on its
// rigid superior plate: plate motion q*, reaction R* (= the load), vertex displacements u*.
// MSS: its superior plate moved to the FEM's exact rigid pose (mss::plate_pose(q*)), inferior
// endplate fixed, static equilibrium (mss::solve_static, started from the FEM's deformed
// vertices). Compared, with S = diag(1, 1, 1, 1/ρ, 1/ρ, 1/ρ), ρ the plate's RMS radius:
//   reaction error      e_R = |S (R − R*)| / |S R*|        (the secant stiffness at that load)
//   displacement error  e_u = ‖u − u*‖ / ‖u*‖ over the vertices off the endplates
// The plate is moved, not loaded, because the MSS's wrench-loaded plate uses the small-rotation
// map (mss/boundary.hpp), which stretches the plate by θ²/2 at physiological rotations; a pose
// is exact in both models.
//
// Fit: unknowns ln s of the model's switched-on knobs (linear_mss.hpp names), residuals
//   r = [S (R − R*) / |S R*| ; √w_u (u − u*) / ‖u*‖] / √N   for each of the N training (c, l),
// so ½|r|² = ½ mean (e_R² + w_u e_u²), by fit_least_squares (window_fit.hpp: forward-difference
// Jacobian on threads, Gauss–Newton, Ipopt).
#pragma once

#include "spinesim/calibration/linear_mss.hpp"
#include "spinesim/calibration/window_fit.hpp"
#include "spinesim/fem/hyperelastic_body.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/solver.hpp"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace spinesim::calibration {

/// One (case, level) of the nonlinear FEM reference.
struct NonlinearReferenceCase {
  std::string name;
  double level = 1.0;                        ///< factor on the standard wrench
  Vector6d wrench = Vector6d::Zero();        ///< applied, global (N, N·mm)
  Vector6d plate_motion = Vector6d::Zero();  ///< q* (mm, rad)
  Vector6d reaction = Vector6d::Zero();      ///< R* (N, N·mm about the moved centre)
  Eigen::MatrixX3d vertex_displacement_mm;   ///< u*, #V×3
  int newton_iterations = 0;
  double seconds = 0;
};

struct NonlinearReference {
  int fem_order = 2;
  Eigen::Vector3d plate_center_mm = Eigen::Vector3d::Zero();
  double plate_rms_radius_mm = 0;
  std::vector<NonlinearReferenceCase> cases;  ///< case-major: every level of a case together
  double seconds = 0;
};

/// Solves the nonlinear FEM disc for every case and level. The fibres' toe exponent is the
/// material's. Throws std::invalid_argument for no case or a level not finite and > 0, and
/// std::runtime_error naming the case and level when a solve does not converge. `done` is called
/// after each solve with (solved, total).
NonlinearReference nonlinear_reference(const mesh::TetMesh& mesh,
                                       const mesh::RegionMaterials& materials,
                                       const std::vector<fem::LoadCase>& cases,
                                       const std::vector<double>& levels, int fem_order,
                                       const fem::NewtonOptions& newton = fem::NewtonOptions(),
                                       const std::function<void(int, int)>& done = {});

/// The MSS against one reference case (header).
struct NonlinearCaseError {
  std::string name;
  double level = 1.0;
  bool trained = false;
  double reaction_error = 0, displacement_error = 0;
  Vector6d reaction_mss = Vector6d::Zero();
  bool converged = false;
  int iterations = 0;
  std::string message;  ///< why the MSS solve did not converge
};

/// How the MSS's equilibrium at a reference pose is found: Newton from the FEM's displacement
/// field; then, where that does not converge, the plate moved to the pose in equal steps of its
/// translation and rotation vector from rest, each solve started from the last equilibrium.
enum class PoseStart { fem_field_then_steps, fem_field, pose_steps };
inline constexpr int kPoseSteps = 8;

/// The MSS with its superior plate at the reference case's pose (as nonlinear_errors and the fit
/// solve it); a failure's message says what each start tried.
mss::StaticResult mss_at_reference_pose(const mss::MssModel& model,
                                        const NonlinearReference& reference,
                                        const NonlinearReferenceCase& c,
                                        const mss::StaticOptions& options = {},
                                        PoseStart start = PoseStart::fem_field_then_steps);

/// Every reference case; `train` names the training cases (for the flag only).
std::vector<NonlinearCaseError> nonlinear_errors(const mss::MssModel& model,
                                                 const NonlinearReference& reference,
                                                 const std::vector<std::string>& train = {},
                                                 const mss::StaticOptions& options = {});

struct NonlinearFitRequest {
  std::vector<std::string> train;    ///< case names fitted (every level of each); the rest held out
  double displacement_weight = 1.0;  ///< w_u (>= 0)
  double lower_scale = 1e-3, upper_scale = 1e3;  ///< bounds of every knob's scale
  /// The Jacobian comes from forward differences of MSS static solves, whose noise keeps Ipopt
  /// from its tolerances (its error measure includes the noisy gradient): the fit stops at the
  /// acceptable level (1e-3, three iterations) or once the objective has changed by less than
  /// 1e-4 (relative) three iterations in a row — the errors it reports then move by < 1e-4 of
  /// themselves. Without it, fits crept on at an unchanged objective for 10+ minutes.
  WindowFitOptions fit = default_fit();
  mss::StaticOptions solver;

  static WindowFitOptions default_fit() {
    WindowFitOptions f;
    f.ipopt.tolerance = 1e-6;
    f.ipopt.acceptable_tolerance = 1e-3;
    f.ipopt.acceptable_iterations = 3;
    f.ipopt.stall_iterations = 3;
    f.ipopt.stall_change = 1e-4;
    f.ipopt.max_iterations = 100;
    return f;
  }
};

struct NonlinearFitResult {
  LeastSquaresFit fit;
  std::vector<Knob> knobs;                                 ///< in fit.parameters order
  std::array<mss::RegionScales, mss::kNumTerms> scales{};  ///< the model's, fitted knobs replaced
  std::vector<NonlinearCaseError> before, after;           ///< every reference case
};

/// Fits the scales of `model`'s switched-on terms, starting from its current scales (clamped
/// into the bounds). Throws std::invalid_argument (one line) for a training case not in the
/// reference, no training case, a reference made on another mesh, or bad weights or bounds.
NonlinearFitResult fit_mss_nonlinear(const mss::MssModel& model,
                                     const NonlinearReference& reference,
                                     const NonlinearFitRequest& request,
                                     const Progress& progress = Progress());

}  // namespace spinesim::calibration
