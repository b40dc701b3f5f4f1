// The seated spine on the command line: `study seating` (one chair, its JSON balanced), a backrest
// from an STL or OBJ file against the same backrest made parametrically (two independent distance
// computations), the sweep's CSV and plots, and bad chairs refused in one line.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

using nlohmann::json;
using namespace spinesim::test_cli;

namespace {

json seating(const std::string& args) {
  const CliRun r = run_spinesim("study seating --json " + args);
  EXPECT_EQ(r.status, 0) << r.err;
  return r.status == 0 ? json::parse(r.out) : json();
}

/// A flat backrest 1000 mm long and 600 mm wide through the seat reference point, `recline` deg
/// to the horizontal, in 10 × 10 quads (two triangles each in STL, one quad each in OBJ); normals
/// towards the sitter unless `flipped`.
std::string backrest_file(const std::string& name, double recline, bool obj, bool flipped = false) {
  const double r = recline * M_PI / 180;
  const double ty = std::sin(r), tz = std::cos(r);  // up the backrest
  auto point = [&](int i, int k) {
    const double x = -300 + 60.0 * i, s = -100 + 110.0 * k;
    return std::array<double, 3>{x, s * ty, s * tz};
  };
  const std::string path = tmp(name);
  std::ofstream f(path);
  if (obj) {
    for (int k = 0; k <= 10; ++k)
      for (int i = 0; i <= 10; ++i) {
        const auto p = point(i, k);
        f << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
      }
    for (int k = 0; k < 10; ++k)
      for (int i = 0; i < 10; ++i) {
        const int a = 1 + k * 11 + i, b = a + 1, c = a + 12, d = a + 11;
        if (flipped)
          f << "f " << a << " " << d << " " << c << " " << b << "\n";
        else
          f << "f " << a << " " << b << " " << c << " " << d << "\n";
      }
    return path;
  }
  f << "solid backrest\n";
  auto tri = [&](std::array<double, 3> a, std::array<double, 3> b, std::array<double, 3> c) {
    if (flipped) std::swap(b, c);
    f << " facet normal 0 0 0\n  outer loop\n";
    for (const auto& p : {a, b, c}) f << "   vertex " << p[0] << " " << p[1] << " " << p[2] << "\n";
    f << "  endloop\n endfacet\n";
  };
  for (int k = 0; k < 10; ++k)
    for (int i = 0; i < 10; ++i) {
      // Counter-clockwise seen from the front (+z side): x to the right is −x of the body.
      tri(point(i, k), point(i + 1, k), point(i + 1, k + 1));
      tri(point(i, k), point(i + 1, k + 1), point(i, k + 1));
    }
  f << "endsolid backrest\n";
  return path;
}

}  // namespace

TEST(CliSeating, OneChairBalancesTheBodyAndReportsEveryLevel) {
  const json j = seating("--backrest-recline 105 --lumbar-support 20 --armrests");
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j["contacts"].size(), 18u);
  EXPECT_EQ(j["joints"].size(), 17u);
  EXPECT_EQ(j["joints"][16]["joint"], "L5-S1");
  EXPECT_LT(j["force_residual_n"].get<double>(), 1e-6);
  EXPECT_TRUE(j["lean_balanced"].get<bool>());
  const double up = j["seat_force_n"][1].get<double>() + j["backrest_force_n"][1].get<double>() +
                    j["armrest_force_n"][1].get<double>();
  EXPECT_NEAR(up, j["body_weight_n"].get<double>(), 1e-6);
  EXPECT_GT(j["armrest_force_n"][1].get<double>(), 0.0);
  EXPECT_GT(j["backrest_force_n"][2].get<double>(), 0.0);  // it pushes the back forward
  EXPECT_GT(j["joints"][16]["axial_n"].get<double>(), 0.0);
  EXPECT_EQ(j["chair"]["backrest_recline_deg"], 105.0);
}

