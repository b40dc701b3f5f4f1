// The output toolkit (output/): the number formatter's NaN rule, UTF-8-aware tables, the progress
// bar's ETA, JSON of Eigen values, output folders.
#include "spinesim/output/files.hpp"
#include "spinesim/output/format.hpp"
#include "spinesim/output/json.hpp"
#include "spinesim/output/progress.hpp"
#include "spinesim/output/table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

using namespace spinesim::output;

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
  spinesim::output::prepare_output_folder(nested.string(), "--out");
  EXPECT_TRUE(fs::is_directory(nested));
  EXPECT_TRUE(fs::is_empty(nested));                                  // the write probe is gone
  spinesim::output::prepare_output_folder(nested.string(), "--out");  // exists: fine
  std::ofstream(root / "file") << "x";
  const auto refused = [](const std::string& path, const std::string& needle) {
    try {
      spinesim::output::prepare_output_folder(path, "--out");
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
