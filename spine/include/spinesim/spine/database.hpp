// The displacement–force database of thesis 3.5: the 6-DOF response of every vertebra to a
// force on any vertebra T1…L5 along ±x, ±y, ±z, sampled by the equilibrium solver
// (equilibrium.hpp) at 0, 50, …, 600 N and fitted by least-squares polynomials, so the 1 kHz
// haptic loop can evaluate all 17 vertebra poses for any force in about a microsecond.
//
// Response: R(f) = displacement(load f) − displacement(gravity only), per vertebra the F.1
// centre's translation (mm) and the rotation vector (deg, world axes) as SpineSolution gives
// them, differenced componentwise. The gravity-only solution is the shared 0 N baseline
// (baseline()), so R(0) = 0 and an absolute displacement is baseline() + R.
//
// Fit: per (loaded vertebra, direction, responding vertebra, component)
//   R(f) ≈ Σ_{k=1..d} c_k s^k,  s = f / f_max  (f_max = 600 N; no constant term: R(0) = 0),
// least squares over the solved forces; d is the lowest of 1…5 whose RMS residual is below
// max(relative · range, absolute), range = max − min of the samples (0 N included).
//
// Oblique force (thesis 3.5's assumption): each component goes to its axis fit at its magnitude,
//   R(F) ≈ R_{±x}(|Fx|) + R_{±y}(|Fy|) + R_{±z}(|Fz|)  (the sign picks + or −);
// check_superposition() measures how far that is from a direct solve.
//
// Units: mm, N, degrees. Frame: x lateral (the body's right is −x), y superior, z anterior.
#pragma once

#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::spine {

inline constexpr int kDbVertebrae = 17;  ///< T1…L5
inline constexpr int kDbDirections = 6;  ///< +x, −x, +y, −y, +z, −z
inline constexpr int kDbComponents = 6;  ///< tx, ty, tz (mm), rx, ry, rz (deg)
inline constexpr int kDbMaxDegree = 5;

/// Per vertebra (rows, T1…L5): tx, ty, tz (mm), rx, ry, rz (deg).
using VertebraResponse = Eigen::Matrix<double, kDbVertebrae, kDbComponents>;

/// "+x", "-x", "+y", "-y", "+z", "-z"; direction d is axis d / 2 with sign + for even d.
const std::vector<std::string>& direction_names();
/// Index of "+x" … "-z"; throws std::invalid_argument listing the names.
int direction_index(const std::string& name);
/// Unit vector of direction d.
Eigen::Vector3d direction_vector(int d);

// --- fitting ---------------------------------------------------------------------------------

struct FitTolerance {
  double relative = 0.01;  ///< of the response range (max − min of the samples)
  double absolute = 1e-3;  ///< mm or deg
  int max_degree = kDbMaxDegree;
  /// Coefficients are rounded to this quantum (mm or deg) before the residuals are computed,
  /// so the saved file is what the residuals describe.
  double quantum = 1e-5;
};

struct PolynomialFit {
  Eigen::VectorXd coefficients;               ///< c_1 … c_d (size d) in s = f / scale_n
  double max_residual = 0, rms_residual = 0;  ///< over the samples, units of y
  bool within_tolerance = false;  ///< false: max_degree was not enough (kept, counted in reports)
};

/// Least squares y ≈ Σ_{k=1..degree} c_k (f/scale_n)^k (no constant term) by Householder QR.
/// Throws std::invalid_argument for sizes that differ, fewer samples than `degree`, or
/// non-finite values.
Eigen::VectorXd fit_zero_intercept(const Eigen::VectorXd& force_n, const Eigen::VectorXd& y,
                                   int degree, double scale_n);

/// The lowest degree 1…tol.max_degree (and ≤ the sample count) meeting the tolerance, or the
/// best of them when none does; coefficients rounded to tol.quantum.
PolynomialFit fit_by_residual(const Eigen::VectorXd& force_n, const Eigen::VectorXd& y,
                              double scale_n, const FitTolerance& tol = FitTolerance());

