// The transcribed thesis tables in data/thesis/ against values read off the thesis text
// (docs/references.md [Thesis], Appendix F, Appendix C, tables 3.2/3.3/5.1), plus the
// structure every shipped CSV must have (a '# source:' line, a header, no empty cells).
// Expected numbers are written here from the thesis; actual numbers come from the files.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
const fs::path kData = SPINESIM_DATA_DIR;
const fs::path kThesis = kData / "thesis";

struct Csv {
  std::vector<std::string> comments;  // the '#' lines, in order
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  std::size_t col(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return i;
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
  const std::vector<std::string>& row(const std::string& key) const {
    for (const auto& r : rows)
      if (r.at(0) == key) return r;
    ADD_FAILURE() << "no row " << key;
    static const std::vector<std::string> empty(32);
    return empty;
  }
  double num(const std::string& key, const std::string& column) const {
    return std::stod(row(key).at(col(column)));
  }
};

Csv read_csv(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  Csv c;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line[0] == '#') {
      c.comments.push_back(line);
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    (c.header.empty() ? c.header : c.rows.emplace_back()) = cells;
  }
  return c;
}

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  return nlohmann::json::parse(in);
}

TEST(ThesisTables, F1VertebraCentres) {
  const Csv f1 = read_csv(kThesis / "F1_vertebra_cm.csv");
  EXPECT_EQ(f1.rows.size(), 24u);  // C1..L5
  EXPECT_DOUBLE_EQ(f1.num("T7", "x_mm"), 0.0);
  EXPECT_DOUBLE_EQ(f1.num("T7", "y_mm"), 384.0);
  EXPECT_DOUBLE_EQ(f1.num("T7", "z_mm"), -65.0);
  EXPECT_DOUBLE_EQ(f1.num("L4", "y_mm"), 112.0);
  EXPECT_DOUBLE_EQ(f1.num("L4", "z_mm"), -8.5);
  EXPECT_DOUBLE_EQ(f1.num("C1", "y_mm"), 675.0);
}

TEST(ThesisTables, F2JointMarkers) {
  const Csv f2 = read_csv(kThesis / "F2_joint_markers.csv");
  EXPECT_EQ(f2.rows.size(), 25u);  // Head-C1 .. L5-S1
  const auto& l45 = f2.row("NSJoint_28");
  EXPECT_EQ(l45[f2.col("location")], "L4-L5");
  EXPECT_DOUBLE_EQ(std::stod(l45[f2.col("x_mm")]), 0.0);
  EXPECT_DOUBLE_EQ(std::stod(l45[f2.col("y_mm")]), 93.0);
  EXPECT_DOUBLE_EQ(std::stod(l45[f2.col("z_mm")]), 0.0);
  EXPECT_EQ(l45[f2.col("marker_id")], ".m24");
  // The OCR text has Cyrillic letters in "T8-T9"; the file must be plain ASCII.
  EXPECT_EQ(f2.row("NSJoint_20")[f2.col("location")], "T8-T9");
  EXPECT_DOUBLE_EQ(f2.num("NSJoint_29", "y_mm"), 63.0);
  EXPECT_DOUBLE_EQ(f2.num("NSJoint_29", "z_mm"), -9.0);
}

TEST(ThesisTables, F4StiffnessAndF5RangeOfMotion) {
  const Csv f4 = read_csv(kThesis / "F4_joint_torsional_stiffness.csv");
  EXPECT_DOUBLE_EQ(f4.num("L1-L5", "flexion_nmm_per_deg"), 1400);
  EXPECT_DOUBLE_EQ(f4.num("L1-L5", "extension_nmm_per_deg"), 2900);
  EXPECT_DOUBLE_EQ(f4.num("T1-T12", "axial_torsion_nmm_per_deg"), 2600);
  EXPECT_DOUBLE_EQ(f4.num("L5-S1", "lateral_bending_nmm_per_deg"), 3600);
  const Csv f5 = read_csv(kThesis / "F5_range_of_motion.csv");
  EXPECT_EQ(f5.rows.size(), 25u);  // Occ-C1 .. L5-S1
  EXPECT_DOUBLE_EQ(f5.num("L4-L5", "flexion_deg"), 13);
  EXPECT_DOUBLE_EQ(f5.num("L4-L5", "extension_deg"), 2);
  EXPECT_DOUBLE_EQ(f5.num("C1-C2", "torsion_deg"), 47);
}

