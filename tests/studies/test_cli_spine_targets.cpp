// Issue 5's targets that the model does NOT meet yet (measured, not loosened): the McGill and
// Wilke validation windows, "fusion reduces motion" under the forward force, and a stable
// equilibrium under a backward force on T1. Label `targets`: left out of the default and sanitizer runs
// so main stays green; run them with `ctest --test-dir build/release -L targets`.
#include "spine_cli_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

using nlohmann::json;
using namespace spinesim::test_cli;

// Thesis 3.3.4: with the lumbar muscles in, the spine reached equilibrium under backward forces.
// Ours does, but under 300 N backward on T1 that equilibrium is not stable (negative tangent
// stiffness in lumbar lateral bending): minimal-effort recruitment does not co-contract.
TEST(SpineTargets, BackwardForceOnT1GivesAStableEquilibrium) {
  const json j = solve_json("--force T1:0,0,-300");
  ASSERT_FALSE(j.empty());
  EXPECT_GT(j["stability"]["min_stiffness_nmm_per_rad"].get<double>(), 0.0) << j["stability"]["softest_mode"];
}

TEST(SpineTargets, McGillAndNormanL5S1Window) {
  const json& a = study("validation")["mcgill"];
  ASSERT_FALSE(a.is_null());
  const double axial = a["axial_n"], shear = a["shear_n"];
  EXPECT_GE(axial, 3929.0) << "L5-S1 axial (joint frame) at 238 N·m, T7 force " << a["t7_force_n"];
  EXPECT_LE(axial, 4688.0) << "L5-S1 axial (joint frame) at 238 N·m, T7 force " << a["t7_force_n"];
  EXPECT_LE(shear, 650.0);
}

TEST(SpineTargets, WilkeCrateL4L5Window) {
  const json& b = study("validation")["wilke"];
  ASSERT_FALSE(b.is_null());
  EXPECT_NEAR(b["axial_n"].get<double>(), 3240.0, 0.15 * 3240.0) << "L4-L5 axial (joint frame), crate held";
}

// "spinal fusion at L3-L4-L5 will restrict the range of motion of the whole spine the most ...
// The same results are achieved when applying equal backward and lateral forces".
TEST(SpineTargets, FusionReducesT1Motion) {
  for (const char* load : {"forward", "backward", "lateral"})
    for (const auto& f : fused_levels()) EXPECT_LT(t1_motion(f, load), t1_motion("normal", load)) << f << ", " << load;
}

