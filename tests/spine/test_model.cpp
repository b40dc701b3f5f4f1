// The spine model as built from data/: every number traced back to its table.
#include "spinesim/spine/model.hpp"

#include <gtest/gtest.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace sp = spinesim::spine;

namespace {
const sp::SpineModel& model() {
  static const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  return m;
}
}  // namespace

TEST(SpineModel, AppendixCRecomputedFromItsInputsMatchesThePrintedResults) {
  const sp::IapStiffness s =
      sp::iap_from_appendix_c(std::string(SPINESIM_DATA_DIR) + "/thesis/appendix_c_iap.json");
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
  EXPECT_NEAR(model().bushing.k_rotation_nmm_per_rad.x(), s.bushing_m_xz_per_deg * 180 / M_PI,
              1e-6);
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
  EXPECT_NEAR(vertebrae, 0.3278 * 70, 1e-9);  // Σ of Bruno et al. 2015's per-level % of 70 kg
  double weight = 0;
  for (const auto& w : m.weights) weight -= w.force_n.y();
  // + head and neck 6.94 % and two arms 4.94 % each
  EXPECT_NEAR(weight, (0.3278 + 0.0694 + 2 * 0.0494) * 70 * 9.81, 1e-6);
}

TEST(SpineModel, MusclesAreTheRightSideTablesMirrored) {
  const auto& m = model();
  // F.8-F.19 (19 + 9 + 11 + 5 + 6 + 6 per side) and the three restored LifeMOD trunk muscles per side.
  ASSERT_EQ(m.muscles.size(), 2u * (19 + 9 + 11 + 5 + 6 + 6 + 3));
  for (std::size_t i = 0; i < m.muscles.size(); i += 2) {
    const auto& r = m.muscles[i];
    const auto& l = m.muscles[i + 1];
    EXPECT_EQ(r.side, "right");
    EXPECT_EQ(l.side, "left");
    EXPECT_DOUBLE_EQ(l.a_mm.x(), -r.a_mm.x());
    EXPECT_DOUBLE_EQ(l.b_mm.y(), r.b_mm.y());
    EXPECT_DOUBLE_EQ(l.pcsa_mm2, r.pcsa_mm2);
    EXPECT_LE(r.a_mm.x(), 0.0) << r.name
                               << ": the printed tables are the body's right side (x <= 0)";
    EXPECT_GT(r.rest_length_mm, 0);
  }
  EXPECT_DOUBLE_EQ(m.muscles[0].max_force_n(), 40 * 0.7);  // NStiss_121: 40 mm² × 0.7 MPa
}

namespace {
const sp::Muscle& muscle(const sp::SpineModel& m, const std::string& name) {
  for (const auto& mu : m.muscles)
    if (mu.name == name) return mu;
  throw std::runtime_error("no muscle " + name);
}
const Eigen::Vector3d& centre(const sp::SpineModel& m, const std::string& vertebra) {
  for (const auto& v : m.vertebrae)
    if (v.name == vertebra) return v.centre_mm;
  throw std::runtime_error("no vertebra " + vertebra);
}
Eigen::Vector3d mean_insertion(const sp::SpineModel& m, int first, int last) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (int i = first; i <= last; ++i) s += muscle(m, "NStiss_" + std::to_string(i) + "_R").b_mm;
  return s / double(last - first + 1);
}
}  // namespace

