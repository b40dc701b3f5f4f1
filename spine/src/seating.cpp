// The seated spine (seating.hpp; docs/seating.md).
#include "spinesim/spine/seating.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/spine/kinematics.hpp"

#include "json_fields.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace spinesim::spine {
namespace {
using detail::number;
using detail::vec3;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kTopRadiusMm = 50;  // the parametric backrest's rounded top edge

/// Posterior pelvic tilt by `deg`: rotation about x carrying superior (y) towards posterior (−z).
Matrix3d tilt(double deg) {
  return Eigen::AngleAxisd(-deg * kRadPerDeg, Vector3d::UnitX()).matrix();
}

bool lumbar_joint(const std::string& name) {
  return name == "L1-L2" || name == "L2-L3" || name == "L3-L4" || name == "L4-L5" ||
         name == "L5-S1";
}

/// The parametric backrest: a plane through the seat reference point at the recline angle, its top
/// rounded back over kTopRadiusMm, and a cosine lumbar pad. φ = n·x − pad(s) (+ the rounding
/// above the top), s = t·x the distance along the backrest; C¹ everywhere.
class ParametricBackrest : public ContactSurface {
 public:
  explicit ParametricBackrest(const Chair& c)
      : t_(0, std::sin(c.backrest_recline_deg * kRadPerDeg),
           std::cos(c.backrest_recline_deg * kRadPerDeg)),
        n_(0, -std::cos(c.backrest_recline_deg * kRadPerDeg),
           std::sin(c.backrest_recline_deg * kRadPerDeg)),
        height_(c.backrest_height_mm),
        depth_(c.lumbar_support_mm),
        centre_(c.lumbar_support_height_mm),
        half_(c.lumbar_support_half_length_mm) {}

  double level(const Vector3d& x, Vector3d& grad) const override {
    const double s = t_.dot(x);
    double phi = n_.dot(x);
    grad = n_;
    if (depth_ > 0 && std::abs(s - centre_) < half_) {  // the pad stands out of the plane
      const double a = kPi * (s - centre_) / half_;
      phi -= 0.5 * depth_ * (1 + std::cos(a));
      grad += 0.5 * depth_ * std::sin(a) * (kPi / half_) * t_;
    }
    if (s > height_) {  // above the top the surface curves away behind
      phi += (s - height_) * (s - height_) / (2 * kTopRadiusMm);
      grad += (s - height_) / kTopRadiusMm * t_;
    }
    return phi;
  }
  bool mirror_symmetric() const override { return true; }

 private:
  Vector3d t_, n_;
  double height_, depth_, centre_, half_;
};

/// A chair-frame surface seen from the pelvis frame: X ↦ R (X − I) + I_w.
class PlacedSurface : public ContactSurface {
 public:
  PlacedSurface(std::shared_ptr<const ContactSurface> s, const Matrix3d& R, const Vector3d& I,
                const Vector3d& Iw)
      : s_(std::move(s)), R_(R), I_(I), Iw_(Iw) {}
  double level(const Vector3d& X, Vector3d& grad) const override {
    Vector3d g;
    const double phi = s_->level(R_ * (X - I_) + Iw_, g);
    grad = R_.transpose() * g;
    return phi;
  }
  bool mirror_symmetric() const override { return s_->mirror_symmetric(); }

