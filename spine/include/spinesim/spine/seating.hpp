// The spine in a chair (thesis 6.2; docs/seating.md): the standing model seated by rotating its
// pelvis back and flexing its lumbar spine (data/spine/seating.json), its back pressing on a
// backrest through compliant soft tissue, solved with the spine's equilibrium and muscle
// recruitment, and the whole body leaning back onto the backrest until its moment about the
// ischial tuberosities is balanced.
//
// Frames. The model's frame is the pelvis's (its fixed parts are the ground), in the standing
// reference. The chair's frame: origin at the seat reference point (where the seat pan and the
// backrest meet, mid-width), x lateral as the spine's, y up (against gravity), z forward. A model
// point X sits at R (X − I) + I_w in the chair, R the pelvis's posterior tilt about x, I the
// ischial pivot, I_w where it rests on the seat.
#pragma once

#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace spinesim::spine {

/// How a body sits and what lies between its back and a backrest (data/spine/seating.json).
struct Sitter {
  double pelvic_tilt_deg = 0;        ///< posterior pelvic rotation from standing
  double lumbar_flexion_deg = 0;     ///< lordosis lost from standing, over L1-L2 … L5-S1
  std::vector<double> lumbar_share;  ///< per joint (17), the share of lumbar_flexion_deg
  double seat_pelvis_coupling = 0;   ///< fraction of the seat angle the pelvis follows
  Eigen::Vector3d ischia_mm = Eigen::Vector3d::Zero(), sacrum_back_mm = Eigen::Vector3d::Zero();
  double tissue_thoracic_mm = 0, tissue_lumbar_mm = 0, tissue_stiffness_n_per_mm = 0;
  double spinous_thoracic_mm = 0, spinous_lumbar_mm = 0;  ///< spine_model.json's process lengths
  /// Per vertebra (T1 … L5): z of the interspinous ligament's origin, halfway along the spinous
  /// process (the ligaments' geometry, spine_model.json), mm. Read once here: no solve reads files.
  std::vector<double> interspinous_z_mm;
  double pelvis_mass_percent = 0;
  Eigen::Vector3d pelvis_com_mm = Eigen::Vector3d::Zero();
  double forearm_hand_percent_each = 0;
  double lean_min_deg = -10, lean_max_deg = 45;
};

/// Reads data/spine/seating.json for `model` (the lumbar shares use its F.5 ranges; the posterior
/// elements' geometry its ligaments, or those of the model with ligaments when it has none).
/// Throws std::runtime_error naming the file and field for missing or malformed data.
Sitter load_sitter(const SpineModel& model);

/// A chair. The backrest is parametric (a plane at `backrest_recline_deg` to the horizontal with
/// a rounded top and an optional lumbar pad) unless `surface` is set (a surface file, chair frame).
struct Chair {
  double seat_angle_deg = 0;          ///< seat pan tilted back (front edge up)
  double backrest_recline_deg = 100;  ///< backrest to the horizontal, behind the sitter: 90 upright
  double backrest_height_mm = 500;    ///< along the backrest from the seat; 0: no backrest
  double lumbar_support_mm = 0;       ///< depth of the lumbar pad (0: flat backrest)
  double lumbar_support_height_mm = 200;          ///< its centre above the seat, along the backrest
  double lumbar_support_half_length_mm = 100;     ///< its cosine profile's half length
  bool armrests = false;                          ///< forearms and hands rest on the chair
  std::shared_ptr<const ContactSurface> surface;  ///< a backrest from a file (chair frame)
  std::string surface_name;                       ///< its file, for reports
};

/// Throws std::invalid_argument (one line naming the field and its valid range) for a chair no one
/// can sit in: non-finite values, negative depths or heights, a recline outside 60–150°, a seat
/// angle outside ±30°, a lumbar pad outside the backrest.
void check_chair(const Chair& chair);

/// The parametric backrest as a contact surface in the chair frame (level φ in mm, > 0 in front).
std::shared_ptr<const ContactSurface> parametric_backrest(const Chair& chair);

