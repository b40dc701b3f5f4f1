// The scoliotic rest posture: the Cobb angle measured independently on the posed end vertebrae
// equals the asked one, T1 ends level and over the sacrum, the apex bulges to the convex side
// and turns toward it, left and right curves are mirror images, the spine rests in its curve
// without load, and curves the model cannot pose are refused.
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/kinematics.hpp"
#include "spinesim/spine/scoliosis.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sp = spinesim::spine;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

sp::SpineModel plain() {
  sp::ModelOptions o;
  o.gravity = o.muscles = o.iap = false;
  return sp::load_spine_model(SPINESIM_DATA_DIR, o);
}

/// The angle between two vertebrae's endplates in the frontal plane (their lateral axes R·x
/// projected onto x–y), deg: the radiograph's Cobb angle.
double endplate_angle_deg(const sp::Pose& a, const sp::Pose& b) {
  Vector3d u = a.R.col(0), v = b.R.col(0);
  u.z() = v.z() = 0;
  return std::acos(std::clamp(u.normalized().dot(v.normalized()), -1.0, 1.0)) * 180 / M_PI;
}

}  // namespace

TEST(Scoliosis, EveryCurveTypeHasItsCobbAngleAndABalancedT1) {
  const auto m = plain();
  for (const auto& type : sp::scoliosis_curve_types())
    for (double cobb : {15.0, 35.0, 55.0}) {
      sp::ScoliosisCurve c = sp::scoliosis_curve(type, cobb);
      c.apical_rotation_deg = 0.4 * cobb;
      const sp::ScoliosisPosture p = sp::scoliotic_posture(m, c);
      const auto P = sp::vertebra_poses(m, p.theta);
      const double measured = endplate_angle_deg(P[std::size_t(sp::vertebra_index(c.upper_end))],
                                                 P[std::size_t(sp::vertebra_index(c.lower_end))]);
      EXPECT_NEAR(measured, cobb, 1e-6) << type << " " << cobb;
      EXPECT_NEAR(p.cobb_deg, cobb, 1e-6) << type;
      EXPECT_NEAR(p.t1_tilt_deg, 0, 1e-6) << type;
      EXPECT_NEAR(p.t1_offset_mm, 0, 1e-4) << type;
      // The apex bulges to the convex side (the body's right is −x) and turns toward it.
      const double side = c.convex_right ? -1 : 1;
      EXPECT_GT(side * p.apex_offset_mm, 0.05 * cobb) << type << " " << cobb;
      EXPECT_NEAR(p.apical_rotation_deg, c.apical_rotation_deg, 0.1 * c.apical_rotation_deg)
          << type;
      EXPECT_LE(p.largest_share, 1.0);
    }
}

TEST(Scoliosis, ALeftCurveIsTheMirrorImageOfTheRightOne) {
  const auto m = plain();
  sp::ScoliosisCurve right = sp::scoliosis_curve("thoracic", 40);
  right.apical_rotation_deg = 12;
  sp::ScoliosisCurve left = right;
  left.convex_right = false;
  const VectorXd a = sp::scoliotic_posture(m, right).theta,
                 b = sp::scoliotic_posture(m, left).theta;
  for (int k = 0; k < 17; ++k) {
    EXPECT_NEAR(a[3 * k], b[3 * k], 1e-12);          // no flexion either way
    EXPECT_NEAR(a[3 * k + 1], -b[3 * k + 1], 1e-9);  // torsion mirrored
    EXPECT_NEAR(a[3 * k + 2], -b[3 * k + 2], 1e-9);  // lateral bending mirrored
  }
}

// The joints, ligaments and bushing rest in the curve: unloaded, the spine stays in it.
TEST(Scoliosis, TheUnloadedSpineRestsInItsCurve) {
  sp::ModelOptions o;
  o.gravity = o.muscles = false;  // the IAP bushing stays
  o.ligaments = sp::Ligaments::On;
  o.scoliosis = sp::scoliosis_curve("thoracolumbar", 40);
  o.scoliosis.apical_rotation_deg = 15;
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  ASSERT_EQ(m.rest_posture.size(), sp::dof_count(m));
  VectorXd g;
  const double energy = sp::potential(m, {}, VectorXd(), m.rest_posture, &g);
  EXPECT_NEAR(energy, 0, 1e-9);
  EXPECT_LT(g.cwiseAbs().maxCoeff(), 1e-9);
  sp::SolveOptions so;
  so.recruit = false;
  const sp::SpineSolution s = sp::solve_spine(m, {}, so);
  EXPECT_LT((s.theta - m.rest_posture).cwiseAbs().maxCoeff(), 1e-9);
  // Loaded, it bends from its curve and comes back: a push on T1 moves T1.
  sp::ExternalLoad push;
  push.vertebra = 0;
  push.force_n = Vector3d(0, 0, 100);
  const sp::SpineSolution pushed = sp::solve_spine(m, {push}, so);
  EXPECT_GT((pushed.theta - m.rest_posture).norm(), 1e-3);
}

TEST(Scoliosis, CurvesTheModelCannotPoseAreRefused) {
  const auto m = plain();
  auto refused = [&](const sp::ScoliosisCurve& c, const char* what) {
    try {
      sp::scoliotic_posture(m, c);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  refused(sp::scoliosis_curve("thoracic", 0), "Cobb");
  refused(sp::scoliosis_curve("thoracic", 130), "Cobb");
  // 100° over the lumbar curve's four joints closes a disc.
  refused(sp::scoliosis_curve("lumbar", 100), "closes its disc");
  sp::ScoliosisCurve c = sp::scoliosis_curve("thoracic", 30);
  c.apex = "T12";
  refused(c, "apex");
  c = sp::scoliosis_curve("thoracic", 30);
  std::swap(c.upper_end, c.lower_end);
  refused(c, "end vertebra");
  c = sp::scoliosis_curve("thoracic", 30);
  c.apical_rotation_deg = 60;
  refused(c, "rotation");
  EXPECT_THROW(sp::scoliosis_curve("double", 30), std::invalid_argument);
  sp::ModelOptions o;
  o.rib_cage = true;
  o.scoliosis = sp::scoliosis_curve("thoracic", 30);
  EXPECT_THROW(sp::load_spine_model(SPINESIM_DATA_DIR, o), std::invalid_argument);
}

// The joints carry their discs' sections (disc_morphometry.csv), scaled with the body like every
// other length: the closing angles of the refusal above do not depend on the body.
TEST(Scoliosis, EachJointCarriesItsDiscScaledWithTheBody) {
  const auto m = plain();
  sp::ModelOptions o;
  o.gravity = o.muscles = o.iap = false;
  o.subject.height_m = 1.6;
  const auto small = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  const double s = 1.6 / 1.778;
  for (std::size_t k = 0; k < m.joints.size(); ++k) {
    EXPECT_GT(m.joints[k].disc_height_mm, 2) << m.joints[k].name;
    EXPECT_GT(m.joints[k].disc_width_mm, 20) << m.joints[k].name;
    EXPECT_GT(m.joints[k].disc_width_mm, m.joints[k].disc_depth_mm) << m.joints[k].name;
    EXPECT_NEAR(small.joints[k].disc_height_mm, s * m.joints[k].disc_height_mm, 1e-12);
    EXPECT_NEAR(small.joints[k].disc_width_mm, s * m.joints[k].disc_width_mm, 1e-12);
    EXPECT_NEAR(small.joints[k].disc_depth_mm, s * m.joints[k].disc_depth_mm, 1e-12);
  }
}
