// The thesis's displacement-force database (3.5) as a study driver (`spinesim spine database`):
// the spine solved under 0…600 N in 50 N steps on each vertebra T1…L5 along ±x, ±y, ±z, every
// vertebra's 6-DOF response fitted by least-squares polynomials (spine/database.hpp), and the
// thesis's superposition assumption (an oblique force's response is the sum of its axis
// responses) measured against direct solves; and the check of an existing file against direct
// solves of the model it names.
#pragma once

#include "spinesim/spine/database.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

/// A displacement database the user gives (`--check --out`, `haptics run --database`): the file
/// is input, so a malformed one — or one with no fits, which would answer every force with the
/// baseline — is refused with std::invalid_argument (one line), not reported as a failed run.
spine::DisplacementDatabase read_database(const std::string& path);

/// The `source` recorded in a generated file: the model, the solver and the protocol.
extern const char* const kDatabaseSource;

/// (done, total) solves, for a progress bar.
using SolveProgress = std::function<void(int done, int total)>;

struct DatabaseRequest {
  spine::ModelOptions model;          ///< e.g. fused joints
  spine::SolveOptions solve;          ///< recruitment on or off
  std::vector<int> loaded_vertebrae;  ///< empty: every vertebra T1…L5
  int workers = 0;                    ///< solver threads; 0: one per core
  std::vector<int> superposition_on;  ///< vertebrae of the oblique forces (those in the file)
  std::vector<double> magnitudes_n;   ///< oblique force magnitudes, N (> 0)
  std::string generated_by;           ///< recorded in the file
};

struct DatabaseBuild {
  spine::DisplacementDatabase db;  ///< fits, info (residuals, superposition check), baseline
  spine::ResponseSamples samples;  ///< solves, workers, seconds, failed and out-of-plane solves
  int loaded_vertebrae = 0;
};

/// The oblique cases on the vertebrae of `on` that the file has (none of them: its first).
std::vector<spine::SuperpositionCase> oblique_cases(const std::vector<int>& on,
                                                    const std::vector<double>& magnitudes_n,
                                                    const spine::DisplacementDatabase& db);

/// Loads the model, solves every (vertebra, direction, force) and the baseline, fits, and checks
/// the oblique forces. Stages: model, solves, superposition (3); `solves` counts solves.
DatabaseBuild generate_database(const std::string& data_dir, const DatabaseRequest& request,
                                const StageHooks& hooks = StageHooks(),
                                const SolveProgress& solves = SolveProgress());

/// The build's readable report: solves, fit residuals, failed and out-of-plane solves,
/// superposition.
void print_database_build(std::ostream& os, const DatabaseBuild& b);

/// Grid forces re-solved: vertebrae of the superposition check, every direction, 300 and 600 N.
struct GridRow {
  int vertebra = 0, direction = 0;
  double force_n = 0, error_mm = 0, error_deg = 0, allowed_mm = 0, allowed_deg = 0;
  std::string message;
  bool ok() const { return message.empty() && error_mm <= allowed_mm && error_deg <= allowed_deg; }
};

struct DatabaseCheck {
  std::string path, generated_by;
  double baseline_mm = 0, baseline_deg = 0;  ///< gravity-only solve vs the file's baseline
  std::vector<GridRow> grid;
  spine::SuperpositionReport superposition;
  /// The solver stops at a gradient tolerance and the coefficients are rounded: a grid response
  /// may differ from the file by its largest fit residual plus this margin (mm, deg).
  double margin = 1e-3;
  bool ok = false;
};

/// Loads the file at `path` and its model, re-solves the grid forces (the vertebrae of the
/// oblique cases, every direction, half and full force) and the oblique cases. Stages: load,
/// grid, superposition (3). Throws std::runtime_error when the gravity-only solve fails.
DatabaseCheck check_database(const std::string& data_dir, const std::string& path,
                             const std::vector<int>& superposition_on,
                             const std::vector<double>& magnitudes_n, int workers,
                             const StageHooks& hooks = StageHooks(),
                             const SolveProgress& solves = SolveProgress());

nlohmann::json database_check_json(const DatabaseCheck& c);
void print_database_check(std::ostream& os, const DatabaseCheck& c);

// The report's pieces (also for other front ends).
void print_residuals(const spine::DatabaseInfo& info, std::ostream& os);
void print_failed(const std::vector<spine::FailedSolve>& failed, std::ostream& os);
void print_out_of_plane(const std::vector<spine::OutOfPlaneSolve>& solves, std::ostream& os);
void print_superposition(const spine::SuperpositionReport& r, std::ostream& os);

}  // namespace spinesim::studies
