// The haptic recording (haptics/recording.hpp): what the writer writes the reader reads back (poses to 0.1 µm, 1e-5°);
// a row cut off by a kill is dropped and the file still reads; another spine model, missing
// ticks, a hook force beyond the spine solve's range and a file without the spine's columns are
// refused in one line.
#include "spinesim/haptics/recording.hpp"
#include "spinesim/spine/kinematics.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

namespace st = spinesim::haptics;
namespace sp = spinesim::spine;
namespace sh = spinesim::haptics;
namespace fs = std::filesystem;

namespace {

const sp::SpineModel& model() {
  static const sp::SpineModel m = sp::load_spine_model(SPINESIM_DATA_DIR);
  return m;
}

fs::path scratch() {
  const fs::path dir =
      fs::path(SPINESIM_TEST_TMP) / ("haptic-recording-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

/// Ticks 1…n of a drag: T1 turned by a growing rotation, the others still.
std::vector<sh::TickRecord> ticks(int n, double force_n = 50) {
  std::vector<sh::TickRecord> rows(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    sh::TickRecord& r = rows[std::size_t(k)];
    r.t_s = 1e-3 * (k + 1);
    r.tick = k + 1;
    r.probe_mm = Eigen::Vector3d(1, 2, 3);
    r.force_n = r.proxy_mm = Eigen::Vector3d::Zero();
    r.compliant = true;
    r.hook.attached = true;
    r.hook.load.vertebra = 0;
    r.hook.load.point_mm = Eigen::Vector3d(0.5, 531, -90);
    r.hook.load.force_n = Eigen::Vector3d(force_n, 0, 0);
    for (int i = 0; i < 17; ++i) {
      const sp::Pose p = sp::pose_from_displacement(
          model().vertebrae[std::size_t(i)].centre_mm, Eigen::Vector3d(0.01 * k, 0, 0),
          i == 0 ? Eigen::Vector3d(0, 0.02 * k, 0.01 * k) : Eigen::Vector3d::Zero());
      r.R[std::size_t(i)] = p.R.cast<float>();
      r.t[std::size_t(i)] = p.t.cast<float>();
    }
  }
  return rows;
}

std::string write_recording(const std::string& name, const std::vector<sh::TickRecord>& rows,
                            bool finish = true) {
  const std::string path = (scratch() / name).string();
  st::HapticRecordingWriter w(path, "test", &model(), "multirate");
  w.append(rows.data(), rows.size());
  if (finish) w.finish();
  return path;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void expect_refused(const std::string& path, const std::string& needle) {
  try {
    st::read_drag_recording(path, model());
    ADD_FAILURE() << "accepted " << path;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(needle), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace

TEST(HapticRecording, ReadsBackWhatWasWritten) {
  const auto rows = ticks(200);
  const st::DragRecording rec = st::read_drag_recording(write_recording("ok.csv", rows), model());
  ASSERT_EQ(rec.frames.size(), rows.size());
  EXPECT_TRUE(rec.complete);
  EXPECT_EQ(rec.response, "multirate");
  EXPECT_EQ(rec.fingerprint, st::spine_model_fingerprint(model()));
  for (std::size_t k = 0; k < rows.size(); k += 37) {
    const st::DragFrame& f = rec.frames[k];
    EXPECT_EQ(f.tick, rows[k].tick);
    EXPECT_EQ(f.hook_vertebra, 0);
    EXPECT_LT((f.hook_ref_mm - rows[k].hook.load.point_mm).norm(), 1e-5);
    EXPECT_LT((f.spine_force_n - rows[k].hook.load.force_n).norm(), 1e-5);
    for (int i = 0; i < 17; i += 4) {
      const sp::Pose p = f.pose(model(), i);
      const Eigen::Vector3d X(10, 500, -40);
      const Eigen::Vector3d expected =
          rows[k].R[std::size_t(i)].cast<double>() * X + rows[k].t[std::size_t(i)].cast<double>();
      EXPECT_LT((p.apply(X) - expected).norm(), 1e-3) << "tick " << k << " vertebra " << i;
    }
  }
}

TEST(HapticRecording, AKilledRunReadsToItsLastCompleteRow) {
  const std::string path = write_recording("killed.csv", ticks(100), false);
  std::string text = slurp(path);
  ASSERT_EQ(text.find("# end"), std::string::npos);
  text.resize(text.size() - 40);  // the kill cut the last row
  std::ofstream(path, std::ios::trunc) << text;
  const st::DragRecording rec = st::read_drag_recording(path, model());
  EXPECT_FALSE(rec.complete);
  EXPECT_EQ(rec.frames.size(), 99u);
}

TEST(HapticRecording, BadRecordingsAreRefusedInOneLine) {
  auto rows = ticks(50);
  rows.erase(rows.begin() + 20);
  expect_refused(write_recording("gap.csv", rows), "missing frames");
  expect_refused(write_recording("force.csv", ticks(10, 2e5)), "beyond");
  // Another model: a different fingerprint in the header.
  std::string text = slurp(write_recording("other.csv", ticks(10)));
  const std::string fp = st::spine_model_fingerprint(model());
  text.replace(text.find(fp), fp.size(), "0123456789abcdef");
  const std::string other = (scratch() / "other.csv").string();
  std::ofstream(other, std::ios::trunc) << text;
  expect_refused(other, "another spine model");
  // A rigid-stage recording has no spine columns.
  const std::string rigid = (scratch() / "rigid.csv").string();
  {
    st::HapticRecordingWriter w(rigid, "test", nullptr, "");
    auto r = ticks(5);
    for (auto& t : r) t.compliant = false;
    w.append(r.data(), r.size());
    w.finish();
  }
  expect_refused(rigid, "not a compliant-stage recording");
  // A bad number.
  text = slurp(write_recording("nan.csv", ticks(5)));
  const auto at = text.find("\n0.003000,");
  ASSERT_NE(at, std::string::npos);
  text.replace(at + 1, 8, "nan");
  const std::string bad = (scratch() / "nan.csv").string();
  std::ofstream(bad, std::ios::trunc) << text;
  expect_refused(bad, "not a finite number");
  // Counts out of range (the fuzzer's 2.6e39 ticks, a hooked vertebra 1e12): refused, not cast.
  for (const auto& [column, value, needle] :
       {std::tuple<int, const char*, const char*>{12, "2.6e39", "tick"},
        std::tuple<int, const char*, const char*>{12, "3.5", "tick"},
        std::tuple<int, const char*, const char*>{14, "1e12", "hooked vertebra"}}) {
    text = slurp(write_recording("count.csv", ticks(5)));
    const auto row = text.find("\n0.003000,") + 1;
    std::size_t cell = row;
    for (int k = 0; k < column; ++k) cell = text.find(',', cell) + 1;
    text.replace(cell, text.find(',', cell) - cell, value);
    const std::string counted = (scratch() / "count.csv").string();
    std::ofstream(counted, std::ios::trunc) << text;
    expect_refused(counted, needle);
  }
}

// A recording is whole only when its end line counts exactly the rows read and the run ended by
// itself: a stopped run, a cut file or a lying end line is read, but not as whole.
TEST(HapticRecording, WholeOnlyWhenTheEndLineMatchesItsRowsAndTheStopWasClean) {
  const auto rows = ticks(30);
  const std::string whole = write_recording("whole.csv", rows);
  EXPECT_TRUE(st::read_drag_recording(whole, model()).complete);
  // An end line that does not count the rows (1,500 rows, "99999 ticks").
  std::string text = slurp(whole);
  const std::string end = "# end: 30 ticks";
  ASSERT_NE(text.find(end), std::string::npos);
  text.replace(text.find(end), end.size(), "# end: 99999 ticks");
  const std::string lying = (scratch() / "lying.csv").string();
  std::ofstream(lying, std::ios::trunc) << text;
  st::DragRecording rec = st::read_drag_recording(lying, model());
  EXPECT_FALSE(rec.complete);
  EXPECT_NE(rec.incomplete_reason.find("does not count the 30 rows"), std::string::npos)
      << rec.incomplete_reason;
  // A run stopped by a signal says so in its end line.
  const std::string stopped = (scratch() / "stopped.csv").string();
  {
    st::HapticRecordingWriter w(stopped, "test", &model(), "multirate");
    w.append(rows.data(), rows.size());
    w.finish("interrupted");
  }
  EXPECT_NE(slurp(stopped).find("# end: 30 ticks; stopped early: interrupted"), std::string::npos);
  rec = st::read_drag_recording(stopped, model());
  EXPECT_FALSE(rec.complete);
  EXPECT_EQ(rec.incomplete_reason, "stopped early: interrupted");
  EXPECT_EQ(rec.frames.size(), 30u);
  // No end line at all.
  rec = st::read_drag_recording(write_recording("no_end.csv", rows, false), model());
  EXPECT_FALSE(rec.complete);
  EXPECT_NE(rec.incomplete_reason.find("no end line"), std::string::npos);
}

TEST(HapticRecording, ARecordingThatCannotBeSteppedOrMovesAVertebraAwayIsRefused) {
  expect_refused(write_recording("one.csv", ticks(1)), "at least two are needed");
  // A vertebra 1e6 mm away (a corrupt row), and 1e308: refused naming the line.
  for (const double far : {1e6, 1e308}) {
    auto rows = ticks(10);
    rows[5].t[3] = Eigen::Vector3f(float(std::min(far, 1e30)), 0, 0);
    expect_refused(write_recording("far.csv", rows), "a vertebra moved");
  }
}
