// The mass-spring verbs of the `spinesim` program: `mss` (static and dynamic), `mss compare`,
// `study probe` and `study drive` — JSON fields, signs, files written (and not written), and bad
// input -> exit 1 with one line on stderr. One coarse L4-L5 disc (cell size 4 mm) for all.
#include "cli_runner.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using namespace spinesim::test_cli;

/// The files a .pvd lists, resolved against its folder.
std::vector<fs::path> pvd_files(const std::string& pvd) {
  const std::string text = slurp(pvd);
  std::vector<fs::path> files;
  const std::regex re("file=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator();
       ++it)
    files.push_back(fs::path(pvd).parent_path() / (*it)[1].str());
  return files;
}

void expect_finite_vector(const json& a, std::size_t n, const std::string& what) {
  ASSERT_TRUE(a.is_array()) << what;
  ASSERT_EQ(a.size(), n) << what;
  for (const auto& v : a) EXPECT_TRUE(v.is_number() && std::isfinite(v.get<double>())) << what;
}

/// The coarse disc, made once per test process.
class MssCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    disc_ = tmp("mss-disc.vtu");
    const CliRun r = run_spinesim("mesh disc --level L4-L5 --cell-size 4 --out '" + disc_ + "'");
    ASSERT_EQ(r.status, 0) << r.err;
  }
  static std::string disc_;
};
std::string MssCli::disc_;

}  // namespace

TEST(MssCliHelp, EveryVerbHasHelp) {
  for (const char* verb : {"mss", "mss compare", "study", "study probe", "study drive"}) {
    const CliRun r = run_spinesim(std::string(verb) + " --help");
    EXPECT_EQ(r.status, 0) << verb;
    EXPECT_NE(r.out.find("--"), std::string::npos) << verb;
  }
  EXPECT_NE(run_spinesim("mss compare --help").out.find("displacement_error"), std::string::npos);
}

TEST_F(MssCli, StaticCompressionPushesThePlateUpAndLosesVolume) {
  const std::string out = tmp("static.vtu");
  const CliRun r =
      run_spinesim("mss --mesh '" + disc_ + "' --motion 0,-0.2,0,0,0,0 --json --out '" + out + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  for (const char* key : {"nodes", "tets", "plate_center", "plate_motion", "reaction_wrench",
                          "volume_mm3", "volume_change", "timings", "converged", "iterations",
                          "springs", "K_d_n_s_per_mm", "equivalent_cylinder"})
    EXPECT_TRUE(j.contains(key)) << key;
  expect_finite_vector(j["plate_center"], 3, "plate_center");
  expect_finite_vector(j["plate_motion"], 6, "plate_motion");
  expect_finite_vector(j["reaction_wrench"], 6, "reaction_wrench");
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_NEAR(j["plate_motion"][1].get<double>(), -0.2, 1e-12);
  EXPECT_GT(j["reaction_wrench"][1].get<double>(), 0.0);  // compression pushes the plate up
  EXPECT_LT(j["volume_change"].get<double>(), 0.0);
  EXPECT_GT(j["volume_change"].get<double>(), -0.05);
  EXPECT_GT(j["springs"]["edge"].get<long>(), 0);
  EXPECT_GT(j["springs"]["angle"].get<long>(), 0);
  EXPECT_EQ(j["springs"]["radial_tets"].get<long>(), j["tets"].get<long>());
  EXPECT_GT(j["K_d_n_s_per_mm"].get<double>(), 0.0);
  const auto& cyl = j["equivalent_cylinder"];
  EXPECT_GT(cyl["D_m_mm"].get<double>(), 30.0);  // L4-L5: about 47 x 35 mm
  EXPECT_GT(cyl["L_m_mm"].get<double>(), 5.0);
  EXPECT_GT(cyl["k_t_nmm_per_rad"]["annulus"].get<double>(), 0.0);

  // The result file: displacement point data and per-tet volume change, readable back.
  std::vector<spinesim::mesh::DataArray> points, cells;
  const auto m = spinesim::mesh::read_vtu(out, &points, &cells);
  EXPECT_EQ(m.num_tets(), j["tets"].get<long>());
  const auto disp = std::find_if(points.begin(), points.end(),
                                 [](const auto& a) { return a.name == "displacement"; });
  ASSERT_NE(disp, points.end());
  ASSERT_EQ(disp->values.cols(), 3);
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
    if (m.surface(i) == 2)
      EXPECT_NEAR(disp->values(i, 1), -0.2, 1e-9);  // plate nodes follow the plate
    if (m.surface(i) == 1) EXPECT_EQ(disp->values.row(i).norm(), 0.0);
  }
  const auto dv = std::find_if(cells.begin(), cells.end(),
                               [](const auto& a) { return a.name == "volume_change"; });
  ASSERT_NE(dv, cells.end());
  EXPECT_EQ(dv->values.rows(), m.num_tets());
}

