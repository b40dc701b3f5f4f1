// `spinesim study bodies`: the spine studies for each sourced body (spine::named_bodies: the
// thesis's reference man, a 5th-percentile woman and a 95th-percentile man), side by side.
//
// Per body, the same protocols with the same loads as for the reference body:
//   - validation (spine_studies.hpp): McGill & Norman's 238 N·m extension moment at L5-S1 and
//     Wilke's 19.8 kg crate at L4-L5, beside their windows;
//   - fusion and trends under the same force on T1: how many of the thesis's statements hold;
//   - the in-vivo postures (seating_study.hpp, run_posture_comparison): standing L4-L5 and the
//     sitting, chair and crate ratios to standing.
// The windows come from one male subject each (McGill & Norman's lifter, Wilke's 70 kg
// volunteer): for the other bodies they are the reference subject's values, shown for scale, not
// targets the body should meet. The loads are not scaled with the body: a small body holding the
// same crate is the case the comparison is for.
#pragma once

#include "spinesim/spine/model.hpp"
#include "spinesim/studies/seating_study.hpp"
#include "spinesim/studies/spine_studies.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

struct BodyStudyRun {
  spine::NamedBody body;  ///< resolved
  ValidationStudy validation;
  FusionStudy fusion;
  TrendsStudy trends;
  SittingValidation postures;  ///< rows only (run_posture_comparison)
};

struct BodyStudy {
  double force_n = 0;
  std::vector<BodyStudyRun> runs;  ///< in the data file's order
  double seconds = 0;
};

/// Stages: four per body (validation, fusion, trends, postures).
inline constexpr int kBodyStudyStagesPerBody = 4;

/// Runs the studies for each named body (all of them when `names` is empty), the rest of `model`
/// (ligaments, muscles, rib cage, joint springs) as given; its subject is replaced per body.
BodyStudy run_body_study(const std::string& data_dir, double force_n,
                         const spine::ModelOptions& model = {},
                         const std::vector<std::string>& names = {},
                         const StageHooks& hooks = StageHooks());
void print_body_study(std::ostream& os, const BodyStudy& s, bool markdown);
nlohmann::json body_study_json(const BodyStudy& s);
std::string body_study_csv(const BodyStudy& s);  ///< one row per quantity, one column per body

}  // namespace spinesim::studies
