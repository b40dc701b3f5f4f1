// A spine for a given body: the reference body is today's model bit for bit, every quantity
// scales by its stated law, and dimensional analysis holds — a passive spine of the same build
// (mass ∝ height²) and a load scaled with it bends by the same angles.
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace sp = spinesim::spine;
using Eigen::Vector3d;

namespace {

const std::string kData = SPINESIM_DATA_DIR;

sp::ModelOptions for_subject(double height_m, double mass_kg, sp::Sex sex) {
  sp::ModelOptions o;
  o.subject.height_m = height_m;
  o.subject.body_mass_kg = mass_kg;
  o.subject.sex = sex;
  return o;
}

/// Both models hold the same numbers, bit for bit (EXPECT_EQ on doubles).
void expect_identical(const sp::SpineModel& a, const sp::SpineModel& b) {
  ASSERT_EQ(a.vertebrae.size(), b.vertebrae.size());
  for (std::size_t i = 0; i < a.vertebrae.size(); ++i) {
    EXPECT_EQ(a.vertebrae[i].centre_mm, b.vertebrae[i].centre_mm);
    EXPECT_EQ(a.vertebrae[i].mass_kg, b.vertebrae[i].mass_kg);
  }
  for (std::size_t i = 0; i < a.joints.size(); ++i) {
    EXPECT_EQ(a.joints[i].point_mm, b.joints[i].point_mm);
    EXPECT_EQ(a.joints[i].k_flexion, b.joints[i].k_flexion);
    EXPECT_EQ(a.joints[i].k_extension, b.joints[i].k_extension);
    EXPECT_EQ(a.joints[i].k_lateral, b.joints[i].k_lateral);
    EXPECT_EQ(a.joints[i].k_torsion, b.joints[i].k_torsion);
  }
  ASSERT_EQ(a.muscles.size(), b.muscles.size());
  for (std::size_t i = 0; i < a.muscles.size(); ++i) {
    EXPECT_EQ(a.muscles[i].a_mm, b.muscles[i].a_mm);
    EXPECT_EQ(a.muscles[i].b_mm, b.muscles[i].b_mm);
    EXPECT_EQ(a.muscles[i].pcsa_mm2, b.muscles[i].pcsa_mm2);
  }
  ASSERT_EQ(a.weights.size(), b.weights.size());
  for (std::size_t i = 0; i < a.weights.size(); ++i) {
    EXPECT_EQ(a.weights[i].point_mm, b.weights[i].point_mm);
    EXPECT_EQ(a.weights[i].force_n, b.weights[i].force_n);
  }
  EXPECT_EQ(a.bushing.point_mm, b.bushing.point_mm);
  EXPECT_EQ(a.bushing.k_translation_n_per_mm, b.bushing.k_translation_n_per_mm);
  EXPECT_EQ(a.bushing.k_rotation_nmm_per_rad, b.bushing.k_rotation_nmm_per_rad);
  EXPECT_EQ(a.chest_front_mm, b.chest_front_mm);
  EXPECT_EQ(a.body_mass_kg, b.body_mass_kg);
}

}  // namespace

// The thesis's GeBod median male (1.778 m, 70 kg) named explicitly is the default model.
TEST(SpineSubject, TheReferenceBodyIsTheTablesOwnModel) {
  const sp::SpineModel plain = sp::load_spine_model(kData);
  const sp::SpineModel named = sp::load_spine_model(kData, for_subject(1.778, 70, sp::Sex::Male));
  expect_identical(plain, named);
  EXPECT_EQ(plain.subject.height_m, 1.778);
  EXPECT_EQ(plain.subject.body_mass_kg, 70.0);
  EXPECT_EQ(plain.scale.length, 1.0);
  EXPECT_EQ(plain.scale.muscle, 1.0);
}