// data/spine/trunk_muscles.csv states the rules its numbers follow; check the numbers against the rules.
TEST(SpineModel, TrunkMusclesFollowTheRulesTheirFileStates) {
  const auto& m = model();
  const double tol = 0.06;  // the file prints one decimal
  const auto& lt = muscle(m, "LTpT_T7_R");
  const auto& il = muscle(m, "ILpT_T7_R");
  const auto& ra = muscle(m, "RA_R");
  // pars thoracis origins: T7 at the offset the F.10 pars lumborum origins have from L1.
  EXPECT_TRUE(
      lt.a_mm.isApprox(centre(m, "T7") + muscle(m, "NStiss_144_R").a_mm - centre(m, "L1"), 1e-12));
  EXPECT_TRUE(
      il.a_mm.isApprox(centre(m, "T7") + muscle(m, "NStiss_140_R").a_mm - centre(m, "L1"), 1e-12));
  EXPECT_EQ(lt.body_a, 6);  // T7
  // insertions: the mean of the same column's F.10 insertions, on the ground.
  EXPECT_LT((lt.b_mm - mean_insertion(m, 144, 148)).cwiseAbs().maxCoeff(), tol);
  EXPECT_LT((il.b_mm - mean_insertion(m, 140, 143)).cwiseAbs().maxCoeff(), tol);
  EXPECT_EQ(lt.body_b, sp::kGround);
  EXPECT_EQ(il.body_b, sp::kGround);
  // Delp et al. 2001: erector spinae 11.6 cm² split equally, rectus abdominis 2.6 cm²; thesis max stress.
  EXPECT_DOUBLE_EQ(lt.pcsa_mm2 + il.pcsa_mm2, 1160.0);
  EXPECT_DOUBLE_EQ(ra.pcsa_mm2, 260.0);
  EXPECT_DOUBLE_EQ(ra.max_stress_mpa, muscle(m, "NStiss_121_R").max_stress_mpa);
  // rectus abdominis: chest front to the lowest rectus-sheath point, at the sheath's mean lateral offset.
  EXPECT_DOUBLE_EQ(ra.a_mm.y(), m.chest_front_mm.y());
  EXPECT_DOUBLE_EQ(ra.a_mm.z(), m.chest_front_mm.z());
  EXPECT_EQ(ra.body_a, m.ribs_body);
  EXPECT_TRUE(ra.b_mm.isApprox(muscle(m, "NStiss_176_R").b_mm, 1e-12));
  const double sheath_x =
      (muscle(m, "NStiss_167_R").b_mm.x() + muscle(m, "NStiss_174_R").b_mm.x() +
       muscle(m, "NStiss_175_R").b_mm.x() + muscle(m, "NStiss_176_R").b_mm.x()) /
      4;
  EXPECT_NEAR(ra.a_mm.x(), sheath_x, tol);
  // The pars thoracis pass behind every lumbar joint and the rectus abdominis in front of it.
  for (const auto& j : m.joints) {
    if (j.point_mm.y() > 231.0 + 1e-9) continue;  // T12-L1 and below
    auto line_z = [&](const sp::Muscle& mu) {
      const double t = (j.point_mm.y() - mu.b_mm.y()) / (mu.a_mm.y() - mu.b_mm.y());
      return mu.b_mm.z() + t * (mu.a_mm.z() - mu.b_mm.z());
    };
    EXPECT_LT(line_z(lt), j.point_mm.z() - 40) << j.name;
    EXPECT_LT(line_z(il), j.point_mm.z() - 25) << j.name;  // 30 mm at L5-S1, below its insertion
    EXPECT_GT(line_z(ra), j.point_mm.z() + 60) << j.name;
  }
}

TEST(SpineModel, TrunkMusclesCanBeLeftOut) {
  sp::ModelOptions o;
  o.trunk_muscles = false;
  const auto m = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  EXPECT_EQ(m.muscles.size(), 2u * (19 + 9 + 11 + 5 + 6 + 6));
  for (const auto& mu : m.muscles) EXPECT_EQ(mu.name.rfind("NStiss_", 0), 0u) << mu.name;
}