/// x rounded to a multiple of `quantum` (> 0; otherwise x), as the nearest double to that
/// decimal so the file stores it in few digits.
double round_to_quantum(double x, double quantum);

/// Σ_{k=1..n} c_k s^k by Horner.
double evaluate_polynomial(const double* c, int n, double s);

// --- sampling the solver ---------------------------------------------------------------------

struct FailedSolve {
  int vertebra = 0, direction = 0;  ///< direction −1: the gravity-only baseline
  double force_n = 0;
  std::string message;  ///< SolveError::what() (or the exception's message)
};

/// A sagittal-plane force (±y, ±z) whose solution left the sagittal plane. The model is
/// symmetric about x = 0, so a symmetric equilibrium exists; such a solve found another one
/// (the symmetric one buckled, or Newton took another branch). Kept in the fit, listed.
struct OutOfPlaneSolve {
  int vertebra = 0, direction = 0;
  double force_n = 0;
  double lateral_mm = 0,
         lateral_deg = 0;  ///< max |tx| (mm), max |(ry, rz)| (deg) over the vertebrae
};

struct GenerationOptions {
  SolveOptions solve;  ///< recruitment on by default, as in the thesis's LifeMOD runs
  std::vector<int> loaded_vertebrae;  ///< empty: all 17
  double force_step_n = 50, force_max_n = 600;
  FitTolerance tolerance;
  /// Threads solving load cases side by side: solve_spine is const on the model, and recruit()
  /// lets one Ipopt run at a time (Debian's sequential MUMPS is not thread-safe). Recruitment is
  /// ~90 % of a solve, so 2 threads gain ~10 % (bench_spine); passive solves scale. 0: one per core.
  int workers = 0;
  /// Called in the calling thread after each finished solve (done, total).
  std::function<void(int, int)> progress;
};

/// Raw samples: responses[v][d][k] at forces_n[k] (forces_n[0] = 0: zero by construction).
struct ResponseSamples {
  std::vector<double> forces_n;
  std::vector<int> loaded_vertebrae;
  VertebraResponse baseline = VertebraResponse::Zero();  ///< gravity-only displacement
  /// [vertebra 0…16][direction 0…5][force]; empty for vertebrae not loaded.
  std::vector<std::array<std::vector<VertebraResponse>, kDbDirections>> responses;
  std::vector<std::array<std::vector<bool>, kDbDirections>> solved;  ///< false: see failed
  std::vector<FailedSolve> failed;
  std::vector<OutOfPlaneSolve> out_of_plane;  ///< beyond 1e-3 mm or 1e-3 deg
  SolveOptions solve;                         ///< as used
  double seconds = 0;                         ///< wall clock of all solves
  int solves = 0;                             ///< attempted, baseline included
  int workers = 1;
};

/// Runs the baseline and every (loaded vertebra, direction, force > 0) solve. A SolveError is
/// recorded in `failed` (that sample is left out of the fit); a failed baseline throws.
ResponseSamples sample_responses(const SpineModel& m, const GenerationOptions& options);

/// Solves each case of `loads` (external loads beside gravity) on `workers` threads (0: one per
/// core): the whole solution per case, or the error message in `errors[i]` (empty: ok; the
/// solution is then default). `progress(done, total)` is called in the calling thread.
void solve_many(const SpineModel& m, const std::vector<std::vector<ExternalLoad>>& loads,
                const SolveOptions& options, int workers, std::vector<SpineSolution>& solutions,
                std::vector<std::string>& errors,
                const std::function<void(int, int)>& progress = {});

/// solve_many, keeping each case's displacement (17×6).
void solve_cases(const SpineModel& m, const std::vector<std::vector<ExternalLoad>>& loads,
                 const SolveOptions& options, int workers,
                 std::vector<VertebraResponse>& displacement, std::vector<std::string>& errors,
                 const std::function<void(int, int)>& progress = {});

