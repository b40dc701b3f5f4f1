// The spine model as built from data/: every number traced back to its table.
#include "spinesim/spine/model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

namespace sp = spinesim::spine;

namespace {
const sp::SpineModel& model() {
  static const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  return m;
}
}  // namespace

TEST(SpineModel, AppendixCRecomputedFromItsInputsMatchesThePrintedResults) {
  const sp::IapStiffness s = sp::iap_from_appendix_c(std::string(SPINESIM_DATA_DIR) + "/thesis/appendix_c_iap.json");
  std::ifstream in(std::string(SPINESIM_DATA_DIR) + "/thesis/appendix_c_iap.json");
  const auto printed = nlohmann::json::parse(in).at("thesis_results");
  EXPECT_NEAR(s.s_mean_mm2, printed.at("S_mean_mm2").get<double>(), 1e-3);
  EXPECT_NEAR(s.h_l1l5_mm, printed.at("h_L1L5_mm").get<double>(), 1e-3);
  EXPECT_NEAR(s.h_mm, printed.at("h_mm").get<double>(), 1e-2);
  EXPECT_NEAR(s.a_mm, printed.at("a_mm").get<double>(), 1e-3);
  EXPECT_NEAR(s.k_y, printed.at("k_y_n_per_mm").get<double>(), 5e-3);  // thesis rounds to 22.44
  EXPECT_NEAR(s.k_x, printed.at("k_x_n_per_mm").get<double>(), 5e-3);
  EXPECT_NEAR(s.bushing_k_y, printed.at("bushing_k_y_n_per_mm").get<double>(), 0.02);
  EXPECT_NEAR(s.bushing_k_xz, printed.at("bushing_k_x_n_per_mm").get<double>(), 0.01);
  // The thesis computed M from its rounded k_y = 22.44 (data/README.md): 6602.86 vs 6602.33 printed.
  EXPECT_NEAR(s.bushing_m_xz_per_deg, printed.at("M_x_nmm_per_deg").get<double>(), 1.0);
  EXPECT_NEAR(s.bushing_m_y_per_deg, printed.at("M_y_nmm_per_deg").get<double>(), 1.0);
  // The bushing converts N·mm/deg to N·mm/rad.
  EXPECT_NEAR(model().bushing.k_rotation_nmm_per_rad.x(), s.bushing_m_xz_per_deg * 180 / M_PI, 1e-6);
}

TEST(SpineModel, ChainOfSeventeenVertebraeOnTableF2Joints) {
  const auto& m = model();
  ASSERT_EQ(m.vertebrae.size(), 17u);
  ASSERT_EQ(m.joints.size(), 17u);
  EXPECT_EQ(m.vertebrae.front().name, "T1");
  EXPECT_EQ(m.joints.back().name, "L5-S1");
  EXPECT_DOUBLE_EQ(m.vertebrae[6].centre_mm.y(), 384.0);  // T7, table F.1
  EXPECT_DOUBLE_EQ(m.joints[15].point_mm.y(), 93.0);      // L4-L5, table F.2
  // Every joint lies between its two vertebrae.
  for (std::size_t k = 0; k + 1 < m.vertebrae.size(); ++k) {
    EXPECT_LT(m.joints[k].point_mm.y(), m.vertebrae[k].centre_mm.y());
    EXPECT_GT(m.joints[k].point_mm.y(), m.vertebrae[k + 1].centre_mm.y());
  }
}

TEST(SpineModel, JointStiffnessFromF4FlexionDiffersFromExtensionAndRomFromF5) {
  const auto& m = model();
  const double per_deg = M_PI / 180;
  const sp::Joint& l4l5 = m.joints[std::size_t(sp::joint_index("L4-L5"))];
  EXPECT_NEAR(l4l5.k_flexion * per_deg, 1400, 1e-9);
  EXPECT_NEAR(l4l5.k_extension * per_deg, 2900, 1e-9);
  EXPECT_NEAR(l4l5.k_torsion * per_deg, 6900, 1e-9);
  EXPECT_NEAR(l4l5.rom_flexion / per_deg, 13, 1e-12);
  EXPECT_NEAR(l4l5.rom_extension / per_deg, 2, 1e-12);
  const sp::Joint& t7t8 = m.joints[std::size_t(sp::joint_index("T7-T8"))];
  EXPECT_NEAR(t7t8.k_lateral * per_deg, 3000, 1e-9);
  const sp::Joint& l5s1 = m.joints[std::size_t(sp::joint_index("L5-S1"))];
  EXPECT_NEAR(l5s1.k_flexion * per_deg, 2100, 1e-9);
}