 private:
  std::shared_ptr<const ContactSurface> s_;
  Matrix3d R_;
  Vector3d I_, Iw_;
};

void check_range(double v, double lo, double hi, const std::string& what) {
  if (!(v >= lo && v <= hi)) {
    std::ostringstream msg;
    msg << "chair: " << what << " = " << v << " is outside " << lo << " … " << hi;
    throw std::invalid_argument(msg.str());
  }
}

/// The back's contact points: behind each vertebra's spinous-process tip by the soft tissue, and
/// the skin over the sacrum (on the pelvis).
void add_back_points(const SpineModel& standing, const Sitter& sitter, SpineModel& m) {
  if (sitter.interspinous_z_mm.size() != standing.vertebrae.size())
    throw std::invalid_argument("seating: the sitter's posterior-element geometry is for " +
                                std::to_string(sitter.interspinous_z_mm.size()) +
                                " vertebrae, the model has " +
                                std::to_string(standing.vertebrae.size()));
  for (std::size_t i = 0; i < standing.vertebrae.size(); ++i) {
    const Vertebra& v = standing.vertebrae[i];
    const bool lumbar = v.name[0] == 'L';
    const double isl_z = sitter.interspinous_z_mm[i];
    const double tip =
        isl_z - 0.5 * (lumbar ? sitter.spinous_lumbar_mm : sitter.spinous_thoracic_mm);
    const double tissue = lumbar ? sitter.tissue_lumbar_mm : sitter.tissue_thoracic_mm;
    m.contacts.push_back({v.name, int(i), Vector3d(0, v.centre_mm.y(), tip - tissue),
                          sitter.tissue_stiffness_n_per_mm});
  }
  m.contacts.push_back({"sacrum", kGround, standing.joints.back().point_mm + sitter.sacrum_back_mm,
                        sitter.tissue_stiffness_n_per_mm});
}

/// The back's contact points at the seated posture (pelvis frame, no deformation beyond it).
std::vector<Vector3d> contact_points_at_posture(const SeatedModel& sm) {
  const std::vector<Pose> P = vertebra_poses(sm.model, sm.posture);
  std::vector<Vector3d> out;
  for (const ContactPoint& c : sm.model.contacts) out.push_back(place(P, c.body, c.point_mm));
  return out;
}

/// One lean: the seated equilibrium with the recruitment's contact forces iterated to the
/// equilibrium's own, and the moment of everything on the body about the ischia (x, N·mm).
struct LeanState {
  SeatedModel seated;
  SpineSolution spine;
  double moment_nmm = 0;
  int rounds = 0;
};

/// The pelvis's weight in the pelvis frame (de Leva's lower-trunk share of the body mass).
Vector3d pelvis_weight(const SeatedModel& sm, const Sitter& sitter) {
  const SpineModel& m = sm.model;
  const double n = sitter.pelvis_mass_percent / 100 * m.body_mass_kg * m.gravity_mm_s2 / 1000;
  return sm.rotation.transpose() * Vector3d(0, -n, 0);
}

double moment_about_ischia(const SeatedModel& sm, const Sitter& sitter,
                           const std::vector<ExternalLoad>& loads, const SpineSolution& sol) {
  const SpineModel& m = sm.model;
  const Vector3d I = m.joints.back().point_mm + sitter.ischia_mm;
  const auto& P = sol.poses;
  Vector3d M = Vector3d::Zero();
  for (const PointLoad& w : m.weights) M += (place(P, w.body, w.point_mm) - I).cross(w.force_n);
  for (const ExternalLoad& l : loads) {
    const Vector3d X = l.has_point ? l.point_mm : m.vertebrae[std::size_t(l.vertebra)].centre_mm;
    M += (place(P, l.vertebra, X) - I).cross(l.force_n) + l.moment_nmm;
  }
  for (std::size_t i = 0; i < m.contacts.size(); ++i)
    M += (sol.contact_point_mm[i] - I).cross(sol.contact_force_n[i]);
  M += (m.joints.back().point_mm + sitter.pelvis_com_mm - I).cross(pelvis_weight(sm, sitter));
  return M.x();
}

LeanState solve_lean(const SpineModel& standing, const Chair& chair, const Sitter& sitter,
                     const std::vector<ExternalLoad>& loads, const SeatingOptions& o,
                     double tilt_deg, double ischia_forward_mm, int& solves) {
  LeanState st;
  st.seated = seat_model(standing, chair, sitter, tilt_deg, ischia_forward_mm);
  SolveOptions so = o.solve;
  so.posture = st.seated.posture;
  std::vector<Vector3d> assumed;  // first round: the contact forces of the posture itself
  VectorXd previous;
  double omega = o.contact_relaxation;
  for (st.rounds = 1;; ++st.rounds) {
    so.recruitment_contact_forces = assumed;
    st.spine = solve_spine(st.seated.model, loads, so);
    ++solves;
    const auto& found = st.spine.contact_force_n;
    double change = 0;
    for (std::size_t i = 0; i < found.size() && !assumed.empty(); ++i)
      change = std::max(change, (found[i] - assumed[i]).norm());
    const bool settled = !assumed.empty() && change <= o.contact_tolerance_n;
    if (settled || !so.recruit || found.empty()) break;
    if (st.rounds >= o.max_contact_iterations) {
      std::ostringstream msg;
      msg << "seated equilibrium: the contact forces did not settle in " << st.rounds
          << " rounds of recruitment (last change " << change << " N)";
      throw SolveError(msg.str());
    }
    if (assumed.empty()) {
      assumed = found;
      continue;
    }
    // Relaxed fixed point on the contact forces, its factor adapted by Aitken's Δ² (Irons &
    // Tuck 1969): ω ← −ω r_{k−1}·(r_k − r_{k−1}) / |r_k − r_{k−1}|², r = found − assumed.
    VectorXd r(3 * Eigen::Index(found.size()));
    for (std::size_t i = 0; i < found.size(); ++i)
      r.segment<3>(3 * Eigen::Index(i)) = found[i] - assumed[i];
    if (previous.size() == r.size()) {
      const VectorXd dr = r - previous;
      if (dr.squaredNorm() > 0)
        omega = std::clamp(-omega * previous.dot(dr) / dr.squaredNorm(), 0.05, 1.0);
    }
    previous = r;
    for (std::size_t i = 0; i < found.size(); ++i)
      assumed[i] += omega * r.segment<3>(3 * Eigen::Index(i));
  }
  st.moment_nmm = moment_about_ischia(st.seated, sitter, loads, st.spine);
  return st;
}

}  // namespace