// F.4's joint springs are whole motion segments, ligaments included (Schultz & Ashton-Miller
// 1991): the default model adds the F.6/F.7 ligaments only on disc joints, which are the disc
// alone; `On` restores the thesis's double count, `Off` leaves them out everywhere.
TEST(SpineModel, LigamentsAreAddedOnlyWhereTheJointSpringsLackThem) {
  sp::ModelOptions o;
  EXPECT_EQ(o.ligaments, sp::Ligaments::Auto);
  EXPECT_FALSE(sp::has_ligaments(o));
  EXPECT_TRUE(model().ligaments.empty());
  o.disc_joints = "fibre-reinforced";
  EXPECT_TRUE(sp::has_ligaments(o));
  EXPECT_EQ(sp::load_spine_model(SPINESIM_DATA_DIR, o).ligaments.size(), 17u * 6);
  o.ligaments = sp::Ligaments::Off;
  EXPECT_TRUE(sp::load_spine_model(SPINESIM_DATA_DIR, o).ligaments.empty());
  o.disc_joints.clear();
  o.ligaments = sp::Ligaments::On;
  EXPECT_TRUE(sp::has_ligaments(o));
  for (sp::Ligaments l : {sp::Ligaments::Auto, sp::Ligaments::On, sp::Ligaments::Off})
    EXPECT_EQ(sp::parse_ligaments(sp::ligaments_name(l)), l);
  EXPECT_THROW(sp::parse_ligaments("yes"), std::invalid_argument);
}

