// `spinesim study rib-cage`: what the rib cage (spine/rib_cage.hpp) does to the thoracic spine,
// beside the cadaver tests that removed it.
//
// In vitro (T1 loaded by pure moments, T12 held): Liebsch et al. 2017 (PLoS One 12:e0178733),
// six specimens at ±2 N·m, report how much the T1-T12 range of motion grows when the anterior
// rib cage is removed (FE +52.2 %, LB +42.0 %, AR +94.4 %); Mannen et al. 2018 (author
// manuscript PMC6016553), eight specimens at ±5 N·m under a 400 N follower load, when the whole
// cage is removed (FE +63.0 %, LB +63.5 %, AR +58.8 %).
//
// The model's test is the same: the thoracic spine alone (no gravity, muscles, IAP), every joint
// below T12 held, a couple of ±M about each axis on T1; the range of motion is T1's rotation at
// +M minus at −M. Cases: no cage, the ribs on their heads (the anterior cage — the costal
// cartilage — removed), the whole cage, and the whole cage with its two springs' stiffness
// changed (sensitivity: the cartilage's is an assumption). The growth on removal is
// ROM(no cage) / ROM(case) − 1, the in-vitro papers' measure.
//
// In the loaded spine: standing (gravity and the recruited muscles) and a 300 N forward force on
// T1, with and without the cage: T1's displacement and the L4-L5 force.
#pragma once

#include "spinesim/spine/model.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

struct RibCageCase {
  std::string name;  ///< "no cage", "ribs on their heads", "whole cage", …
  double cartilage_scale = 1, costovertebral_scale = 1;
  bool cage = true, cartilage = true;
  std::array<double, 3> rom_deg{};     ///< flexion/extension, lateral bending, axial rotation
  std::array<double, 3> growth_pct{};  ///< ROM(no cage)/ROM(case) − 1, %
};

/// A loaded scene with and without the cage.
struct RibCageScene {
  std::string name;
  double thoracic_flexion_deg[2] = {0, 0};  ///< T1's flexion relative to T12, without, with
  double t1_translation_mm[2] = {0, 0};     ///< |Δ T1| without, with the cage
  double l4l5_axial_n[2] = {0, 0};
};

struct RibCageStudy {
  double moment_nm = 2;
  spine::Subject subject;
  std::vector<RibCageCase> cases;
  std::vector<RibCageScene> scenes;
  double seconds = 0;
};

/// Runs the study for the body in `model` (its subject, ligaments and joint springs; the rest of
/// `model` is set by the study). Throws std::invalid_argument for a moment outside 0.1 … 20 N·m.
RibCageStudy run_rib_cage_study(const std::string& data_dir, double moment_nm,
                                const spine::ModelOptions& model,
                                const StageHooks& hooks = StageHooks());

void print_rib_cage_study(std::ostream& os, const RibCageStudy& s, bool markdown);
nlohmann::json rib_cage_study_json(const RibCageStudy& s);

}  // namespace spinesim::studies
