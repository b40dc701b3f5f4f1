// The spine studies (`spinesim study validation|fusion|trends`, and the spine section of
// `spinesim demo`): the thesis's validation of its spine model (3.4), its fusion comparison
// (6.1) and its reading of relative vertebra motions under a force on T1 (6.3–6.4), run on our
// open model (spine/). Every study solves spine::solve_spine with the default options (gravity,
// muscles recruited by the polynomial criterion p = 3, ligaments, the IAP bushing) and reports;
// nothing is tuned towards the thesis's numbers. Targets are read from
// data/spine/spine_model.json "validation".
//
// Frame and units (thesis tables): x lateral (the body's right is −x), y superior, z anterior;
// mm, N, N·mm (N·m in the readable tables), degrees.
//
// validation — two cases:
//   (a) McGill & Norman 1987 (thesis 3.4, fig. 3.32–3.35): a horizontal force +z (posterior →
//       anterior) at the T7 centre, raised (secant on solve_spine) until the net external
//       moment about the L5-S1 joint point reaches the target (238 N·m). That moment is
//         M_ext = e_x · Σ_k (x_k − p_L5S1) × f_k
//       over every load above L5-S1 — the T7 force and the weights of the vertebrae, head and
//       arms — at their points in the equilibrium posture x_k (the L5-S1 point does not move:
//       the sacrum is fixed), plus any applied couple. M_ext > 0 flexes the trunk: it is the
//       extension moment the trunk (muscles, ligaments, IAP and the joint) must supply. We also
//       split it: M_joint, what the L5-S1 joint's spring carries (JointReaction::moment_world_nmm
//       x), and M_ext − M_joint, carried by the muscles, ligaments and the IAP bushing. L5-S1 axial and shear force (shear = in-plane magnitude) in the joint frame
//       (the thesis's Fy/Fz) and in the disc mid-plane frame, beside 3929–4688 N and ≤ 650 N.
//   (b) Wilke et al. 2001: a crate (spine_model.json "crate": 19.8 kg) held in front of the chest
//       (chest_front_mm + (0, 0, distance_from_chest_mm)), its weight a dead load on the crate's
//       carrier (T6, the rib cage), arms reaching forward (ModelOptions::arms_forward); the L4-L5
//       axial force beside 3240 N ± 15 %.
// fusion — thesis 6.1: the normal spine and fusion at L3-L4, L4-L5, L3-L4-L5 (fixed joints) under
//   the same forward (+z), backward (−z) and lateral (−x) force on the T1 centre. T1 motion is
//   the force's effect: the equilibrium under gravity + force minus the same model's gravity-only
//   equilibrium. Joint forces (L2-L3, L5-S1) are the totals (gravity, muscles and force): what
//   the disc carries. The thesis's findings are checked and reported, not forced.
// trends — thesis 6.3 (translations) and 6.4 (rotations): under a lateral (−x), forward (+z) and
//   backward (−z) force on T1, per adjacent pair T1-T2 … L4-L5: the relative translation of the
//   F.1 centres (upper minus lower, world axes, mm) and the relative rotation (the joint
//   coordinate θ: lower vertebra's axes, x flexion +, y torsion, z lateral bending; deg), each
//   minus its gravity-only value. Following the thesis's reading of its figures, Δy < 0 is
//   "compression", Δy > 0 "tension", |Δx| and |Δz| "shearing". Each trend the thesis states is
//   checked: MATCH or DIFFERS with our numbers.
#pragma once

#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::studies {

/// One statement of the thesis checked against our numbers.
struct Finding {
  std::string id;      ///< short key, e.g. "forward-max-tension"
  std::string load;    ///< the load case it is about ("forward", … or "all")
  std::string thesis;  ///< what the thesis says
  std::string ours;    ///< our numbers
  bool match = false;
};
nlohmann::json findings_json(const std::vector<Finding>& findings);
/// `says` heads the statements' column ("thesis says"; "literature says" for in-vivo data).
void print_findings(std::ostream& os, const std::vector<Finding>& findings, bool markdown,
                    const std::string& says = "thesis says");

/// Stages of each study, for StageHooks: validation 2 (McGill, Wilke), fusion 4 (one per fusion), trends 1.
inline constexpr int kValidationStages = 2, kFusionStages = 4, kTrendsStages = 1;

/// A joint reaction as JSON: world force and moment, joint-frame and disc-frame components.
nlohmann::json joint_reaction_json(const spine::JointReaction& r);
/// In-plane shear magnitude in the joint frame, N.
double joint_shear_n(const spine::JointReaction& r);

// --- validation --------------------------------------------------------------------------------

struct McGillCase {
  double target_moment_nmm = 0;    ///< spine_model.json validation.mcgill_extension_moment_nmm
  double t7_force_n = 0;           ///< found: +z force on the T7 centre
  double external_moment_nmm = 0;  ///< M_ext at the equilibrium (see the header)
  double external_moment_reference_nmm = 0;  ///< the same loads in the reference posture
  double joint_moment_nmm =
      0;  ///< x moment the L5-S1 joint spring carries (JointReaction; flexion +)
  double other_moment_nmm = 0;  ///< M_ext − M_joint: carried by muscles, ligaments, IAP
  spine::JointReaction l5s1;
  int solves = 0, iterations = 0;  ///< solve_spine calls; Newton iterations of the last
  double axial_lo_n = 0, axial_hi_n = 0, shear_max_n = 0;  ///< McGill & Norman's window
  /// Reference values (NaN when spine_model.json does not list them).
  double thesis_force_n = 0, thesis_axial_n = 0, thesis_shear_n = 0, dezee_axial_n = 0,
         dezee_shear_n = 0;
  std::string source;
  bool axial_ok() const;  ///< joint-frame axial within the window
  bool shear_ok() const;  ///< joint-frame shear magnitude ≤ the maximum
};