Sitter load_sitter(const SpineModel& model) {
  const std::string file = model.data_dir + "/spine/seating.json";
  const nlohmann::json j = detail::read_json(file);
  Sitter s;
  s.pelvic_tilt_deg = number(j, "pelvic_tilt_deg", file);
  s.lumbar_flexion_deg = number(j, "lumbar_flexion_deg", file);
  s.seat_pelvis_coupling = number(j, "seat_pelvis_coupling", file);
  // The body's points scale with the subject as the spine's do (spine/README.md); the soft
  // tissue's thickness does not (it is fat and skin, not skeleton).
  const double length = model.scale.length;
  s.ischia_mm = vec3(j, "ischia_mm", file) * length;
  s.sacrum_back_mm = vec3(j, "sacrum_back_mm", file) * length;
  s.tissue_thoracic_mm = number(j.at("tissue_thickness_mm"), "thoracic", file);
  s.tissue_lumbar_mm = number(j.at("tissue_thickness_mm"), "lumbar", file);
  s.tissue_stiffness_n_per_mm = number(j, "tissue_stiffness_n_per_mm", file);
  s.pelvis_mass_percent = model.segment_mass_percent.pelvis;
  s.pelvis_com_mm = vec3(j, "pelvis_com_mm", file) * length;
  s.forearm_hand_percent_each = model.segment_mass_percent.forearm_hand_each;
  const std::string model_file = model.data_dir + "/spine/spine_model.json";
  const nlohmann::json lengths =
      detail::read_json(model_file).at("ligaments").at("spinous_length_mm");
  s.spinous_thoracic_mm = number(lengths, "thoracic", model_file) * length;
  s.spinous_lumbar_mm = number(lengths, "lumbar", model_file) * length;
  // The posterior elements' geometry is the ligaments' (spine_model.json): a model built without
  // ligaments takes it from one built with them.
  SpineModel with_ligaments;
  const SpineModel* geometry = &model;
  if (model.ligaments.empty()) {
    ModelOptions geometry_options;
    geometry_options.ligaments = Ligaments::On;
    geometry_options.subject = model.subject;
    with_ligaments = load_spine_model(model.data_dir, geometry_options);
    geometry = &with_ligaments;
  }
  for (std::size_t i = 0; i < model.vertebrae.size(); ++i) {
    // The interspinous ligament leaves the vertebra halfway along its spinous process.
    double isl_z = NAN;
    for (const Ligament& l : geometry->ligaments)
      if (l.type == "ISL" && l.body_a == int(i)) isl_z = l.a_mm.z();
    if (std::isnan(isl_z))
      throw std::runtime_error("seating: no interspinous ligament geometry for " +
                               model.vertebrae[i].name);
    s.interspinous_z_mm.push_back(isl_z);
  }
  const auto& lean = j.at("lean_range_deg");
  if (!lean.is_array() || lean.size() != 2 || !lean[0].is_number() || !lean[1].is_number())
    throw std::runtime_error(file + ": lean_range_deg must be [min, max]");
  s.lean_min_deg = lean[0].get<double>();
  s.lean_max_deg = lean[1].get<double>();
  if (!(s.tissue_stiffness_n_per_mm > 0) || !(s.tissue_thoracic_mm >= 0) ||
      !(s.tissue_lumbar_mm >= 0) || !(s.lean_min_deg < s.lean_max_deg) ||
      !(std::abs(s.pelvic_tilt_deg) < 60) || !(std::abs(s.lumbar_flexion_deg) < 60))
    throw std::runtime_error(file + ": tissue stiffness must be > 0, thicknesses >= 0, " +
                             "the lean range increasing, tilt and flexion within 60 deg");
  // The lost lordosis, shared by L1-L2 … L5-S1 in proportion to their flexion range (F.5).
  double total = 0;
  for (const Joint& jt : model.joints) total += lumbar_joint(jt.name) ? jt.rom_flexion : 0;
  for (const Joint& jt : model.joints)
    s.lumbar_share.push_back(lumbar_joint(jt.name) && total > 0 ? jt.rom_flexion / total : 0);
  return s;
}

