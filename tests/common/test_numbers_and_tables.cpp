// The one number reader (numbers.hpp), the one data-table reader (csv_table.hpp), the constants,
// the cross-product matrix, and the strict JSON reader's duplicate and unknown keys.
#include "spinesim/common/constants.hpp"
#include "spinesim/common/csv_table.hpp"
#include "spinesim/common/input_file.hpp"
#include "spinesim/common/numbers.hpp"
#include "spinesim/common/skew.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace {

std::string scratch_file(const std::string& name, const std::string& text) {
  const fs::path dir = fs::path(SPINESIM_TEST_TMP) / ("numbers-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(Numbers, PlainDecimalNotationOnly) {
  for (const char* ok : {"0", "12", "-3", "+4", "1.5", ".5", "5.", "1e3", "-2.5E-7", "1e+2"}) {
    EXPECT_TRUE(spinesim::is_plain_number(ok)) << ok;
    EXPECT_EQ(spinesim::to_double(ok, "x"), std::strtod(ok, nullptr)) << ok;
  }
  // What strtod or std::stod would have read as something else: hex, nan, inf, blanks, an empty
  // text, a partial number.
  for (const char* bad : {"", " 1", "1 ", "0x10", "nan", "NaN", "inf", "-inf", "1e", "e3", ".", "-",
                          "1,5", "1.2.3", "12abc", "1e400"}) {
    EXPECT_THROW(spinesim::to_double(bad, "the flag"), std::invalid_argument) << bad;
  }
  try {
    spinesim::to_double("0x10", "--pelvic-tilt");
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "--pelvic-tilt: '0x10' is not a finite number");
  }
  EXPECT_TRUE(spinesim::is_plain_number("-12", true));
  for (const char* bad : {"1.0", "1e3", "", "+", "0x1"})
    EXPECT_FALSE(spinesim::is_plain_number(bad, true)) << bad;
}

TEST(CsvTable, ReadsTheDataConventionAndNamesEveryError) {
  const std::string path =
      scratch_file("t.csv", "# a comment\n\nlevel, x_mm ,y_mm\nL1, 1.5, -2\r\nL2,3,4e1\n");
  const spinesim::CsvTable t = spinesim::read_csv(path);
  ASSERT_EQ(t.header, (std::vector<std::string>{"level", "x_mm", "y_mm"}));
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.number(t.find("level", "L2"), "y_mm"), 40.0);
  EXPECT_EQ(t.text(0, "x_mm"), "1.5");
  EXPECT_THROW(t.column("z_mm"), std::invalid_argument);
  EXPECT_THROW(t.find("level", "L3"), std::invalid_argument);
  const spinesim::CsvTable bad = spinesim::read_csv(scratch_file("b.csv", "a,b\n0x10,nan\n"));
  try {
    bad.number(0, "a");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("row 1 column 'a'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(bad.number(0, "b"), std::invalid_argument);
  EXPECT_THROW(spinesim::read_csv(scratch_file("r.csv", "a,b\n1\n")), std::invalid_argument);
  EXPECT_THROW(spinesim::read_csv(scratch_file("e.csv", "# only a comment\n")),
               std::invalid_argument);
  EXPECT_THROW(spinesim::read_csv("/nonexistent.csv"), std::invalid_argument);
}

TEST(Constants, DegreesAndRadians) {
  EXPECT_DOUBLE_EQ(spinesim::kPi, std::acos(-1.0));
  EXPECT_DOUBLE_EQ(180 * spinesim::kRadPerDeg, spinesim::kPi);
  EXPECT_DOUBLE_EQ(spinesim::kPi * spinesim::kDegPerRad, 180.0);
}

TEST(Skew, IsTheCrossProduct) {
  const Eigen::Vector3d a(0.3, -1.2, 2.5), b(-0.7, 0.4, 1.1);
  const Eigen::Matrix3d S = spinesim::skew(a);
  EXPECT_LT((S * b - a.cross(b)).norm(), 1e-15);
  EXPECT_LT((S + S.transpose()).norm(), 1e-15);
  // On an expression too (the MSS takes it of arm differences).
  EXPECT_EQ(spinesim::skew(a - b), spinesim::skew(Eigen::Vector3d(a - b)));
}

TEST(StrictJson, AKeyTwiceInOneObjectIsRefused) {
  EXPECT_THROW(spinesim::read_json_file(scratch_file("d.json", R"({"a": 1, "b": 2, "a": 3})"), "x"),
               std::invalid_argument);
  try {
    spinesim::read_json_file(scratch_file("n.json", R"({"o": {"k": 1, "k": 2}})"), "material file");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"k\" twice"), std::string::npos) << e.what();
  }
  // The same key in two objects, and in objects of an array, is no duplicate.
  const auto j = spinesim::read_json_file(
      scratch_file("ok.json", R"({"a": {"k": 1}, "b": {"k": 2}, "c": [{"k": 1}, {"k": 2}]})"), "x");
  EXPECT_EQ(j["b"]["k"], 2);
}

TEST(StrictJson, UnknownFieldsAreNamed) {
  const nlohmann::json j = {{"E_mpa", 1}, {"direction", {0, 0, 0}}};
  try {
    spinesim::require_known_keys(j, {"E_mpa", "nu"}, "fibres");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown field \"direction\""), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("known: E_mpa, nu"), std::string::npos);
  }
  EXPECT_NO_THROW(spinesim::require_known_keys({{"nu", 0.3}}, {"E_mpa", "nu"}, "x"));
}

TEST(InputFile, StreamedFilesGetTheSameChecks) {
  EXPECT_THROW(spinesim::open_regular_file("/nonexistent", "the recording"), std::invalid_argument);
  EXPECT_THROW(spinesim::open_regular_file(SPINESIM_TEST_TMP, "the recording"),
               std::invalid_argument);
  spinesim::InputLimits small;
  small.max_bytes = 3;
  EXPECT_THROW(spinesim::open_regular_file(scratch_file("big.csv", "12345"), "x", small),
               std::invalid_argument);
  std::ifstream in = spinesim::open_regular_file(scratch_file("s.csv", "ab\n"), "x");
  std::string line;
  EXPECT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "ab");
}

}  // namespace