TEST_F(MssCli, WrenchCaseIsBalancedByTheReaction) {
  const CliRun r = run_spinesim("mss --mesh '" + disc_ + "' --case compression --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["case"], "compression");
  EXPECT_TRUE(j["converged"].get<bool>());
  // 500 N along the disc axis: the reaction has that size and points up the (tilted) disc.
  const auto& w = j["reaction_wrench"];
  const double f = std::hypot(w[0].get<double>(), w[1].get<double>(), w[2].get<double>());
  EXPECT_NEAR(f, 500.0, 1e-6 * 500.0);
  EXPECT_GT(w[1].get<double>(), 400.0);
  EXPECT_LT(j["plate_motion"][1].get<double>(), 0.0);
}

TEST_F(MssCli, VolumeTermsKeepTheVolumeBetter) {
  double dv[4];
  const char* flags[] = {"--no-radial", "", "--volume-term", "--disc-volume-term"};
  for (int i = 0; i < 4; ++i) {
    const CliRun r =
        run_spinesim("mss --mesh '" + disc_ + "' --motion 0,-1,0,0,0,0 --json " + flags[i]);
    ASSERT_EQ(r.status, 0) << flags[i] << r.err;
    dv[i] = json::parse(r.out)["volume_change"].get<double>();
    EXPECT_LT(dv[i], 0.0) << flags[i];
  }
  EXPECT_LT(std::abs(dv[2]), std::abs(dv[1]));
  EXPECT_LT(std::abs(dv[2]), std::abs(dv[0]));
  EXPECT_LT(std::abs(dv[3]), std::abs(dv[1]));
}

TEST_F(MssCli, ImplicitRunWritesATimeSeries) {
  const std::string pvd = tmp("run.pvd");
  tmp("run");
  const CliRun r = run_spinesim(
      "mss --mesh '" + disc_ +
      "' --case compression --dt 1e-3 --steps 20 --frame-every 5 --json --out '" + pvd + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_FALSE(j["diverged"].get<bool>());
  EXPECT_EQ(j["steps_done"].get<int>(), 20);
  EXPECT_GT(j["step_seconds_mean"].get<double>(), 0.0);
  EXPECT_EQ(j["ramp_steps"].get<int>(), 2);
  EXPECT_GT(j["reaction_wrench"][1].get<double>(), 0.0);
  const auto files = pvd_files(pvd);
  EXPECT_EQ(files.size(), 5u);  // t = 0 and every 5th step
  EXPECT_EQ(j["frames"].get<std::size_t>(), files.size());
  for (const auto& f : files) EXPECT_TRUE(fs::exists(f)) << f;
  std::vector<spinesim::mesh::DataArray> points;
  spinesim::mesh::read_vtu(files.back().string(), &points);
  ASSERT_FALSE(points.empty());
  EXPECT_TRUE(points[0].values.allFinite());
}

TEST_F(MssCli, ExplicitEulerAtOneMillisecondDivergesAndWritesNothing) {
  const std::string pvd = tmp("explicit.pvd");
  tmp("explicit");
  const CliRun r = run_spinesim(
      "mss --mesh '" + disc_ +
      "' --case compression --dt 1e-3 --steps 50 --integrator explicit --json --out '" + pvd + "'");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("diverged"), std::string::npos) << r.err;
  const json j = json::parse(r.out);
  EXPECT_TRUE(j["diverged"].get<bool>());
  EXPECT_LT(j["steps_done"].get<int>(), 50);
  EXPECT_NE(j.dump().find("diverged"), std::string::npos);
  EXPECT_EQ(r.out.find("NaN"), std::string::npos);
  EXPECT_EQ(r.out.find("null"), std::string::npos);  // nlohmann writes NaN as null
  EXPECT_FALSE(fs::exists(pvd));
  EXPECT_TRUE(!fs::exists(tmp_dir() / "explicit") || fs::is_empty(tmp_dir() / "explicit"));
}

TEST_F(MssCli, CompareGivesEightFiniteCases) {
  const std::string csv = tmp("compare.csv");
  const CliRun r =
      run_spinesim("mss compare --mesh '" + disc_ + "' --order 1 --json --csv '" + csv + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["cases"].size(), 8u);
  const char* names[] = {"compression", "tension",   "shear-ap",        "shear-lat",
                         "flexion",     "extension", "lateral-bending", "torsion"};
  for (std::size_t i = 0; i < 8; ++i) {
    const auto& c = j["cases"][i];
    EXPECT_EQ(c["name"], names[i]);
    for (const char* key : {"displacement_error", "plate_motion_error", "reaction_error",
                            "reaction_force_error", "reaction_moment_error"}) {
      const double e = c[key].get<double>();
      EXPECT_TRUE(std::isfinite(e) && e >= 0.0 && e < 10.0) << names[i] << " " << key << " " << e;
    }
    EXPECT_GT(c["displacement_error"].get<double>(), 0.0);  // untuned: not equal to the FEM
    expect_finite_vector(c["reaction_wrench_fem"], 6, "reaction_wrench_fem");
    expect_finite_vector(c["reaction_wrench_mss"], 6, "reaction_wrench_mss");
    EXPECT_TRUE(c["converged"].get<bool>()) << names[i];
  }
  // Wrench-loaded FEM: its reaction is minus the applied wrench.
  EXPECT_NEAR(j["cases"][0]["reaction_wrench_fem"][1].get<double>(),
              -j["cases"][0]["wrench"][1].get<double>(), 1e-6);
  const auto& ratio = j["stiffness_diagonal"]["ratio_mss_over_fem"];
  expect_finite_vector(ratio, 6, "stiffness ratio");
  for (const auto& v : ratio) EXPECT_GT(v.get<double>(), 0.0);
  EXPECT_EQ(count_lines(csv_table(csv)), 9);

  const CliRun two =
      run_spinesim("mss compare --mesh '" + disc_ + "' --order 1 --cases compression,torsion");
  ASSERT_EQ(two.status, 0) << two.err;
  EXPECT_NE(two.out.find("torsion"), std::string::npos);
  EXPECT_EQ(two.out.find("flexion"), std::string::npos);
}

TEST_F(MssCli, BadInputIsRefusedInOneLineWithoutOutput) {
  const std::string out = tmp("bad.vtu"), pvd = tmp("bad.pvd");
  const std::string mss = "mss --mesh '" + disc_ + "' ";
  const std::string o = " --out '" + out + "'";
  const std::string material = tmp("zero-modulus.json");
  std::ofstream(material) << R"({"name":"zero","E_mpa":0,"nu":0.3})";
  expect_refused(run_spinesim(mss + "--material '" + material + "' --case compression" + o),
                 "Young's modulus");
  expect_refused(run_spinesim(mss + "--case compression --dt 0 --steps 5" + o), "--dt");
  expect_refused(run_spinesim(mss + "--case compression --dt -1e-3 --steps 5" + o), "--dt");
  expect_refused(run_spinesim(mss + "--case compression --dt nan --steps 5" + o), "--dt");
  expect_refused(run_spinesim(mss + "--motion 0,nan,0,0,0,0" + o), "not a finite number");
  expect_refused(run_spinesim(mss + "--wrench 0,-500,0" + o), "expected 6");
  expect_refused(run_spinesim(mss + "--case compression --steps 0" + o), "--steps");
  expect_refused(run_spinesim(mss + "--case compression --dt abc --steps 5" + o),
                 "abc");  // malformed number
  expect_refused(run_spinesim(mss + "--case compression --dt 1e-3 --steps 2.5" + o), "2.5");
  expect_refused(run_spinesim(mss + "--case compression --dt 1e-3" + o), "--steps");
  expect_refused(run_spinesim(mss + "--case squat" + o), "unknown load case");
  expect_refused(run_spinesim(mss + "--case compression --integrator rk4 --steps 5" + o),
                 "--integrator");
  expect_refused(run_spinesim(mss + "--case compression --damping -1" + o), "--damping");
  expect_refused(run_spinesim(mss + "--case compression --damping nan" + o), "--damping");
  expect_refused(run_spinesim(mss + "--case compression --static --steps 5" + o), "not both");
  expect_refused(run_spinesim(mss + "--case compression --motion 0,-0.1,0,0,0,0" + o),
                 "at most one");
  expect_refused(run_spinesim(mss + "--case compression --out '" + pvd + "'"), "dynamic");
  expect_refused(run_spinesim(mss + "--case compression --out '" + tmp("bad.txt") + "'"), ".vtu");
  expect_refused(run_spinesim(mss + "--case compression --out /nonexistent/folder/r.vtu"),
                 "does not exist");
  expect_refused(run_spinesim("mss --case compression" + o), "--mesh");
  expect_refused(run_spinesim("mss compare --mesh '" + disc_ + "' --cases compression,squat"),
                 "unknown load case");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(pvd));

  const std::string dir = tmp("bad-study");
  const std::string probe = "study probe --mesh '" + disc_ + "' --out '" + dir + "' ";
  expect_refused(run_spinesim(probe + "--radius 0"), "--radius");
  expect_refused(run_spinesim(probe + "--depth nan"), "--depth");
  expect_refused(run_spinesim(probe + "--dt 0"), "--dt");
  expect_refused(run_spinesim(probe + "--sites inside"), "inside");
  expect_refused(run_spinesim(probe + "--integrator leapfrog"), "--integrator");
  expect_refused(run_spinesim(probe + "--material '" + material + "'"), "Young's modulus");
  expect_refused(run_spinesim("study drive --mesh '" + disc_ + "' --out '" + dir +
                              "' --materials real-disc,unobtainium"),
                 "unknown material");
  expect_refused(
      run_spinesim("study drive --mesh '" + disc_ + "' --out '" + dir + "' --time-scale 0"),
      "--time-scale");
  EXPECT_FALSE(fs::exists(dir));
}

