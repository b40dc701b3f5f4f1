// Loads in time: a schedule is read strictly (every malformed file refused in one line), loads
// are linear between key times, each sampled time is exactly the independent equilibrium of its
// loads (so the answer does not depend on the sampling), and the recording the offline discs
// follow holds those vertebra motions.
#include "spinesim/haptics/recording.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/studies/spine_schedule.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace st = spinesim::studies;
namespace sp = spinesim::spine;
namespace fs = std::filesystem;
using Eigen::Vector3d;

namespace {

std::string write(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / "spinesim_schedule_test";
  fs::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

void expect_refused(const std::string& text, const std::string& word) {
  const std::string path = write("bad.csv", text);
  try {
    st::read_load_schedule(path);
    ADD_FAILURE() << "accepted:\n" << text;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(word), std::string::npos) << what;
    EXPECT_NE(what.find("bad.csv"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace

TEST(LoadSchedule, MalformedSchedulesAreRefusedInOneLine) {
  expect_refused("time_s,T7.fz_n\n0,0\n1,\n", "empty");                 // a gap
  expect_refused("time_s,T7.fz_n\n0,0\n1\n", "");                       // a missing cell
  expect_refused("time_s,T7.fz_n\n0,0\n2,1\n1,2\n", "times must increase");
  expect_refused("time_s,T7.fz_n\n0,0\n0,1\n", "times must increase");  // a repeated time
  expect_refused("time_s,T13.fz_n\n0,0\n", "T13");
  expect_refused("time_s,T7.force\n0,0\n", "unknown component");
  expect_refused("time_s,T7\n0,0\n", "VERTEBRA.COMPONENT");
  expect_refused("time_s,T7.fz_n,t7.fz_n\n0,0,0\n", "twice");
  expect_refused("time_s,T7.fz_n\n0,abc\n", "T7.fz_n");
  expect_refused("time_s,T7.fz_n\n0,nan\n", "T7.fz_n");
  expect_refused("t,T7.fz_n\n0,0\n", "time_s");
  expect_refused("time_s,T7.fz_n\n", "no rows");
  expect_refused("time_s\n0\n", "no load column");
  expect_refused("time_s,T7.fz_n\n0,2e6\n", "beyond any body");
}

TEST(LoadSchedule, LoadsAreLinearBetweenKeyTimesAndCombinePerVertebra) {
  const st::LoadSchedule s = st::read_load_schedule(
      write("ramp.csv", "# a ramp\ntime_s,T7.fz_n,T7.mx_nmm,L1.fy_n\n0,0,100,-50\n2,300,100,50\n"));
  ASSERT_EQ(s.time_s.size(), 2u);
  const auto at = st::schedule_loads(s, 0.5);
  ASSERT_EQ(at.size(), 2u);  // T7 (force and couple) and L1
  EXPECT_EQ(at[0].vertebra, sp::vertebra_index("T7"));
  EXPECT_DOUBLE_EQ(at[0].force_n.z(), 75.0);
  EXPECT_DOUBLE_EQ(at[0].moment_nmm.x(), 100.0);
  EXPECT_DOUBLE_EQ(at[1].force_n.y(), -25.0);
  EXPECT_DOUBLE_EQ(st::schedule_loads(s, 2.0)[0].force_n.z(), 300.0);
  EXPECT_THROW(st::schedule_loads(s, 2.5), std::invalid_argument);
  const std::vector<double> times = st::schedule_times(s, 0.75);
  EXPECT_EQ(times, (std::vector<double>{0, 0.75, 1.5, 2}));
  EXPECT_EQ(st::schedule_times(s, 0), (std::vector<double>{0, 2}));
}

// Quasi-static: each sampled time is the equilibrium of its loads alone, bit for bit the same as
// a single solve of them, whatever else was sampled and on how many threads.
TEST(LoadSchedule, EachStepIsTheIndependentEquilibriumOfItsLoads) {
  const st::LoadSchedule s = st::read_load_schedule(
      write("lift.csv", "time_s,T7.fz_n,L1.mx_nmm\n0,0,0\n2,300,0\n4,300,6000\n"));
  const sp::ModelOptions mo;
  const sp::SolveOptions so;
  const st::ScheduleRun coarse = st::run_load_schedule(SPINESIM_DATA_DIR, s, mo, so, 1.0, 2);
  const st::ScheduleRun fine = st::run_load_schedule(SPINESIM_DATA_DIR, s, mo, so, 0.5, 1);
  ASSERT_EQ(coarse.steps.size(), 5u);
  ASSERT_EQ(fine.steps.size(), 9u);
  EXPECT_EQ(coarse.failed, 0);
  const sp::SpineModel model = sp::load_spine_model(SPINESIM_DATA_DIR);
  for (const auto& step : coarse.steps) {
    SCOPED_TRACE(step.t_s);
    const sp::SpineSolution alone = sp::solve_spine(model, st::schedule_loads(s, step.t_s), so);
    EXPECT_EQ(step.solution.displacement, alone.displacement);
    EXPECT_EQ(step.solution.joints[16].axial_n, alone.joints[16].axial_n);
    const auto same = std::find_if(fine.steps.begin(), fine.steps.end(),
                                   [&](const st::ScheduleStep& f) { return f.t_s == step.t_s; });
    ASSERT_NE(same, fine.steps.end());
    EXPECT_EQ(same->solution.displacement, step.solution.displacement);
  }
  // The pull on T7 moves T1 forward more as it ramps up.
  EXPECT_GT(coarse.steps[2].solution.displacement(0, 2), coarse.steps[1].solution.displacement(0, 2));
  EXPECT_GT(coarse.steps[1].solution.displacement(0, 2), coarse.steps[0].solution.displacement(0, 2));
  // The CSV: a header and one row per step; the JSON names each step's loads.
  const std::string csv = st::schedule_csv(coarse);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 6);
  EXPECT_DOUBLE_EQ(st::schedule_json(coarse)["steps"][1]["loads"]["T7.fz_n"].get<double>(), 150.0);
}

// The recording written for `spine discs` holds a row a millisecond, each solved step's vertebra
// motions at its time and the straight path between them.
TEST(LoadSchedule, TheRecordingHoldsEachStepsVertebraMotion) {
  const st::LoadSchedule s =
      st::read_load_schedule(write("pull.csv", "time_s,T1.fz_n\n0,0\n1,200\n"));
  const st::ScheduleRun run =
      st::run_load_schedule(SPINESIM_DATA_DIR, s, sp::ModelOptions(), sp::SolveOptions(), 0.25, 2);
  const std::string path = write("motion.csv", "");
  st::write_schedule_recording(run, path);
  const auto rec = spinesim::haptics::read_drag_recording(path, run.model);
  ASSERT_EQ(rec.frames.size(), 1001u);  // 0 … 1 s, every millisecond
  EXPECT_TRUE(rec.complete);
  for (const auto& step : run.steps) {
    const auto& f = rec.frames[std::size_t(std::lround(step.t_s * 1000))];
    SCOPED_TRACE(step.t_s);
    EXPECT_NEAR(f.t_s, step.t_s, 1e-6);
    EXPECT_FALSE(f.attached);
    for (int v = 0; v < 17; ++v)
      for (int k = 0; k < 6; ++k)
        EXPECT_NEAR(f.motion(v, k), step.solution.displacement(v, k), 1e-4);
  }
  // Halfway between two steps, T1's forward shift is halfway between theirs: a straight path
  // for the pose's translation and the geodesic for its rotation, so the centre's path bends by
  // second order in the step's rotation (under 2 % of the step here).
  const double a = run.steps[0].solution.displacement(0, 2),
               b = run.steps[1].solution.displacement(0, 2);
  EXPECT_NEAR(rec.frames[125].motion(0, 2), 0.5 * (a + b), 0.02 * std::abs(b - a));
  EXPECT_GT(rec.frames.back().motion(0, 2), 1.0);  // 200 N forward moves T1 by millimetres
}
