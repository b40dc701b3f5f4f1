// Hostile input, as a user brings it by mistake or on purpose: every case exits 1 with one line
// that names the real cause, and leaves no new file. (Regression tests of what a fuzzing session
// found: deep JSON, FIFOs and folders as inputs, devices and links as outputs, loads whose norm
// overflows.)
#include "cli_runner.hpp"

#include <fstream>

#include <sys/stat.h>

#include <set>

using namespace spinesim::test_cli;

namespace {

/// A small structured disc, made once per test process.
const std::string& disc() {
  static const std::string path = [] {
    const std::string p = tmp("hostile-disc.vtu");
    const CliRun r = run_spinesim("mesh disc --level T7-T8 --structured --out '" + p + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    return p;
  }();
  return path;
}

/// Refused in one line naming `cause`, and nothing new in the temp folder.
void expect_refused_cleanly(const std::string& args, const std::string& cause) {
  SCOPED_TRACE(args);
  const auto before = files_in(tmp_dir());
  const CliRun r = run_spinesim(args);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(cause), std::string::npos) << r.err;
  const auto after = new_files(before);
  EXPECT_TRUE(after.empty()) << "new file: " << *after.begin();
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

TEST(HostileInput, DeeplyNestedJsonIsRefusedNotACrash) {
  const std::string deep = tmp("deep.json");
  std::ofstream(deep) << "{\"version\": " << std::string(100000, '[') << std::string(100000, ']')
                      << "}";
  expect_refused_cleanly(
      "mss --mesh " + quoted(disc()) + " --params " + quoted(deep) + " --case compression",
      "nested 100001 levels deep");
  expect_refused_cleanly("mss compare --mesh " + quoted(disc()) + " --params " + quoted(deep),
                         "nested 100001 levels deep");
  expect_refused_cleanly("fem --mesh " + quoted(disc()) + " --material " + quoted(deep),
                         "nested 100001 levels deep");
}

TEST(HostileInput, FifoAndFolderInputsAreNamedNotWaitedOn) {
  const std::string fifo = tmp("in-fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expect_refused_cleanly("fem --mesh " + quoted(disc()) + " --material " + quoted(fifo),
                         "a FIFO, not a regular file");
  expect_refused_cleanly("mss --mesh " + quoted(disc()) + " --params " + quoted(fifo),
                         "a FIFO, not a regular file");
  expect_refused_cleanly("fem --mesh " + quoted(fifo), "a FIFO, not a regular file");
  expect_refused_cleanly("fem --mesh " + quoted(tmp_dir().string()),
                         "a directory, not a regular file");
}

TEST(HostileInput, OutputsThatAreNotRegularFilesAreNeverReplaced) {
  const std::string fifo = tmp("out-fifo"), target = tmp("target.vtu"), link = tmp("link.vtu");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::ofstream(target) << "keep";
  fs::create_symlink(target, link);
  for (const std::string& out : {fifo, link, std::string("/dev/null")}) {
    expect_refused_cleanly("mesh disc --level T7-T8 --structured --out " + quoted(out),
                           "not a regular file: refusing to replace it");
    expect_refused_cleanly("fem --mesh " + quoted(disc()) + " --out " + quoted(out),
                           "not a regular file: refusing to replace it");
  }
  EXPECT_EQ(fs::status(fifo).type(), fs::file_type::fifo);
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(slurp(target), "keep");
  EXPECT_EQ(fs::status("/dev/null").type(), fs::file_type::character);
}

// An overflowing norm must never pass a convergence test (inf <= tol * inf) or give null numbers.
TEST(HostileInput, LoadsWhoseNormOverflowsAreRefusedNotConverged) {
  expect_refused_cleanly("mss --mesh " + quoted(disc()) + " --wrench 0,-1e155,0,0,0,0 --json",
                         "too large");
  expect_refused_cleanly("fem --mesh " + quoted(disc()) + " --wrench 0,-1e308,0,0,0,0 --json",
                         "too large");
  expect_refused_cleanly("spine solve --force T1:1e155,0,0", "outside any physical load");
  expect_refused_cleanly("spine solve --force T1:100,0,0 --at 1e300,0,0", "from the origin");
}

// Absurd resolutions are refused in a moment, before any allocation, naming the estimate.
TEST(HostileInput, AbsurdMeshResolutionsAreRefusedBeforeMeshing) {
  const std::string out = quoted(tmp("absurd.vtu"));
  for (const std::string& flags :
       {"--cell-size 1e-6", "--facet-distance 1e-9", "--facet-size 1e-6"})
    expect_refused_cleanly("mesh disc --level L4-L5 " + flags + " --out " + out,
                           "more than the limit of");
  expect_refused_cleanly("mesh disc --level L4-L5 --structured --sectors 1000000 --out " + out,
                         "more than the limit of");
  expect_refused_cleanly("mesh disc --level L4-L5 --cell-size 3 --max-elements 100 --out " + out,
                         "more than the limit of 100");
  // Values the mesher cannot take are refused by the command line with the mesher's bounds.
  expect_refused_cleanly("mesh disc --level L4-L5 --facet-size -1 --out " + out, "--facet-size");
  expect_refused_cleanly("mesh disc --level L4-L5 --facet-size nan --out " + out, "--facet-size");
  expect_refused_cleanly("mesh disc --level L4-L5 --radius-edge 1.5 --out " + out,
                         "--radius-edge must be a finite number >= 2");
}

// A user's string with a newline in it still makes a one-line error.
TEST(HostileInput, NewlinesInUserStringsStayOnTheErrorLine) {
  expect_refused_cleanly("fem --mesh " + quoted(disc()) + " --case \"$(printf 'flex\\nion')\"",
                         "unknown load case");
}

// A material file with a field of the wrong type: the file is named, not a raw parser code.
TEST(HostileInput, WrongTypeInAMaterialFileNamesTheFile) {
  const std::string bad = tmp("typed.json");
  std::ofstream(bad) << R"({"name": "typed", "E_mpa": "soft", "nu": 0.45})";
  expect_refused_cleanly("fem --mesh " + quoted(disc()) + " --material " + quoted(bad),
                         "material file '" + bad + "'");
  const CliRun r = run_spinesim("fem --mesh " + quoted(disc()) + " --material " + quoted(bad));
  EXPECT_EQ(r.err.find("[json.exception"), std::string::npos) << r.err;
}