// --- the database ----------------------------------------------------------------------------

/// Residuals over a set of fits, per component (each series on its own): translations (mm) and
/// rotations (deg) apart.
struct ResidualSummary {
  double max_translation_mm = 0, rms_translation_mm = 0;
  double max_rotation_deg = 0, rms_rotation_deg = 0;
  int fits = 0, fits_above_tolerance = 0;
  std::array<int, kDbMaxDegree + 1> degree_count{};  ///< fits per degree (index 0 unused)
};

/// One oblique force against the database's superposition.
struct SuperpositionCase {
  int vertebra = 0;
  std::string plane;  ///< "xz", "xy", "yz", "xyz", "-x-y-z"
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  bool solved = false;  ///< false: the direct solve failed (message)
  /// The force needs an axis fit beyond its largest solved force (solves failed there): the db
  /// error then measures extrapolation, so it is left out of the report's worst case.
  bool extrapolated = false;
  std::string message;
  /// Over the vertebrae, max |Δt| (mm) and max |Δr| (deg) of database − direct response, and of
  /// (Σ direct axis solves) − direct response: the latter is the model's own departure from
  /// superposition, the former adds the fit residual.
  double db_error_translation_mm = 0, db_error_rotation_deg = 0;
  double axis_sum_error_translation_mm = 0, axis_sum_error_rotation_deg = 0;
  double response_translation_mm = 0,
         response_rotation_deg = 0;  ///< max |t|, |r| of the direct response
};

struct SuperpositionReport {
  std::vector<SuperpositionCase> cases;
  /// Worst over the solved cases (db: not extrapolated); relative = error / that case's
  /// response magnitude.
  double max_db_translation_mm = 0, max_db_rotation_deg = 0;
  double max_db_translation_relative = 0, max_db_rotation_relative = 0;
  double max_axis_sum_translation_mm = 0, max_axis_sum_rotation_deg = 0;
  double max_axis_sum_translation_relative = 0, max_axis_sum_rotation_relative = 0;
  double seconds = 0;
};

/// What the file says about how it was made.
struct DatabaseInfo {
  std::string generated_by;  ///< the command line
  std::string source;        ///< what the numbers are
  ModelOptions model;        ///< fused joints etc. of the model sampled
  /// The solver's options; the file keeps recruit, criterion, power and tolerance (the rest
  /// load as defaults).
  SolveOptions solve;
  FitTolerance tolerance;
  ResidualSummary residuals;
  std::array<ResidualSummary, kDbDirections> residuals_per_direction;
  std::vector<FailedSolve> failed;
  std::vector<OutOfPlaneSolve> out_of_plane;
  bool has_superposition = false;
  SuperpositionReport superposition;
  double generation_seconds = 0;
  int workers = 1, solves = 0;
};

/// Evaluation for the haptic loop. evaluate() is const, allocation-free and thread-safe.
class DisplacementDatabase {
 public:
  DisplacementDatabase() = default;

  /// Fits every sampled (vertebra, direction, responding vertebra, component). Throws
  /// std::runtime_error when a direction has fewer than 3 solved forces.
  static DisplacementDatabase fit(const ResponseSamples& samples, const FitTolerance& tol);

  /// Reads a file written by save(); throws std::runtime_error naming the path and the problem.
  static DisplacementDatabase load(const std::string& path);
  /// Writes compact JSON (coefficients only, see data/README.md); throws on I/O failure and
  /// never leaves a half-written file.
  void save(const std::string& path) const;

  /// Response of all 17 vertebrae to `force_n` (N) on `loaded_vertebra` (0 = T1 … 16 = L5),
  /// by superposition of the axis fits. Beyond the sampled range the polynomials are
  /// extrapolated, not clamped: check in_range(). Throws std::invalid_argument for an index out
  /// of range, a vertebra not in this database, or a non-finite force.
  void evaluate(int loaded_vertebra, const Eigen::Vector3d& force_n,
                Eigen::Ref<VertebraResponse> out) const;

