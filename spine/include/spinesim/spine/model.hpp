// The thoracolumbar spine model (thesis 3.3; spine/README.md): 17 rigid vertebrae T1…L5 in a
// chain above the fixed sacrum, joined by spherical joints at the table F.2 points with F.4
// rotational stiffness and F.5 range-of-motion limits; ligaments (F.6/F.7), the lumbar
// muscles (F.8–F.19, mirrored) and the LifeMOD trunk muscles the thesis names without data
// (data/spine/trunk_muscles.csv), the intra-abdominal-pressure bushing (appendix C) between
// the rib cage (fixed to T6) and the pelvis; gravity on the vertebrae, the head and the arms.
// Everything numeric comes from data/ (thesis/ tables and spine/spine_model.json).
//
// Units: mm, N, N·mm, kg; angles in radians inside (degrees in files and reports).
// Frame (thesis tables): x lateral (the body's right is −x), y superior, z anterior.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <vector>

namespace spinesim::spine {

struct RibCage;  // rib_cage.hpp

/// Body index of everything fixed to the pelvis (sacrum, ilium, femur, lower torso, rectus sheath).
inline constexpr int kGround = -1;

/// "T1" … "L5", top to bottom; vertebra i sits on joint i.
const std::vector<std::string>& vertebra_names();
/// "T1-T2" … "L5-S1"; joint i connects vertebra i (above) to vertebra i+1 (or the sacrum).
const std::vector<std::string>& joint_names();
/// Index of a vertebra name ("t7" accepted); throws std::invalid_argument listing the names.
int vertebra_index(const std::string& name);
/// Index of a joint name ("l4-l5" accepted); throws std::invalid_argument listing the names.
int joint_index(const std::string& name);
/// Fusion levels: "L3-L4" → {joint L3-L4}; "L3-L4-L5" → {L3-L4, L4-L5}; several separated
/// by commas. Throws std::invalid_argument for an unknown or non-adjacent level.
std::vector<int> parse_fusion(const std::string& levels);

struct Vertebra {
  std::string name;
  Eigen::Vector3d centre_mm;  ///< table F.1 centre of mass (reference posture)
  double mass_kg = 0;         ///< per-level trunk mass (Bruno et al. 2015, % of body mass)
};

/// Spherical joint with a rotational spring; θ (rotation vector of the upper vertebra relative
/// to the lower one, in the lower one's axes) has components x = flexion (+) / extension (−),
/// y = axial torsion, z = lateral bending. The spring is the thesis's F.4 (diagonal, flexion and
/// extension apart) or a disc's 3×3 rotational stiffness about the joint point
/// (ModelOptions::disc_joints): its diagonal in the k's, its off-diagonal in `coupling`
/// (energy ½ θᵀ coupling θ on top of the diagonal springs).
struct Joint {
  std::string name;
  Eigen::Vector3d point_mm;                                                     ///< table F.2
  double k_flexion = 0, k_extension = 0, k_lateral = 0, k_torsion = 0;          ///< N·mm/rad (F.4)
  double rom_flexion = 0, rom_extension = 0, rom_lateral = 0, rom_torsion = 0;  ///< rad (F.5)
  Eigen::Matrix3d coupling = Eigen::Matrix3d::Zero();  ///< N·mm/rad, zero diagonal
  std::string stiffness_source = "thesis F.4";
  bool fused = false;  ///< fixed joint (spinal fusion): θ ≡ 0
  /// The springs' stress-free rotation (rad): zero, or a scoliotic curve's wedged disc.
  Eigen::Vector3d rest_rad = Eigen::Vector3d::Zero();
  /// Its disc (disc_morphometry.csv, scaled with the body): mid height, and the means of the
  /// lower and upper outlines' lateral width and antero-posterior depth, mm.
  double disc_height_mm = 0, disc_width_mm = 0, disc_depth_mm = 0;
};

/// A straight line element between two bodies (attachment points in the reference posture).
struct Line {
  std::string name;
  int body_a = kGround, body_b = kGround;  ///< vertebra index or kGround
  Eigen::Vector3d a_mm, b_mm;
  double rest_length_mm = 0;  ///< |a − b| in the reference posture
};

/// Tension-only linear spring (N/mm), slack-free in the reference posture.
struct Ligament : Line {
  std::string type;  ///< ISL, LF, ALL, PLL, JC
  int joint = -1;    ///< the joint it spans
  double k_n_per_mm = 0;
};

/// Muscle fascicle: recruited force F (0 ≤ F ≤ pcsa·σmax) at the reference length, with the
/// short-range stiffness k = q·F/L0 (Bergmark 1989) about it, tension only.
struct Muscle : Line {
  std::string group;  ///< multifidus, erector spinae, psoas major, quadratus lumborum, ...
  std::string side;   ///< "right" (as printed) or "left" (mirrored x → −x)
  double pcsa_mm2 = 0, max_stress_mpa = 0;
  double max_force_n() const { return pcsa_mm2 * max_stress_mpa; }
};

/// Six-DOF linear bushing (appendix C) between body_a and the ground at `point_mm`.
struct Bushing {
  int body = kGround;
  Eigen::Vector3d point_mm;
  Eigen::Vector3d k_translation_n_per_mm;  ///< k'x, k'y, k'z
  Eigen::Vector3d k_rotation_nmm_per_rad;  ///< M'x, M'y, M'z (appendix C gives N·mm/deg)
  /// The body's pose (rotation and translation of the reference posture) at which the bushing is
  /// unloaded: the reference posture (identity), or the posture the body settles into (seated).
  Eigen::Matrix3d rest_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d rest_translation_mm = Eigen::Vector3d::Zero();
};

/// A constant (dead) force on a body, e.g. a weight.
struct PointLoad {
  std::string name;
  int body = kGround;
  Eigen::Vector3d point_mm;
  Eigen::Vector3d force_n;
};

/// A fixed surface the back can lean on (a chair's backrest), in the model's frame (the pelvis's:
/// fixed parts are the ground): a level function φ(x) in mm, positive on the body's side and
/// negative inside the surface, with ∇φ close to the unit normal and C¹ where the back touches.
class ContactSurface {
 public:
  virtual ~ContactSurface() = default;
  /// φ(x_mm) and its gradient.
  virtual double level(const Eigen::Vector3d& x_mm, Eigen::Vector3d& gradient) const = 0;
  /// Is the surface its own mirror image in x → −x? (The sagittal solve needs it.)
  virtual bool mirror_symmetric() const { return false; }
};

/// A point of the back — on a vertebra, through the soft tissue — that presses on the contact
/// surface: compliant, frictionless, one-sided. With penetration δ = max(−φ(x), 0):
/// Π = ½ k δ² (its stiffness ramped in over kContactToeMm, so Π is C²), force k δ ∇φ.
struct ContactPoint {
  std::string name;
  int body = kGround;
  Eigen::Vector3d point_mm;  ///< reference posture
  double k_n_per_mm = 0;
};
inline constexpr double kContactToeMm = 0.5;

/// Appendix C recomputed from its inputs (never pasted).
struct IapStiffness {
  double s_mean_mm2 = 0, h_l1l5_mm = 0, h_mm = 0, a_mm = 0, pressure_mpa = 0;
  double k_x = 0, k_y = 0;                   ///< spring structure, N/mm (as the thesis writes them)
  double bushing_k_xz = 0, bushing_k_y = 0;  ///< k'x = k'z = 4 k_x, k'y = 4 k_y (N/mm)
  double bushing_m_xz_per_deg = 0, bushing_m_y_per_deg = 0;  ///< M'x = M'z, M'y (N·mm/deg)
};
/// `length_scale` scales appendix C's geometry (areas by its square, the volume by its cube) for
/// a subject's body; the pressure stays.
IapStiffness iap_from_appendix_c(const std::string& appendix_c_json_path,
                                 double length_scale = 1.0);

enum class Sex { Male, Female };
/// "male", "female".
const char* sex_name(Sex sex);
/// The inverse of sex_name; throws std::invalid_argument listing the names.
Sex parse_sex(const std::string& name);

/// The body the spine belongs to (spine/README.md, "A spine for a given body"). A zero height or
/// mass is the reference body's (spine_model.json: the thesis's GeBod median male, 1.778 m and
/// 70 kg), and the reference body's model is the tables' own, bit for bit.
struct Subject {
  double height_m = 0;
  double body_mass_kg = 0;
  Sex sex = Sex::Male;
};

/// A scoliotic curve (scoliosis.hpp): none while cobb_deg is 0.
struct ScoliosisCurve {
  std::string type = "custom";  ///< thoracic, thoracolumbar, lumbar (scoliosis_curve) or custom
  double cobb_deg = 0;          ///< between the end vertebrae's outer endplates
  std::string upper_end, apex, lower_end;  ///< vertebra names (T1 … L5)
  double apical_rotation_deg = 0;  ///< the apex's axial turn toward the convexity, vs the ends
  bool convex_right = true;        ///< the convexity on the body's right (−x)
};

/// `subject` with a zero height or mass replaced by the reference body's, checked against the
/// range the scaling laws are applied to (std::invalid_argument, one line, when outside).
Subject resolve_subject(const std::string& data_dir, Subject subject);

/// A sourced body by name (spine_model.json "anthropometry.bodies": reference, p5-female,
/// p95-male), with where its stature and mass come from.
struct NamedBody {
  std::string name, source;
  Subject subject;
};
/// Every named body, shortest first; each one resolved and checked like any subject.
std::vector<NamedBody> named_bodies(const std::string& data_dir);
/// The named body `name`; std::invalid_argument listing the names when there is none.
NamedBody named_body(const std::string& data_dir, const std::string& name);

/// Segment masses of one sex, % of body mass (de Leva 1996; spine_model.json "anthropometry").
struct SegmentMassPercent {
  double trunk = 0, head_neck = 0, arm_each = 0, pelvis = 0, forearm_hand_each = 0;
};

/// How a subject's model differs from the reference body's.
struct SubjectScale {
  double length = 1;      ///< every length: height / reference height (geometric similarity)
  double mass = 1;        ///< body mass / reference mass
  double muscle = 1;      ///< every pCSA: muscle volume ratio (Handsfield 2014) / length
  double trunk_mass = 1;  ///< per-level trunk masses: this sex's trunk % / the male's
};

/// Whether the F.6/F.7 ligaments are elements of the model. Table F.4's joint springs are
/// Schultz & Ashton-Miller's (1991) whole motion segments, ligaments and facets included, so
/// adding the ligaments to them counts them twice (the thesis did). `Auto` adds them only where
/// the joint springs are discs alone (ModelOptions::disc_joints).
enum class Ligaments {
  Auto,  ///< with disc joints, none with F.4 (the default)
  On,    ///< always; with F.4 this is the thesis's model, which counts them twice
  Off,   ///< never
};
/// "auto", "on", "off" (the CLI's and the study files' names).
const char* ligaments_name(Ligaments l);
/// The inverse of ligaments_name; throws std::invalid_argument listing the names.
Ligaments parse_ligaments(const std::string& name);

struct ModelOptions {
  std::vector<int> fused_joints;  ///< joint indices (parse_fusion)
  Ligaments ligaments = Ligaments::Auto;
  bool muscles = true, iap = true, gravity = true;
  /// The LifeMOD default trunk muscles appendix F names without data (thoracic erector spinae, rectus
  /// abdominis), restored in data/spine/trunk_muscles.csv; false: the F.8-F.19 lumbar muscles only.
  bool trunk_muscles = true;
  bool arms_forward = false;  ///< arms reaching forward (crate case) instead of hanging
  /// The rib cage on the twelve thoracic vertebrae (rib_cage.hpp); false: none (the thesis's
  /// model, whose thoracic spine is its F.4 joints alone).
  bool rib_cage = false;
  Subject subject;            ///< the body (default: the reference body)
  /// A scoliotic spine: its joints rest in the curve's posture (scoliosis.hpp). Not with the
  /// rib cage (its scoliotic shape is not modelled).
  ScoliosisCurve scoliosis;
  /// A disc-joint stiffness file (`spinesim spine disc-joints`; data/spine/disc_joints/): each
  /// joint's spring becomes that level's disc 3×3 rotational stiffness about the joint point, in
  /// place of F.4. A preset name (file stem in data/spine/disc_joints/) or a path; empty: F.4.
  std::string disc_joints;
  /// Muscle activity the recruitment does not choose (the standing-gap mechanisms; 0: none,
  /// the thesis's static optimisation). co_contraction: every muscle's activation is at least
  /// this, and the criterion counts it; muscle_tone: every muscle carries this activation as
  /// resting tone, and the criterion counts only what is recruited above it. Fractions of each
  /// muscle's maximum force, 0 … 0.5.
  double co_contraction = 0, muscle_tone = 0;
  /// The model's uncertain inputs, for sensitivity studies (1: the tables' values), each within
  /// kInputScaleRange: every muscle's maximum stress (its strength), every joint's rotational
  /// stiffness (F.4's, or the disc joints' with their coupling) and every F.6/F.7 ligament's
  /// stiffness (when the model has them; ligaments).
  double muscle_strength = 1, joint_stiffness = 1, ligament_stiffness = 1;
  /// The standing posture's forward inclination, deg (kInclinationRangeDeg): the whole body
  /// above the hips pitched forward about the lateral axis, so that in the pelvis's frame, the
  /// model's, gravity turns forward by this angle (it pulls along (0, −cos φ, sin φ)). The spine
  /// itself keeps its shape; external loads stay in the model's frame. 0: upright, the thesis's.
  double inclination_deg = 0;
};

/// The range of ModelOptions' input scales (muscle_strength, joint_stiffness,
/// ligament_stiffness), and of inclination_deg.
inline constexpr double kInputScaleRange[2] = {0.1, 10};
inline constexpr double kInclinationRangeDeg[2] = {-30, 90};

/// Makes `m` rest in the scoliotic curve options.scoliosis (scoliosis.hpp): the joints' springs,
/// the ligaments' slack lengths and the IAP bushing are stress-free in its posture, and
/// rest_posture is that posture. load_spine_model calls it; throws std::invalid_argument (one
/// line) for a curve the model cannot pose or together with the rib cage.
struct SpineModel;
void rest_in_scoliosis(SpineModel& m, const ModelOptions& options);

/// Does a model built with these options carry the F.6/F.7 ligaments? (Ligaments::Auto: only
/// on disc joints.)
bool has_ligaments(const ModelOptions& options);

/// Reads a disc-joint file into the joints (every joint must be there, each 3×3 symmetric
/// positive definite and finite). Throws std::invalid_argument with one line otherwise.
void apply_disc_joints(std::vector<Joint>& joints, const std::string& name_or_path,
                       const std::string& data_dir);

struct SpineModel {
  std::vector<Vertebra> vertebrae;  ///< 17, T1…L5
  std::vector<Joint> joints;        ///< 17, T1-T2…L5-S1
  std::vector<Ligament> ligaments;
  std::vector<Muscle> muscles;
  bool has_bushing = false;
  Bushing bushing;  ///< IAP: rib cage (T6) to pelvis
  IapStiffness iap;
  std::vector<PointLoad>
      weights;  ///< gravity on vertebrae, head+neck, arms (empty without gravity)
  /// The back's contact points and the surface they press on (none: no contact; seating.hpp).
  std::vector<ContactPoint> contacts;
  std::shared_ptr<const ContactSurface> contact_surface;
  std::vector<int> recruited_joints;  ///< joints whose equilibrium the muscles are recruited for
  double muscle_q = 10;               ///< short-range stiffness factor (k = q F / L0)
  /// The muscles' least activation and its unrecruited part (ModelOptions::co_contraction,
  /// muscle_tone; recruit() uses max(floor, tone) as the lower bound).
  double muscle_floor = 0, muscle_tone = 0;
  double rom_bump_factor = 100;       ///< joint stiffness multiplier beyond the F.5 range
  double rom_bump_onset = 0;          ///< rad over which the bump's stiffness ramps up (C² energy)
  double body_mass_kg = 70, gravity_mm_s2 = 9810;
  Subject subject;                          ///< resolved: height and mass filled in
  SubjectScale scale;                       ///< applied to the reference body's tables
  SegmentMassPercent segment_mass_percent;  ///< the subject's sex's
  /// The rib cage (rib_cage.hpp; ModelOptions::rib_cage), or none.
  std::shared_ptr<const RibCage> rib_cage;
  /// The joints' stress-free posture (rad, 3 per joint; empty: θ = 0, the thesis's upright
  /// spine): a scoliotic curve (ModelOptions::scoliosis). Recruitment and Newton start there.
  Eigen::VectorXd rest_posture;
  ScoliosisCurve scoliosis;  ///< the curve that made rest_posture (cobb_deg 0: none)
  Eigen::Vector3d chest_front_mm;  ///< for loads held "in front of the chest"
  int ribs_body = 5;               ///< T6
  std::string data_dir;
};

/// Builds the model from `data_dir` (thesis/ tables, disc_morphometry.csv, spine/spine_model.json),
/// scaled to options.subject. Throws std::runtime_error naming the file for missing or malformed
/// data, std::invalid_argument for a subject outside the scaling laws' range.
SpineModel load_spine_model(const std::string& data_dir,
                            const ModelOptions& options = ModelOptions());

/// Number of joint coordinates (3 per joint, fused joints included and held at zero).
inline int dof_count(const SpineModel& m) { return 3 * int(m.joints.size()); }

}  // namespace spinesim::spine
