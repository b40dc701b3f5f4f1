// The seated spine: the backrest's level function and the contact forces against finite
// differences, the recruitment's arms at a posture against muscle-length differences, the lean
// balance about the ischia, force balance of body, seat, backrest and armrests, bad chairs.
#include "spinesim/spine/seating.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace sp = spinesim::spine;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

const sp::SpineModel& standing() {
  static const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  return m;
}

const sp::Sitter& sitter() {
  static const sp::Sitter s = sp::load_sitter(standing());
  return s;
}

/// A plane in the chair frame: φ = n·(x − p).
class Plane : public sp::ContactSurface {
 public:
  Plane(Vector3d n, Vector3d p) : n_(n.normalized()), p_(p) {}
  double level(const Vector3d& x, Vector3d& g) const override {
    g = n_;
    return n_.dot(x - p_);
  }

 private:
  Vector3d n_, p_;
};

}  // namespace

TEST(Backrest, LevelGradientMatchesFiniteDifferencesOnPadTopAndPlane) {
  sp::Chair c;
  c.backrest_recline_deg = 107;
  c.lumbar_support_mm = 40;
  c.lumbar_support_height_mm = 180;
  c.backrest_height_mm = 450;
  const auto back = sp::parametric_backrest(c);
  const Vector3d t(0, std::sin(107 * M_PI / 180), std::cos(107 * M_PI / 180));
  const Vector3d n(0, -t.z(), t.y());
  // On the plane, across the pad, near and above the rounded top.
  for (double s : {50.0, 120.0, 180.0, 230.0, 440.0, 470.0, 520.0})
    for (double d : {-20.0, 5.0}) {
      const Vector3d x = s * t + d * n + Vector3d(13, 0, 0);
      Vector3d g;
      const double phi = back->level(x, g);
      for (int a = 0; a < 3; ++a) {
        Vector3d e = Vector3d::Zero();
        e[a] = 1e-5;
        Vector3d dummy;
        const double fd = (back->level(x + e, dummy) - back->level(x - e, dummy)) / 2e-5;
        EXPECT_NEAR(g[a], fd, 1e-6) << "s " << s << " d " << d << " axis " << a;
      }
      if (s == 180.0) EXPECT_NEAR(phi, d - 40, 1e-9);  // the pad's crest stands 40 mm out
      if (s == 50.0) EXPECT_NEAR(phi, d, 1e-9);        // the bare plane
    }
}

TEST(Seating, ContactEnergyGradientMatchesFiniteDifferences) {
  // Seat the sitter far back so that the back presses into the backrest.
  sp::Chair c;
  c.backrest_recline_deg = 95;
  c.lumbar_support_mm = 30;
  const sp::SeatedModel sm = sp::seat_model(standing(), c, sitter(), 25, 60);
  VectorXd theta = sm.posture, g;
  theta[3 * 8] += 0.02;  // some thoracic flexion as well
  sp::potential(sm.model, {}, VectorXd(), theta, &g);
  int pressed = 0;
  {
    Vector3d grad;
    const auto P = sp::vertebra_poses(sm.model, theta);
    for (const auto& cp : sm.model.contacts)
      pressed += sm.model.contact_surface->level(sp::place(P, cp.body, cp.point_mm), grad) < 0;
  }
  ASSERT_GE(pressed, 3) << "the test needs points pressed into the backrest";
  for (Eigen::Index k = 0; k < theta.size(); ++k) {
    VectorXd tp = theta, tm = theta;
    tp[k] += 1e-6;
    tm[k] -= 1e-6;
    const double fd = (sp::potential(sm.model, {}, VectorXd(), tp) -
                       sp::potential(sm.model, {}, VectorXd(), tm)) /
                      2e-6;
    EXPECT_NEAR(g[k], fd, 1e-3 * std::max(1.0, std::abs(fd))) << "coordinate " << k;
  }
}

TEST(Seating, RecruitmentArmsAtAPostureAreMinusTheMuscleLengthDerivatives) {
  const sp::SeatedModel sm = sp::seat_model(standing(), sp::Chair(), sitter(), 18.3, 100);
  Eigen::MatrixXd arm;
  VectorXd b;
  std::vector<int> joints;
  sp::recruitment_problem(sm.model, {}, arm, b, joints, sm.posture);
  auto length = [&](const VectorXd& th, std::size_t i) {
    const auto P = sp::vertebra_poses(sm.model, th);
    const auto& mu = sm.model.muscles[i];
    return (sp::place(P, mu.body_a, mu.a_mm) - sp::place(P, mu.body_b, mu.b_mm)).norm();
  };
  for (std::size_t r = 0; r < joints.size(); ++r)
    for (int a = 0; a < 3; ++a)
      for (std::size_t i = 0; i < sm.model.muscles.size(); i += 7) {
        VectorXd tp = sm.posture, tm = sm.posture;
        tp[3 * joints[r] + a] += 1e-6;
        tm[3 * joints[r] + a] -= 1e-6;
        const double dL = (length(tp, i) - length(tm, i)) / 2e-6;
        EXPECT_NEAR(arm(3 * Eigen::Index(r) + a, Eigen::Index(i)), -dL, 1e-4)
            << sm.model.muscles[i].name << " about " << sm.model.joints[joints[r]].name;
      }
}

