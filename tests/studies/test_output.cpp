// The output toolkit: the number formatter's NaN rule, UTF-8-aware tables, the progress bar's
// ETA, JSON of Eigen values, output folders, the verdicts the program prints (missed deadlines,
// the demo's summary).
#include "spinesim/studies/demo.hpp"
#include "spinesim/studies/files.hpp"
#include "spinesim/studies/format.hpp"
#include "spinesim/studies/haptics_run.hpp"
#include "spinesim/studies/json.hpp"
#include "spinesim/studies/progress.hpp"
#include "spinesim/studies/table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

using namespace spinesim::studies;

TEST(Format, OneNanRuleAndNoNegativeZero) {
  EXPECT_EQ(fixed(NAN, 2), "n/a");
  EXPECT_EQ(fixed(-0.0004, 3), "0.000");
  EXPECT_EQ(fixed(-1.25, 1), "-1.2");  // round half to even in printf
  EXPECT_EQ(fixed(INFINITY, 1), "inf");
  EXPECT_EQ(percent(0.1234), "12.3 %");
  EXPECT_EQ(percent(NAN), "n/a");
  EXPECT_EQ(significant(718.1234, 4), "718.1");
  EXPECT_EQ(one_line("a\nb\nc"), "a b c");
}

TEST(Table, AlignsByDisplayColumnsAndEscapesPipesInMarkdown) {
  TextTable t({"joint", "Δx (mm)", "N·mm"});
  t.add({"T1-T2", "1.5", "|F|"});
  t.add({"L4-L5", "-12.25", "7"});
  std::ostringstream text, md;
  t.print(text, false, "");
  t.print(md, true);
  EXPECT_EQ(text.str(), "joint  Δx (mm)  N·mm\nT1-T2      1.5   |F|\nL4-L5   -12.25     7\n");
  EXPECT_EQ(md.str(),
            "| joint | Δx (mm) | N·mm |\n|---|---:|---:|\n| T1-T2 | 1.5 | \\|F\\| |\n| L4-L5 | "
            "-12.25 | 7 |\n");
}

TEST(ProgressBar, RendersCountPercentageAndEta) {
  EXPECT_EQ(ProgressBar::render(0, 17, 0.0, "", "levels", 10), "[..........]  0/17 levels  0 %");
  // 4 of 16 done in 20 s: 5 s each, 12 left -> 60 s.
  EXPECT_EQ(ProgressBar::render(4, 16, 20.0, "T5-T6", "", 8),
            "T5-T6  [##......]  4/16  25 %  ETA 1 min 0 s");
  EXPECT_EQ(ProgressBar::render(16, 16, 80.0, "", "", 4), "[####]  16/16  100 %");
  EXPECT_EQ(human_duration(8.44), "8.4 s");
  EXPECT_EQ(human_duration(3725), "1 h 02 min");
}

TEST(Json, EigenVectorsAndMatrices) {
  const Eigen::Vector3d v(1, 2, 3);
  EXPECT_EQ(to_json(v).dump(), "[1.0,2.0,3.0]");
  Eigen::Matrix2d m;
  m << 1, 2, 3, 4;
  EXPECT_EQ(to_json(m).dump(), "[[1.0,2.0],[3.0,4.0]]");
  EXPECT_EQ(matrix_to_json(Eigen::RowVector2d(5, 6)).dump(), "[[5.0,6.0]]");
  EXPECT_TRUE(path_or_null("").is_null());
}

// Every --out DIR: made (parents too) before the work; refused only when it cannot be written.
TEST(Files, AnOutputFolderIsMadeOrRefusedInOneLine) {
  namespace fs = std::filesystem;
  const fs::path root = fs::path(SPINESIM_TEST_TMP) / ("out-folders-" + std::to_string(::getpid()));
  fs::remove_all(root);
  const fs::path nested = root / "a" / "b" / "c";
  spinesim::studies::prepare_output_folder(nested.string(), "--out");
  EXPECT_TRUE(fs::is_directory(nested));
  EXPECT_TRUE(fs::is_empty(nested));  // the write probe is gone
  spinesim::studies::prepare_output_folder(nested.string(), "--out");  // exists: fine
  std::ofstream(root / "file") << "x";
  const auto refused = [](const std::string& path, const std::string& needle) {
    try {
      spinesim::studies::prepare_output_folder(path, "--out");
      ADD_FAILURE() << path;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  refused((root / "file").string(), "exists and is not a folder");
  refused((root / "file" / "sub").string(), "cannot create the folder");
  refused("", "give an output folder");
  if (::geteuid() != 0) {  // root writes anywhere: the permission case needs a user
    fs::create_directories(root / "locked");
    fs::permissions(root / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    refused((root / "locked").string(), "cannot be written");
  }
  refused("/proc/version/x", "cannot create the folder");
}

TEST(HapticsRun, MissedDeadlinesAreJudgedAgainstTheLimit) {
  HapticsRunResult r;
  r.stats.ticks = 2863;
  r.stats.missed_deadlines = 611;
  r.stats.rate_hz = 954;
  const std::string w = missed_deadlines_warning(r, 1.0);
  EXPECT_NE(w.find("611 of 2863 deadlines missed (21.34 %"), std::string::npos) << w;
  EXPECT_EQ(w.find('\n'), std::string::npos);
  r.stats.missed_deadlines = 2;  // 0.07 %: within 1 %
  EXPECT_EQ(missed_deadlines_warning(r, 1.0), "");
  EXPECT_NE(missed_deadlines_warning(r, 0.0), "");
  r.stats.ticks = 0;  // a run that never ticked has nothing to judge
  EXPECT_EQ(missed_deadlines_warning(r, 0.0), "");
}

TEST(Demo, TheSummaryIsShortAndSaysWhereTheReportIs) {
  DemoResult r;
  r.report_path = "demo-out/report.md";
  r.html.written = true;
  r.html.message = "report written to demo-out/report.html";
  r.report_markdown = std::string(20000, 'x');
  r.summary = nlohmann::json::parse(R"({
    "level": "L4-L5", "fem_order": 2, "fem_dofs": 30000,
    "mesh": {"tets": 12000, "nodes": 2500, "min_dihedral_deg": 11.2},
    "stiffness_6x6_disc_frame": [[1,0,0,0,0,0],[0,1234.6,0,0,0,0]],
    "calibration": {"holdout": [{"untuned_error": 0.5, "tuned_error": 0.06},
                                {"untuned_error": 0.3, "tuned_error": 0.08}]},
    "spine_validation": {"mcgill": {"axial_n": 4219.8}, "wilke": {"axial_n": 3525, "target": {"axial_n": 3500}}},
    "haptics_run": {"rate_hz": 1000, "missed_deadlines": 1, "ticks": 3000}})");
  const std::string s = demo_summary(r);
  EXPECT_LT(std::count(s.begin(), s.end(), '\n'), 12) << s;
  EXPECT_EQ(s.find("xxxx"), std::string::npos);  // not the report
  EXPECT_NE(s.find("demo-out/report.md"), std::string::npos) << s;
  EXPECT_NE(s.find("report.html"), std::string::npos) << s;
  EXPECT_NE(s.find("1235 N/mm"), std::string::npos) << s;
  EXPECT_NE(s.find("untuned 40.0 %, tuned 7.0 %"), std::string::npos) << s;
  EXPECT_NE(s.find("L5-S1 4220 N"), std::string::npos) << s;
  // A summary without a step says n/a, it does not throw.
  r.summary = nlohmann::json::object();
  EXPECT_NE(demo_summary(r).find("n/a"), std::string::npos);
}