void check_chair(const Chair& c) {
  check_range(c.seat_angle_deg, -30, 30, "seat angle (deg)");
  check_range(c.backrest_recline_deg, 60, 150, "backrest recline (deg)");
  check_range(c.backrest_height_mm, 0, 1500, "backrest height (mm)");
  check_range(c.lumbar_support_mm, 0, 150, "lumbar support depth (mm)");
  check_range(c.lumbar_support_half_length_mm, 10, 500, "lumbar support half length (mm)");
  check_range(c.lumbar_support_height_mm, 0, 1500, "lumbar support height (mm)");
  if (c.lumbar_support_mm > 0 && !c.surface && c.lumbar_support_height_mm > c.backrest_height_mm)
    throw std::invalid_argument("chair: the lumbar support (" +
                                std::to_string(int(c.lumbar_support_height_mm)) +
                                " mm up) is above the backrest's top (" +
                                std::to_string(int(c.backrest_height_mm)) + " mm)");
}

std::shared_ptr<const ContactSurface> parametric_backrest(const Chair& chair) {
  check_chair(chair);
  return std::make_shared<ParametricBackrest>(chair);
}

SeatedModel seat_model(const SpineModel& standing, const Chair& chair, const Sitter& sitter,
                       double tilt_deg, double ischia_forward_mm) {
  SeatedModel out;
  out.model = standing;
  SpineModel& m = out.model;
  out.rotation = tilt(tilt_deg);
  const double a = chair.seat_angle_deg * kRadPerDeg;
  out.ischia_world_mm = ischia_forward_mm * Vector3d(0, std::sin(a), std::cos(a));
  const Vector3d I = standing.joints.back().point_mm + sitter.ischia_mm;
  // Gravity keeps pointing down in the chair: in the pelvis frame it turns with the tilt.
  const Matrix3d to_pelvis = out.rotation.transpose();
  const double forearm_n =
      sitter.forearm_hand_percent_each / 100 * m.body_mass_kg * m.gravity_mm_s2 / 1000;
  for (PointLoad& w : m.weights) {
    if (chair.armrests && w.name.find("arm weight") != std::string::npos)
      w.force_n.y() = std::min(0.0, w.force_n.y() + forearm_n);  // the armrest holds the forearm
    w.force_n = to_pelvis * w.force_n;
  }
  add_back_points(standing, sitter, m);
  std::shared_ptr<const ContactSurface> back =
      chair.surface ? chair.surface
                    : (chair.backrest_height_mm > 0 ? parametric_backrest(chair) : nullptr);
  if (back)
    m.contact_surface = std::make_shared<PlacedSurface>(back, out.rotation, I, out.ischia_world_mm);
  // A scoliotic spine sits in its curve: the seated flexion adds to its rest posture.
  out.posture = m.rest_posture.size() ? m.rest_posture : VectorXd::Zero(dof_count(m));
  for (std::size_t k = 0; k < m.joints.size(); ++k)
    out.posture[3 * Eigen::Index(k)] +=
        sitter.lumbar_flexion_deg * kRadPerDeg * sitter.lumbar_share[k];
  // The IAP bushing stands for the abdomen's pressure, not for an elastic memory of standing:
  // seated, the abdomen settles into the sitting posture and the bushing rests there (stress-free
  // at standing, its appendix C stiffness would hold the ribs 1 kN up and 55 N·m back against the
  // 16.6° of flattened lordosis).
  if (m.has_bushing) {
    const Pose ribs = vertebra_poses(m, out.posture)[std::size_t(m.bushing.body)];
    m.bushing.rest_rotation = ribs.R;
    m.bushing.rest_translation_mm = ribs.t;
  }
  return out;
}

