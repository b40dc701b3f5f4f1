// `spinesim study standing-gap`: the mechanisms the literature uses to reach the in-vivo standing
// disc load, each tried on the model and measured against the same in-vivo rows
// (run_posture_comparison: standing L4-L5, sitting / standing, leaning back / standing,
// crate / standing) and the crate's own window.
//
//   - The disc's swelling pressure: with no load on it (lying prone) the L4-L5 nucleus holds
//     0.10 MPa (Wilke et al. 1999). The ligaments and annulus fibres that hold it in carry the
//     same force in tension, so the pre-stress is self-equilibrated: the joint reactions do not
//     change, and the disc's compression is the joint's plus p0 times the area the comparison
//     converts pressures with (sitting_in_vivo.json "disc_area_mm2"). First order: the swelling
//     pressure is taken as the same in every posture.
//   - Co-contraction: every trunk muscle at least a fraction of its maximum
//     (ModelOptions::co_contraction); the recruitment balances the load with it.
//   - Resting tone: every muscle carries a fraction of its maximum the criterion does not count
//     (ModelOptions::muscle_tone).
// Each is run at several levels; then the level of each muscle mechanism that, on top of the
// swelling pressure, brings standing to the in-vivo load is found by bisection, and the other
// rows are read there: what closing the gap that way would cost.
#pragma once

#include "spinesim/spine/model.hpp"
#include "spinesim/studies/seating_study.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

struct StandingGapCase {
  std::string name, mechanism;  ///< mechanism: none, swelling, co-contraction, tone, or a sum
  double prestress_mpa = 0, co_contraction = 0, muscle_tone = 0;
  /// L4-L5 compression (N): standing, sitting without backrest, leaning back, crate.
  double standing_n = 0, sitting_n = 0, chair_n = 0, crate_n = 0;
  int in_window = 0;  ///< of the five rows (four posture rows, the crate's own window)
  bool found = true;  ///< a bisected case: false when even the largest level stays below
};

struct StandingGapStudy {
  double standing_target_n = 0, prestress_force_n = 0, area_mm2 = 0, tolerance = 0;
  double sitting_ratio = 0, chair_ratio = 0, crate_ratio = 0;  ///< in vivo, to standing
  double crate_lo_n = 0, crate_hi_n = 0;                       ///< the spine's crate window
  std::vector<StandingGapCase> cases;
  double seconds = 0;
};

/// Stages: one per case.
inline constexpr int kStandingGapStages = 10;

/// The study on the body and model of `model` (its co_contraction and muscle_tone are set per
/// case). `prestress_mpa` is the swelling pressure (Wilke et al. 1999: 0.10).
StandingGapStudy run_standing_gap_study(const std::string& data_dir,
                                        const spine::ModelOptions& model = {},
                                        double prestress_mpa = 0.10,
                                        const StageHooks& hooks = StageHooks());
void print_standing_gap_study(std::ostream& os, const StandingGapStudy& s, bool markdown);
nlohmann::json standing_gap_study_json(const StandingGapStudy& s);

}  // namespace spinesim::studies
