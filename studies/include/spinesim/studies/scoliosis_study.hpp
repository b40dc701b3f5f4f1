// `spinesim study scoliosis`: disc loads on the concave and convex sides of scoliotic spines
// (spine/scoliosis.hpp), beside published findings.
//
// Each curve type (thoracic, thoracolumbar, lumbar) at Cobb 20, 40 and 60° stands under gravity
// with its muscles recruited; each disc of the curve carries the joint's axial force N and its
// frontal-plane moment M, read on the disc's elliptic section (width w and depth d from
// disc_morphometry.csv, scaled with the body) as a beam: σ = N/A ± M·(w/2)/I at its two lateral
// edges, A = π w d / 4, I = π d w³ / 64. (The joint spring is the whole motion segment, facets and
// ligaments included, so this puts all of the moment on the disc: an upper bound of the
// asymmetry.) The findings:
//  - Meir et al. 2007 (in vivo, during surgery): stress peaks in the concave annulus — the
//    concave edge more loaded than the convex one at the apical discs;
//  - Meir et al. 2007: a mean pressure of 0.25 MPa in scoliotic discs without muscle load
//    (< 0.07 MPa in other anaesthetised patients) — the model's curve is stress-free at rest;
//  - Modi et al. 2008 (150 patients): the discs (and bodies) are most wedged at the apex —
//    read through Hueter–Volkmann, the asymmetry should be largest at the apical discs.
#pragma once

#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

/// The compressive stress (MPa) at a disc's two lateral edges from its joint reaction: left (+x)
/// and right (−x), and the mean N/A.
struct DiscEdgeStress {
  double left_mpa = 0, right_mpa = 0, mean_mpa = 0;
};
DiscEdgeStress disc_edge_stress(const spine::JointReaction& r, double width_mm, double depth_mm);

struct ScoliosisDisc {
  std::string joint;
  double axial_n = 0, lateral_moment_nmm = 0;
  double concave_mpa = 0, convex_mpa = 0;
};

struct ScoliosisCase {
  spine::ScoliosisCurve curve;
  std::string refusal;               ///< why the model cannot pose it ("": posed)
  std::vector<ScoliosisDisc> discs;  ///< every disc of the curve, top down
  std::string most_asymmetric;       ///< the disc with the largest concave − convex stress
  double apical_concave_mpa = 0, apical_convex_mpa = 0;  ///< mean over the two apical discs
  double unloaded_apical_mpa = 0;  ///< the same discs' mean stress without gravity or muscles
  double apex_offset_mm = 0;
};

struct ScoliosisFinding {
  std::string source, finding, model;
  bool match = false;
};

struct ScoliosisStudy {
  std::vector<ScoliosisCase> cases;
  std::vector<ScoliosisFinding> findings;
  spine::Subject subject;
  double seconds = 0;
};

/// `model`'s options (ligaments, body) with each curve in turn.
ScoliosisStudy run_scoliosis_study(const std::string& data_dir, const spine::ModelOptions& model,
                                   const StageHooks& hooks = {});
void print_scoliosis_study(std::ostream& os, const ScoliosisStudy& s);
nlohmann::json scoliosis_study_json(const ScoliosisStudy& s);

}  // namespace spinesim::studies
