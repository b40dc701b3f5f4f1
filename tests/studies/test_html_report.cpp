// The demo's HTML report (studies/html_report.hpp, scripts/report.py) on a small demo folder made
// here: every plot is written and shown in report.html; a missing or broken input is one line and
// no report.html. Needs Debian's python3 with matplotlib and markdown (scripts/install-deps.sh).
#include "spinesim/output/html_report.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using spinesim::studies::write_html_report;

namespace {

bool have_plotting() {
  return fs::exists("/usr/bin/python3") &&
         std::system("/usr/bin/python3 -c 'import matplotlib, markdown' >/dev/null 2>&1") == 0;
}

std::string fresh_dir(const std::string& name) {
  const fs::path p = fs::path(SPINESIM_TEST_TMP) / (name + "-" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

void write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

std::string read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

nlohmann::json load_case(const std::string& name, double untuned, double tuned) {
  return {{"name", name}, {"untuned_error", untuned}, {"tuned_error", tuned}};
}

nlohmann::json material(const std::string& name, double k_fem) {
  return {{"material", name},
          {"fem", {{"axial_stiffness_n_per_mm", k_fem}}},
          {"untuned", {{"axial_stiffness_n_per_mm", 0.7 * k_fem}, {"displacement_error", 0.5}}},
          {"tuned", {{"axial_stiffness_n_per_mm", 1.01 * k_fem}, {"displacement_error", 0.08}}}};
}

/// What the demo writes, small: two load cases, two materials, ten depths, a few ticks.
std::string demo_folder(const std::string& name) {
  const std::string d = fresh_dir(name);
  nlohmann::json s;
  s["level"] = "L4-L5";
  s["calibration"]["train"] = {load_case("compression", 0.52, 0.07)};
  s["calibration"]["holdout"] = {load_case("tension", 0.51, 0.06)};
  s["materials"] = {material("real-disc", 718), material("rubber", 8400)};
  s["spine_validation"] = {
      {"pass", true},
      {"mcgill",
       {{"axial_n", 4220.0},
        {"shear_n", 52.0},
        {"target", {{"axial_range_n", {3929.0, 4688.0}}, {"shear_max_n", 650.0}}},
        {"thesis", {{"axial_n", 4582.0}, {"shear_n", 625.0}}}}},
      {"wilke",
       {{"axial_n", 3525.0},
        {"target", {{"axial_range_n", {2754.0, 3726.0}}}},
        {"thesis", {{"axial_n", 3161.6}}}}}};
  const nlohmann::json finding = {{"id", "some-finding"}, {"match", true}};
  s["spine_trends"] = {{"force_n", 300.0}, {"findings", {finding}}};
  s["spine_fusion"] = {{"findings", {finding, {{"id", "other"}, {"match", false}}}}};
  write(fs::path(d) / "summary.json", s.dump(2));
  std::string trends = "load,pair,dx_mm,dy_mm,dz_mm,theta_x_deg,theta_y_deg,theta_z_deg\n";
  for (const char* load : {"lateral", "forward"})
    for (const char* pair : {"T1-T2", "T2-T3", "T3-T4"})
      trends += std::string(load) + "," + pair + ",-1.5,0.2,0.1,0.3,-0.4,2.0\n";
  write(fs::path(d) / "spine_trends.csv", trends);
  std::string fusion =
      "fusion,load,t1_translation_mm,l2l3_resultant_n,l5s1_resultant_n,other_column\n";
  for (const char* f : {"normal", "L3-L4"})
    for (const char* load : {"forward", "lateral"})
      fusion += std::string(f) + "," + load + ",29.4,1674.6,2684.2,1\n";
  write(fs::path(d) / "spine_fusion.csv", fusion);
  fs::create_directories(fs::path(d) / "probe");
  write(fs::path(d) / "probe" / "probe.csv",
        "time_s,site,depth_mm,force_n,volume_change\n0.001,anterior,0.5,3.0,-0.0001\n"
        "0.002,anterior,1.0,6.0,-0.0002\n0.003,left,0.5,2.0,-0.0001\n");
  std::string plane =
      "# comment\ndepth_mm,small_eq49_n,large_eq49_n,small_eq410_n,large_eq410_n,"
      "small_eq49_exact_n,large_eq49_exact_n,small_eq410_exact_n,large_eq410_exact_n\n";
  for (int k = 0; k <= 10; ++k) {
    const double x = k, s49 = x * (10 - x), l49 = 4 * s49;
    plane += std::to_string(x) + "," + std::to_string(s49) + "," + std::to_string(l49) + "," +
             std::to_string(s49) + "," + std::to_string(s49) + "," + std::to_string(s49) + "," +
             std::to_string(l49) + "," + std::to_string(s49) + "," + std::to_string(s49) + "\n";
  }
  write(fs::path(d) / "haptic_plane.csv", plane);
  write(fs::path(d) / "haptics_stroke.csv",
        "# recording\nt_s,x_mm,y_mm,z_mm,button,fx_n,fy_n,fz_n,proxy_x_mm,proxy_y_mm,proxy_z_mm,"
        "contact,tick\n0.001,0,0,0,0,0,0,0,0,0,0,0,1\n0.002,0,0,0,0,0.3,0.4,0,0,0,0,1,2\n");
  write(fs::path(d) / "report.md", "# Demo\n\n| a | b |\n|---|---|\n| 1 | 2 |\n");
  return d;
}

}  // namespace

// The viewer's screenshots (viewer.json and its PNGs, written by the demo's front end) join the
// figures with their captions; an entry whose PNG is missing is left out.
TEST(HtmlReport, ViewerScreenshotsJoinTheFigures) {
  if (!have_plotting()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib and markdown missing";
  const std::string d = demo_folder("html-report-viewer");
  fs::create_directories(fs::path(d) / "plots");
  write(fs::path(d) / "plots" / "view_a.png", "\x89PNG not really");
  const nlohmann::json shots = {
      {{"file", "view_a.png"}, {"title", "Viewer A"}, {"thesis", "HOOPS"}, {"ours", "60 Hz"}},
      {{"file", "view_missing.png"}, {"title", "Viewer B"}, {"thesis", "-"}, {"ours", "-"}}};
  write(fs::path(d) / "viewer.json", shots.dump());
  const auto r = write_html_report(d);
  ASSERT_TRUE(r.written) << r.message;
  EXPECT_NE(r.message.find("9 figures"), std::string::npos) << r.message;
  const std::string html = read(r.path);
  EXPECT_NE(html.find("plots/view_a.png"), std::string::npos);
  EXPECT_NE(html.find("Viewer A"), std::string::npos);
  EXPECT_EQ(html.find("view_missing.png"), std::string::npos);
}

TEST(HtmlReport, WritesEveryPlotAndShowsThemInTheHtml) {
  if (!have_plotting()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib and markdown missing";
  const std::string d = demo_folder("html-report");
  const auto r = write_html_report(d);
  ASSERT_TRUE(r.written) << r.message;
  EXPECT_NE(r.message.find("8 figures"), std::string::npos) << r.message;
  const std::string html = read(r.path);
  for (const char* png : {"haptic_plane.png", "calibration.png", "materials.png", "validation.png",
                          "spine_t1.png", "fusion.png", "haptic_stroke.png", "probe_test.png"}) {
    const fs::path file = fs::path(d) / "plots" / png;
    ASSERT_TRUE(fs::exists(file)) << png;
    EXPECT_GT(fs::file_size(file), 5000u) << png;  // a drawn figure, not an empty canvas
    EXPECT_EQ(read(file).substr(1, 3), "PNG") << png;
    EXPECT_NE(html.find(std::string("plots/") + png), std::string::npos) << png;
  }
  EXPECT_NE(html.find("<table>"), std::string::npos);  // report.md's table, as HTML
  EXPECT_NE(html.find("Thesis:"), std::string::npos);
  // Our numbers from the input beside the thesis's: the eq 4.9 ratio at the small peak is 4.
  EXPECT_NE(html.find("eq 4.9 4.00"), std::string::npos);
  EXPECT_NE(html.find("1 of 2 thesis findings reproduced (differ: other)"), std::string::npos);
}

TEST(HtmlReport, MissingOrBrokenInputIsOneLineAndNoReport) {
  if (!have_plotting()) GTEST_SKIP() << "/usr/bin/python3 with matplotlib and markdown missing";
  const std::string empty = fresh_dir("html-report-empty");
  auto r = write_html_report(empty);
  EXPECT_FALSE(r.written);
  EXPECT_FALSE(fs::exists(r.path));
  EXPECT_EQ(r.message.find('\n'), std::string::npos);
  EXPECT_NE(r.message.find("summary.json"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("report.html not written"), std::string::npos) << r.message;

  const std::string d = demo_folder("html-report-broken");
  write(fs::path(d) / "haptic_plane.csv", "depth_mm,small_eq49_n\n0,zero\n");
  r = write_html_report(d);
  EXPECT_FALSE(r.written);
  EXPECT_FALSE(fs::exists(r.path));
  EXPECT_NE(r.message.find("bad input"), std::string::npos) << r.message;

  // A stale report.html from an earlier run does not survive a failed one.
  write(fs::path(d) / "report.html", "old");
  r = write_html_report(d);
  EXPECT_FALSE(fs::exists(r.path));
}

TEST(HtmlReport, AMissingPlottingLibraryIsOneClearLine) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "/usr/bin/python3 missing";
  const std::string d = demo_folder("html-report-nolib");
  // A matplotlib that cannot be imported, first on the path.
  const fs::path fake = fs::path(d) / "fake" / "matplotlib";
  fs::create_directories(fake);
  write(fake / "__init__.py", "raise ImportError('not installed')\n");
  const fs::path out = fs::path(d) / "out.txt";
  const std::string command = "PYTHONPATH='" + (fs::path(d) / "fake").string() +
                              "' /usr/bin/python3 '" SPINESIM_SCRIPTS_DIR "/report.py' '" + d +
                              "' >'" + out.string() + "' 2>&1";
  EXPECT_NE(std::system(command.c_str()), 0);
  const std::string said = read(out);
  EXPECT_EQ(said,
            "report: python3-matplotlib is missing (apt-get install python3-matplotlib); "
            "report.html not written\n");
  EXPECT_FALSE(fs::exists(fs::path(d) / "report.html"));
}