// Every quantity by its law, computed here from the sources' numbers: lengths ∝ height, joint
// stiffness ∝ length³, ligament stiffness ∝ length, pCSA ∝ V(m, h)/h with Handsfield's
// V = 47.0 m h + 1285 cm³, masses from de Leva's female percentages.
TEST(SpineSubject, AScaledBodyFollowsEachScalingLaw) {
  sp::ModelOptions ro;
  ro.ligaments = sp::Ligaments::On;
  const sp::SpineModel ref = sp::load_spine_model(kData, ro);
  sp::ModelOptions o = for_subject(1.60, 55, sp::Sex::Female);
  o.ligaments = sp::Ligaments::On;
  const sp::SpineModel f = sp::load_spine_model(kData, o);
  const double s = 1.60 / 1.778;
  const double muscle = (47.0 * 55 * 1.60 + 1285) / (47.0 * 70 * 1.778 + 1285) / s;
  EXPECT_NEAR(f.scale.length, s, 1e-15);
  EXPECT_NEAR(f.scale.muscle, muscle, 1e-15);
  for (std::size_t i = 0; i < ref.vertebrae.size(); ++i) {
    EXPECT_TRUE(f.vertebrae[i].centre_mm.isApprox(s * ref.vertebrae[i].centre_mm, 1e-14));
    // Bruno's per-level masses are a male's: a female's trunk is 42.57 % of her mass, his 43.46 %.
    EXPECT_NEAR(f.vertebrae[i].mass_kg, ref.vertebrae[i].mass_kg / 70 * 55 * 42.57 / 43.46, 1e-12);
  }
  for (std::size_t j = 0; j < ref.joints.size(); ++j) {
    EXPECT_TRUE(f.joints[j].point_mm.isApprox(s * ref.joints[j].point_mm, 1e-14));
    EXPECT_NEAR(f.joints[j].k_flexion, s * s * s * ref.joints[j].k_flexion,
                1e-12 * ref.joints[j].k_flexion);
    EXPECT_NEAR(f.joints[j].k_torsion, s * s * s * ref.joints[j].k_torsion,
                1e-12 * ref.joints[j].k_torsion);
    EXPECT_EQ(f.joints[j].rom_flexion, ref.joints[j].rom_flexion);  // angles do not scale
  }
  ASSERT_EQ(f.ligaments.size(), ref.ligaments.size());
  for (std::size_t i = 0; i < ref.ligaments.size(); ++i) {
    EXPECT_NEAR(f.ligaments[i].k_n_per_mm, s * ref.ligaments[i].k_n_per_mm, 1e-12);
    EXPECT_NEAR(f.ligaments[i].rest_length_mm, (f.ligaments[i].a_mm - f.ligaments[i].b_mm).norm(),
                1e-9);
    EXPECT_NEAR(f.ligaments[i].rest_length_mm, s * ref.ligaments[i].rest_length_mm, 1e-9);
  }
  for (std::size_t i = 0; i < ref.muscles.size(); ++i) {
    EXPECT_NEAR(f.muscles[i].pcsa_mm2, muscle * ref.muscles[i].pcsa_mm2, 1e-9);
    EXPECT_NEAR(f.muscles[i].rest_length_mm, (f.muscles[i].a_mm - f.muscles[i].b_mm).norm(), 1e-9);
  }
  double head_n = 0, arms_n = 0;
  for (const sp::PointLoad& w : f.weights) {
    if (w.name == "head and neck weight") head_n = -w.force_n.y();
    if (w.name.find("arm weight") != std::string::npos) arms_n += -w.force_n.y();
  }
  EXPECT_NEAR(head_n, 0.0668 * 55 * 9.81, 1e-9);
  EXPECT_NEAR(arms_n, 2 * 0.0449 * 55 * 9.81, 1e-9);
  // Appendix C on the scaled abdomen: areas ∝ s², volume ∝ s³, the pressure unchanged, so the
  // bushing's "k" (pressure × area) ∝ s² and its rotational stiffness (k × area) ∝ s⁴.
  EXPECT_TRUE(f.bushing.k_translation_n_per_mm.isApprox(
      s * s * ref.bushing.k_translation_n_per_mm, 1e-12));
  EXPECT_TRUE(f.bushing.k_rotation_nmm_per_rad.isApprox(
      s * s * s * s * ref.bushing.k_rotation_nmm_per_rad, 1e-12));
  EXPECT_TRUE(f.bushing.point_mm.isApprox(s * ref.bushing.point_mm, 1e-14));
}

// Dimensional analysis: with lengths × s, mass × s² and a load × s², every moment grows by s³
// and so does every rotational stiffness, so a passive spine (joint springs and their ranges,
// gravity, a force on T1) bends by exactly the same angles. A length, mass or stiffness left
// unscaled anywhere breaks this.
TEST(SpineSubject, APassiveSpineOfTheSameBuildBendsByTheSameAngles) {
  const auto solve = [](double s) {
    sp::ModelOptions o = for_subject(1.778 * s, 70 * s * s, sp::Sex::Male);
    o.muscles = o.iap = false;
    o.ligaments = sp::Ligaments::Off;
    const sp::SpineModel m = sp::load_spine_model(kData, o);
    sp::ExternalLoad push;
    push.vertebra = sp::vertebra_index("T1");
    push.force_n = Vector3d(40, -30, 120) * s * s;
    sp::SolveOptions so;
    so.recruit = false;
    so.tolerance = 1e-8;
    return sp::solve_spine(m, {push}, so);
  };
  const sp::SpineSolution ref = solve(1.0);
  for (double s : {0.9, 1.08}) {
    SCOPED_TRACE(s);
    const sp::SpineSolution scaled = solve(s);
    EXPECT_LT((scaled.theta - ref.theta).cwiseAbs().maxCoeff(),
              1e-7 * ref.theta.cwiseAbs().maxCoeff());
    // Translations scale with the body.
    EXPECT_LT((scaled.displacement.leftCols(3) - s * ref.displacement.leftCols(3))
                  .cwiseAbs()
                  .maxCoeff(),
              1e-6 * ref.displacement.leftCols(3).cwiseAbs().maxCoeff());
  }
}