TEST_F(MssCli, ProbeStudyWritesSeriesCsvAndSummary) {
  const std::string dir = tmp("probe");
  const CliRun r = run_spinesim(
      "study probe --mesh '" + disc_ + "' --out '" + dir +
      "' --sites anterior,left --radius 4 --depth 0.5 --speed 10 --hold 0.01 --rest 0.01 "
      "--frame-every 20 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_FALSE(j["diverged"].get<bool>());
  EXPECT_EQ(j["steps"].get<int>(), 240);  // 2 sites x (0.05 + 0.01 + 0.05 + 0.01) s at 1 ms
  EXPECT_EQ(j["steps_done"].get<int>(), 240);
  EXPECT_GT(j["max_force_n"].get<double>(), 0.0);
  EXPECT_TRUE(std::isfinite(j["max_volume_change"].get<double>()));
  EXPECT_GT(j["step_seconds_mean"].get<double>(), 0.0);
  ASSERT_EQ(j["sites"].size(), 2u);
  for (const auto& s : j["sites"]) expect_finite_vector(s["normal"], 3, "site normal");
  const auto files = pvd_files(dir + "/probe.pvd");
  EXPECT_EQ(files.size(), j["frames"].get<std::size_t>());
  EXPECT_GE(files.size(), 12u);
  for (const auto& f : files) EXPECT_TRUE(fs::exists(f)) << f;
  const std::string csv = csv_table(dir + "/probe.csv");
  EXPECT_EQ(count_lines(csv), 241);
  EXPECT_EQ(csv.rfind("time_s,site,probe_active,", 0), 0u);
  EXPECT_EQ(csv.find("nan"), std::string::npos);
  EXPECT_EQ(json::parse(slurp(dir + "/probe.json"))["steps_done"], 240);
}

TEST_F(MssCli, DriveStudyPolyethyleneIsStifferThanTheRealDisc) {
  const std::string dir = tmp("drive");
  const CliRun r =
      run_spinesim("study drive --mesh '" + disc_ + "' --out '" + dir +
                   "' --materials real-disc,polyethylene --time-scale 0.1 --frame-every 40 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_FALSE(j["diverged"].get<bool>());
  ASSERT_EQ(j["materials"].size(), 2u);
  const auto& real = j["materials"][0];
  const auto& poly = j["materials"][1];
  EXPECT_EQ(real["steps_done"].get<int>(), 120);
  EXPECT_GT(real["peak_axial_force_n"].get<double>(), 0.0);  // compression pushes the plate up
  EXPECT_GT(poly["peak_force_n"].get<double>(),
            10.0 * real["peak_force_n"].get<double>());  // E 200 vs 3.22 MPa
  for (const auto& run : j["materials"]) {
    const auto files = pvd_files(run["files"]["pvd"].get<std::string>());
    EXPECT_EQ(files.size(), run["frames"].get<std::size_t>());
    for (const auto& f : files) EXPECT_TRUE(fs::exists(f)) << f;
    const std::string csv = csv_table(run["files"]["csv"].get<std::string>());
    EXPECT_EQ(count_lines(csv), 121);
    EXPECT_EQ(csv.find("nan"), std::string::npos);
  }
  EXPECT_TRUE(fs::exists(dir + "/drive.json"));
}