TEST(Seating, BadPosturesAndContactForcesAreRefused) {
  const sp::SeatedModel sm = sp::seat_model(standing(), sp::Chair(), sitter(), 18.3, 100);
  sp::SolveOptions o;
  o.posture = VectorXd::Zero(5);
  EXPECT_THROW(sp::solve_spine(sm.model, {}, o), std::invalid_argument);
  o.posture = sm.posture;
  o.posture[3] = NAN;
  EXPECT_THROW(sp::solve_spine(sm.model, {}, o), std::invalid_argument);
  o.posture = sm.posture;
  o.recruitment_contact_forces.assign(2, Vector3d::Zero());  // not one per contact point
  EXPECT_THROW(sp::solve_spine(sm.model, {}, o), std::invalid_argument);
  o.recruitment_contact_forces.assign(sm.model.contacts.size(), Vector3d(0, NAN, 0));
  EXPECT_THROW(sp::solve_spine(sm.model, {}, o), std::invalid_argument);
}

TEST(Seating, BodyWeightBalancesSeatBackrestAndArmrestsAndTheLeanBalances) {
  for (bool armrests : {false, true}) {
    sp::Chair c;
    c.backrest_recline_deg = 105;
    c.armrests = armrests;
    const sp::SeatedSolution s = sp::solve_seated(standing(), c, sitter());
    EXPECT_TRUE(s.lean_balanced);
    EXPECT_LE(std::abs(s.hip_moment_nmm), sp::SeatingOptions().lean_tolerance_nmm);
    // The seat reaction from the pelvis's own free body equals the one that balances the body.
    EXPECT_LT(s.force_residual_n, 1e-6);
    EXPECT_NEAR((s.seat_force_n + s.backrest_force_n + s.armrest_force_n).y(), s.body_weight_n,
                1e-9);
    // 70 kg: trunk (Bruno), head and arms (de Leva), pelvis (de Leva).
    EXPECT_NEAR(s.body_weight_n, 70 * 9.81 * (0.3278 + 0.0694 + 2 * 0.0494 + 0.1117), 0.5);
    // The backrest only pushes, along its normal, on points pressed into it.
    double back = 0;
    for (const auto& k : s.contacts) {
      if (k.gap_mm >= 0) EXPECT_EQ(k.force_n.norm(), 0.0) << k.name;
      back += k.force_n.norm();
    }
    EXPECT_GT(back, 1.0);
    EXPECT_GT(s.seat_force_n.y(), 0);
    EXPECT_EQ(s.armrest_force_n.y() > 0, armrests);
    // The backrest pushes forward, so the flat seat must hold the pelvis back by friction:
    // |F_z| / F_y of the seat's reaction.
    EXPECT_NEAR(s.seat_friction_needed, -s.seat_force_n.z() / s.seat_force_n.y(), 1e-12);
  }
}

TEST(Seating, ArmrestsUnloadTheLumbarDiscs) {
  sp::Chair c;
  const double without = sp::solve_seated(standing(), c, sitter()).spine.joints.back().axial_n;
  c.armrests = true;
  const double with = sp::solve_seated(standing(), c, sitter()).spine.joints.back().axial_n;
  EXPECT_LT(with, without);
}

TEST(Seating, WithoutBackrestTheHipsHoldTheMomentAndNothingTouches) {
  sp::Chair stool;
  stool.backrest_height_mm = 0;
  const sp::SeatedSolution s = sp::solve_seated(standing(), stool, sitter());
  EXPECT_EQ(s.lean_deg, 0);
  EXPECT_EQ(s.backrest_force_n.norm(), 0);
  EXPECT_NEAR(s.seat_force_n.y(), s.body_weight_n, 1e-9);
  EXPECT_LT(s.force_residual_n, 1e-6);
  EXPECT_NEAR(s.seat_friction_needed, 0, 1e-12);  // a flat seat under a vertical load
}

TEST(Seating, BadChairsAreRefusedInOneLine) {
  auto refused = [](sp::Chair c, const std::string& words) {
    try {
      sp::solve_seated(standing(), c, sitter());
      ADD_FAILURE() << "accepted: " << words;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << words << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  };
  sp::Chair c;
  c.lumbar_support_mm = -10;
  refused(c, "lumbar support depth");
  c = sp::Chair();
  c.backrest_recline_deg = NAN;
  refused(c, "backrest recline");
  c = sp::Chair();
  c.backrest_recline_deg = 200;
  refused(c, "backrest recline");
  c = sp::Chair();
  c.lumbar_support_mm = 30;
  c.lumbar_support_height_mm = 700;
  refused(c, "above the backrest");
  // A surface 2 m behind the seat: no lean reaches it.
  c = sp::Chair();
  c.surface = std::make_shared<Plane>(Vector3d(0, 0, 1), Vector3d(0, 0, -2000));
  refused(c, "out of the back's reach");
  // A surface facing away from the sitter.
  c.surface = std::make_shared<Plane>(Vector3d(0, 0, -1), Vector3d(0, 0, 0));
  refused(c, "face the back");
}
