// `spinesim spine solve --scoliosis`: the curve and its measured rest posture in the JSON, the
// spine standing in its curve (the apex to the convex side), and every refusal in one line.
#include "spine_cli_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <string>

using nlohmann::json;
using namespace spinesim::test_cli;

TEST(ScoliosisSolve, TheCurveAndItsRestPostureAreReportedAndTheSpineStandsInIt) {
  const json j = solve_json("--scoliosis thoracic --cobb 40 --apical-rotation 15");
  ASSERT_FALSE(j.empty());
  const json& s = j["options"]["scoliosis"];
  EXPECT_EQ(s["type"], "thoracic");
  EXPECT_EQ(s["apex"], "T8");
  EXPECT_EQ(s["convex"], "right");
  EXPECT_NEAR(s["rest_posture"]["cobb_deg"].get<double>(), 40, 1e-6);
  EXPECT_NEAR(s["rest_posture"]["t1_offset_mm"].get<double>(), 0, 1e-3);
  EXPECT_LT(s["rest_posture"]["apex_offset_mm"].get<double>(), -5);  // the body's right is −x
  EXPECT_TRUE(j["converged"].get<bool>());
  // Under gravity the apex stays on the convex side, off the midline by millimetres.
  EXPECT_LT(j["vertebrae"][7]["translation_mm"][0].get<double>(), -5) << j["vertebrae"][7];
  EXPECT_TRUE(solve_json("--force T1:0,0,100")["options"]["scoliosis"].is_null());
  const CliRun text = run_spinesim("spine solve --scoliosis thoracic --cobb 40");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("scoliosis: thoracic, T5-T11, apex T8, convex right; at rest Cobb 40.0"),
            std::string::npos)
      << text.out.substr(0, 600);
}

TEST(ScoliosisSolve, ACustomLeftCurveMirrorsTheRightOne) {
  const json right = solve_json("--scoliosis thoracic --cobb 30 --no-muscles --no-gravity");
  const json left =
      solve_json("--scoliosis thoracic --cobb 30 --convex left --no-muscles --no-gravity");
  ASSERT_FALSE(right.empty() || left.empty());
  EXPECT_EQ(left["options"]["scoliosis"]["type"], "custom (thoracic)");
  for (int v = 0; v < 17; ++v)
    EXPECT_NEAR(right["vertebrae"][v]["translation_mm"][0].get<double>(),
                -left["vertebrae"][v]["translation_mm"][0].get<double>(), 1e-6)
        << v;
}

TEST(ScoliosisSolve, BadCurvesAreRefused) {
  expect_refused(run_spinesim("spine solve --cobb 40"), "--scoliosis");
  expect_refused(run_spinesim("spine solve --scoliosis thoracic"), "--cobb");
  expect_refused(run_spinesim("spine solve --scoliosis double --cobb 30"), "thoracolumbar");
  expect_refused(run_spinesim("spine solve --scoliosis lumbar --cobb 100"), "closes its disc");
  expect_refused(run_spinesim("spine solve --scoliosis thoracic --cobb 30 --curve-ends T6"),
                 "upper,lower");
  expect_refused(run_spinesim("spine solve --scoliosis thoracic --cobb 30 --apex L3"), "apex");
  expect_refused(run_spinesim("spine solve --scoliosis thoracic --cobb 30 --rib-cage"), "rib cage");
  expect_refused(run_spinesim("spine solve --scoliosis thoracic --cobb 30 --convex up"),
                 "--convex");
}

