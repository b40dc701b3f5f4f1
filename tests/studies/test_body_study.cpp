// The bodies study and the discs of a body: the reference body's column is the single-body studies' own numbers, and the
// bodies differ the way statics says they must — the same external moment on a smaller trunk
// (shorter muscle lever arms) needs a larger spine compression, and standing loads grow with
// the body's weight.
#include "spinesim/spine/scoliosis.hpp"
#include "spinesim/studies/body_study.hpp"
#include "spinesim/studies/mesh_disc.hpp"

#include <gtest/gtest.h>

#include <string>

namespace st = spinesim::studies;

namespace {
const std::string kData = SPINESIM_DATA_DIR;

const st::BodyStudyRun& run_of(const st::BodyStudy& s, const std::string& name) {
  for (const auto& r : s.runs)
    if (r.body.name == name) return r;
  throw std::logic_error("no run for " + name);
}
}  // namespace

TEST(BodyStudy, ReferenceColumnIsTheDefaultStudyAndBodiesScaleAsStaticsSays) {
  const st::BodyStudy s = st::run_body_study(kData, 300);
  ASSERT_EQ(s.runs.size(), 3u);
  EXPECT_EQ(s.runs.front().body.name, "p5-female");
  EXPECT_EQ(s.runs.back().body.name, "p95-male");

  const st::BodyStudyRun& ref = run_of(s, "reference");
  const st::ValidationStudy v = st::run_validation_study(kData);
  EXPECT_EQ(ref.validation.mcgill.l5s1.axial_n, v.mcgill.l5s1.axial_n);
  EXPECT_EQ(ref.validation.wilke.l4l5.axial_n, v.wilke.l4l5.axial_n);
  const st::FusionStudy f = st::run_fusion_study(kData, 300);
  EXPECT_EQ(ref.fusion.run("normal", "forward").t1_translation_mm,
            f.run("normal", "forward").t1_translation_mm);

  const st::BodyStudyRun& small = run_of(s, "p5-female");
  const st::BodyStudyRun& large = run_of(s, "p95-male");
  // The same 238 N·m at L5-S1: the shorter body's muscles sit closer to the joint.
  EXPECT_GT(small.validation.mcgill.l5s1.axial_n, ref.validation.mcgill.l5s1.axial_n);
  EXPECT_GT(ref.validation.mcgill.l5s1.axial_n, large.validation.mcgill.l5s1.axial_n);
  // Standing: the trunk's weight and the muscles that balance it grow with the body.
  const auto standing = [](const st::BodyStudyRun& r) { return r.postures.rows.front().ours; };
  ASSERT_EQ(small.postures.rows.front().id, "standing");
  EXPECT_LT(standing(small), standing(ref));
  EXPECT_LT(standing(ref), standing(large));

  const std::string csv = st::body_study_csv(s);
  EXPECT_NE(csv.find("quantity,unit,window_low,window_high,p5-female,reference,p95-male"),
            std::string::npos)
      << csv;
  const nlohmann::json j = st::body_study_json(s);
  EXPECT_EQ(j["runs"].size(), 3u);
  EXPECT_EQ(j["table"][0]["values"].size(), 3u);
}

TEST(BodyStudy, AnUnknownBodyIsRefusedBeforeAnyWork) {
  EXPECT_THROW(st::run_body_study(kData, 300, {}, {"p5-female", "giant"}), std::invalid_argument);
}

// A disc meshed for another body is the reference body's disc scaled by its length scale, node
// for node — straight, and wedged in a scoliotic curve (whose angles do not change with size).
TEST(BodyStudy, ADiscMeshedForABodyIsTheReferenceDiscScaled) {
  namespace sp = spinesim::spine;
  for (const bool curved : {false, true}) {
    st::MeshDiscRequest rq;
    rq.level = "T7-T8";
    rq.structured = true;
    if (curved) rq.scoliosis = sp::scoliosis_curve("thoracic", 40);
    const st::MeshDiscResult ref = st::run_mesh_disc(rq, kData);
    rq.subject = sp::named_body(kData, "p5-female").subject;
    const st::MeshDiscResult small = st::run_mesh_disc(rq, kData);
    const double s = small.disc["length_scale"].get<double>();
    EXPECT_NEAR(s, 1.501 / 1.778, 1e-12);
    ASSERT_EQ(small.mesh.V.rows(), ref.mesh.V.rows());
    EXPECT_LE((small.mesh.V - s * ref.mesh.V).cwiseAbs().maxCoeff(), 1e-9) << curved;
    EXPECT_EQ(small.mesh.T, ref.mesh.T);
    EXPECT_EQ(small.disc["subject"]["sex"], "female");
  }
  st::MeshDiscRequest between;
  between.inferior = "a.stl";
  between.superior = "b.stl";
  between.subject.height_m = 1.6;
  EXPECT_THROW(st::run_mesh_disc(between, kData), std::invalid_argument);
}
