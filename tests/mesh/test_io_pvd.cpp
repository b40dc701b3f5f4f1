// PVD (ParaView collection) writer: an independent XML parser (python3's xml.etree) reads back
// exactly the times and file names written; bad input is refused in one line with no file
// left behind; a refused write leaves an existing file as it was.
#include "spinesim/mesh/io.hpp"

#include "io_fixtures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace spinesim::mesh;

namespace {

std::string tmp_dir(const std::string& name) { return test::fresh_tmp_dir("io_pvd_", name); }

using test::slurp;

int count_files(const std::string& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

/// Times that need all 17 digits, and names that need XML escaping.
std::vector<PvdEntry> sample_entries() {
  return {{0.0, "series/frame_000000.vtu"},
          {0.1 + 0.2, "series/frame_000300.vtu"},
          {1.0 / 3.0, "odd & \"quoted\" <name>'s.vtu"},
          {12.5, "/absolute/path/frame.vtu"}};
}

bool has_python3() {
  return fs::exists("/usr/bin/python3") &&
         std::system("/usr/bin/python3 -c 'import xml.etree.ElementTree' >/dev/null 2>&1") == 0;
}

}  // namespace

TEST(IoPvd, IndependentXmlParserReadsBackTimesAndNames) {
  if (!has_python3()) GTEST_SKIP() << "/usr/bin/python3 not available";
  const std::string dir = tmp_dir("xml");
  const std::string path = dir + "/series.pvd";
  const auto entries = sample_entries();
  write_pvd(path, entries);

  // python prints one line per DataSet: float.hex(timestep) TAB file; hex is bit-exact.
  const std::string script = dir + "/read.py";
  std::ofstream(script) << "import sys, xml.etree.ElementTree as ET\n"
                           "root = ET.parse(sys.argv[1]).getroot()\n"
                           "assert root.tag == 'VTKFile' and root.get('type') == 'Collection'\n"
                           "for d in root.find('Collection').findall('DataSet'):\n"
                           "    assert d.get('part') == '0'\n"
                           "    print(float(d.get('timestep')).hex() + '\\t' + d.get('file'))\n";
  FILE* p = popen(("/usr/bin/python3 '" + script + "' '" + path + "'").c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  ASSERT_EQ(pclose(p), 0) << out;

  std::istringstream lines(out);
  std::string line;
  std::size_t i = 0;
  while (std::getline(lines, line)) {
    ASSERT_LT(i, entries.size());
    const auto tab = line.find('\t');
    ASSERT_NE(tab, std::string::npos) << line;
    EXPECT_EQ(std::strtod(line.substr(0, tab).c_str(), nullptr), entries[i].time_s) << line;
    EXPECT_EQ(line.substr(tab + 1), entries[i].file);
    ++i;
  }
  EXPECT_EQ(i, entries.size());
}

TEST(IoPvd, ShortestTimesAndOneLinePerDataset) {
  const std::string dir = tmp_dir("text");
  const std::string path = dir + "/t.pvd";
  write_pvd(path, {{0.0, "a.vtu"}, {0.001, "b.vtu"}, {2.0, "c.vtu"}});
  const std::string text = slurp(path);
  EXPECT_NE(text.find("timestep=\"0.001\""), std::string::npos) << text;
  EXPECT_NE(text.find("type=\"Collection\""), std::string::npos);
  std::size_t n = 0;
  for (std::size_t at = text.find("<DataSet"); at != std::string::npos;
       at = text.find("<DataSet", at + 1))
    ++n;
  EXPECT_EQ(n, 3u);
  EXPECT_EQ(count_files(dir), 1);  // no temporary left behind
}

// Parts: each part's times increase on their own; the part number is written.
TEST(IoPvd, PartsShareTimesAndAreWritten) {
  const std::string dir = tmp_dir("parts");
  const std::string path = dir + "/two.pvd";
  write_pvd(path, {{0.0, "d0.vtu", 0}, {0.0, "v0.vtu", 1}, {0.5, "d1.vtu", 0}, {0.5, "v1.vtu", 1}});
  const std::string text = slurp(path);
  EXPECT_NE(text.find("part=\"1\" file=\"v1.vtu\""), std::string::npos) << text;
  EXPECT_NE(text.find("part=\"0\" file=\"d1.vtu\""), std::string::npos) << text;
  test::expect_one_line_refusal(
      [&] {
        write_pvd(path, {{0.0, "a.vtu", 1}, {0.0, "b.vtu", 1}});
      },
      path, "strictly increasing");
  test::expect_one_line_refusal(
      [&] {
        write_pvd(path, {{0.0, "a.vtu", -1}});
      },
      path, "negative part");
}

TEST(IoPvd, BadInputIsRefusedWithoutTouchingTheFile) {
  const std::string dir = tmp_dir("bad");
  const std::string path = dir + "/keep.pvd";
  write_pvd(path, {{0.0, "a.vtu"}});
  const std::string before = slurp(path);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::pair<std::vector<PvdEntry>, const char*> bad[] = {
      {{}, "no datasets"},
      {{{nan, "a.vtu"}}, "non-finite"},
      {{{0.0, "a.vtu"}, {std::numeric_limits<double>::infinity(), "b.vtu"}}, "non-finite"},
      {{{1.0, "a.vtu"}, {0.5, "b.vtu"}}, "strictly increasing"},
      {{{1.0, "a.vtu"}, {1.0, "b.vtu"}}, "strictly increasing"},
      {{{0.0, ""}}, "empty file name"},
      {{{0.0, "a\nb.vtu"}}, "control character"}};
  for (const auto& [entries, needle] : bad)
    test::expect_one_line_refusal([&] { write_pvd(path, entries); }, path, needle);
  EXPECT_EQ(slurp(path), before);
  EXPECT_EQ(count_files(dir), 1);
}

TEST(IoPvd, MissingFolderIsAnOperatingSystemError) {
  const std::string dir = tmp_dir("missing");
  EXPECT_THROW(write_pvd(dir + "/no/such/folder/s.pvd", {{0.0, "a.vtu"}}), std::runtime_error);
  EXPECT_EQ(count_files(dir), 0);
}

// The reader gives back what the writer wrote (times to the last bit, parts, names), relative
// names resolved against the collection's folder, absolute ones kept.
TEST(IoPvd, ReaderReturnsWhatTheWriterWrote) {
  const std::string dir = tmp_dir("read_back");
  const std::string path = dir + "/series.pvd";
  std::vector<PvdEntry> written = sample_entries();
  written.push_back({0.0, "v0.vtu", 1});
  write_pvd(path, written);
  const std::vector<PvdEntry> read = read_pvd(path);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].time_s, written[i].time_s) << i;  // bit for bit
    EXPECT_EQ(read[i].part, written[i].part) << i;
    const fs::path w(written[i].file);
    EXPECT_EQ(read[i].file, w.is_absolute() ? w.string() : (fs::path(dir) / w).string()) << i;
  }
}