TEST(SpineSubject, BodiesOutsideTheScalingLawsRangeAreRefusedInOneLine) {
  const auto refused = [](const sp::ModelOptions& o, const std::string& word) {
    try {
      sp::load_spine_model(kData, o);
      ADD_FAILURE() << "accepted: " << word;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(word), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  refused(for_subject(2.5, 90, sp::Sex::Male), "height");
  refused(for_subject(1.2, 30, sp::Sex::Female), "height");
  refused(for_subject(1.7, 160, sp::Sex::Male), "body-mass index");
  refused(for_subject(1.7, 35, sp::Sex::Female), "body-mass index");
  refused(for_subject(-1.7, 60, sp::Sex::Male), "finite");
  refused(for_subject(NAN, 60, sp::Sex::Male), "finite");
  EXPECT_EQ(sp::parse_sex("female"), sp::Sex::Female);
  EXPECT_THROW(sp::parse_sex("f"), std::invalid_argument);
}

// The male anthropometry table is the one the reference model always used (head 6.94 %, arm
// 4.94 %): the default model's weights come from it.
TEST(SpineSubject, TheMaleTableIsTheReferenceModelsMasses) {
  const sp::SpineModel m = sp::load_spine_model(kData);
  EXPECT_EQ(m.segment_mass_percent.head_neck, 6.94);
  EXPECT_EQ(m.segment_mass_percent.arm_each, 4.94);
  EXPECT_EQ(m.segment_mass_percent.pelvis, 11.17);
  EXPECT_EQ(m.segment_mass_percent.forearm_hand_each, 2.23);
  EXPECT_NEAR(m.segment_mass_percent.arm_each, 2.71 + 1.62 + 0.61, 1e-12);
}

// The named bodies: the reference is the default body exactly, every body lies in the scaling
// laws' range, they come smallest first, and an unknown name is refused with the names.
TEST(SpineSubject, NamedBodiesAreSourcedAndTheReferenceIsTheDefault) {
  const std::vector<sp::NamedBody> bodies = sp::named_bodies(kData);
  ASSERT_GE(bodies.size(), 3u);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    EXPECT_FALSE(bodies[i].source.empty()) << bodies[i].name;
    const sp::Subject& s = bodies[i].subject;
    const sp::Subject again = sp::resolve_subject(kData, s);  // in range: no throw
    EXPECT_EQ(again.height_m, s.height_m);
    if (i > 0) EXPECT_LE(bodies[i - 1].subject.height_m, s.height_m);
  }
  const sp::Subject ref = sp::named_body(kData, "reference").subject;
  const sp::Subject def = sp::resolve_subject(kData, sp::Subject());
  EXPECT_EQ(ref.height_m, def.height_m);
  EXPECT_EQ(ref.body_mass_kg, def.body_mass_kg);
  EXPECT_EQ(ref.sex, def.sex);
  sp::ModelOptions o;
  o.subject = ref;
  expect_identical(sp::load_spine_model(kData, o), sp::load_spine_model(kData));

  const sp::NamedBody small = sp::named_body(kData, "p5-female");
  EXPECT_EQ(small.subject.sex, sp::Sex::Female);
  EXPECT_NEAR(small.subject.height_m, 59.1 * 0.0254, 0.001);            // 59.1 in
  EXPECT_NEAR(small.subject.body_mass_kg, 108.0 * 0.45359237, 0.05);    // 108.0 lb
  const sp::NamedBody large = sp::named_body(kData, "p95-male");
  EXPECT_NEAR(large.subject.height_m, 74 * 0.0254, 0.001);             // 74 in
  EXPECT_NEAR(large.subject.body_mass_kg, 223 * 0.45359237, 0.05);     // 223 lb
  try {
    sp::named_body(kData, "p50-female");
    FAIL() << "an unknown body was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("p5-female"), std::string::npos) << what;
    EXPECT_NE(what.find("reference"), std::string::npos) << what;
  }
}
