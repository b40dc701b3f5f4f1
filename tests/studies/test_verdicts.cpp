// The verdicts the program prints: the missed deadlines of a haptic run judged against a limit,
// and the demo's short summary.
#include "spinesim/studies/demo.hpp"
#include "spinesim/studies/haptics_run.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace spinesim::studies;

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
  // With the floor measured beside it, the warning says how much of it the machine misses.
  r.stats.missed_deadlines = 611;
  r.floor.wakeups = 2870;
  r.floor.late = 30;
  r.floor.late_percent = 100.0 * 30 / 2870;
  const std::string f = missed_deadlines_warning(r, 1.0);
  EXPECT_NE(f.find("the machine's own floor in the same run: 1.05 %"), std::string::npos) << f;
  EXPECT_EQ(f.find('\n'), std::string::npos);
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