  /// Every |F_i| ≤ force_max_n() (the validated 600 N of thesis 3.3.5).
  bool in_range(const Eigen::Vector3d& force_n) const;
  /// And within the largest force actually solved for the directions this force uses.
  bool in_range(int loaded_vertebra, const Eigen::Vector3d& force_n) const;

  bool has_vertebra(int v) const { return v >= 0 && v < kDbVertebrae && present_[std::size_t(v)]; }
  double force_max_n() const { return force_max_n_; }
  const std::vector<double>& forces_n() const { return forces_n_; }
  const VertebraResponse& baseline() const { return baseline_; }
  /// Coefficients c_1…c_d of one fit (d = degree; zero-padded storage is hidden).
  Eigen::VectorXd coefficients(int vertebra, int direction, int responding, int component) const;
  int degree(int vertebra, int direction, int responding, int component) const;
  /// Worst fit residual of (vertebra, direction) over its solved forces and the 17 vertebrae,
  /// as max_response_difference() measures it: |Δ translation| (mm), |Δ rotation vector| (deg).
  double max_residual_translation_mm(int vertebra, int direction) const;
  double max_residual_rotation_deg(int vertebra, int direction) const;
  /// Largest solved force of (vertebra, direction) (< force_max_n() when solves failed).
  double solved_max_n(int vertebra, int direction) const;

  DatabaseInfo info;

 private:
  static constexpr int kSeries = kDbVertebrae * kDbComponents;  // 102, column-major 17×6
  // coefficient k (0-based) of series i for (v, d): coef_[((v*6 + d)*kMaxDegree + k)*102 + i],
  // zero beyond a fit's degree, so evaluation is 5 dense 102-vectors per axis.
  std::vector<double> coef_;
  std::vector<unsigned char> degree_;  // [(v*6 + d)*102 + i]
  std::array<bool, kDbVertebrae> present_{};
  std::array<std::array<double, kDbDirections>, kDbVertebrae> residual_t_{}, residual_r_{},
      solved_max_{};
  std::vector<double> forces_n_;
  double force_max_n_ = 600;
  VertebraResponse baseline_ = VertebraResponse::Zero();

  void allocate();
  const double* block(int v, int d) const {
    return coef_.data() + std::size_t((v * kDbDirections + d) * kDbMaxDegree * kSeries);
  }
  double* block(int v, int d) {
    return coef_.data() + std::size_t((v * kDbDirections + d) * kDbMaxDegree * kSeries);
  }
  void set_fit(int v, int d, int series, const Eigen::VectorXd& c);
};

/// Oblique-force cases of thesis 3.5's superposition check: on each of `vertebrae`, forces of
/// each magnitude along the x–z, x–y, y–z diagonals, (1,1,1)/√3 and −(1,1,1)/√3.
std::vector<SuperpositionCase> superposition_cases(const std::vector<int>& vertebrae,
                                                   const std::vector<double>& magnitudes_n);

/// Direct solves of each case and of its axis components; compares both with the database.
/// Failed direct solves are kept in the report (solved = false), never dropped.
SuperpositionReport check_superposition(const SpineModel& m, const DisplacementDatabase& db,
                                        std::vector<SuperpositionCase> cases,
                                        const SolveOptions& options, int workers = 0,
                                        const std::function<void(int, int)>& progress = {});

/// The report as JSON text, as the file's "superposition_check" holds it (for reports).
std::string superposition_json_text(const SuperpositionReport& report);

/// The response summary of (db − reference) over the vertebrae: max |Δt| (mm), max |Δr| (deg).
std::pair<double, double> max_response_difference(const VertebraResponse& a,
                                                  const VertebraResponse& b);

}  // namespace spinesim::spine
