// `spinesim sweep`: a plan's points are the verb run directly; the summary is the same bytes run
// serially, three at a time, on two MPI ranks and as three Slurm array tasks; a sweep stopped by SIGTERM or killed
// by SIGKILL resumes to the same summary; a failed point is recorded and the others go on; bad
// plans are refused before anything runs.
#include "spine_cli_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

namespace {

using namespace spinesim::test_cli;
using nlohmann::json;
namespace fs = std::filesystem;

const fs::path kExamplePlan =
    fs::path(SPINESIM_DATA_DIR).parent_path() / "examples" / "sweep-bodies" / "plan.json";

/// 32 points (8 statures x 4 masses), two of them outside the scaling laws' body-mass index.
std::string slow_plan() {
  const std::string path = tmp("plan32.json");
  spit(path,
       R"JSON({"spinesim_sweep": 1, "verb": "spine solve", "options": {"force": ["T7:0,0,100"]},
    "parameters": {"height": {"from": 1.55, "to": 1.9, "steps": 8},
                   "mass": {"from": 50, "to": 90, "steps": 4}},
    "outputs": {"L5-S1 axial (N)": "/joints/16/axial_n"}})JSON");
  return path;
}

std::string sweep(const std::string& plan, const std::string& out, const std::string& before = "") {
  const CliRun r =
      run_spinesim("sweep " + in_quotes(plan) + " --out " + in_quotes(out) + " --quiet", before);
  EXPECT_EQ(r.status, 0) << r.err;
  return slurp(out + "/summary.csv");
}

int statuses(const std::string& out) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(out + "/points"))
    n += fs::exists(e.path() / "status.json");
  return n;
}

}  // namespace

// Each row is the verb run by hand with the point's values; the JSON summary says the same.
TEST(SweepCli, EveryPointIsTheVerbRunWithItsValues) {
  const std::string out = tmp("sweep-serial");
  const CliRun r = run_spinesim("sweep " + in_quotes(kExamplePlan.string()) + " --out " +
                                in_quotes(out) + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["points"], 12);
  EXPECT_EQ(j["ok"], 12);
  // The projection from the points' own times: one rank takes their sum, more ranks less, and
  // never less than the slowest point.
  const json& timing = j["timing"];
  const json& projected = timing["projected_wall_seconds_by_ranks"];
  EXPECT_EQ(timing["points_timed"], 12);
  EXPECT_DOUBLE_EQ(projected["1"].get<double>(), timing["point_seconds_sum"].get<double>());
  EXPECT_LE(projected["2"].get<double>(), projected["1"].get<double>());
  EXPECT_LE(projected["512"].get<double>(), projected["64"].get<double>());
  EXPECT_GE(projected["512"].get<double>(), timing["mean_point_seconds"].get<double>() * 0.999);
  const json summary = json::parse(slurp(out + "/summary.json"));
  ASSERT_EQ(summary["points"].size(), 12u);
  for (int i : {0, 7, 11}) {
    const json& row = summary["points"][std::size_t(i)];
    const json& v = row["values"];
    const json direct =
        solve_json("--force T7:0,0,100 --height " + v["height"].dump() + " --mass " +
                   v["mass"].dump() + " --sex " + v["sex"].get<std::string>());
    EXPECT_EQ(row["outputs"]["L5-S1 axial (N)"].get<double>(),
              direct["joints"][16]["axial_n"].get<double>())
        << i;
    EXPECT_EQ(row["outputs"]["T1 forward (mm)"].get<double>(),
              direct["vertebrae"][0]["translation_mm"][2].get<double>())
        << i;
  }
  const std::string csv = slurp(out + "/summary.csv");
  EXPECT_NE(csv.find("# provenance: {"), std::string::npos);
  EXPECT_NE(csv.find("point,height,mass,sex,status,L4-L5 axial (N)"), std::string::npos);
  EXPECT_EQ(count_lines(csv), 2 + 12);
}