namespace {

/// A backrest faces the sitter: its level rises forward (+z in the chair) where the back is.
void check_facing(const SeatedModel& sm) {
  if (!sm.model.contact_surface) return;
  double forward = 0;
  for (const Vector3d& x : contact_points_at_posture(sm)) {
    Vector3d g;
    sm.model.contact_surface->level(x, g);
    forward += (sm.rotation * g).z();
  }
  if (!(forward > 0))
    throw std::invalid_argument(
        "chair: the backrest surface does not face the back (its normals point away from the "
        "sitter; reverse the triangles' winding)");
}

/// How far in front of the seat reference point the ischia rest at pelvic tilt `tilt_deg`: the
/// sitter sits back until the back first touches the backrest (never behind the seat's end).
/// Moving the body d along the seat moves its points by Rᵀ u d in the pelvis frame.
double slide_back(const SpineModel& standing, const Chair& chair, const Sitter& sitter,
                  double tilt_deg) {
  const SeatedModel sm = seat_model(standing, chair, sitter, tilt_deg, 0);
  if (!sm.model.contact_surface) return 0;
  const std::vector<Vector3d> points = contact_points_at_posture(sm);
  const double a = chair.seat_angle_deg * kRadPerDeg;
  const Vector3d shift = sm.rotation.transpose() * Vector3d(0, std::sin(a), std::cos(a));
  auto gap = [&](double d) {
    double g = INFINITY;
    Vector3d grad;
    for (const Vector3d& x : points)
      g = std::min(g, sm.model.contact_surface->level(x + d * shift, grad));
    return g;
  };
  if (gap(0) >= 0) return 0;
  double lo = 0, hi = 1000;
  if (gap(hi) < 0)
    throw std::invalid_argument(
        "chair: the backrest is in front of the sitter's back even 1 m forward of the seat's "
        "end; does the surface face the back?");
  for (int it = 0; it < 60 && hi - lo > 0.01; ++it)
    (gap(0.5 * (lo + hi)) < 0 ? lo : hi) = 0.5 * (lo + hi);
  return hi;
}

/// The seat reaction from the pelvis's own free body, chair frame: it balances the pelvis's weight,
/// the sacral contact and what the spine does to the pelvis (the L5-S1 reaction, the pull of every
/// muscle and ligament anchored on it, the IAP bushing).
Vector3d seat_from_pelvis(const SeatedModel& sm, const Sitter& sitter, const SpineSolution& sol) {
  const SpineModel& m = sm.model;
  const auto& P = sol.poses;
  Vector3d f = -sol.joints.back().force_world_n;  // the spine's push on the sacrum
  auto anchored = [&](const Line& l, double T) {
    if ((l.body_a == kGround) == (l.body_b == kGround)) return;
    const Vector3d xa = place(P, l.body_a, l.a_mm), xb = place(P, l.body_b, l.b_mm);
    const Vector3d towards_b = (xb - xa).normalized();
    f += l.body_a == kGround ? Vector3d(T * towards_b) : Vector3d(-T * towards_b);
  };
  for (std::size_t i = 0; i < m.muscles.size(); ++i)
    anchored(m.muscles[i], sol.muscle_force_n[Eigen::Index(i)]);
  for (std::size_t i = 0; i < m.ligaments.size(); ++i)
    anchored(m.ligaments[i], sol.ligament_force_n[Eigen::Index(i)]);
  if (m.has_bushing) f -= sol.bushing_wrench.head<3>();
  for (std::size_t i = 0; i < m.contacts.size(); ++i)
    if (m.contacts[i].body == kGround) f += sol.contact_force_n[i];
  f += pelvis_weight(sm, sitter);
  return -(sm.rotation * f);
}

void fill_result(const LeanState& st, const Chair& chair, const Sitter& sitter,
                 const std::vector<ExternalLoad>& loads, SeatedSolution& out) {
  const SeatedModel& sm = st.seated;
  const SpineModel& m = sm.model;
  const Matrix3d& R = sm.rotation;
  out.spine = st.spine;
  out.rotation = R;
  out.ischia_world_mm = sm.ischia_world_mm;
  const Vector3d I = m.joints.back().point_mm + sitter.ischia_mm;
  auto to_chair = [&](const Vector3d& x) { return Vector3d(R * (x - I) + sm.ischia_world_mm); };
  out.contacts.clear();
  out.backrest_force_n.setZero();
  for (std::size_t i = 0; i < m.contacts.size(); ++i) {
    SeatedContact c;
    c.name = m.contacts[i].name;
    c.force_n = R * st.spine.contact_force_n[i];
    c.point_mm = to_chair(st.spine.contact_point_mm[i]);
    Vector3d g;
    c.gap_mm = m.contact_surface ? m.contact_surface->level(st.spine.contact_point_mm[i], g) : NAN;
    out.backrest_force_n += c.force_n;
    out.contacts.push_back(c);
  }
  const double g_n = m.gravity_mm_s2 / 1000;
  const double forearms_n =
      chair.armrests ? 2 * sitter.forearm_hand_percent_each / 100 * m.body_mass_kg * g_n : 0;
  out.armrest_force_n = Vector3d(0, forearms_n, 0);
  Vector3d weight = R * pelvis_weight(sm, sitter) + Vector3d(0, -forearms_n, 0);
  for (const PointLoad& w : m.weights) weight += R * w.force_n;
  for (const ExternalLoad& l : loads) weight += R * l.force_n;  // carried like a weight
  out.body_weight_n = -weight.y();
  out.seat_force_n = -(weight + out.backrest_force_n + out.armrest_force_n);
  out.force_residual_n = (seat_from_pelvis(sm, sitter, st.spine) - out.seat_force_n).norm();
  const double a = chair.seat_angle_deg * kRadPerDeg;
  const Vector3d across(0, std::cos(a), -std::sin(a));  // the seat pan's normal, up
  const double pressing = out.seat_force_n.dot(across);
  out.seat_friction_needed = (out.seat_force_n - pressing * across).norm() / pressing;
  out.hip_moment_nmm = st.moment_nmm;
  out.vertebra_angle_deg.clear();
  for (const Pose& p : st.spine.poses)
    out.vertebra_angle_deg.push_back(rotation_log(R * p.R).x() / kRadPerDeg);
  out.warnings = st.spine.warnings;
}

}  // namespace