TEST(CliSeating, ABackrestFromStlOrObjMatchesTheSameParametricBackrest) {
  const json p = seating("--backrest-recline 100 --backrest-height 900");
  ASSERT_FALSE(p.empty());
  for (bool obj : {false, true}) {
    const std::string file = backrest_file(obj ? "back.obj" : "back.stl", 100, obj);
    const json f = seating("--chair '" + file + "'");
    ASSERT_FALSE(f.empty()) << file;
    EXPECT_EQ(f["chair"]["surface"], file);
    EXPECT_NEAR(f["sitter"]["lean_deg"].get<double>(), p["sitter"]["lean_deg"].get<double>(), 0.05);
    for (int axis : {1, 2})
      EXPECT_NEAR(f["backrest_force_n"][axis].get<double>(),
                  p["backrest_force_n"][axis].get<double>(), 0.5)
          << file;
    for (std::size_t k = 0; k < 17; ++k)
      EXPECT_NEAR(f["joints"][k]["axial_n"].get<double>(), p["joints"][k]["axial_n"].get<double>(),
                  1.0)
          << file << " " << p["joints"][k]["joint"];
  }
}

TEST(CliSeating, SweepWritesOneRowPerValueItsPlotsAndTheLiteratureTrends) {
  const std::string csv = tmp("sweep.csv"), out = tmp("sweep_out");
  const CliRun r = run_spinesim(
      "study seating-sweep --parameter lumbar-support --values 0,25,50 --quiet --csv '" + csv +
      "' --out '" + out + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(count_lines(csv_table(csv)), 4);  // header + 3
  EXPECT_NE(r.out.find("lumbar-support"), std::string::npos);
  EXPECT_NE(r.out.find("Andersson"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(fs::path(out) / "seating_sweep.json"));
  EXPECT_TRUE(fs::exists(fs::path(out) / "plots" / "seating_sweep.png")) << r.err;
  EXPECT_TRUE(fs::exists(fs::path(out) / "report.html")) << r.err;
}

TEST(CliSeating, BadChairsAreRefusedInOneLine) {
  expect_refused(run_spinesim("study seating --lumbar-support -5"), "lumbar support depth");
  expect_refused(run_spinesim("study seating --backrest-recline 200"), "backrest recline");
  expect_refused(run_spinesim("study seating --seat-angle nan"), "--seat-angle");
  expect_refused(run_spinesim("study seating --lumbar-support 30 --lumbar-height 900"),
                 "above the backrest");
  expect_refused(run_spinesim("study seating --pelvic-tilt 80"), "--pelvic-tilt");
  expect_refused(run_spinesim("study seating --chair /nonexistent/chair.stl"), "no such file");
  const std::string junk = tmp("junk.stl");
  std::ofstream(junk) << "this is not a surface\n";
  expect_refused(run_spinesim("study seating --chair '" + junk + "'"), "junk.stl");
  expect_refused(
      run_spinesim("study seating --chair '" + backrest_file("away.stl", 100, false, true) + "'"),
      "does not face the back");
  expect_refused(run_spinesim("study seating-sweep --parameter colour --values 1,2"), "not one of");
  expect_refused(run_spinesim("study seating-sweep --parameter seat-angle --values 1,x"),
                 "--values: 'x' is not a finite number");
  expect_refused(run_spinesim("study seating-sweep --parameter backrest-recline --values 90,170"),
                 "backrest-recline 170");
}

// The haptic loop on the seated spine: a scripted drag of T1 hooks the spine leaning on the
// backrest; the worker solves the seated equilibrium under the hook without a failure.
TEST(CliSeating, HapticLoopDragsTheSeatedSpine) {
  const std::string script = std::string(SPINESIM_DATA_DIR) + "/haptics/drag_t1_sagittal.csv";
  const auto r = run_spinesim(
      "haptics run --scene spine --triangles 1500 --spine multirate --posture seated "
      "--backrest-recline 105 --script '" +
      script + "' --duration 3 --no-realtime --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = json::parse(r.out);
  const auto& c = j["compliant_stage"];
  EXPECT_EQ(c["posture"], "seated");
  EXPECT_GT(c["worker_solves"].get<int>(), 3);
  EXPECT_EQ(c["worker_failures"].get<int>(), 0) << c["worker_error"];
  EXPECT_GT(c["max_spine_force_n"].get<double>(), 20.0);
  EXPECT_EQ(j["non_finite_ticks"].get<long>(), 0);
  expect_refused(run_spinesim("haptics run --scene spine --posture seated --spine database"),
                 "--spine multirate");
  expect_refused(run_spinesim("haptics run --scene spine --chair x.stl"), "--posture seated");
}