TEST(SweepCli, ThreeJobsTwoMpiRanksAndThreeSlurmTasksWriteTheSerialSummary) {
  const std::string one = tmp("sweep-one");
  const std::string serial = sweep(kExamplePlan.string(), one);
  // Three points at once on this machine.
  const std::string three = tmp("sweep-jobs");  // (tmp() clears the path: called once)
  const CliRun jobs = run_spinesim("sweep " + in_quotes(kExamplePlan.string()) + " --out " +
                                   in_quotes(three) + " --quiet --jobs 3");
  ASSERT_EQ(jobs.status, 0) << jobs.err;
  EXPECT_EQ(slurp(three + "/summary.csv"), serial);
  if (std::system("command -v mpirun >/dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
  const std::string on_mpi = tmp("sweep-mpi");
  const std::string mpi =
      sweep(kExamplePlan.string(), on_mpi,
            "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
            "OMPI_MCA_rmaps_base_oversubscribe=1 mpirun -np 2 --oversubscribe ");
  EXPECT_EQ(mpi, serial);
  EXPECT_EQ(slurp(on_mpi + "/summary.json"), slurp(one + "/summary.json"));
  const std::string array = tmp("sweep-array");
  for (int task = 3; task <= 5; ++task) {  // an array submitted as --array=3-5
    const CliRun r = run_spinesim(
        "sweep " + in_quotes(kExamplePlan.string()) + " --out " + in_quotes(array) + " --json",
        "SLURM_ARRAY_TASK_ID=" + std::to_string(task) +
            " SLURM_ARRAY_TASK_MIN=3 SLURM_ARRAY_TASK_COUNT=3 ");
    ASSERT_EQ(r.status, 0) << r.err;
    const json j = json::parse(r.out);
    EXPECT_EQ(j["ran"], 4);                       // points task-3, task-3+3, …
    EXPECT_EQ(j.contains("summary"), task == 5);  // the last task finds every point done
  }
  EXPECT_EQ(slurp(array + "/summary.csv"), serial);
  expect_refused(run_spinesim("sweep " + in_quotes(kExamplePlan.string()) + " --out " +
                                  in_quotes(tmp("sweep-bad-array")),
                              "SLURM_ARRAY_TASK_ID=7 SLURM_ARRAY_TASK_MIN=0 "
                              "SLURM_ARRAY_TASK_COUNT=3 "),
                 "SLURM_ARRAY_TASK_COUNT");
}

// Stopped by SIGTERM (the point running is left without its status) or killed by SIGKILL, the
// same command resumes: no point is lost or run twice, and the summary is the serial one. The
// two points outside the scaling laws are recorded as failed with the program's own error.
TEST(SweepCli, AStoppedOrKilledSweepResumesToTheSameSummary) {
  const std::string plan = slow_plan();
  const std::string whole = sweep(plan, tmp("sweep-whole"));
  EXPECT_EQ(count_lines(whole), 2 + 32);
  EXPECT_NE(whole.find(",failed,,\"spinesim: error: "), std::string::npos) << whole;
  EXPECT_NE(whole.find("body-mass index"), std::string::npos);
  for (const int signal : {SIGTERM, SIGKILL}) {
    SCOPED_TRACE(signal);
    const std::string out = tmp("sweep-stopped-" + std::to_string(signal));
    const pid_t pid = start_spinesim("sweep " + in_quotes(plan) + " --out " + in_quotes(out) +
                                     (signal == SIGTERM ? " --jobs 2" : ""));
    for (int k = 0; k < 600 && (!fs::exists(out + "/points") || statuses(out) < 3); ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ::kill(pid, signal);
    int status = 0;
    ::waitpid(pid, &status, 0);
    const int done = statuses(out);
    EXPECT_GE(done, 3);
    EXPECT_LT(done, 32) << "the sweep finished before it was stopped";
    if (signal == SIGTERM) EXPECT_EQ(WEXITSTATUS(status), 1);
    EXPECT_FALSE(fs::exists(out + "/summary.csv"));
    const CliRun r =
        run_spinesim("sweep " + in_quotes(plan) + " --out " + in_quotes(out) + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const json j = json::parse(r.out);
    EXPECT_EQ(j["skipped"].get<int>() + j["ran"].get<int>(), 32);
    EXPECT_GE(j["skipped"].get<int>(), done);
    EXPECT_EQ(j["failed"], 2);
    EXPECT_EQ(slurp(out + "/summary.csv"), whole);
  }
}

// A point's outputs land in its own folder, even where a file of that name lies beside the plan
// (which stays as it was); an input beside the plan is found from every point's folder.
TEST(SweepCli, OutputsLandInThePointsFolderAndInputsAreFound) {
  const std::string dir = tmp("sweep-paths");
  fs::create_directories(dir);
  spit(dir + "/solve.csv", "mine\n");
  spit(dir + "/loads.csv", "time_s,T7.fz_n\n0,0\n0.1,50\n");
  spit(dir + "/plan.json", R"JSON({"spinesim_sweep": 1, "verb": "spine schedule",
    "options": {"loads": "loads.csv", "csv": "solve.csv"},
    "parameters": {"height": {"values": [1.7, 1.8]}}})JSON");
  const CliRun r = run_spinesim("sweep " + in_quotes(dir + "/plan.json") + " --out " +
                                in_quotes(dir + "/out") + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["ok"], 2);
  EXPECT_EQ(slurp(dir + "/solve.csv"), "mine\n");
  for (const char* p : {"/out/points/0000", "/out/points/0001"}) {
    EXPECT_NE(slurp(dir + p + "/solve.csv").find("# provenance"), std::string::npos) << p;
    EXPECT_EQ(json::parse(slurp(dir + p + "/study.json"))["options"]["loads"],
              "../../../loads.csv");
  }
}

TEST(SweepCli, BadPlansAreRefusedBeforeAnythingRuns) {
  const std::string plan = tmp("bad-plan.json");
  spit(plan, R"JSON({"spinesim_sweep": 1, "verb": "spine solve",
    "parameters": {"heigth": {"values": [1.6]}}})JSON");
  const std::string out = tmp("sweep-never");
  expect_refused(run_spinesim("sweep " + in_quotes(plan) + " --out " + in_quotes(out)),
                 "point 0: options.heigth");
  EXPECT_FALSE(fs::exists(out));
  spit(plan, R"JSON({"spinesim_sweep": 1, "verb": "spine solve",
    "parameters": {"height": {"from": 1.6, "to": 1.7}}})JSON");
  expect_refused(run_spinesim("sweep " + in_quotes(plan) + " --out " + in_quotes(out)),
                 "latin_hypercube");
  // A folder holds one plan's sweep.
  const std::string other = tmp("sweep-other");
  sweep(kExamplePlan.string(), other);
  spit(plan, R"JSON({"spinesim_sweep": 1, "verb": "spine solve",
    "parameters": {"height": {"values": [1.6]}}})JSON");
  expect_refused(run_spinesim("sweep " + in_quotes(plan) + " --out " + in_quotes(other)),
                 "another plan");
}