struct SeatingOptions {
  SolveOptions solve;
  int max_contact_iterations = 60;
  double contact_tolerance_n = 0.5;  ///< on the largest change of a contact force between rounds
  double contact_relaxation = 0.5;   ///< first relaxation factor (then Aitken's Δ²)
  double lean_tolerance_nmm = 200;   ///< on the moment about the ischia (0.2 N·m)
  int max_lean_iterations = 40;
};

struct SeatedContact {
  std::string name;          ///< "T1" … "L5", "sacrum"
  Eigen::Vector3d force_n;   ///< on the back, chair frame
  Eigen::Vector3d point_mm;  ///< where, chair frame
  double gap_mm = 0;         ///< φ at the point (< 0: pressed in)
};

struct SeatedSolution {
  SpineSolution spine;  ///< in the pelvis frame (joint reactions in the lower vertebra's axes)
  double pelvic_tilt_deg = 0;  ///< sitter's tilt + seat coupling + lean
  double lean_deg = 0;  ///< the lean onto the backrest that balances the moment about the ischia
  double ischia_forward_mm = 0;  ///< the ischia's distance in front of the seat reference point
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< pelvis frame → chair frame
  Eigen::Vector3d ischia_world_mm = Eigen::Vector3d::Zero();
  std::vector<SeatedContact> contacts;                         ///< T1 … L5, sacrum
  Eigen::Vector3d backrest_force_n = Eigen::Vector3d::Zero();  ///< total, on the body, chair frame
  Eigen::Vector3d seat_force_n = Eigen::Vector3d::Zero();      ///< on the body, chair frame
  Eigen::Vector3d armrest_force_n = Eigen::Vector3d::Zero();   ///< on the forearms, chair frame
  double body_weight_n = 0;  ///< trunk, head, arms and pelvis (what seat, backrest, armrests carry)
  /// |weight + backrest + armrests + seat| with the seat reaction taken from the pelvis's own free
  /// body (L5-S1 reaction, ground-side muscle, ligament and bushing forces, its weight, the sacral
  /// contact): the reported forces balance to this, N.
  double force_residual_n = 0;
  double hip_moment_nmm = 0;  ///< about the ischia, what the hips hold (0 when the lean balances)
  /// The seat's reaction along the seat pan over its reaction across it: the friction coefficient
  /// the seat needs to hold the pelvis (the model is frictionless at the back, the pelvis fixed on
  /// the seat). Above 1 the backrest pushes the sitter forward harder than the seat presses.
  double seat_friction_needed = 0;
  std::vector<double>
      vertebra_angle_deg;  ///< sagittal tilt of each vertebra in the chair (+ forward)
  int contact_rounds = 0, lean_iterations = 0, solves = 0;
  bool lean_balanced = false;  ///< false: the lean hit its range (reported in warnings)
  std::vector<std::string> warnings;
  double seconds = 0;
};

/// Seats `standing` (built with load_spine_model) in `chair` and solves it; `loads` act as in
/// solve_spine (reference posture). Throws std::invalid_argument for a bad chair, one the back
/// cannot reach within the sitter's lean range, or bad loads; SolveError when the equilibrium
/// does not converge.
SeatedSolution solve_seated(const SpineModel& standing, const Chair& chair, const Sitter& sitter,
                            const std::vector<ExternalLoad>& loads = {},
                            const SeatingOptions& options = SeatingOptions());

/// The standing model as it sits in the chair at pelvic tilt `tilt_deg` (contacts, rotated gravity,
/// armrests), with the ischia at `ischia_forward_mm` in front of the seat reference point; and the
/// lumbar posture the recruitment holds. Exposed for the haptic loop and tests.
struct SeatedModel {
  SpineModel model;
  Eigen::VectorXd posture;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d ischia_world_mm = Eigen::Vector3d::Zero();
};
SeatedModel seat_model(const SpineModel& standing, const Chair& chair, const Sitter& sitter,
                       double tilt_deg, double ischia_forward_mm);

}  // namespace spinesim::spine
