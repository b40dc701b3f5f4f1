// The scoliosis study: the disc's edge stresses integrate back to the joint's axial force and
// moment over the elliptic section (brute-force quadrature), a known lateral push presses the
// side it bends toward, and the study reports every curve, refuses the one it cannot pose and
// gives each finding a verdict from its own numbers.
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/studies/scoliosis_study.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sp = spinesim::spine;
namespace st = spinesim::studies;

// A linear stress σ(x) = a + b x over the ellipse (x/(w/2))² + (z/(d/2))² ≤ 1 through the two
// edge values: ∫σ dA must be N and −∫σ x dA (a stress at +x, the left, resists a load bending
// toward −x) the lateral moment.
TEST(ScoliosisStudy, EdgeStressesIntegrateToTheJointsForceAndMoment) {
  sp::JointReaction r;
  r.disc_axial_n = 800;
  r.moment_local_nmm = Eigen::Vector3d(0, 0, 3000);
  const double w = 40, d = 30;
  const st::DiscEdgeStress e = st::disc_edge_stress(r, w, d);
  const double a = 0.5 * (e.left_mpa + e.right_mpa), b = (e.left_mpa - e.right_mpa) / w;
  double force = 0, moment = 0;
  const int n = 2000;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = -w / 2 + w * (i + 0.5) / n, z = -d / 2 + d * (j + 0.5) / n;
      if (std::pow(x / (w / 2), 2) + std::pow(z / (d / 2), 2) > 1) continue;
      const double dA = (w / n) * (d / n), s = a + b * x;
      force += s * dA;
      moment -= s * x * dA;
    }
  EXPECT_NEAR(force, 800, 0.002 * 800);
  EXPECT_NEAR(moment, 3000, 0.002 * 3000);
  EXPECT_NEAR(e.mean_mpa, a, 1e-12);
  EXPECT_THROW(st::disc_edge_stress(r, 0, d), std::invalid_argument);
}

// Pushing T1 toward the body's left (+x) bends the spine to the left and presses the discs'
// left edges (the IAP bushing, which would carry most of the push past T6, left out).
TEST(ScoliosisStudy, ALateralPushPressesTheSideTheSpineBendsToward) {
  sp::ModelOptions o;
  o.gravity = o.muscles = o.iap = false;
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  sp::SolveOptions so;
  so.recruit = false;
  for (double push : {100.0, -100.0}) {
    sp::ExternalLoad l;
    l.vertebra = 0;
    l.force_n = Eigen::Vector3d(push, 0, 0);
    const sp::SpineSolution s = sp::solve_spine(m, {l}, so);
    EXPECT_GT(push * s.displacement(0, 0), 0);  // T1 moved the way it was pushed
    const st::DiscEdgeStress e =
        st::disc_edge_stress(s.joints[std::size_t(sp::joint_index("T6-T7"))], 30, 23);
    EXPECT_GT(push * (e.left_mpa - e.right_mpa), 0) << push;
  }
}

TEST(ScoliosisStudy, EveryCurveIsReportedAndEachFindingFollowsFromTheNumbers) {
  const st::ScoliosisStudy s = st::run_scoliosis_study(SPINESIM_DATA_DIR, sp::ModelOptions());
  ASSERT_EQ(s.cases.size(), 9u);
  ASSERT_EQ(s.findings.size(), 3u);
  int posed = 0, concave = 0;
  double unloaded = 0;
  for (const auto& c : s.cases) {
    if (!c.refusal.empty()) {
      EXPECT_NE(c.refusal.find("closes its disc"), std::string::npos) << c.refusal;
      continue;
    }
    ++posed;
    ASSERT_FALSE(c.discs.empty());
    concave += c.apical_concave_mpa > c.apical_convex_mpa;
    unloaded = std::max(unloaded, std::abs(c.unloaded_apical_mpa));
    const double side = c.curve.convex_right ? -1 : 1;
    EXPECT_GT(side * c.apex_offset_mm, 0) << c.curve.type;
  }
  EXPECT_GE(posed, 6);
  EXPECT_EQ(s.findings[0].match, concave == posed);
  EXPECT_LT(unloaded, 1e-6);  // the curve rests stress-free: nothing without load
  EXPECT_FALSE(s.findings[1].match);
  const auto j = st::scoliosis_study_json(s);
  EXPECT_EQ(j["cases"].size(), 9u);
  EXPECT_EQ(j["findings"][1]["verdict"], "DIFFERS");
}
