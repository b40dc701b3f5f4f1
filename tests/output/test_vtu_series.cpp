// The VTU time series: a series replaces an earlier one of the same name only when it is
// complete, and then wholly (no frame of the earlier one left beside it); one that fails leaves
// the earlier series as it was and no staging folder.
#include "spinesim/output/files.hpp"

#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mss/model.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace spinesim;

namespace {

/// The structured T7-T8 disc (no CGAL), made once.
const spinesim::mesh::TetMesh& t7_t8() {
  static const spinesim::mesh::TetMesh m = spinesim::mesh::mesh_structured_disc(
      spinesim::mesh::disc_dimensions("T7-T8", SPINESIM_DATA_DIR));
  return m;
}

std::string fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::path(SPINESIM_TEST_TMP) / ("series-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::set<std::string> names_in(const std::string& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

std::string slurp(const std::string& path) {
  std::ifstream is(path);
  std::stringstream ss;
  ss << is.rdbuf();
  return ss.str();
}

/// Writes `frames` frames of the disc at rest (displaced by `shift` mm) into `series`.
void fill(output::VtuSeries& series, int frames, double shift) {
  const mss::MssModel model(t7_t8(), mesh::load_material("real-disc", SPINESIM_DATA_DIR));
  Eigen::VectorXd x = model.rest_positions_mm();
  x.array() += shift;
  for (int k = 0; k < frames; ++k) series.add(1e-3 * k, model, x);
}

}  // namespace

TEST(VtuSeries, AFinishedSeriesReplacesAnEarlierOneWhole) {
  const std::string dir = fresh_dir("replace"), pvd = dir + "/run.pvd";
  {
    output::VtuSeries first(pvd);
    fill(first, 5, 0.0);
    first.finish();
  }
  EXPECT_EQ(names_in(dir + "/run").size(), 5u);
  std::ofstream(dir + "/run/notes.txt") << "the user's";  // not a frame: never touched
  {
    output::VtuSeries second(pvd);
    fill(second, 3, 1.0);
    // Until it finishes, the earlier series is whole.
    EXPECT_EQ(names_in(dir + "/run").size(), 6u);
    second.finish();
  }
  EXPECT_EQ(names_in(dir + "/run"), (std::set<std::string>{"notes.txt", "run_000000.vtu",
                                                           "run_000001.vtu", "run_000002.vtu"}));
  EXPECT_EQ(names_in(dir), (std::set<std::string>{"run", "run.pvd"}));  // no staging left
  const std::string text = slurp(pvd);
  EXPECT_NE(text.find("run/run_000002.vtu"), std::string::npos);
  EXPECT_EQ(text.find("run/run_000003.vtu"), std::string::npos);
}

TEST(VtuSeries, AnUnfinishedSeriesLeavesTheEarlierOneAsItWas) {
  const std::string dir = fresh_dir("unfinished"), pvd = dir + "/run.pvd";
  {
    output::VtuSeries first(pvd);
    fill(first, 4, 0.0);
    first.finish();
  }
  const std::string pvd_before = slurp(pvd), frame_before = slurp(dir + "/run/run_000001.vtu");
  {
    output::VtuSeries failed(pvd);
    fill(failed, 2, 1.0);  // then an exception, as from a full disk: destroyed unfinished
  }
  EXPECT_EQ(slurp(pvd), pvd_before);
  EXPECT_EQ(slurp(dir + "/run/run_000001.vtu"), frame_before);
  EXPECT_EQ(names_in(dir + "/run").size(), 4u);
  EXPECT_EQ(names_in(dir), (std::set<std::string>{"run", "run.pvd"}));
}

TEST(VtuSeries, AFrameFolderThatIsNotAFolderIsRefused) {
  const std::string dir = fresh_dir("not-a-folder");
  std::ofstream(dir + "/run") << "a file where the frames would go";
  EXPECT_THROW(output::VtuSeries(dir + "/run.pvd"), std::invalid_argument);
  EXPECT_EQ(slurp(dir + "/run"), "a file where the frames would go");
}