TEST(IoPvd, ReaderRefusesBadCollectionsInOneLine) {
  const std::string dir = tmp_dir("read_bad");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir + "/" + name) << text;
    return dir + "/" + name;
  };
  const std::string head = "<VTKFile type=\"Collection\"><Collection>";
  const std::string tail = "</Collection></VTKFile>";
  test::expect_one_line_refusal([&] { read_pvd(dir + "/absent.pvd"); }, "absent.pvd",
                                "no such file");
  const std::string junk = write("junk.pvd", "not xml <<<");
  test::expect_one_line_refusal([&] { read_pvd(junk); }, junk, "XML");
  const std::string grid = write("grid.pvd", "<VTKFile type=\"UnstructuredGrid\"/>");
  test::expect_one_line_refusal([&] { read_pvd(grid); }, grid, "Collection");
  const std::string empty = write("empty.pvd", head + tail);
  test::expect_one_line_refusal([&] { read_pvd(empty); }, empty, "no datasets");
  const std::string nan = write("nan.pvd", head + "<DataSet timestep=\"nan\" file=\"a\"/>" + tail);
  test::expect_one_line_refusal([&] { read_pvd(nan); }, nan, "finite");
  const std::string back =
      write("back.pvd", head +
                            "<DataSet timestep=\"1\" file=\"a\"/><DataSet timestep=\"0.5\" "
                            "file=\"b\"/>" +
                            tail);
  test::expect_one_line_refusal([&] { read_pvd(back); }, back, "strictly increasing");
  const std::string part =
      write("part.pvd", head + "<DataSet timestep=\"1\" part=\"-2\" file=\"a\"/>" + tail);
  test::expect_one_line_refusal([&] { read_pvd(part); }, part, "part");
  const std::string nofile = write("nofile.pvd", head + "<DataSet timestep=\"1\"/>" + tail);
  test::expect_one_line_refusal([&] { read_pvd(nofile); }, nofile, "no file");
}
