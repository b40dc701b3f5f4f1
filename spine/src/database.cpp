// The displacement–force database (thesis 3.5): sampling the equilibrium solver, fitting,
// evaluation, the JSON file, and the superposition check. See database.hpp.
#include "spinesim/spine/database.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/input_file.hpp"
#include "spinesim/common/timer.hpp"

#include <Eigen/QR>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <tuple>

namespace spinesim::spine {
namespace {
using nlohmann::json;

constexpr const char* kKind = "spinesim displacement-force database";
constexpr int kFormatVersion = 1;
const std::array<const char*, kDbComponents> kComponentNames = {"tx_mm",  "ty_mm",  "tz_mm",
                                                                "rx_deg", "ry_deg", "rz_deg"};

VertebraResponse as_response(const Eigen::Matrix<double, Eigen::Dynamic, 6>& d) {
  if (d.rows() != kDbVertebrae)
    throw std::runtime_error("displacement database: the solver returned " +
                             std::to_string(d.rows()) + " vertebrae, expected 17");
  return d;
}

}  // namespace

// --- directions ------------------------------------------------------------------------------

const std::vector<std::string>& direction_names() {
  static const std::vector<std::string> names = {"+x", "-x", "+y", "-y", "+z", "-z"};
  return names;
}

int direction_index(const std::string& name) {
  const auto& names = direction_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return int(i);
  throw std::invalid_argument("unknown direction '" + name +
                              "' (expected +x, -x, +y, -y, +z or -z)");
}

Eigen::Vector3d direction_vector(int d) {
  if (d < 0 || d >= kDbDirections) throw std::invalid_argument("direction index out of range");
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  e[d / 2] = d % 2 == 0 ? 1.0 : -1.0;
  return e;
}

// --- fitting ---------------------------------------------------------------------------------

double round_to_quantum(double x, double quantum) {
  if (!(quantum > 0)) return x;
  // n / (1/q) with an integral 1/q is the double nearest the decimal n·q, so the file prints it
  // short ("0.12346", not "0.12345999999999999"); + 0.0 turns −0 into 0.
  const double inverse = std::round(1.0 / quantum);
  const double n = std::round(x / quantum);
  return (std::abs(inverse * quantum - 1.0) < 1e-12 ? n / inverse : n * quantum) + 0.0;
}

double evaluate_polynomial(const double* c, int n, double s) {
  double p = 0;
  for (int k = n - 1; k >= 0; --k) p = p * s + c[k];
  return p * s;  // no constant term
}

Eigen::VectorXd fit_zero_intercept(const Eigen::VectorXd& force_n, const Eigen::VectorXd& y,
                                   int degree, double scale_n) {
  if (force_n.size() != y.size())
    throw std::invalid_argument("fit: forces and values differ in size");
  if (degree < 1 || force_n.size() < degree)
    throw std::invalid_argument("fit: degree " + std::to_string(degree) +
                                " needs at least that many samples, got " +
                                std::to_string(force_n.size()));
  if (!force_n.allFinite() || !y.allFinite() || !(scale_n > 0) || !std::isfinite(scale_n))
    throw std::invalid_argument("fit: non-finite sample or scale");
  // Monomials in s = f/scale ∈ [0, 1]: degree 5 keeps the Vandermonde condition ~1e4, ample for QR.
  Eigen::MatrixXd a(force_n.size(), degree);
  for (Eigen::Index i = 0; i < force_n.size(); ++i) {
    const double s = force_n[i] / scale_n;
    double p = s;
    for (int k = 0; k < degree; ++k, p *= s) a(i, k) = p;
  }
  return a.colPivHouseholderQr().solve(y);
}

PolynomialFit fit_by_residual(const Eigen::VectorXd& force_n, const Eigen::VectorXd& y,
                              double scale_n, const FitTolerance& tol) {
  if (tol.max_degree < 1 || tol.max_degree > kDbMaxDegree || !(tol.quantum >= 0))
    throw std::invalid_argument("fit: max degree must be 1.." + std::to_string(kDbMaxDegree) +
                                ", quantum >= 0");
  const double range =
      std::max(0.0, y.size() ? y.maxCoeff() : 0.0) - std::min(0.0, y.size() ? y.minCoeff() : 0.0);
  const double allowed = std::max(tol.relative * range, tol.absolute);
  const int top = std::min<int>(tol.max_degree, int(force_n.size()));
  PolynomialFit best;
  best.rms_residual = HUGE_VAL;
  for (int d = 1; d <= top; ++d) {
    PolynomialFit f;
    f.coefficients = fit_zero_intercept(force_n, y, d, scale_n);
    for (Eigen::Index k = 0; k < d; ++k)
      f.coefficients[k] = round_to_quantum(f.coefficients[k], tol.quantum);
    double sum2 = 0;
    for (Eigen::Index i = 0; i < y.size(); ++i) {
      const double r = evaluate_polynomial(f.coefficients.data(), d, force_n[i] / scale_n) - y[i];
      sum2 += r * r;
      f.max_residual = std::max(f.max_residual, std::abs(r));
    }
    f.rms_residual = std::sqrt(sum2 / double(y.size()));
    f.within_tolerance = f.rms_residual <= allowed;
    if (f.within_tolerance) return f;
    if (f.rms_residual < best.rms_residual) best = f;
  }
  return best;
}

// --- solving load cases ----------------------------------------------------------------------

void solve_many(const SpineModel& m, const std::vector<std::vector<ExternalLoad>>& loads,
                const SolveOptions& options, int workers, std::vector<SpineSolution>& solutions,
                std::vector<std::string>& errors, const std::function<void(int, int)>& progress) {
  const int n = int(loads.size());
  solutions.assign(std::size_t(n), SpineSolution());
  errors.assign(std::size_t(n), std::string());
  if (n == 0) return;
  if (workers <= 0) workers = int(std::max(1u, std::thread::hardware_concurrency()));
  workers = std::max(1, std::min(workers, n));

  std::atomic<int> next{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::condition_variable changed;
  int done = 0;
  auto work = [&] {
    for (int i = next++; i < n && !stop; i = next++) {
      std::string error;
      SpineSolution solution;
      try {
        solution = solve_spine(m, loads[std::size_t(i)], options);
      } catch (const std::exception& e) {  // SolveError above all; anything else is kept too
        error = e.what();
        if (error.empty()) error = "solve failed (no message)";
      } catch (...) {
        error = "solve failed (unknown exception)";
      }
      std::lock_guard<std::mutex> lock(mutex);
      solutions[std::size_t(i)] = std::move(solution);
      errors[std::size_t(i)] = error;
      ++done;
      changed.notify_one();
    }
  };
  std::vector<std::thread> pool;
  for (int w = 0; w < workers; ++w) pool.emplace_back(work);
  // The caller's thread only reports, so progress() never needs to be thread-safe.
  try {
    for (int reported = 0; reported < n;) {
      int now = 0;
      {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait(lock, [&] { return done > reported; });
        now = done;
      }
      while (reported < now)
        if (++reported, progress) progress(reported, n);
    }
  } catch (...) {  // a throwing progress() (e.g. cancel) stops the pool before unwinding
    stop = true;
    for (auto& t : pool) t.join();
    throw;
  }
  for (auto& t : pool) t.join();
}

void solve_cases(const SpineModel& m, const std::vector<std::vector<ExternalLoad>>& loads,
                 const SolveOptions& options, int workers,
                 std::vector<VertebraResponse>& displacement, std::vector<std::string>& errors,
                 const std::function<void(int, int)>& progress) {
  std::vector<SpineSolution> solutions;
  solve_many(m, loads, options, workers, solutions, errors, progress);
  displacement.assign(solutions.size(), VertebraResponse::Zero());
  for (std::size_t i = 0; i < solutions.size(); ++i)
    if (errors[i].empty()) displacement[i] = as_response(solutions[i].displacement);
}

namespace {

ExternalLoad load_at_centre(int vertebra, const Eigen::Vector3d& force_n) {
  ExternalLoad l;
  l.vertebra = vertebra;
  l.force_n = force_n;
  return l;  // no point: the vertebra's F.1 centre
}

}  // namespace

ResponseSamples sample_responses(const SpineModel& m, const GenerationOptions& o) {
  if (int(m.vertebrae.size()) != kDbVertebrae)
    throw std::invalid_argument("displacement database: the model has " +
                                std::to_string(m.vertebrae.size()) + " vertebrae, expected 17");
  if (!(o.force_step_n > 0) || !(o.force_max_n >= o.force_step_n) || !std::isfinite(o.force_max_n))
    throw std::invalid_argument("displacement database: need 0 < force step <= force max");
  ResponseSamples s;
  s.solve = o.solve;
  s.loaded_vertebrae = o.loaded_vertebrae;
  if (s.loaded_vertebrae.empty())
    for (int v = 0; v < kDbVertebrae; ++v) s.loaded_vertebrae.push_back(v);
  for (int v : s.loaded_vertebrae)
    if (v < 0 || v >= kDbVertebrae)
      throw std::invalid_argument("displacement database: vertebra index out of range");
  const int steps = int(std::lround(o.force_max_n / o.force_step_n));
  for (int k = 0; k <= steps; ++k)
    s.forces_n.push_back(std::min(o.force_max_n, k * o.force_step_n));

  // Case 0 is the gravity-only baseline; then (vertebra, direction, force > 0).
  std::vector<std::vector<ExternalLoad>> loads = {{}};
  std::vector<std::tuple<int, int, int>> index = {{-1, -1, 0}};
  for (int v : s.loaded_vertebrae)
    for (int d = 0; d < kDbDirections; ++d)
      for (int k = 1; k <= steps; ++k) {
        loads.push_back({load_at_centre(v, s.forces_n[std::size_t(k)] * direction_vector(d))});
        index.emplace_back(v, d, k);
      }
  const Timer t0;
  std::vector<VertebraResponse> disp;
  std::vector<std::string> errors;
  solve_cases(m, loads, o.solve, o.workers, disp, errors, o.progress);
  s.seconds = t0.seconds();
  s.solves = int(loads.size());
  s.workers = o.workers > 0 ? std::min(o.workers, s.solves)
                            : int(std::max(1u, std::thread::hardware_concurrency()));
  if (!errors[0].empty())
    throw std::runtime_error("displacement database: the gravity-only baseline did not converge: " +
                             errors[0]);
  s.baseline = disp[0];

  s.responses.resize(kDbVertebrae);
  s.solved.resize(kDbVertebrae);
  for (int v : s.loaded_vertebrae)
    for (int d = 0; d < kDbDirections; ++d) {
      s.responses[std::size_t(v)][std::size_t(d)].assign(s.forces_n.size(),
                                                         VertebraResponse::Zero());
      s.solved[std::size_t(v)][std::size_t(d)].assign(s.forces_n.size(),
                                                      true);  // 0 N: the baseline
    }
  for (std::size_t i = 1; i < loads.size(); ++i) {
    const auto [v, d, k] = index[i];
    if (errors[i].empty()) {
      const VertebraResponse r = disp[i] - s.baseline;
      s.responses[std::size_t(v)][std::size_t(d)][std::size_t(k)] = r;
      if (d >= 2) {  // ±y, ±z: tx, ry, rz are zero at the symmetric equilibrium
        const double mm = r.col(0).cwiseAbs().maxCoeff(),
                     deg = r.rightCols<2>().rowwise().norm().maxCoeff();
        if (mm > 1e-3 || deg > 1e-3)
          s.out_of_plane.push_back({v, d, s.forces_n[std::size_t(k)], mm, deg});
      }
    } else {
      s.solved[std::size_t(v)][std::size_t(d)][std::size_t(k)] = false;
      s.failed.push_back({v, d, s.forces_n[std::size_t(k)], errors[i]});
    }
  }
  return s;
}

// --- the database ----------------------------------------------------------------------------

namespace {

/// Running sums of a ResidualSummary (RMS = sqrt of the mean over all samples).
struct ResidualSums {
  double sum2_t = 0, sum2_r = 0;
  long n_t = 0, n_r = 0;
  void add(ResidualSummary& s, int component, const PolynomialFit& f, int samples) {
    const bool translation = component < 3;
    double& mx = translation ? s.max_translation_mm : s.max_rotation_deg;
    mx = std::max(mx, f.max_residual);
    (translation ? sum2_t : sum2_r) += f.rms_residual * f.rms_residual * samples;
    (translation ? n_t : n_r) += samples;
    ++s.fits;
    if (!f.within_tolerance) ++s.fits_above_tolerance;
    ++s.degree_count[std::size_t(f.coefficients.size())];
  }
  void finish(ResidualSummary& s) const {
    s.rms_translation_mm = n_t ? std::sqrt(sum2_t / double(n_t)) : 0;
    s.rms_rotation_deg = n_r ? std::sqrt(sum2_r / double(n_r)) : 0;
  }
};

}  // namespace

void DisplacementDatabase::allocate() {
  coef_.assign(std::size_t(kDbVertebrae * kDbDirections * kDbMaxDegree * kSeries), 0.0);
  degree_.assign(std::size_t(kDbVertebrae * kDbDirections * kSeries), 0);
  present_.fill(false);
}

void DisplacementDatabase::set_fit(int v, int d, int series, const Eigen::VectorXd& c) {
  double* b = block(v, d);
  for (int k = 0; k < kDbMaxDegree; ++k) b[k * kSeries + series] = k < c.size() ? c[k] : 0.0;
  degree_[std::size_t((v * kDbDirections + d) * kSeries + series)] =
      static_cast<unsigned char>(c.size());
}

DisplacementDatabase DisplacementDatabase::fit(const ResponseSamples& s, const FitTolerance& tol) {
  DisplacementDatabase db;
  db.allocate();
  db.forces_n_ = s.forces_n;
  db.force_max_n_ = s.forces_n.empty() ? 0 : s.forces_n.back();
  db.baseline_ = s.baseline;
  db.info.tolerance = tol;
  db.info.solve = s.solve;
  db.info.failed = s.failed;
  db.info.out_of_plane = s.out_of_plane;
  db.info.generation_seconds = s.seconds;
  db.info.solves = s.solves;
  db.info.workers = s.workers;
  ResidualSums all;
  std::array<ResidualSums, kDbDirections> per_direction;
  for (int v : s.loaded_vertebrae) {
    db.present_[std::size_t(v)] = true;
    for (int d = 0; d < kDbDirections; ++d) {
      const auto& ok = s.solved[std::size_t(v)][std::size_t(d)];
      const auto& r = s.responses[std::size_t(v)][std::size_t(d)];
      std::vector<std::size_t> used;  // solved forces > 0 (0 N is zero by construction)
      for (std::size_t k = 1; k < s.forces_n.size(); ++k)
        if (ok[k]) used.push_back(k);
      if (used.size() < 3)
        throw std::runtime_error("displacement database: only " + std::to_string(used.size()) +
                                 " of " + std::to_string(s.forces_n.size() - 1) +
                                 " solves converged for " + vertebra_names()[std::size_t(v)] + " " +
                                 direction_names()[std::size_t(d)] + ": too few to fit");
      Eigen::VectorXd f(Eigen::Index(used.size())), y(Eigen::Index(used.size()));
      for (std::size_t i = 0; i < used.size(); ++i) f[Eigen::Index(i)] = s.forces_n[used[i]];
      db.solved_max_[std::size_t(v)][std::size_t(d)] = f.maxCoeff();
      for (int c = 0; c < kDbComponents; ++c)
        for (int j = 0; j < kDbVertebrae; ++j) {
          for (std::size_t i = 0; i < used.size(); ++i) y[Eigen::Index(i)] = r[used[i]](j, c);
          const PolynomialFit pf = fit_by_residual(f, y, db.force_max_n_, tol);
          db.set_fit(v, d, c * kDbVertebrae + j, pf.coefficients);
          all.add(db.info.residuals, c, pf, int(used.size()));
          per_direction[std::size_t(d)].add(db.info.residuals_per_direction[std::size_t(d)], c, pf,
                                            int(used.size()));
        }
      // Per (v, d), as max_response_difference() measures: |Δ translation| and |Δ rotation| per vertebra.
      for (std::size_t k : used) {
        VertebraResponse fitted;
        db.evaluate(v, s.forces_n[k] * direction_vector(d), fitted);
        const auto [mm, deg] = max_response_difference(fitted, r[k]);
        db.residual_t_[std::size_t(v)][std::size_t(d)] =
            std::max(db.residual_t_[std::size_t(v)][std::size_t(d)], mm);
        db.residual_r_[std::size_t(v)][std::size_t(d)] =
            std::max(db.residual_r_[std::size_t(v)][std::size_t(d)], deg);
      }
    }
  }
  all.finish(db.info.residuals);
  for (int d = 0; d < kDbDirections; ++d)
    per_direction[std::size_t(d)].finish(db.info.residuals_per_direction[std::size_t(d)]);
  return db;
}

void DisplacementDatabase::evaluate(int v, const Eigen::Vector3d& force_n,
                                    Eigen::Ref<VertebraResponse> out) const {
  if (!has_vertebra(v))
    throw std::invalid_argument(
        v < 0 || v >= kDbVertebrae
            ? "displacement database: vertebra index " + std::to_string(v) + " out of range 0..16"
            : "displacement database: no fits for vertebra " + vertebra_names()[std::size_t(v)]);
  if (!force_n.allFinite()) throw std::invalid_argument("displacement database: non-finite force");
  using Series = Eigen::Matrix<double, kSeries, 1>;
  Series sum = Series::Zero();
  for (int axis = 0; axis < 3; ++axis) {
    const double f = force_n[axis];
    if (f == 0) continue;
    const double s = std::abs(f) / force_max_n_;
    const double* c = block(v, 2 * axis + (f < 0 ? 1 : 0));
    // Horner on whole 102-vectors (zero-padded to degree 5): 5 fused multiply-adds per entry.
    Series p = Eigen::Map<const Series>(c + (kDbMaxDegree - 1) * kSeries);
    for (int k = kDbMaxDegree - 2; k >= 0; --k)
      p = p * s + Eigen::Map<const Series>(c + k * kSeries);
    sum += s * p;
  }
  out = Eigen::Map<const VertebraResponse>(sum.data());
}

bool DisplacementDatabase::in_range(const Eigen::Vector3d& force_n) const {
  return force_n.allFinite() && force_n.cwiseAbs().maxCoeff() <= force_max_n_;
}

bool DisplacementDatabase::in_range(int v, const Eigen::Vector3d& force_n) const {
  if (!has_vertebra(v) || !in_range(force_n)) return false;
  for (int axis = 0; axis < 3; ++axis) {
    const double f = force_n[axis];
    if (f != 0 &&
        std::abs(f) > solved_max_[std::size_t(v)][std::size_t(2 * axis + (f < 0 ? 1 : 0))])
      return false;
  }
  return true;
}

namespace {
void check_fit_index(int v, int d, int j, int c) {
  if (v < 0 || v >= kDbVertebrae || d < 0 || d >= kDbDirections || j < 0 || j >= kDbVertebrae ||
      c < 0 || c >= kDbComponents)
    throw std::invalid_argument("displacement database: fit index out of range");
}
}  // namespace

int DisplacementDatabase::degree(int v, int d, int j, int c) const {
  check_fit_index(v, d, j, c);
  return degree_.empty()
             ? 0
             : degree_[std::size_t((v * kDbDirections + d) * kSeries + c * kDbVertebrae + j)];
}

Eigen::VectorXd DisplacementDatabase::coefficients(int v, int d, int j, int c) const {
  const int n = degree(v, d, j, c);
  Eigen::VectorXd out(n);
  for (int k = 0; k < n; ++k) out[k] = block(v, d)[k * kSeries + c * kDbVertebrae + j];
  return out;
}

double DisplacementDatabase::max_residual_translation_mm(int v, int d) const {
  check_fit_index(v, d, 0, 0);
  return residual_t_[std::size_t(v)][std::size_t(d)];
}
double DisplacementDatabase::max_residual_rotation_deg(int v, int d) const {
  check_fit_index(v, d, 0, 0);
  return residual_r_[std::size_t(v)][std::size_t(d)];
}
double DisplacementDatabase::solved_max_n(int v, int d) const {
  check_fit_index(v, d, 0, 0);
  return solved_max_[std::size_t(v)][std::size_t(d)];
}

// --- file ------------------------------------------------------------------------------------

namespace {

json matrix_json(const VertebraResponse& r) {
  json a = json::array();
  for (int j = 0; j < kDbVertebrae; ++j) {
    json row = json::array();
    for (int c = 0; c < kDbComponents; ++c) row.push_back(r(j, c));
    a.push_back(row);
  }
  return a;
}

/// NaN/inf (a failed axis solve in the superposition check) as null.
json number_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json residuals_json(const ResidualSummary& s) {
  json degrees = json::object();
  for (int d = 1; d <= kDbMaxDegree; ++d)
    degrees[std::to_string(d)] = s.degree_count[std::size_t(d)];
  return {{"max_translation_mm", s.max_translation_mm},
          {"rms_translation_mm", s.rms_translation_mm},
          {"max_rotation_deg", s.max_rotation_deg},
          {"rms_rotation_deg", s.rms_rotation_deg},
          {"fits", s.fits},
          {"fits_above_tolerance", s.fits_above_tolerance},
          {"fits_per_degree", degrees}};
}

ResidualSummary residuals_from_json(const json& j) {
  ResidualSummary s;
  s.max_translation_mm = j.at("max_translation_mm").get<double>();
  s.rms_translation_mm = j.at("rms_translation_mm").get<double>();
  s.max_rotation_deg = j.at("max_rotation_deg").get<double>();
  s.rms_rotation_deg = j.at("rms_rotation_deg").get<double>();
  s.fits = j.at("fits").get<int>();
  s.fits_above_tolerance = j.at("fits_above_tolerance").get<int>();
  for (int d = 1; d <= kDbMaxDegree; ++d)
    s.degree_count[std::size_t(d)] = j.at("fits_per_degree").at(std::to_string(d)).get<int>();
  return s;
}

std::string vertebra_or_baseline(int v) {
  return v >= 0 ? vertebra_names()[std::size_t(v)] : "baseline";
}

json superposition_json(const SuperpositionReport& r) {
  json cases = json::array();
  for (const auto& c : r.cases)
    cases.push_back(
        {{"vertebra", vertebra_names()[std::size_t(c.vertebra)]},
         {"plane", c.plane},
         {"force_n", {c.force_n.x(), c.force_n.y(), c.force_n.z()}},
         {"solved", c.solved},
         {"extrapolated", c.extrapolated},
         {"message", c.message},
         {"response_translation_mm", c.response_translation_mm},
         {"response_rotation_deg", c.response_rotation_deg},
         {"db_error_translation_mm", number_or_null(c.db_error_translation_mm)},
         {"db_error_rotation_deg", number_or_null(c.db_error_rotation_deg)},
         {"axis_sum_error_translation_mm", number_or_null(c.axis_sum_error_translation_mm)},
         {"axis_sum_error_rotation_deg", number_or_null(c.axis_sum_error_rotation_deg)}});
  return {{"what",
           "oblique force F on a vertebra: the database's superposition of its axis fits (db) and "
           "the sum of "
           "direct solves at each axis component (axis_sum), both against a direct solve of F; "
           "errors are the "
           "max over the 17 vertebrae of |Δ translation| (mm) and |Δ rotation vector| (deg); "
           "relative = error / "
           "the max over the vertebrae of the direct response's |translation| (|rotation|); "
           "extrapolated: the force "
           "needs an axis fit beyond its largest solved force, so its db error is left out of the "
           "maxima"},
          {"max_db_translation_mm", r.max_db_translation_mm},
          {"max_db_rotation_deg", r.max_db_rotation_deg},
          {"max_db_translation_relative", r.max_db_translation_relative},
          {"max_db_rotation_relative", r.max_db_rotation_relative},
          {"max_axis_sum_translation_mm", r.max_axis_sum_translation_mm},
          {"max_axis_sum_rotation_deg", r.max_axis_sum_rotation_deg},
          {"max_axis_sum_translation_relative", r.max_axis_sum_translation_relative},
          {"max_axis_sum_rotation_relative", r.max_axis_sum_rotation_relative},
          {"seconds", r.seconds},
          {"cases", cases}};
}

double finite_or_nan(const json& j) { return j.is_number() ? j.get<double>() : std::nan(""); }

SuperpositionReport superposition_from_json(const json& j) {
  SuperpositionReport r;
  r.max_db_translation_mm = j.at("max_db_translation_mm").get<double>();
  r.max_db_rotation_deg = j.at("max_db_rotation_deg").get<double>();
  r.max_db_translation_relative = j.at("max_db_translation_relative").get<double>();
  r.max_db_rotation_relative = j.at("max_db_rotation_relative").get<double>();
  r.max_axis_sum_translation_mm = j.at("max_axis_sum_translation_mm").get<double>();
  r.max_axis_sum_rotation_deg = j.at("max_axis_sum_rotation_deg").get<double>();
  r.max_axis_sum_translation_relative = j.at("max_axis_sum_translation_relative").get<double>();
  r.max_axis_sum_rotation_relative = j.at("max_axis_sum_rotation_relative").get<double>();
  r.seconds = j.at("seconds").get<double>();
  for (const auto& c : j.at("cases")) {
    SuperpositionCase s;
    s.vertebra = vertebra_index(c.at("vertebra").get<std::string>());
    s.plane = c.at("plane").get<std::string>();
    const auto& f = c.at("force_n");
    s.force_n =
        Eigen::Vector3d(f.at(0).get<double>(), f.at(1).get<double>(), f.at(2).get<double>());
    s.solved = c.at("solved").get<bool>();
    s.extrapolated = c.at("extrapolated").get<bool>();
    s.message = c.at("message").get<std::string>();
    s.response_translation_mm = c.at("response_translation_mm").get<double>();
    s.response_rotation_deg = c.at("response_rotation_deg").get<double>();
    s.db_error_translation_mm = finite_or_nan(c.at("db_error_translation_mm"));
    s.db_error_rotation_deg = finite_or_nan(c.at("db_error_rotation_deg"));
    s.axis_sum_error_translation_mm = finite_or_nan(c.at("axis_sum_error_translation_mm"));
    s.axis_sum_error_rotation_deg = finite_or_nan(c.at("axis_sum_error_rotation_deg"));
    r.cases.push_back(s);
  }
  return r;
}

json model_json(const DatabaseInfo& i) {
  json fused = json::array();
  for (int j : i.model.fused_joints) fused.push_back(joint_names().at(std::size_t(j)));
  return {
      {"fused_joints", fused},
      {"ligaments", has_ligaments(i.model)},
      {"rib_cage", i.model.rib_cage},
      {"muscles", i.model.muscles},
      {"iap", i.model.iap},
      {"gravity", i.model.gravity},
      {"arms_forward", i.model.arms_forward},
      {"body_mass_kg", i.model.subject.body_mass_kg},
      {"height_m", i.model.subject.height_m},
      {"sex", sex_name(i.model.subject.sex)},
      {"recruit", i.solve.recruit},
      {"criterion", i.solve.recruitment.criterion == Criterion::MinMax ? "min-max" : "polynomial"},
      {"criterion_power", i.solve.recruitment.power},
      {"solve_tolerance_nmm", i.solve.tolerance}};
}

void model_from_json(const json& j, DatabaseInfo& i) {
  i.model.fused_joints.clear();
  for (const auto& n : j.at("fused_joints"))
    i.model.fused_joints.push_back(joint_index(n.get<std::string>()));
  i.model.ligaments = j.at("ligaments").get<bool>() ? Ligaments::On : Ligaments::Off;
  i.model.rib_cage = j.value("rib_cage", false);  // files written before the rib cage have none
  i.model.muscles = j.at("muscles").get<bool>();
  i.model.iap = j.at("iap").get<bool>();
  i.model.gravity = j.at("gravity").get<bool>();
  i.model.arms_forward = j.at("arms_forward").get<bool>();
  i.model.subject.body_mass_kg = j.at("body_mass_kg").get<double>();
  // Files written before subjects existed are the reference body's.
  i.model.subject.height_m = j.value("height_m", 0.0);
  i.model.subject.sex = parse_sex(j.value("sex", std::string("male")));
  i.solve = SolveOptions();
  i.solve.recruit = j.at("recruit").get<bool>();
  const std::string criterion = j.at("criterion").get<std::string>();
  if (criterion != "polynomial" && criterion != "min-max")
    throw std::runtime_error("unknown criterion " + criterion);
  i.solve.recruitment.criterion =
      criterion == "min-max" ? Criterion::MinMax : Criterion::Polynomial;
  i.solve.recruitment.power = j.at("criterion_power").get<double>();
  i.solve.tolerance = j.at("solve_tolerance_nmm").get<double>();
}

/// A finite number from j; throws (caught by load and reported with the path).
double finite(const json& j) {
  const double x = j.get<double>();
  if (!std::isfinite(x)) throw std::runtime_error("non-finite number");
  return x;
}

}  // namespace

void DisplacementDatabase::save(const std::string& path) const {
  if (coef_.empty())
    throw std::runtime_error("displacement database: nothing to save (not fitted or loaded)");
  json head = json::object();  // small metadata first, pretty; then one line per fit
  head["kind"] = kKind;
  head["format_version"] = kFormatVersion;
  head["generated_by"] = info.generated_by;
  head["source"] = info.source;
  head["units"] =
      "force N; translation mm (F.1 centre); rotation deg (rotation vector, world axes); "
      "frame x lateral (body's right = -x), y superior, z anterior";
  head["response"] =
      "displacement(force on the vertebra's F.1 centre, with gravity) - displacement(gravity "
      "only), "
      "componentwise; the gravity-only displacement is 'baseline'";
  head["basis"] =
      "value(f) = sum_{k=1..degree} c[k-1] * s^k, s = f / force_max_n (no constant term)";
  head["fit_fields"] =
      "per loaded vertebra and direction: solved_max_n (largest force solved), max_residual_mm / "
      "max_residual_deg (worst |fit - sample| of a vertebra's translation / rotation vector over "
      "the "
      "solved forces and the 17 vertebrae), c[responding vertebra][component] = c_1..c_degree";
  head["model"] = model_json(info);
  head["force_max_n"] = force_max_n_;
  head["forces_n"] = forces_n_;
  head["vertebrae"] = vertebra_names();
  head["directions"] = direction_names();
  head["components"] = kComponentNames;
  head["fit_tolerance"] = {
      {"relative", info.tolerance.relative},
      {"absolute", info.tolerance.absolute},
      {"max_degree", info.tolerance.max_degree},
      {"quantum", info.tolerance.quantum},
      {"rule", "lowest degree whose RMS residual <= max(relative * range, absolute)"}};
  head["residuals"] = residuals_json(info.residuals);
  json per_direction = json::object();
  for (int d = 0; d < kDbDirections; ++d)
    per_direction[direction_names()[std::size_t(d)]] =
        residuals_json(info.residuals_per_direction[std::size_t(d)]);
  head["residuals_per_direction"] = per_direction;
  json failed = json::array();
  for (const auto& f : info.failed)
    failed.push_back(
        {{"vertebra", vertebra_or_baseline(f.vertebra)},
         {"direction", f.direction >= 0 ? direction_names()[std::size_t(f.direction)] : ""},
         {"force_n", f.force_n},
         {"message", f.message}});
  head["failed_solves"] = failed;
  json out_of_plane = json::array();
  for (const auto& o : info.out_of_plane)
    out_of_plane.push_back({{"vertebra", vertebra_names()[std::size_t(o.vertebra)]},
                            {"direction", direction_names()[std::size_t(o.direction)]},
                            {"force_n", o.force_n},
                            {"lateral_mm", o.lateral_mm},
                            {"lateral_deg", o.lateral_deg}});
  head["out_of_plane_solves"] = {{"what",
                                  "sagittal-plane forces (+-y, +-z) whose solution left the "
                                  "sagittal plane (max |tx| > 0.001 mm or "
                                  "|(ry, rz)| > 0.001 deg over the vertebrae): the model is "
                                  "symmetric about x = 0, so these solves found "
                                  "a non-symmetric equilibrium; they are kept in the fits"},
                                 {"solves", out_of_plane}};
  head["superposition_check"] =
      info.has_superposition ? superposition_json(info.superposition) : json(nullptr);
  head["generation"] = {
      {"seconds", info.generation_seconds}, {"solves", info.solves}, {"workers", info.workers}};
  head["baseline"] = matrix_json(baseline_);

  std::ostringstream text;
  const std::string h = head.dump(1);
  text << h.substr(0, h.size() - 2)
       << ",\n \"fits\": [\n";  // reopen the object before its closing "\n}"
  bool first = true;
  for (int v = 0; v < kDbVertebrae; ++v) {
    if (!present_[std::size_t(v)]) continue;
    for (int d = 0; d < kDbDirections; ++d) {
      json c = json::array();  // [responding vertebra][component] -> c_1..c_degree
      for (int j = 0; j < kDbVertebrae; ++j) {
        json row = json::array();
        for (int k = 0; k < kDbComponents; ++k) {
          const Eigen::VectorXd cs = coefficients(v, d, j, k);
          row.push_back(std::vector<double>(cs.data(), cs.data() + cs.size()));
        }
        c.push_back(row);
      }
      const json fit = {{"vertebra", vertebra_names()[std::size_t(v)]},
                        {"direction", direction_names()[std::size_t(d)]},
                        {"solved_max_n", solved_max_[std::size_t(v)][std::size_t(d)]},
                        {"max_residual_mm", residual_t_[std::size_t(v)][std::size_t(d)]},
                        {"max_residual_deg", residual_r_[std::size_t(v)][std::size_t(d)]},
                        {"c", c}};
      text << (first ? "  " : ",\n  ") << fit.dump();
      first = false;
    }
  }
  text << "\n ]\n}\n";

  write_text_atomically(path, text.str());  // a failure never leaves a half file
}

DisplacementDatabase DisplacementDatabase::load(const std::string& path) {
  json j;
  try {
    j = read_json_file(path, "displacement database");
  } catch (const std::invalid_argument& e) {  // load's contract: std::runtime_error
    throw std::runtime_error(e.what());
  }
  DisplacementDatabase db;
  try {
    if (!j.is_object() || j.value("kind", "") != kKind)
      throw std::runtime_error(std::string("not a displacement database (\"kind\" is not \"") +
                               kKind + "\")");
    if (j.at("format_version").get<int>() != kFormatVersion)
      throw std::runtime_error("format_version " + j.at("format_version").dump() + ", expected " +
                               std::to_string(kFormatVersion));
    db.allocate();
    db.info.generated_by = j.at("generated_by").get<std::string>();
    db.info.source = j.at("source").get<std::string>();
    model_from_json(j.at("model"), db.info);
    db.force_max_n_ = finite(j.at("force_max_n"));
    if (!(db.force_max_n_ > 0)) throw std::runtime_error("force_max_n must be > 0");
    for (const auto& f : j.at("forces_n")) db.forces_n_.push_back(finite(f));
    const auto& tol = j.at("fit_tolerance");
    db.info.tolerance = {finite(tol.at("relative")), finite(tol.at("absolute")),
                         tol.at("max_degree").get<int>(), finite(tol.at("quantum"))};
    db.info.residuals = residuals_from_json(j.at("residuals"));
    for (int d = 0; d < kDbDirections; ++d)
      db.info.residuals_per_direction[std::size_t(d)] = residuals_from_json(
          j.at("residuals_per_direction").at(direction_names()[std::size_t(d)]));
    for (const auto& f : j.at("failed_solves")) {
      const std::string v = f.at("vertebra").get<std::string>(),
                        d = f.at("direction").get<std::string>();
      db.info.failed.push_back({v == "baseline" ? -1 : vertebra_index(v),
                                d.empty() ? -1 : direction_index(d), f.at("force_n").get<double>(),
                                f.at("message").get<std::string>()});
    }
    for (const auto& o : j.at("out_of_plane_solves").at("solves"))
      db.info.out_of_plane.push_back({vertebra_index(o.at("vertebra").get<std::string>()),
                                      direction_index(o.at("direction").get<std::string>()),
                                      finite(o.at("force_n")), finite(o.at("lateral_mm")),
                                      finite(o.at("lateral_deg"))});
    if (!j.at("superposition_check").is_null()) {
      db.info.has_superposition = true;
      db.info.superposition = superposition_from_json(j.at("superposition_check"));
    }
    const auto& g = j.at("generation");
    db.info.generation_seconds = g.at("seconds").get<double>();
    db.info.solves = g.at("solves").get<int>();
    db.info.workers = g.at("workers").get<int>();
    const auto& b = j.at("baseline");
    if (b.size() != kDbVertebrae) throw std::runtime_error("baseline must have 17 rows");
    for (int r = 0; r < kDbVertebrae; ++r) {
      if (b.at(std::size_t(r)).size() != kDbComponents)
        throw std::runtime_error("baseline rows must have 6 values");
      for (int c = 0; c < kDbComponents; ++c)
        db.baseline_(r, c) = finite(b.at(std::size_t(r)).at(std::size_t(c)));
    }
    for (const auto& fit : j.at("fits")) {
      const int v = vertebra_index(fit.at("vertebra").get<std::string>());
      const int d = direction_index(fit.at("direction").get<std::string>());
      db.present_[std::size_t(v)] = true;
      db.solved_max_[std::size_t(v)][std::size_t(d)] = finite(fit.at("solved_max_n"));
      db.residual_t_[std::size_t(v)][std::size_t(d)] = finite(fit.at("max_residual_mm"));
      db.residual_r_[std::size_t(v)][std::size_t(d)] = finite(fit.at("max_residual_deg"));
      const auto& c = fit.at("c");
      if (c.size() != kDbVertebrae)
        throw std::runtime_error("a fit must have 17 responding vertebrae");
      for (int r = 0; r < kDbVertebrae; ++r) {
        if (c.at(std::size_t(r)).size() != kDbComponents)
          throw std::runtime_error("a fit row must have 6 components");
        for (int k = 0; k < kDbComponents; ++k) {
          const auto& cs = c.at(std::size_t(r)).at(std::size_t(k));
          if (!cs.is_array() || cs.empty() || cs.size() > std::size_t(kDbMaxDegree))
            throw std::runtime_error("a fit needs 1.." + std::to_string(kDbMaxDegree) +
                                     " coefficients");
          Eigen::VectorXd coeff(Eigen::Index(cs.size()));
          for (std::size_t i = 0; i < cs.size(); ++i) coeff[Eigen::Index(i)] = finite(cs.at(i));
          db.set_fit(v, d, k * kDbVertebrae + r, coeff);
        }
      }
    }
    // An empty database answers every force with the baseline: a check of it checks nothing.
    if (std::none_of(db.present_.begin(), db.present_.end(), [](bool p) { return p; }))
      throw std::runtime_error("\"fits\" is empty: the database holds no vertebra's response");
    // Every present vertebra needs all six directions, or evaluate() would silently add zeros.
    for (int v = 0; v < kDbVertebrae; ++v)
      for (int d = 0; d < kDbDirections; ++d)
        if (db.present_[std::size_t(v)] &&
            db.degree_[std::size_t((v * kDbDirections + d) * kSeries)] == 0)
          throw std::runtime_error("no fit for " + vertebra_names()[std::size_t(v)] + " " +
                                   direction_names()[std::size_t(d)]);
  } catch (const std::exception& e) {
    throw std::runtime_error("malformed displacement database " + path + ": " + e.what());
  }
  return db;
}

// --- superposition check ---------------------------------------------------------------------

std::string superposition_json_text(const SuperpositionReport& report) {
  return superposition_json(report).dump();
}

std::pair<double, double> max_response_difference(const VertebraResponse& a,
                                                  const VertebraResponse& b) {
  const VertebraResponse d = a - b;
  return {d.leftCols<3>().rowwise().norm().maxCoeff(),
          d.rightCols<3>().rowwise().norm().maxCoeff()};
}

std::vector<SuperpositionCase> superposition_cases(const std::vector<int>& vertebrae,
                                                   const std::vector<double>& magnitudes_n) {
  const std::vector<std::pair<std::string, Eigen::Vector3d>> directions = {
      {"xz", Eigen::Vector3d(1, 0, 1)},
      {"xy", Eigen::Vector3d(1, 1, 0)},
      {"yz", Eigen::Vector3d(0, 1, 1)},
      {"xyz", Eigen::Vector3d(1, 1, 1)},
      {"-x-y-z", Eigen::Vector3d(-1, -1, -1)}};
  std::vector<SuperpositionCase> cases;
  for (int v : vertebrae)
    for (const auto& [plane, dir] : directions)
      for (double f : magnitudes_n) {
        SuperpositionCase c;
        c.vertebra = v;
        c.plane = plane;
        c.force_n = f * dir.normalized();
        cases.push_back(c);
      }
  return cases;
}

SuperpositionReport check_superposition(const SpineModel& m, const DisplacementDatabase& db,
                                        std::vector<SuperpositionCase> cases,
                                        const SolveOptions& options, int workers,
                                        const std::function<void(int, int)>& progress) {
  const Timer t0;
  // Unique load cases: the baseline, each oblique force, each of its axis components.
  std::vector<std::vector<ExternalLoad>> loads = {{}};
  std::map<std::tuple<int, double, double, double>, std::size_t> known;
  auto case_of = [&](int v, const Eigen::Vector3d& f) {
    const auto key = std::make_tuple(v, f.x(), f.y(), f.z());
    const auto it = known.find(key);
    if (it != known.end()) return it->second;
    loads.push_back({load_at_centre(v, f)});
    return known[key] = loads.size() - 1;
  };
  std::vector<std::size_t> direct(cases.size());
  std::vector<std::array<std::size_t, 3>> axis(cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    if (!db.has_vertebra(cases[i].vertebra))
      throw std::invalid_argument("superposition check: no fits for vertebra " +
                                  vertebra_names().at(std::size_t(cases[i].vertebra)));
    direct[i] = case_of(cases[i].vertebra, cases[i].force_n);
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d f = Eigen::Vector3d::Zero();
      f[a] = cases[i].force_n[a];
      axis[i][std::size_t(a)] = f[a] == 0 ? 0 : case_of(cases[i].vertebra, f);  // 0: none
    }
  }
  std::vector<VertebraResponse> disp;
  std::vector<std::string> errors;
  solve_cases(m, loads, options, workers, disp, errors, progress);
  if (!errors[0].empty())
    throw std::runtime_error("superposition check: the gravity-only solve failed: " + errors[0]);

  SuperpositionReport r;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SuperpositionCase& c = cases[i];
    c.solved = errors[direct[i]].empty();
    if (!c.solved) {
      c.message = "direct solve failed: " + errors[direct[i]];
      c.db_error_translation_mm = c.db_error_rotation_deg = std::nan("");
      c.axis_sum_error_translation_mm = c.axis_sum_error_rotation_deg = std::nan("");
      continue;
    }
    c.extrapolated = !db.in_range(c.vertebra, c.force_n);
    const VertebraResponse reference = disp[direct[i]] - disp[0];
    VertebraResponse from_db;
    db.evaluate(c.vertebra, c.force_n, from_db);
    std::tie(c.db_error_translation_mm, c.db_error_rotation_deg) =
        max_response_difference(from_db, reference);
    std::tie(c.response_translation_mm, c.response_rotation_deg) =
        max_response_difference(reference, VertebraResponse::Zero());
    VertebraResponse sum = VertebraResponse::Zero();
    for (std::size_t a : axis[i]) {
      if (a == 0) continue;
      if (!errors[a].empty()) c.message = "axis solve failed: " + errors[a];
      sum += disp[a] - disp[0];
    }
    if (c.message.empty())
      std::tie(c.axis_sum_error_translation_mm, c.axis_sum_error_rotation_deg) =
          max_response_difference(sum, reference);
    else
      c.axis_sum_error_translation_mm = c.axis_sum_error_rotation_deg = std::nan("");
    auto worst = [](double& w, double x) {
      if (std::isfinite(x)) w = std::max(w, x);
    };
    auto rel = [](double e, double scale) { return scale > 0 ? e / scale : 0.0; };
    if (!c.extrapolated) {
      worst(r.max_db_translation_mm, c.db_error_translation_mm);
      worst(r.max_db_rotation_deg, c.db_error_rotation_deg);
      worst(r.max_db_translation_relative,
            rel(c.db_error_translation_mm, c.response_translation_mm));
      worst(r.max_db_rotation_relative, rel(c.db_error_rotation_deg, c.response_rotation_deg));
    }
    worst(r.max_axis_sum_translation_mm, c.axis_sum_error_translation_mm);
    worst(r.max_axis_sum_rotation_deg, c.axis_sum_error_rotation_deg);
    worst(r.max_axis_sum_translation_relative,
          rel(c.axis_sum_error_translation_mm, c.response_translation_mm));
    worst(r.max_axis_sum_rotation_relative,
          rel(c.axis_sum_error_rotation_deg, c.response_rotation_deg));
  }
  r.cases = std::move(cases);
  r.seconds = t0.seconds();
  return r;
}

}  // namespace spinesim::spine
