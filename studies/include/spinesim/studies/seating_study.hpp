// The seating studies (`spinesim study seating | seating-sweep | seating-validation`; thesis 6.2;
// docs/seating.md): the spine seated in a chair (spine/seating.hpp) reported as the thesis's
// figures 6.7 (contact force between torso and chair) and 6.8 (L5-S1 force and moment), with
// the load on every disc, the muscles and the vertebrae's angles; a sweep of one chair parameter;
// and the standing and seated spine beside in-vivo disc loads (data/validation/sitting_in_vivo.json).
//
// Frames: forces on the body in the chair's frame (x lateral, y up, z forward); joint reactions
// in the lower vertebra's axes (the thesis's joint frame); units N, N·m, mm, degrees.
#pragma once

#include "spinesim/spine/seating.hpp"
#include "spinesim/studies/spine_studies.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

struct SeatingRequest {
  spine::Chair chair;
  std::optional<double> pelvic_tilt_deg;  ///< the sitter's, in place of data/spine/seating.json's
  spine::ModelOptions model;
};

struct SeatingRun {
  SeatingRequest request;
  spine::SpineModel model;  ///< seated (contacts, rotated gravity)
  spine::Sitter sitter;
  spine::SeatedSolution seated;
  double back_muscle_force_n = 0;  ///< Σ tension of multifidus, erector spinae, quadratus lumborum
  double back_muscle_max_activation = 0;
  double seconds = 0;
};

/// Reads a chair surface (STL or OBJ, mm, the chair's frame) for Chair::surface: the backrest as
/// a triangle soup with its signed distance (CGAL AABB tree). Throws std::invalid_argument (one
/// line) for a missing, empty, non-finite or unreadable file.
std::shared_ptr<const spine::ContactSurface> read_chair_surface(const std::string& path);

/// Throws std::invalid_argument for a bad chair or tilt, std::runtime_error when the seated
/// equilibrium does not converge.
SeatingRun run_seating(const std::string& data_dir, const SeatingRequest& request);

/// The checks run_seating makes before any work (the chair, the pelvic tilt); one-line
/// std::invalid_argument. A sweep checks every value with it before its first point.
void check_seating_request(const SeatingRequest& request);

void print_seating(std::ostream& os, const SeatingRun& run, bool markdown);
nlohmann::json seating_json(const SeatingRun& run);
/// One row per level T1 … L5 and the sacrum: contact force, gap, the joint below's reaction.
std::string seating_csv(const SeatingRun& run);

/// The chair parameters a sweep can vary: backrest-recline, lumbar-support, seat-angle,
/// backrest-height, pelvic-tilt (deg or mm as their flags).
const std::vector<std::string>& seating_parameters();
/// `request` with `parameter` set to `value`; throws std::invalid_argument for an unknown name.
SeatingRequest with_parameter(SeatingRequest request, const std::string& parameter, double value);

struct SeatingSweep {
  std::string parameter;
  std::vector<double> values;
  std::vector<SeatingRun> runs;
  std::vector<Finding> findings;  ///< the literature's trends over this parameter, checked
  double seconds = 0;
};
/// One seated solve per value (each refused chair is an error naming the value).
SeatingSweep run_seating_sweep(const std::string& data_dir, const std::string& parameter,
                               const std::vector<double>& values, const SeatingRequest& base,
                               const StageHooks& hooks = StageHooks());
void print_seating_sweep(std::ostream& os, const SeatingSweep& s, bool markdown);
nlohmann::json seating_sweep_json(const SeatingSweep& s);
std::string seating_sweep_csv(const SeatingSweep& s);

/// Standing, sitting without and with a backrest, and the crate, beside Wilke's in-vivo loads
/// (absolute standing load and the ratios to standing), then every trend of the validation file.
struct SittingValidation {
  struct Row {
    std::string id, what;
    double ours = 0, target = 0, low = 0, high = 0;
    std::string unit, source;
    bool pass = false;
  };
  std::vector<Row> rows;
  std::vector<SeatingSweep> sweeps;
  std::vector<Finding> findings;  ///< the rows and the trends, MATCH / DIFFERS
  double disc_area_mm2 = 0;       ///< the area the in-vivo pressures are converted with
  /// The disc's swelling pressure (MPa) and its force on this body's L4-L5 disc (N: pressure ×
  /// disc_area_mm2 × the body's length scale²), in every posture's compression.
  double swelling_mpa = 0, swelling_n = 0;
  double seconds = 0;
};
/// The first part alone: standing, sitting without and with a backrest, and the crate (rows and
/// their findings; no sweeps, seconds 0). Each L4-L5 compression is the joint's axial force plus
/// the disc's swelling pressure times the disc area (`swelling_mpa`; NaN: the validation file's
/// "swelling_pressure_mpa", Wilke et al. 1999's unloaded disc). The pre-stress is
/// self-equilibrated (the annulus fibres and ligaments hold it in), so no joint reaction changes;
/// the in-vivo pressures it is compared with include it.
SittingValidation run_posture_comparison(
    const std::string& data_dir, const spine::ModelOptions& model = spine::ModelOptions(),
    double swelling_mpa = std::numeric_limits<double>::quiet_NaN());
inline constexpr int kSittingValidationStages = 5;  ///< postures, then one per swept parameter
SittingValidation run_sitting_validation(const std::string& data_dir,
                                         const spine::ModelOptions& model = spine::ModelOptions(),
                                         const StageHooks& hooks = StageHooks());
void print_sitting_validation(std::ostream& os, const SittingValidation& v, bool markdown);
nlohmann::json sitting_validation_json(const SittingValidation& v);
std::string sitting_validation_csv(const SittingValidation& v);

}  // namespace spinesim::studies
