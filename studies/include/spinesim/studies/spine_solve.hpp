// One spine equilibrium as the program reports it (`spinesim spine solve`): the model from
// data/, spine::solve_spine under the loads, and the result as JSON, CSV or readable tables
// (vertebra motion, joint reactions, the strongest muscles and ligaments, the IAP bushing).
//
// Units: mm, N, N·mm (N·m in the readable tables), degrees. Frame: x lateral (the body's right
// is −x), y superior, z anterior.
#pragma once

#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

/// The thesis validated its spine for forces up to 600 N (thesis 3.5: 0 … 600 N in 50 N steps).
inline constexpr double kValidatedForceN = 600.0;

struct SpineSolveRequest {
  std::vector<spine::ExternalLoad> loads;
  spine::ModelOptions model;
  spine::SolveOptions solve;
};

struct SpineSolveRun {
  SpineSolveRequest request;
  spine::SpineModel model;
  spine::SpineSolution solution;
  double model_seconds = 0, total_seconds = 0;
};

/// Loads the model and solves. Throws std::runtime_error "the spine did not reach equilibrium: …"
/// (one line) when Newton fails; the solution's own warnings are in solution.warnings.
SpineSolveRun run_spine_solve(const std::string& data_dir, const SpineSolveRequest& request);

/// Everything as one object: loads, options, convergence, stability, vertebrae, joints, muscles,
/// ligaments, bushing, recruitment, warnings, timings, units; `csv` is the CSV path or empty.
nlohmann::json spine_solve_json(const SpineSolveRun& run, const std::string& csv);

/// One row per vertebra and the joint below it.
std::string spine_solve_csv(const spine::SpineSolution& s);

/// A resolved subject (spine::resolve_subject) as JSON: height_m, body_mass_kg, sex.
nlohmann::json subject_json(const spine::Subject& subject);

/// The model's scoliotic curve and its measured rest posture (Cobb angle, apex offset, T1's
/// balance, the largest disc closure); null for a straight spine.
nlohmann::json scoliosis_json(const spine::SpineModel& model);
/// A curve's parameters alone (null for a straight spine).
nlohmann::json scoliosis_curve_json(const spine::ScoliosisCurve& curve);
/// "female, 1.600 m, 55.0 kg" for the tables' headers.
std::string subject_text(const spine::Subject& subject);

/// Readable tables; `top` muscles and ligaments are listed, `csv` is named at the end if given.
void print_spine_solve(std::ostream& os, const SpineSolveRun& run, int top, const std::string& csv);

}  // namespace spinesim::studies