TEST(SpineModel, LigamentsSpanEveryJointThoracicTakesTheMeanOfCervicalAndLumbar) {
  sp::ModelOptions o;
  o.ligaments = sp::Ligaments::On;
  const auto m = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  ASSERT_EQ(m.ligaments.size(), 17u * 6);  // ISL, LF, ALL, PLL, two capsules
  for (const auto& l : m.ligaments) {
    EXPECT_EQ(l.body_a, l.joint);
    EXPECT_GT(l.rest_length_mm, 0);
    if (l.type == "ALL") {
      EXPECT_NEAR(l.k_n_per_mm,
                  m.joints[std::size_t(l.joint)].name[0] == 'T' ? 0.5 * (17 + 33) : 33, 1e-12);
    }
    if (l.type == "ALL") EXPECT_GT(l.a_mm.z(), m.vertebrae[std::size_t(l.joint)].centre_mm.z());
    if (l.type == "ISL")
      EXPECT_LT(l.a_mm.z(), m.vertebrae[std::size_t(l.joint)].centre_mm.z() - 20);
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
  EXPECT_THROW(sp::parse_fusion("L3-L4,L3-L4"), std::invalid_argument);     // twice
  EXPECT_THROW(sp::parse_fusion("L3-L4-L5,L4-L5"), std::invalid_argument);  // overlapping
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

// A data folder whose trunk-muscle table is broken: the error names the file and what is wrong.
TEST(SpineModel, BrokenTrunkMuscleTableIsRefusedNamingTheFile) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("spinesim_trunk_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::copy(SPINESIM_DATA_DIR, dir, fs::copy_options::recursive);
  const fs::path table = dir / "spine" / "trunk_muscles.csv";
  std::string text;
  {
    std::ifstream in(table);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  auto write_with = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const auto at = t.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    std::ofstream(table) << t;
  };
  auto message = [&]() -> std::string {
    try {
      (void)sp::load_spine_model(dir.string());
    } catch (const std::exception& e) {  // broken data, or a missing table (data/ CSV reader)
      return e.what();
    }
    return "";
  };
  write_with("RA,rectus abdominis,Ribs", "RA,rectus abdominis,Sternum");
  std::string what = message();
  EXPECT_NE(what.find("trunk_muscles.csv"), std::string::npos) << what;
  EXPECT_NE(what.find("'Sternum'"), std::string::npos) << what;
  write_with(",260,0.7", ",0,0.7");
  what = message();
  EXPECT_NE(what.find("RA_R needs pCSA > 0"), std::string::npos) << what;
  fs::remove(table);
  what = message();
  EXPECT_NE(what.find("trunk_muscles.csv"), std::string::npos) << what;
  // Without the trunk muscles the table is not read at all.
  sp::ModelOptions lumbar;
  lumbar.trunk_muscles = false;
  EXPECT_NO_THROW((void)sp::load_spine_model(dir.string(), lumbar));
  fs::remove_all(dir);
}

// The uncertain inputs: each scale multiplies exactly what it names (muscle strength the maximum
// stress, joint stiffness F.4's springs or a disc joint's matrix with its coupling, ligament
// stiffness the ligaments) and nothing else; the inclination turns every weight forward by its
// angle and keeps its size; out-of-range values are refused.
TEST(SpineModel, InputScalesMultiplyWhatTheyNameAndTheInclinationTurnsGravity) {
  sp::ModelOptions base;
  base.disc_joints = "fibre-reinforced";  // ligaments as elements, joints with coupling
  const sp::SpineModel m0 = sp::load_spine_model(SPINESIM_DATA_DIR, base);
  sp::ModelOptions o = base;
  o.muscle_strength = 1.3, o.joint_stiffness = 0.7, o.ligament_stiffness = 2,
  o.inclination_deg = 25;
  const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR, o);
  ASSERT_EQ(m.muscles.size(), m0.muscles.size());
  ASSERT_FALSE(m.ligaments.empty());
  for (std::size_t i = 0; i < m.muscles.size(); ++i) {
    EXPECT_DOUBLE_EQ(m.muscles[i].max_force_n(), 1.3 * m0.muscles[i].max_force_n());
    EXPECT_EQ(m.muscles[i].pcsa_mm2, m0.muscles[i].pcsa_mm2);
  }
  int coupled = 0;  // the disc joints carry coupling, so its scaling is tested
  for (std::size_t i = 0; i < m.joints.size(); ++i) {
    coupled += !m0.joints[i].coupling.isZero();
    EXPECT_DOUBLE_EQ(m.joints[i].k_flexion, 0.7 * m0.joints[i].k_flexion);
    EXPECT_DOUBLE_EQ(m.joints[i].k_torsion, 0.7 * m0.joints[i].k_torsion);
    EXPECT_TRUE(m.joints[i].coupling.isApprox(0.7 * m0.joints[i].coupling, 1e-15) ||
                m0.joints[i].coupling.isZero());
    EXPECT_EQ(m.joints[i].rom_flexion, m0.joints[i].rom_flexion);
  }
  EXPECT_GT(coupled, 0);
  for (std::size_t i = 0; i < m.ligaments.size(); ++i)
    EXPECT_DOUBLE_EQ(m.ligaments[i].k_n_per_mm, 2 * m0.ligaments[i].k_n_per_mm);
  const double phi = 25 * M_PI / 180;
  ASSERT_EQ(m.weights.size(), m0.weights.size());
  for (std::size_t i = 0; i < m.weights.size(); ++i) {
    const Eigen::Vector3d& f0 = m0.weights[i].force_n;
    const Eigen::Vector3d& f = m.weights[i].force_n;
    EXPECT_NEAR(f.norm(), f0.norm(), 1e-12 * f0.norm());
    EXPECT_NEAR(f.y(), f0.y() * std::cos(phi), 1e-12 * f0.norm());
    EXPECT_NEAR(f.z(), -f0.y() * std::sin(phi), 1e-12 * f0.norm());  // forward, +z
    EXPECT_EQ(m.weights[i].point_mm, m0.weights[i].point_mm);
  }
  for (auto bad : {0.0, 11.0, std::nan("")}) {
    sp::ModelOptions b;
    b.joint_stiffness = bad;
    EXPECT_THROW(sp::load_spine_model(SPINESIM_DATA_DIR, b), std::invalid_argument) << bad;
  }
  sp::ModelOptions steep;
  steep.inclination_deg = 95;
  EXPECT_THROW(sp::load_spine_model(SPINESIM_DATA_DIR, steep), std::invalid_argument);
}