TEST(ThesisTables, F6F7Ligaments) {
  const Csv lig = read_csv(kThesis / "F6_F7_ligament_stiffness.csv");
  EXPECT_DOUBLE_EQ(lig.num("lumbar", "all_n_per_mm"), 33);
  EXPECT_DOUBLE_EQ(lig.num("lumbar", "jc_n_per_mm"), 33.9);
  EXPECT_DOUBLE_EQ(lig.num("cervical", "isl_n_per_mm"), 7);
  EXPECT_DOUBLE_EQ(lig.num("cervical", "pll_n_per_mm"), 24.2);
}

TEST(ThesisTables, MuscleAttachmentsAndProperties) {
  const Csv mf = read_csv(kThesis / "F8_F9_multifidus.csv");
  EXPECT_DOUBLE_EQ(mf.num("NStiss_134", "distal_x_mm"), -19.3);
  EXPECT_DOUBLE_EQ(mf.num("NStiss_134", "distal_y_mm"), 64.9);
  EXPECT_DOUBLE_EQ(mf.num("NStiss_134", "distal_z_mm"), -46.3);
  EXPECT_EQ(mf.row("NStiss_134")[mf.col("distal_segment")], "Sacrum");
  EXPECT_DOUBLE_EQ(mf.num("NStiss_134", "pcsa_mm2"), 186);
  const Csv eo = read_csv(kThesis / "F16_F17_external_oblique.csv");
  EXPECT_DOUBLE_EQ(eo.num("NStiss_165", "pcsa_mm2"), 397.4);
  EXPECT_EQ(eo.row("NStiss_165")[eo.col("distal_segment")], "Lower-Torso");
  const Csv io = read_csv(kThesis / "F18_F19_internal_oblique.csv");
  EXPECT_DOUBLE_EQ(io.num("NStiss_176", "pcsa_mm2"), 185.3);
  const Csv ps = read_csv(kThesis / "F12_F13_psoas_major.csv");
  EXPECT_DOUBLE_EQ(ps.num("NStiss_149", "proximal_y_mm"), 223.13);
  // Every lumbar muscle has the thesis's 0.7 MPa maximum stress and lies on the right (x <= 0).
  for (const char* f : {"F8_F9_multifidus.csv", "F10_F11_erector_spinae.csv",
                        "F12_F13_psoas_major.csv", "F14_F15_quadratus_lumborum.csv",
                        "F16_F17_external_oblique.csv", "F18_F19_internal_oblique.csv"}) {
    const Csv m = read_csv(kThesis / f);
    for (const auto& r : m.rows) {
      EXPECT_DOUBLE_EQ(std::stod(r[m.col("max_stress_mpa")]), 0.7) << f << " " << r[0];
      EXPECT_LE(std::stod(r[m.col("proximal_x_mm")]), 0.0) << f << " " << r[0];
      EXPECT_LE(std::stod(r[m.col("distal_x_mm")]), 0.0) << f << " " << r[0];
    }
  }
}

TEST(ThesisTables, Table51Materials) {
  const Csv t = read_csv(kThesis / "table5_1_materials.csv");
  EXPECT_DOUBLE_EQ(t.num("Real disc", "youngs_modulus_mpa"), 3.22);
  EXPECT_DOUBLE_EQ(t.num("Real disc", "shear_modulus_mpa"), 1.106);
  EXPECT_DOUBLE_EQ(t.num("Real disc", "density_kg_per_mm3"), 1.038e-6);
  EXPECT_DOUBLE_EQ(t.num("Rubber", "shear_modulus_mpa"), 0.6);
  EXPECT_DOUBLE_EQ(t.num("Polyethylene", "youngs_modulus_mpa"), 200);
}