// A Morris plan: the sensitivity table is written, and its signs are what statics says (a
// heavier body loads L5-S1 more; a taller one, with longer levers and stiffer joints, less).
TEST(SweepCli, AMorrisPlanWritesTheSensitivityOfEachOutput) {
  const fs::path plan = kExamplePlan.parent_path() / "screening.json";
  const std::string out = tmp("sweep-morris");
  const CliRun r = run_spinesim("sweep " + in_quotes(plan.string()) + " --out " + in_quotes(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("Morris elementary effects"), std::string::npos) << r.out;
  const json s = json::parse(slurp(out + "/summary.json"))["sensitivity"];
  EXPECT_EQ(s["runs"], 30);
  const json& load = s["outputs"]["L5-S1 axial (N)"];
  EXPECT_GT(load["mass"]["mu"].get<double>(), 0);
  EXPECT_LT(load["height"]["mu"].get<double>(), 0);
  EXPECT_DOUBLE_EQ(load["mass"]["mu_star_over_range"].get<double>(),
                   load["mass"]["mu_star"].get<double>() * 40);
  // The bootstrap intervals hold their estimate, and mass's (nearly constant effect: the body's
  // weight) is narrower relative to it than height's (σ/μ* 0.1 against 0.45).
  auto relative_width = [&](const json& v) {
    const double lo = v["mu_star_interval"][0], hi = v["mu_star_interval"][1];
    EXPECT_LE(lo, v["mu_star"].get<double>());
    EXPECT_GE(hi, v["mu_star"].get<double>());
    return (hi - lo) / v["mu_star"].get<double>();
  };
  EXPECT_LT(relative_width(load["mass"]), relative_width(load["height"]));
  EXPECT_EQ(s["bootstrap"]["resamples"], 1000);
  const std::string csv = slurp(out + "/sensitivity.csv");
  EXPECT_NE(csv.find("output,parameter,mu_star_over_range,mu_star,mu,sigma,mu_star_over_range_low,"
                     "mu_star_over_range_high,mu_star_low,mu_star_high,error"),
            std::string::npos);
  EXPECT_EQ(count_lines(csv), 3 + 4);
  for (const char* f : {"/report.html", "/plots/sweep.png", "/plots/sensitivity.png"})
    EXPECT_TRUE(fs::exists(out + f)) << f;
}

// A plan with a window: a Latin hypercube over body mass, weighted by a window on the L4-L5
// load around its value at 70 kg (378 N). The load is about proportional to mass (5.4 N/kg), so
// the window's ±4.9 % on the log scale is ±3.5 kg: the weighted mass is 70 ± 3.5 kg, the
// weighted load sits in its window, and the report draws both.
TEST(SweepCli, WindowsWeighTheSampleIntoThePosterior) {
  const std::string dir = tmp("sweep-windows");
  fs::create_directories(dir);
  spit(dir + "/plan.json", R"JSON({"spinesim_sweep": 1, "verb": "spine solve",
    "parameters": {"mass": {"from": 50, "to": 100}},
    "design": {"latin_hypercube": {"points": 40, "seed": 3}},
    "outputs": {"L4-L5 axial (N)": "/joints/15/axial_n", "T1 forward (mm)": "/vertebrae/0/translation_mm/2"},
    "windows": {"L4-L5 axial (N)": {"low": 360, "high": 397, "source": "a test window"}}})JSON");
  const std::string out = dir + "/out";
  const CliRun r =
      run_spinesim("sweep " + in_quotes(dir + "/plan.json") + " --out " + in_quotes(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("effective sample size"), std::string::npos) << r.out;
  const json u = json::parse(slurp(out + "/summary.json"))["uncertainty"];
  EXPECT_EQ(u["points_used"], 40);
  const json& mass = u["parameters"]["mass"];
  EXPECT_NEAR(mass["prior"]["mean"].get<double>(), 75, 1);  // uniform on 50 … 100
  EXPECT_NEAR(mass["posterior"]["mean"].get<double>(), 70, 1.5);
  EXPECT_NEAR(mass["posterior"]["sd"].get<double>(), 3.5, 1);
  const json& load = u["outputs"]["L4-L5 axial (N)"]["posterior"];
  EXPECT_GT(load["q50"].get<double>(), 360);
  EXPECT_LT(load["q50"].get<double>(), 397);
  EXPECT_GT(u["effective_sample_size"].get<double>(), 3);
  EXPECT_LT(u["effective_sample_size"].get<double>(), 20);
  const std::string csv = slurp(out + "/uncertainty.csv");
  EXPECT_NE(csv.find("kind,name,prior_mean,prior_sd,prior_q05"), std::string::npos);
  EXPECT_EQ(count_lines(csv), 3 + 3);  // provenance, method, header; mass and two outputs
  EXPECT_TRUE(fs::exists(out + "/plots/uncertainty.png"));
}

// The studies' plans (data/sweeps: the disc's and the spine's sensitivity, the disc material's
// uncertainty; docs/sensitivity.md) are valid plans of runnable studies: every point's options
// are checked by --dry-run without running one.
TEST(SweepCli, TheStudyPlansInTheDataFolderAreValid) {
  const fs::path folder = fs::path(SPINESIM_DATA_DIR) / "sweeps";
  int plans = 0;
  for (const auto& e : fs::directory_iterator(folder)) {
    if (e.path().extension() != ".json") continue;
    ++plans;
    const std::string out = tmp("dry-" + e.path().stem().string());
    const CliRun r = run_spinesim("sweep " + in_quotes(e.path().string()) + " --out " +
                                  in_quotes(out) + " --dry-run");
    EXPECT_EQ(r.status, 0) << e.path() << "\n" << r.err;
    EXPECT_TRUE(json::parse(slurp(e.path().string())).contains("description")) << e.path();
  }
  EXPECT_GE(plans, 5);
}