// The haptic scene: the scoliotic spine is dragged on the multirate spine (its solves start from
// the curve; a mild curve, because the scripted hand reaches for T1 where the straight spine has
// it and a curve lowers T1 — by 6 mm at 30°); the displacement database is the straight spine's
// and is refused with a curve.
TEST(ScoliosisHaptics, TheCurvedSpineIsDraggedAndTheDatabaseRefused) {
  const std::string script = std::string(SPINESIM_DATA_DIR) + "/haptics/drag_t1_lateral.csv";
  const std::string rec = tmp("curved-drag.csv");
  const CliRun r = run_spinesim(
      "haptics run --scene spine --triangles 1500 --spine multirate --scoliosis lumbar --cobb 15 "
      "--script '" +
      script + "' --duration 2 --no-realtime --json --record '" + rec + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_NE(j["scene_description"].get<std::string>().find("scoliosis"), std::string::npos);
  EXPECT_GT(j["compliant_stage"]["hooked_ticks"].get<int>(), 500);
  EXPECT_GT(j["compliant_stage"]["worker_solves"].get<int>(), 2);
  EXPECT_EQ(j["compliant_stage"]["worker_failures"].get<int>(), 0);
  // The offline discs follow the curved spine: the recording names its curve, and `spine discs`
  // steps the wedged discs through the drag without a rejected step.
  const std::string out = tmp("curved-discs");
  const CliRun d = run_spinesim("spine discs --quiet --json --vertebra-triangles 0 --record '" +
                                rec + "' --out '" + out + "'");
  ASSERT_EQ(d.status, 0) << d.err;
  const json dj = json::parse(d.out);
  EXPECT_EQ(dj["scoliosis"]["cobb_deg"].get<double>(), 15);
  ASSERT_EQ(dj["per_disc"].size(), 17u);
  for (const auto& disc : dj["per_disc"]) {
    EXPECT_EQ(disc["rejected_steps"].get<int>(), 0) << disc["level"];
    EXPECT_EQ(disc["inverted_tets_max"].get<int>(), 0) << disc["level"];
  }
  expect_refused(run_spinesim("haptics run --duration 1 --scene spine --spine database "
                              "--scoliosis thoracic --cobb 30"),
                 "straight spine");
  expect_refused(
      run_spinesim("haptics run --duration 1 --scene plane --scoliosis thoracic --cobb 30"),
      "--scene spine");
}

// A schedule on a curved spine: the curve is reported, its recording is measured from the
// curve's rest posture (so the first frame is the standing sag, a few mm, not the curve's own
// offsets from the straight spine), and the offline discs rest wedged in the curve and follow it.
TEST(ScoliosisScheduleCli, ACurvedSpinesScheduleIsRecordedFromItsCurveAndItsDiscsFollow) {
  const std::string loads = tmp("curved-loads.csv");
  spit(loads, "time_s,T7.fz_n\n0,0\n0.2,100\n");
  const std::string rec = tmp("curved-schedule.csv");
  const CliRun r = run_spinesim(
      "spine schedule --quiet --json --step 0.1 --scoliosis lumbar "
      "--cobb 30 --loads " +
      in_quotes(loads) + " --record " + in_quotes(rec));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["scoliosis"]["cobb_deg"].get<double>(), 30);
  // L2 rests 29.6 mm to the side of the straight spine; standing sags it 3 mm further.
  const json rest = solve_json("--scoliosis lumbar --cobb 30 --no-gravity --no-muscles");
  double at_rest = 0;
  for (const auto& v : rest["vertebrae"])
    if (v["name"] == "L2") at_rest = v["translation_mm"][0].get<double>();
  EXPECT_GT(std::abs(at_rest), 20);
  EXPECT_LT(std::abs(csv_column(rec, "L2_tx_mm").front()), 0.25 * std::abs(at_rest));

  const std::string out = tmp("curved-schedule-discs");
  const CliRun d = run_spinesim("spine discs --quiet --json --vertebra-triangles 0 --record " +
                                in_quotes(rec) + " --out " + in_quotes(out));
  ASSERT_EQ(d.status, 0) << d.err;
  const json dj = json::parse(d.out);
  EXPECT_EQ(dj["scoliosis"]["type"], "lumbar");
  for (const auto& disc : dj["per_disc"]) {
    EXPECT_EQ(disc["rejected_steps"].get<int>(), 0) << disc["level"];
    EXPECT_EQ(disc["inverted_tets_max"].get<int>(), 0) << disc["level"];
  }
}

TEST(ScoliosisStudyCli, TablesNameTheSourcesAndTheJsonHasEveryCurve) {
  const CliRun r = run_spinesim("study scoliosis --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s : {"Meir", "Modi", "concave (MPa)", "MATCH", "DIFFERS", "Body: male"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  const json& j = study("scoliosis");
  ASSERT_EQ(j["cases"].size(), 9u);
  for (const auto& c : j["cases"])
    if (c["posed"].get<bool>()) EXPECT_FALSE(c["discs"].empty()) << c["type"];
  expect_refused(run_spinesim("study scoliosis --height 3"), "height");
}

// A disc of the curve meshed wedged between its posed vertebrae: its frontal wedge is the
// joint's rest bend (toward the concavity: negative for a right-convex curve), its endplates
// meet at an angle of that size, no tet inverts; the viewer draws the mesh (it has no fields).
TEST(ScoliosisMesh, TheApicalDiscIsWedgedAsTheCurveHasIt) {
  const std::string vtu = tmp("wedged_t7t8.vtu");
  const CliRun r = run_spinesim(
      "mesh disc --level T7-T8 --structured --placement local "
      "--scoliosis thoracic --cobb 40 --out '" +
      vtu + "' --json --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  const double wedge = j["scoliosis"]["frontal_wedge_deg"].get<double>();
  EXPECT_LT(wedge, -3);
  EXPECT_GT(j["min_dihedral_deg"].get<double>(), 5);
  expect_refused(run_spinesim("mesh disc --inferior a.stl --superior b.stl --scoliosis thoracic "
                              "--cobb 30 --out '" +
                              tmp("x.vtu") + "'"),
                 "--level");
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0) GTEST_SKIP() << "no xvfb-run";
  const std::string png = tmp("wedged.png");
  const CliRun v = run_spinesim("view --play '" + vtu +
                                    "' --no-panel --width 320 --height 240 "
                                    "--frames 2 --screenshot '" +
                                    png + "'",
                                "xvfb-run -a -s '-screen 0 640x480x24' ");
  EXPECT_EQ(v.status, 0) << v.err;
  EXPECT_TRUE(std::filesystem::exists(png));
}