struct WilkeCase {
  double crate_mass_kg = 0, distance_from_chest_mm = 0;
  std::string carried_by;
  Eigen::Vector3d crate_point_mm = Eigen::Vector3d::Zero();
  spine::JointReaction l4l5;
  double target_n = 0, tolerance = 0, thesis_n = 0;  ///< 3240 N, 0.15, 3161.6 N
  std::string source;
  int iterations = 0;
  bool ok() const;  ///< joint-frame axial within target·(1 ± tolerance)
};

/// The crate case (b) alone.
WilkeCase run_wilke_case(const std::string& data_dir, const spine::ModelOptions& model = {});

struct ValidationStudy {
  McGillCase mcgill;
  WilkeCase wilke;
  bool trunk_muscles = true;  ///< the model's muscle set (spine::ModelOptions::trunk_muscles)
  bool ligaments = false;     ///< the F.6/F.7 ligaments were elements (spine::has_ligaments)
  spine::Subject subject;     ///< the body, resolved (spine::resolve_subject)
  double seconds = 0;
};
/// `model` gives the muscle set (trunk_muscles); each case sets its own loads and arm posture.
ValidationStudy run_validation_study(const std::string& data_dir,
                                     const spine::ModelOptions& model = {},
                                     const StageHooks& hooks = StageHooks());
void print_validation(std::ostream& os, const ValidationStudy& s, bool markdown);
nlohmann::json validation_json(const ValidationStudy& s);
std::string validation_csv(const ValidationStudy& s);  ///< one row per case × quantity

// --- fusion ------------------------------------------------------------------------------------

/// A named load direction on T1: forward (+z), backward (−z), lateral (−x).
struct LoadDirection {
  std::string name;
  Eigen::Vector3d direction;
};
const std::vector<LoadDirection>& t1_load_directions();

struct FusionRun {
  std::string fusion;  ///< "normal", "L3-L4", "L4-L5", "L3-L4-L5"
  std::string load;    ///< forward, backward, lateral
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d t1_translation_mm = Eigen::Vector3d::Zero();  ///< the force's effect
  Eigen::Vector3d t1_rotation_deg = Eigen::Vector3d::Zero();    ///< the force's effect
  Eigen::Vector3d t1_total_translation_mm =
      Eigen::Vector3d::Zero();      ///< from the reference posture (gravity + force)
  spine::JointReaction l2l3, l5s1;  ///< totals
  int iterations = 0;
  double seconds = 0;
};

struct FusionStudy {
  double force_n = 0;
  std::vector<std::string> fusions, loads;
  std::vector<FusionRun> runs;  ///< fusion-major
  std::vector<Finding> findings;
  bool trunk_muscles = true;  ///< the model's muscle set (spine::ModelOptions::trunk_muscles)
  bool ligaments = false;     ///< the F.6/F.7 ligaments were elements (spine::has_ligaments)
  spine::Subject subject;     ///< the body, resolved (spine::resolve_subject)
  double seconds = 0;
  const FusionRun& run(const std::string& fusion, const std::string& load) const;
};
/// `model` gives the muscle set; the study sets the fused joints itself.
FusionStudy run_fusion_study(const std::string& data_dir, double force_n,
                             const spine::ModelOptions& model = {},
                             const StageHooks& hooks = StageHooks());
void print_fusion(std::ostream& os, const FusionStudy& s, bool markdown);
nlohmann::json fusion_json(const FusionStudy& s);
std::string fusion_csv(const FusionStudy& s);  ///< one row per fusion × load

// --- trends ------------------------------------------------------------------------------------

struct TrendRun {
  std::string load;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  std::vector<std::string> pairs;   ///< "T1-T2" … "L4-L5"
  Eigen::MatrixX3d translation_mm;  ///< #pairs × 3, upper minus lower, world axes, force's effect
  Eigen::MatrixX3d rotation_deg;  ///< #pairs × 3, joint coordinate (lower's axes), force's effect
  int iterations = 0;
};

struct TrendsStudy {
  double force_n = 0;
  std::vector<TrendRun> runs;  ///< lateral, forward, backward
  std::vector<Finding> findings;
  bool trunk_muscles = true;  ///< the model's muscle set (spine::ModelOptions::trunk_muscles)
  bool ligaments = false;     ///< the F.6/F.7 ligaments were elements (spine::has_ligaments)
  spine::Subject subject;     ///< the body, resolved (spine::resolve_subject)
  double seconds = 0;
};
TrendsStudy run_trends_study(const std::string& data_dir, double force_n,
                             const spine::ModelOptions& model = {},
                             const StageHooks& hooks = StageHooks());
void print_trends(std::ostream& os, const TrendsStudy& s, bool markdown);
nlohmann::json trends_json(const TrendsStudy& s);
std::string trends_csv(const TrendsStudy& s);  ///< one row per load × pair

}  // namespace spinesim::studies
