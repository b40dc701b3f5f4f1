// `spinesim spine solve --scoliosis`: the curve and its measured rest posture in the JSON, the
// spine standing in its curve (the apex to the convex side), and every refusal in one line.
#include "spine_cli_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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
  expect_refused(run_spinesim("spine solve --scoliosis thoracic --cobb 30 --rib-cage"),
                 "rib cage");
  expect_refused(run_spinesim("spine solve --scoliosis thoracic --cobb 30 --convex up"),
                 "--convex");
}