TEST(SpineModel, MassesFromBrunoAndDeLevaSumToTheUpperBody) {
  const auto& m = model();
  double vertebrae = 0;
  for (const auto& v : m.vertebrae) vertebrae += v.mass_kg;
  EXPECT_NEAR(vertebrae, 0.3278 * 70, 1e-9);  // Σ of SPEC's per-level % of 70 kg
  double weight = 0;
  for (const auto& w : m.weights) weight -= w.force_n.y();
  // + head and neck 6.94 % and two arms 4.94 % each
  EXPECT_NEAR(weight, (0.3278 + 0.0694 + 2 * 0.0494) * 70 * 9.81, 1e-6);
}

TEST(SpineModel, MusclesAreTheRightSideTablesMirrored) {
  const auto& m = model();
  ASSERT_EQ(m.muscles.size(), 2u * (19 + 9 + 11 + 5 + 6 + 6));
  for (std::size_t i = 0; i < m.muscles.size(); i += 2) {
    const auto& r = m.muscles[i];
    const auto& l = m.muscles[i + 1];
    EXPECT_EQ(r.side, "right");
    EXPECT_EQ(l.side, "left");
    EXPECT_DOUBLE_EQ(l.a_mm.x(), -r.a_mm.x());
    EXPECT_DOUBLE_EQ(l.b_mm.y(), r.b_mm.y());
    EXPECT_DOUBLE_EQ(l.pcsa_mm2, r.pcsa_mm2);
    EXPECT_LE(r.a_mm.x(), 0.0) << r.name << ": the printed tables are the body's right side (x <= 0)";
    EXPECT_GT(r.rest_length_mm, 0);
  }
  EXPECT_DOUBLE_EQ(m.muscles[0].max_force_n(), 40 * 0.7);  // NStiss_121: 40 mm² × 0.7 MPa
}

TEST(SpineModel, LigamentsSpanEveryJointThoracicTakesTheMeanOfCervicalAndLumbar) {
  const auto& m = model();
  ASSERT_EQ(m.ligaments.size(), 17u * 6);  // ISL, LF, ALL, PLL, two capsules
  for (const auto& l : m.ligaments) {
    EXPECT_EQ(l.body_a, l.joint);
    EXPECT_GT(l.rest_length_mm, 0);
    if (l.type == "ALL") {
      EXPECT_NEAR(l.k_n_per_mm, m.joints[std::size_t(l.joint)].name[0] == 'T' ? 0.5 * (17 + 33) : 33, 1e-12);
    }
    if (l.type == "ALL") EXPECT_GT(l.a_mm.z(), m.vertebrae[std::size_t(l.joint)].centre_mm.z());
    if (l.type == "ISL") EXPECT_LT(l.a_mm.z(), m.vertebrae[std::size_t(l.joint)].centre_mm.z() - 20);
  }
}

TEST(SpineModel, NamesAndFusionLevelsParseAndBadOnesAreRefusedByName) {
  EXPECT_EQ(sp::vertebra_index("t7"), 6);
  EXPECT_EQ(sp::joint_index("l4-l5"), 15);
  EXPECT_EQ(sp::parse_fusion("L3-L4"), std::vector<int>({14}));
  EXPECT_EQ(sp::parse_fusion("L3-L4-L5"), std::vector<int>({14, 15}));
  EXPECT_EQ(sp::parse_fusion("L4-L5,L3-L4"), std::vector<int>({14, 15}));
  try {
    sp::vertebra_index("C3");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown vertebra 'C3'"), std::string::npos);
  }
  EXPECT_THROW(sp::parse_fusion("L3-L5"), std::invalid_argument);
  EXPECT_THROW(sp::parse_fusion("L3"), std::invalid_argument);
  EXPECT_THROW(sp::parse_fusion(""), std::invalid_argument);
  sp::ModelOptions o;
  o.fused_joints = sp::parse_fusion("L3-L4-L5");
  const auto fused = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  EXPECT_TRUE(fused.joints[14].fused && fused.joints[15].fused && !fused.joints[16].fused);
}

TEST(SpineModel, MissingDataFolderNamesTheFile) {
  try {
    sp::load_spine_model("/nonexistent");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("spine_model.json"), std::string::npos);
  }
}