SeatedSolution solve_seated(const SpineModel& standing, const Chair& chair, const Sitter& sitter,
                            const std::vector<ExternalLoad>& loads, const SeatingOptions& o) {
  check_chair(chair);
  Timer timer;
  SeatedSolution out;
  const double tilt0 = sitter.pelvic_tilt_deg + sitter.seat_pelvis_coupling * chair.seat_angle_deg;
  check_facing(seat_model(standing, chair, sitter, tilt0, 0));
  // The sitter sits back until the back touches the backrest, upright; then rolls back on the
  // ischia without sliding (the seat's friction holds the pelvis). Sliding forward to keep the back
  // just touching at every lean was tried: the backrest then carries nothing beyond what the
  // spine's own give presses into it, and no lean up to 45° balances (docs/seating.md).
  const double ischia = slide_back(standing, chair, sitter, tilt0);
  auto at = [&](double lean) {
    return solve_lean(standing, chair, sitter, loads, o, tilt0 + lean, ischia, out.solves);
  };
  LeanState st = at(0);
  out.contact_rounds = st.rounds;
  const bool backrest = bool(st.seated.model.contact_surface);
  double lean = 0;
  if (backrest && std::abs(st.moment_nmm) > o.lean_tolerance_nmm) {
    // March the lean towards the side the moment turns the body, 5° at a time, until it changes
    // sign; then regula falsi (Illinois) inside the bracket.
    const double dir = st.moment_nmm < 0 ? 1.0 : -1.0;  // −x moment: the body tips back
    double a = 0, fa = st.moment_nmm, b = 0, fb = fa;
    LeanState sb = st;
    while (fb * fa > 0) {
      a = b;
      fa = fb;
      b += 5 * dir;
      if (b > sitter.lean_max_deg || b < sitter.lean_min_deg) break;
      sb = at(b);
      fb = sb.moment_nmm;
      ++out.lean_iterations;
    }
    if (fb * fa > 0) {
      if (dir > 0) {
        std::ostringstream msg;
        msg << "chair: the backrest is out of the back's reach: leaning back "
            << sitter.lean_max_deg << " deg beyond the sitting tilt the body still tips back ("
            << sb.moment_nmm / 1000 << " N·m about the ischia)";
        throw std::invalid_argument(msg.str());
      }
      st = sb;  // the backrest pushes the sitter forward even at its most upright: hips hold it
      lean = a;
      out.warnings.push_back("the backrest pushes the sitter forward even leaning " +
                             std::to_string(int(a)) + " deg: the hips hold the rest");
    } else {
      for (int it = 0; it < o.max_lean_iterations; ++it, ++out.lean_iterations) {
        lean = (a * fb - b * fa) / (fb - fa);
        st = at(lean);
        const double fc = st.moment_nmm;
        if (std::abs(fc) <= o.lean_tolerance_nmm || std::abs(b - a) < 1e-3) break;
        if (fc * fb < 0) {
          a = b;
          fa = fb;
        } else {
          fa *= 0.5;  // Illinois: keeps the stale end from stalling the regula falsi
        }
        b = lean;
        fb = fc;
      }
    }
    out.contact_rounds = st.rounds;
  }
  out.lean_deg = lean;
  out.pelvic_tilt_deg = tilt0 + lean;
  out.ischia_forward_mm = st.seated.ischia_world_mm.norm();
  out.lean_balanced = !backrest || std::abs(st.moment_nmm) <= o.lean_tolerance_nmm;
  std::vector<std::string> before = out.warnings;
  fill_result(st, chair, sitter, loads, out);
  out.warnings.insert(out.warnings.begin(), before.begin(), before.end());
  if (backrest && !out.lean_balanced && before.empty())
    out.warnings.push_back("the lean onto the backrest did not balance: " +
                           std::to_string(st.moment_nmm / 1000) + " N·m left for the hips");
  out.seconds = timer.seconds();
  return out;
}

}  // namespace spinesim::spine