// Appendix C: recompute the intra-abdominal-pressure bushing from the JSON inputs.
TEST(ThesisTables, AppendixCRecomputesTheBushing) {
  const auto j = read_json(kThesis / "appendix_c_iap.json");
  const double volume_mm3 = j.at("V_L1L5_mm3");
  EXPECT_DOUBLE_EQ(volume_mm3, 1994099.78);
  const auto areas = j.at("section_areas_mm2").get<std::vector<double>>();
  ASSERT_EQ(areas.size(), 5u);
  double sum_mm2 = 0;
  for (double s : areas) sum_mm2 += s;
  EXPECT_NEAR(sum_mm2, 84289.38, 1e-6);
  const double s_mean_mm2 = sum_mm2 / areas.size();
  const double h_l1l5_mm = volume_mm3 / s_mean_mm2;
  const double h_mm = j.at("abdominal_height_factor").get<double>() * h_l1l5_mm;
  const double a_mm = std::sqrt(s_mean_mm2);
  EXPECT_NEAR(h_l1l5_mm, 118.2889, 1e-4);
  EXPECT_NEAR(h_mm, 177.433, 1e-3);
  EXPECT_NEAR(a_mm, 129.837, 1e-3);
  // P = rho g h: kg/m^3 * 1e-9 = kg/mm^3; times mm of mercury and m/s^2 gives N/mm^2.
  const double p_n_mm2 = j.at("iap_mmhg").get<double>() *
                         j.at("mercury_density_kg_m3").get<double>() * 1e-9 *
                         j.at("gravity_m_s2").get<double>();
  const double k_y = 0.5 * p_n_mm2 * a_mm * a_mm;
  const double k_x = 0.5 * p_n_mm2 * a_mm * h_mm;
  const double deg = 3.14159265358979323846 / 180.0;
  EXPECT_NEAR(k_y, 22.44, 0.005);
  EXPECT_NEAR(k_x, 30.667, 0.002);
  // The thesis multiplied its rounded k_y = 22.44 and a = 129.837, hence ~1e-4 relative slack.
  EXPECT_NEAR(k_y * deg * a_mm * a_mm, 6602.329, 6602.329 * 2e-4);
  EXPECT_NEAR(k_x * deg * a_mm * a_mm, 9022.888, 9022.888 * 2e-4);
  EXPECT_NEAR(4 * k_x, 122.668, 0.01);
  EXPECT_NEAR(4 * k_y, 89.76, 0.01);
  const auto loc = j.at("bushing_location_mm").get<std::vector<double>>();
  EXPECT_EQ(loc, (std::vector<double>{0.0, 110.0, 40.0}));
}

// Every transcribed CSV (data/thesis/*.csv, data/disc_morphometry.csv, data/vertebra_morphometry.csv): a '# source:' first
// line, a '# units:' line, a header, rectangular rows, no empty cells.
TEST(DataFiles, EveryCsvIsWellFormed) {
  std::vector<fs::path> paths = {kData / "disc_morphometry.csv",
                                 kData / "vertebra_morphometry.csv"};
  for (const auto& entry : fs::directory_iterator(kThesis))
    if (entry.path().extension() == ".csv") paths.push_back(entry.path());
  int files = 0;
  for (const auto& path : paths) {
    ++files;
    const Csv c = read_csv(path);
    const std::string name = path.string();
    ASSERT_FALSE(c.comments.empty()) << name;
    EXPECT_EQ(c.comments.front().rfind("# source:", 0), 0u)
        << name << ": first line must be '# source: ...'";
    bool has_units = false;
    for (const auto& line : c.comments) has_units = has_units || line.rfind("# units:", 0) == 0;
    EXPECT_TRUE(has_units) << name;
    ASSERT_FALSE(c.header.empty()) << name;
    EXPECT_FALSE(c.rows.empty()) << name;
    for (const auto& r : c.rows) {
      EXPECT_EQ(r.size(), c.header.size()) << name << " row " << r.at(0);
      for (const auto& cell : r) EXPECT_FALSE(cell.empty()) << name << " row " << r.at(0);
    }
  }
  EXPECT_GE(files, 14);
}

TEST(DataFiles, MuscleTablesHaveTheirRowCounts) {
  const std::map<std::string, std::size_t> rows = {
      {"F8_F9_multifidus.csv", 19},        {"F10_F11_erector_spinae.csv", 9},
      {"F12_F13_psoas_major.csv", 11},     {"F14_F15_quadratus_lumborum.csv", 5},
      {"F16_F17_external_oblique.csv", 6}, {"F18_F19_internal_oblique.csv", 6}};
  for (const auto& [file, n] : rows) {
    const Csv c = read_csv(kThesis / file);
    EXPECT_EQ(c.rows.size(), n) << file;
    for (const auto& r : c.rows) {
      EXPECT_EQ(r.at(0).rfind("NStiss_", 0), 0u) << file;
      for (std::size_t k = 2; k < r.size(); ++k)
        if (k != c.col("distal_segment"))
          EXPECT_NO_THROW((void)std::stod(r[k])) << file << " " << r[0];
    }
  }
}

TEST(DataFiles, EveryJsonParsesAndNamesItsSource) {
  int files = 0;
  for (const auto& dir : {kThesis, kData / "materials", kData / "materials" / "invalid"})
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() != ".json") continue;
      ++files;
      const auto j = read_json(entry.path());
      EXPECT_TRUE(j.contains("source") && j.at("source").is_string()) << entry.path();
    }
  EXPECT_GE(files, 7);
}

}  // namespace
