// The disc material identified from in-vitro tests (`spinesim study disc-identify`).
//
// Ipopt (calibration/window_fit.hpp) moves four parameters of the nonlinear disc — the annulus
// matrix's Young's modulus, a scale on the fibre moduli, the fibres' toe exponent k2 and the
// nucleus's Young's modulus — inside their published ranges until the disc's six in-vitro
// quantities (disc_validation.hpp: compression, torsion, flexion, extension, lateral bending
// stiffness, nucleus pressure ratio) sit as near the centres of their windows as they can.
//
// Each fit evaluates the disc some hundred times, so it runs on a coarse disc (P1 tetrahedra,
// nodal-average volume) corrected toward a fine one (P2, mean dilatation) by output space
// mapping (Bandler et al. 2004; Koziel et al. 2006): the fine/coarse ratio of every quantity,
// taken where the last fit ended, multiplies the coarse model in the next fit, until the ratios
// settle. Every number the study reports as the disc's is the fine disc's.
//
// Beside the fit: the leave-one-out table (each quantity predicted by the fit to the other five,
// on the fine disc) and a held-out data set of other laboratories' tests, reported hit or miss.
#pragma once

#include "spinesim/calibration/window_fit.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/studies/disc_validation.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <limits>
#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

/// One identified parameter with where its bounds come from.
struct DiscParameter {
  calibration::FitParameter fit;  ///< name, units, start (the preset's), bounds
  std::string source;             ///< the bounds' sources
};

/// The four parameters of `base` (an annulus with fibres and a nucleus); throws
/// std::invalid_argument for a material without them.
std::vector<DiscParameter> disc_parameters(const mesh::RegionMaterials& base);

/// `base` with parameters p (disc_parameters order) applied; named `name`.
mesh::RegionMaterials disc_material_at(const mesh::RegionMaterials& base, const Eigen::VectorXd& p,
                                       const std::string& name);

struct DiscIdentificationOptions {
  int coarse_order = 1, fine_order = 2;  ///< nonlinear disc orders (NonlinearDiscOptions)
  int load_increments = 4;               ///< per load case (the secant stiffness needs few)
  int max_mapping_rounds = 4;
  double mapping_tolerance = 0.01;  ///< stop when no fine/coarse ratio moves more than this
  int threads = 2;                  ///< disc solves side by side
  bool leave_one_out = true;        ///< the six fits without one quantity each
  /// Ipopt: the gradient comes from forward differences of converged Newton solves (relative
  /// noise ~1e-7), so the tolerance is looser than the calibration's, and a fit stops early.
  calibration::IpoptSettings ipopt = identification_ipopt();

  static calibration::IpoptSettings identification_ipopt() {
    calibration::IpoptSettings s;
    s.tolerance = 1e-6;
    s.acceptable_tolerance = 1e-4;
    s.max_iterations = 40;
    return s;
  }
};

/// Throws std::invalid_argument (one line) for options out of range.
void validate(const DiscIdentificationOptions& options);

/// One quantity against one window (a fit target or a held-out row): `ours` is the identified
/// fine disc's value (NaN where it did not converge), `match()` says whether it is inside.
struct IdentifiedRow : DiscValidationRow {
  double preset = std::numeric_limits<double>::quiet_NaN();  ///< the fine disc with the preset
  /// The fine disc at the fit without this row (fit rows only).
  double loo_prediction = std::numeric_limits<double>::quiet_NaN();
};

struct MappingRound {
  Eigen::VectorXd parameters, coarse, fine, ratio;  ///< ratio = fine / coarse
  int ipopt_iterations = 0;
  std::string ipopt_status;
};

struct DiscIdentificationResult {
  std::string material_name, coarse_label, fine_label;
  std::vector<DiscParameter> parameters;
  Eigen::VectorXd identified;  ///< p
  std::vector<std::string> active_bounds;
  std::vector<IdentifiedRow> fit_rows, held_out_rows;
  std::vector<Eigen::VectorXd> loo_parameters;  ///< per fit row (none with a single row)
  std::vector<MappingRound> rounds;
  bool success = false;  ///< every fit solved and the ratios settled
  std::string status;
  int coarse_evaluations = 0, fine_evaluations = 0;
  double seconds = 0, coarse_seconds_each = 0, fine_seconds_each = 0;
};

/// Identifies the disc material on `coarse` corrected by `fine` (both the same disc). `targets`
/// and `held_out` as read_disc_targets; the held-out rows may be empty. Throws
/// std::invalid_argument for bad options or a targets file without a quantity the disc gives.
DiscIdentificationResult identify_disc_material(
    const mesh::TetMesh& coarse, const mesh::TetMesh& fine, const mesh::RegionMaterials& base,
    const nlohmann::json& targets, const nlohmann::json& held_out,
    const DiscIdentificationOptions& options, const std::string& coarse_label,
    const std::string& fine_label, const StageHooks& hooks = StageHooks());

/// The identified material as a preset file (data/materials format), with its sources.
nlohmann::json identified_material_json(const DiscIdentificationResult& r,
                                        const mesh::RegionMaterials& base);

nlohmann::json disc_identification_json(const DiscIdentificationResult& r);
void print_disc_identification(std::ostream& os, const DiscIdentificationResult& r,
                               bool markdown = false);

}  // namespace spinesim::studies
