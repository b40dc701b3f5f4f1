// The output toolkit: the number formatter's NaN rule, UTF-8-aware tables, the progress bar's
// ETA, JSON of Eigen values.
#include "spinesim/studies/format.hpp"
#include "spinesim/studies/json.hpp"
#include "spinesim/studies/progress.hpp"
#include "spinesim/studies/table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

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
